//! Every scene file in `scenes/` loads and renders; renders are bit-identical
//! whatever the thread count. Object transforms place every shape as the
//! equivalent hand-placed description would.

use std::path::Path;

use glam::Vec3;
use rust_v::geometry::Ray;
use rust_v::scene::load_scene_str;
use rust_v::shape::{Cuboid, Shape};

use crate::common::{render_str, root, rust_v, temp_dir};

fn scene_files() -> Vec<std::path::PathBuf> {
    let mut v: Vec<_> = std::fs::read_dir(root().join("scenes"))
        .expect("scenes/ exists")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .collect();
    v.sort();
    v
}

#[test]
fn every_scene_renders_at_16x16() {
    let dir = temp_dir("scenes");
    let files = scene_files();
    assert!(files.len() >= 2, "expected scene files, found {files:?}");
    for scene in files {
        let out = dir.join(format!("{}.png", scene.file_stem().unwrap().to_string_lossy()));
        let o = rust_v(&[
            "render",
            scene.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--width",
            "16",
            "--height",
            "16",
            "--spp",
            "2",
            "--quiet",
        ]);
        assert!(o.status.success(), "{}: {}", scene.display(), String::from_utf8_lossy(&o.stderr));
        let img = image::open(&out).expect("output is a PNG");
        assert_eq!((img.width(), img.height()), (16, 16));
        assert!(matches!(img, image::DynamicImage::ImageRgb16(_)), "16-bit RGB PNG");
        // Something in every scene is lit, except the prism, whose only light
        // is 0.07 degrees across: at 16x16 no pixel is likely to see it.
        let lit_exempt = scene.ends_with("prism.ron");
        assert!(
            lit_exempt || img.to_rgb16().pixels().any(|p| p.0.iter().any(|&c| c > 0)),
            "{} is black",
            scene.display()
        );
    }
}

#[test]
fn render_is_bit_identical_for_any_thread_count() {
    let dir = temp_dir("threads");
    let mut outputs = Vec::new();
    for threads in ["1", "2", "3"] {
        let out = dir.join(format!("t{threads}.exr"));
        let o = rust_v(&[
            "render",
            "scenes/cornell.ron",
            "-o",
            out.to_str().unwrap(),
            "--width",
            "32",
            "--height",
            "32",
            "--spp",
            "4",
            "--threads",
            threads,
            "--quiet",
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        outputs.push(std::fs::read(&out).unwrap());
    }
    assert_eq!(outputs[0], outputs[1], "1 vs 2 threads");
    assert_eq!(outputs[0], outputs[2], "1 vs 3 threads");
}

/// The scene-format example in the README parses and loads (it uses every
/// shape, material, spectrum and IOR form), so the documentation stays true.
#[test]
fn readme_scene_example_loads() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let start = readme.find("```ron\n").expect("README has a ```ron block") + "```ron\n".len();
    let end = start + readme[start..].find("```").unwrap();
    let example = &readme[start..end];
    // Paths in the example are relative to a scene in scenes/.
    let scene = rust_v::scene::load_scene_str(example, &root().join("scenes/readme-example.ron"), &Default::default())
        .unwrap_or_else(|e| panic!("README example: {e}"));
    assert_eq!(scene.object_count(), 14, "13 objects and one instance of a one-mesh group");
    assert_eq!((scene.objects[7].priority, scene.objects[8].priority), (1, 2), "priorities of the nested glass");
    assert_eq!(
        scene.lights.len(),
        10,
        "disk, sphere, quad, cuboid and mesh emitters; point, spot, distant and beam lights; the sky"
    );
    assert!(scene.has_environment());
    assert!(scene.has_dispersion());
}

/// A scene of one object (its RON text) with two materials and a point light.
fn one_object(object: &str) -> String {
    format!(
        r#"(
    camera: (eye: (0, 0, 8), look_at: (0, 0, 0), fov_deg: 40),
    render: (width: 8, height: 8, spp: 1),
    materials: {{ "white": Lambertian(reflectance: Constant(0.5)), "glass": Dielectric(ior: Constant(1.5)) }},
    objects: [ {object} ],
    lights: [ Point(position: (0, 3, 3), intensity: Constant(10)) ],
)"#
    )
}

/// The shape of the one object of [`one_object`], loaded as if from `dir`.
fn shape_in(dir: &Path, object: &str) -> Shape {
    let scene = load_scene_str(&one_object(object), &dir.join("t.ron"), &Default::default())
        .unwrap_or_else(|e| panic!("{object}: {e}"));
    scene.objects.into_iter().next().unwrap().shape
}

fn shape(object: &str) -> Shape {
    shape_in(Path::new("."), object)
}

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).abs().max_element() <= 1e-5 * (1.0 + b.abs().max_element())
}

#[test]
fn transformed_spheres_disks_and_planes_are_the_placed_shapes() {
    // Scale then translate, no rotation: exact in f32.
    let Shape::Sphere(s) = shape(
        r#"(shape: Sphere(center: (1, 0, 0), radius: 0.5), material: "white", transform: (scale: 2, translate: (0, 1, 0)))"#,
    ) else {
        panic!("a sphere stays a sphere")
    };
    assert_eq!((s.center, s.radius), (Vec3::new(2.0, 1.0, 0.0), 1.0));
    // A quarter turn about z takes +x to +y.
    let Shape::Sphere(s) = shape(
        r#"(shape: Sphere(center: (1, 0, 0), radius: 0.5), material: "white", transform: (rotate_deg: (0, 0, 90)))"#,
    ) else {
        panic!("a sphere stays a sphere")
    };
    assert!(close(s.center, Vec3::Y) && s.radius == 0.5, "{s:?}");
    let Shape::Bubble(b) = shape(
        r#"(shape: Bubble(center: (0, 0, 0), outer_radius: 1, inner_radius: 0.5), material: "glass", transform: (scale: 3, translate: (0, 0, 1)))"#,
    ) else {
        panic!("a bubble stays a bubble")
    };
    assert_eq!((b.center, b.outer_radius, b.inner_radius), (Vec3::Z, 3.0, 1.5));
    // A quarter turn about x takes +z to -y.
    let Shape::Disk(d) = shape(
        r#"(shape: Disk(center: (0, 0, 0), normal: (0, 0, 1), radius: 1), material: "white", transform: (scale: 2, rotate_deg: (90, 0, 0), translate: (0, 0, 1)))"#,
    ) else {
        panic!("a disk stays a disk")
    };
    assert!(close(d.center, Vec3::Z) && close(d.normal, -Vec3::Y) && d.radius == 2.0, "{d:?}");
    // Under a non-uniform scale a plane's normal stays perpendicular to the scaled
    // plane: (1, -1, 0) lies in the plane, (2, -1, 0) in the scaled one.
    let Shape::Plane(p) = shape(
        r#"(shape: Plane(point: (0, 0, 0), normal: (1, 1, 0)), material: "white", transform: (scale: (2, 1, 1), translate: (0, 0, 5)))"#,
    ) else {
        panic!("a plane stays a plane")
    };
    assert_eq!(p.point, Vec3::new(0.0, 0.0, 5.0));
    assert!(p.normal.dot(Vec3::new(2.0, -1.0, 0.0)).abs() < 1e-6 && p.normal.z == 0.0, "{:?}", p.normal);
    assert!((p.normal.length() - 1.0).abs() < 1e-6 && p.normal.x > 0.0);
}

#[test]
fn a_transformed_quad_is_the_placed_parallelogram() {
    let Shape::Quad(q) = shape(
        r#"(shape: Quad(origin: (0, 0, 0), edge_u: (1, 0, 0), edge_v: (0, 1, 0)), material: "white", transform: (scale: (2, 3, 1), rotate_deg: (0, 0, 90), translate: (1, 1, 1)))"#,
    ) else {
        panic!("a quad stays a quad")
    };
    // Scaled to (2, 0, 0) and (0, 3, 0), turned a quarter about z.
    assert!(close(q.origin, Vec3::ONE) && close(q.edge_u, Vec3::new(0.0, 2.0, 0.0)), "{q:?}");
    assert!(close(q.edge_v, Vec3::new(-3.0, 0.0, 0.0)), "{q:?}");
    // It covers x in [-2, 1], y in [1, 3] at z = 1, normal +z as before.
    let hit = |x: f32, y: f32| q.intersect(&Ray::new(Vec3::new(x, y, 5.0), -Vec3::Z), f32::INFINITY);
    let h = hit(-1.5, 2.5).expect("inside");
    assert!((h.t - 4.0).abs() < 1e-5 && close(h.n, Vec3::Z), "{h:?}");
    assert!(hit(-2.1, 2.0).is_none() && hit(0.0, 3.1).is_none() && hit(1.1, 2.0).is_none());
}

#[test]
fn a_transformed_cuboid_stays_a_box_or_becomes_a_closed_mesh() {
    let Shape::Cuboid(c) = shape(
        r#"(shape: Cuboid(min: (-1, -1, -1), max: (1, 1, 1)), material: "white", transform: (scale: (1, 2, 3), translate: (0, 0, 1)))"#,
    ) else {
        panic!("without a rotation a cuboid stays a cuboid")
    };
    assert_eq!((c.min, c.max), (Vec3::new(-1.0, -2.0, -2.0), Vec3::new(1.0, 2.0, 4.0)));
    // A quarter turn about y takes (x, y, z) to (z, y, -x): the box [0,1]x[0,2]x[0,3]
    // becomes [0,3]x[0,2]x[-1,0].
    let rotated = shape(
        r#"(shape: Cuboid(min: (0, 0, 0), max: (1, 2, 3)), material: "glass", transform: (rotate_deg: (0, 90, 0)))"#,
    );
    let Shape::Mesh(m) = &rotated else { panic!("a rotated cuboid becomes a mesh") };
    assert_eq!(m.triangle_count(), 12);
    let b = m.bounds();
    let (lo, hi) = (Vec3::new(0.0, 0.0, -1.0), Vec3::new(3.0, 2.0, 0.0));
    assert!(close(b.min, lo) && close(b.max, hi), "{b:?}");
    let aligned = Cuboid::new(lo, hi);
    // Rays from outside and from inside meet it where they meet the equivalent box,
    // with the outward normal (a solid: a ray leaving it has n along the ray).
    let centre = (lo + hi) * 0.5;
    let dirs = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z, Vec3::new(0.3, 0.5, -0.8).normalize()];
    for d in dirs {
        for origin in [centre, centre - d * 10.0 + Vec3::new(0.1, 0.05, -0.02)] {
            let ray = Ray::new(origin, d);
            let (got, want) =
                (rotated.intersect(&ray, f32::INFINITY).unwrap(), aligned.intersect(&ray, f32::INFINITY).unwrap());
            assert!((got.t - want.t).abs() < 1e-4, "{d}: t {} vs {}", got.t, want.t);
            assert!(close(got.n, want.n), "{d}: n {} vs {}", got.n, want.n);
            if origin == centre {
                assert!(got.n.dot(d) > 0.0, "leaving the solid along {d}");
            }
        }
    }
    // As glass it is a volume that the points inside are in, with its priority.
    let text = one_object(
        r#"(shape: Cuboid(min: (-1, -1, -1), max: (1, 1, 1)), material: "glass", priority: 2, transform: (rotate_deg: (0, 30, 10)))"#,
    );
    let scene = load_scene_str(&text, Path::new("t.ron"), &Default::default()).unwrap();
    let inside = scene.volumes_at(Vec3::new(0.2, -0.3, 0.1));
    assert_eq!(inside.entries().iter().map(|v| (v.object, v.priority)).collect::<Vec<_>>(), [(0, 2)]);
    assert!(scene.volumes_at(Vec3::new(0.0, 0.0, 2.0)).is_empty(), "outside");
    // It emits like any mesh.
    let text = one_object(
        r#"(shape: Cuboid(min: (0, 0, 0), max: (1, 1, 1)), emission: Constant(1), transform: (rotate_deg: (30, 0, 0)))"#,
    );
    let scene = load_scene_str(&text, Path::new("t.ron"), &Default::default()).unwrap();
    assert_eq!(scene.lights.len(), 2);
}

#[test]
fn a_mesh_applies_its_own_transform_then_the_objects() {
    let dir = temp_dir("mesh-transform");
    std::fs::write(dir.join("tri.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let Shape::Mesh(m) = shape_in(
        &dir,
        r#"(shape: Mesh(path: "tri.obj", scale: 2, translate: (0, 0, 1)), material: "white", transform: (rotate_deg: (0, 0, 90), translate: (5, 0, 0)))"#,
    ) else {
        panic!("a mesh stays a mesh")
    };
    // Own: (0,0,1), (2,0,1), (0,2,1); then a quarter turn about z and +5 in x.
    let mut got = m.triangle(0).to_vec();
    got.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    let want = [Vec3::new(3.0, 0.0, 1.0), Vec3::new(5.0, 0.0, 1.0), Vec3::new(5.0, 2.0, 1.0)];
    assert!(got.iter().zip(want).all(|(g, w)| close(*g, w)), "{got:?}");
}

#[test]
fn bad_transforms_name_the_field() {
    let cases = [
        (
            r#"Sphere(center: (0, 0, 0), radius: 1)"#,
            "scale: (1, 2, 1)",
            "objects[0].transform.scale",
            "a sphere takes only a uniform scale",
        ),
        (
            r#"Bubble(center: (0, 0, 0), outer_radius: 1, inner_radius: 0.5)"#,
            "scale: (2, 2, 1)",
            "objects[0].transform.scale",
            "a bubble takes only a uniform scale",
        ),
        (
            r#"Disk(center: (0, 0, 0), normal: (0, 0, 1), radius: 1)"#,
            "scale: (2, 2, 1)",
            "objects[0].transform.scale",
            "a disk takes only a uniform scale",
        ),
        (
            r#"Sphere(center: (0, 0, 0), radius: 1)"#,
            "scale: -1",
            "objects[0].transform.scale",
            "expected a positive number",
        ),
        (
            r#"Quad(origin: (0, 0, 0), edge_u: (1, 0, 0), edge_v: (0, 1, 0))"#,
            "scale: (1, 0, 1)",
            "objects[0].transform.scale[1]",
            "expected a positive number",
        ),
        (
            r#"Sphere(center: (0, 0, 0), radius: 1)"#,
            "rotate_deg: (NaN, 0, 0)",
            "objects[0].transform.rotate_deg",
            "finite",
        ),
        (
            r#"Plane(point: (0, 0, 0), normal: (0, 1, 0))"#,
            "translate: (1e30, 0, 0)",
            "objects[0].transform.translate",
            "finite",
        ),
        (
            r#"Sphere(center: (1e15, 0, 0), radius: 1)"#,
            "translate: (1e15, 0, 0)",
            "objects[0].transform",
            "out of range",
        ),
        (r#"Sphere(center: (0, 0, 0), radius: 1e10)"#, "scale: 1e10", "objects[0].transform.scale", "size"),
        (
            r#"Cuboid(min: (0, 0, 0), max: (1, 1, 1))"#,
            "scale: 1e-30, rotate_deg: (0, 0, 45)",
            "objects[0].transform.scale",
            "singular",
        ),
    ];
    for (shape, transform, field, message) in cases {
        let text = one_object(&format!(r#"(shape: {shape}, material: "glass", transform: ({transform}))"#));
        let e = load_scene_str(&text, Path::new("t.ron"), &Default::default()).unwrap_err().to_string();
        // `t.ron:LINE:COL: field: message` (the position of the field in the text).
        assert!(
            e.starts_with("t.ron:") && e.contains(&format!(": {field}: ")) && e.contains(message),
            "{transform}: {e}"
        );
    }
    // A misspelt part is a parse error with its position.
    let text = one_object(
        r#"(shape: Sphere(center: (0, 0, 0), radius: 1), material: "white", transform: (rotate: (0, 0, 1)))"#,
    );
    let e = load_scene_str(&text, Path::new("t.ron"), &Default::default()).unwrap_err().to_string();
    assert!(e.starts_with("t.ron:5:") && e.contains("`rotate`") && e.contains("`rotate_deg`"), "{e}");
}

/// A unit square at z = 0 facing +z, seen from the front and lit.
const SQUARE_POSITIONS: &str = "positions: [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)]";

fn square_scene(shape: &str) -> String {
    format!(
        r#"(
    camera: (eye: (0.3, 0.2, 4), look_at: (0, 0, 0), fov_deg: 40),
    render: (width: 12, height: 12, spp: 4, seed: 3),
    materials: {{ "white": Lambertian(reflectance: Constant(0.5)) }},
    objects: [
        (shape: {shape}, material: "white"),
        (shape: Sphere(center: (0.5, 0.5, 2), radius: 0.2), emission: Constant(20)),
    ],
    lights: [ Point(position: (-1, 1, 2), intensity: Constant(3)) ],
)"#
    )
}

#[test]
fn an_inline_mesh_renders_like_the_same_obj_file() {
    let dir = temp_dir("inline-mesh");
    let obj = dir.join("square.obj");
    std::fs::write(&obj, "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3\nf 1 3 4\n").unwrap();
    let from_file = render_str(&square_scene(&format!("Mesh(path: {:?})", obj.to_str().unwrap())), &Default::default());
    let inline = render_str(
        &square_scene(&format!("Triangles({SQUARE_POSITIONS}, indices: [(0, 1, 2), (0, 2, 3)])")),
        &Default::default(),
    );
    let (a, b) = (from_file.mean_xyz(), inline.mean_xyz());
    assert!(a.iter().filter(|p| p[1] > 0.0).count() > a.len() / 4, "the square is lit");
    assert!(a.iter().zip(&b).all(|(p, q)| p.map(f64::to_bits) == q.map(f64::to_bits)), "bit-identical");
    // With normals and uvs it is still a mesh, and it can emit.
    let text = one_object(&format!(
        "(shape: Triangles({SQUARE_POSITIONS}, indices: [(0, 1, 2), (0, 2, 3)], normals: [(0, 0, 1), (0, 0, 1), \
         (0, 0, 1), (0, 0, 1)], uvs: [(0, 0), (1, 0), (1, 1), (0, 1)]), emission: Constant(1))"
    ));
    let scene = load_scene_str(&text, Path::new("t.ron"), &Default::default()).unwrap();
    let Shape::Mesh(m) = &scene.objects[0].shape else { panic!("an inline mesh is a mesh") };
    assert!(m.has_normals() && m.triangle_count() == 2 && scene.lights.len() == 2);
}

#[test]
fn bad_inline_meshes_name_the_field() {
    let p3 = "positions: [(0, 0, 0), (1, 0, 0), (0, 1, 0)]";
    let cases = [
        (format!("{p3}, indices: [(0, 1, 5)]"), "objects[0].shape.indices[0]", "vertex index 5 out of range"),
        (format!("{p3}, indices: [(0, 1, 2), (2, 3, 0)]"), "objects[0].shape.indices[1]", "there are 3 positions"),
        (format!("{p3}, indices: [(0, 1, 2)], normals: [(0, 0, 1)]"), "objects[0].shape.normals", "found 1"),
        (
            format!("{p3}, indices: [(0, 1, 2)], normals: [(0, 0, 1), (0, 0, 0), (0, 0, 1)]"),
            "objects[0].shape.normals[1]",
            "non-zero",
        ),
        (
            format!("{p3}, indices: [(0, 1, 2)], uvs: [(0, 0), (1, 0)]"),
            "objects[0].shape.uvs",
            "one entry per position",
        ),
        (format!("{p3}, indices: [(0, 1, 2)], uvs: [(0, 0), (1, 0), (inf, 0)]"), "objects[0].shape.uvs[2]", "finite"),
        ("positions: [(0, 0, 0), (1, NaN, 0)], indices: [(0, 1, 1)]".into(), "objects[0].shape.positions[1]", "finite"),
        ("positions: [], indices: [(0, 1, 2)]".into(), "objects[0].shape.positions", "at least one"),
        (format!("{p3}, indices: []"), "objects[0].shape.indices", "at least one triangle"),
        (format!("{p3}, indices: [(0, 1, 1)]"), "objects[0].shape.indices", "no valid triangles"),
    ];
    for (body, field, message) in cases {
        let text = one_object(&format!(r#"(shape: Triangles({body}), material: "white")"#));
        let e = load_scene_str(&text, Path::new("t.ron"), &Default::default()).unwrap_err().to_string();
        assert!(e.starts_with("t.ron:") && e.contains(&format!(": {field}: ")) && e.contains(message), "{body}: {e}");
    }
}

/// An inline mesh's per-vertex uvs are interpolated at a hit: a square
/// `(-1..1)²` in the z = 0 plane with uvs (0,0), (1,0), (1,1), (0,1) at its
/// corners gives `((x + 1) / 2, (y + 1) / 2)` at every point, on both of its
/// triangles (an affine map, so interpolation is exact up to rounding). Without
/// uvs each triangle gets pbrt's default, so the same points differ.
#[test]
fn inline_mesh_uvs_are_interpolated_at_hits() {
    let with = r#"(shape: Triangles(positions: [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], indices: [(0, 1, 2), (0, 2, 3)], uvs: [(0, 0), (1, 0), (1, 1), (0, 1)]), material: "white")"#;
    let without = r#"(shape: Triangles(positions: [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], indices: [(0, 1, 2), (0, 2, 3)]), material: "white")"#;
    let load = |o: &str| load_scene_str(&one_object(o), Path::new("t.ron"), &Default::default()).unwrap();
    let (a, b) = (load(with), load(without));
    let mut differs = false;
    for (x, y) in [(0.5f32, -0.25f32), (-0.6, 0.7), (0.1, 0.05), (-0.9, -0.2)] {
        let ray = Ray::new(Vec3::new(x, y, 3.0), Vec3::new(0.0, 0.0, -1.0));
        let si = a.intersect(&ray, f32::INFINITY).expect("hits the square");
        let uv = a.uv(&si);
        let want = glam::Vec2::new((x + 1.0) / 2.0, (y + 1.0) / 2.0);
        assert!((uv - want).abs().max_element() < 1e-5, "({x}, {y}): {uv} want {want}");
        let si = b.intersect(&ray, f32::INFINITY).unwrap();
        differs |= (b.uv(&si) - want).abs().max_element() > 1e-3;
    }
    assert!(differs, "without uvs the default per-triangle mapping applies");
}

/// Texture coordinates come from mesh files: OBJ `vt` and PLY `s t` / `u v` /
/// `texture_u texture_v` columns, interpolated at hits like inline `uvs`. The
/// same square as in `inline_mesh_uvs_are_interpolated_at_hits`, with uvs
/// `((x + 1) / 2, (y + 1) / 2)` at its corners, in each format.
#[test]
fn mesh_files_bring_their_texture_coordinates() {
    let dir = temp_dir("mesh-uvs");
    let obj = "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";
    std::fs::write(dir.join("sq.obj"), obj).unwrap();
    for (name, u, v) in [("st", "s", "t"), ("uv", "u", "v"), ("tex", "texture_u", "texture_v")] {
        let ply = format!(
            "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty float {u}\nproperty float {v}\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n-1 -1 0 0 0\n1 -1 0 1 0\n1 1 0 1 1\n-1 1 0 0 1\n3 0 1 2\n3 0 2 3\n"
        );
        std::fs::write(dir.join(format!("sq-{name}.ply")), ply).unwrap();
    }
    for file in ["sq.obj", "sq-st.ply", "sq-uv.ply", "sq-tex.ply"] {
        let text = one_object(&format!(r#"(shape: Mesh(path: "{file}"), material: "white")"#));
        let scene = load_scene_str(&text, &dir.join("t.ron"), &Default::default()).unwrap_or_else(|e| panic!("{e}"));
        for (x, y) in [(0.5f32, -0.25f32), (-0.6, 0.7), (0.1, 0.05)] {
            let ray = Ray::new(Vec3::new(x, y, 3.0), Vec3::new(0.0, 0.0, -1.0));
            let si = scene.intersect(&ray, f32::INFINITY).expect("hits the square");
            let uv = scene.uv(&si);
            let want = glam::Vec2::new((x + 1.0) / 2.0, (y + 1.0) / 2.0);
            assert!((uv - want).abs().max_element() < 1e-5, "{file} ({x}, {y}): {uv} want {want}");
        }
    }
}

/// Errors found while building the scene (after parsing) name the line and
/// column of the field as well as its path: here the `radius:` of the second
/// object, on line 6, column 24, and a missing material at the first object's
/// opening parenthesis (line 4, column 9).
#[test]
fn build_errors_carry_the_field_s_position() {
    let text = "(\n    camera: (eye: (0, 1, 4), look_at: (0, 0, 0), fov_deg: 40),\n    objects: [\n        (shape: Sphere(center: (0, 0, 0), radius: 1), material: \"white\"),\n        (shape: Sphere(center: (0, 0, 0),\n                       radius: -1), material: \"white\"),\n    ],\n    materials: { \"white\": Lambertian(reflectance: Constant(0.5)) },\n)\n";
    let e = load_scene_str(text, Path::new("p.ron"), &Default::default()).unwrap_err().to_string();
    assert!(e.starts_with("p.ron:6:24: objects[1].shape.radius: "), "{e}");
    let text = text.replace("radius: -1), material: \"white\"", "radius: 1)").replacen(", material: \"white\"", "", 1);
    let e = load_scene_str(&text, Path::new("p.ron"), &Default::default()).unwrap_err().to_string();
    assert!(e.starts_with("p.ron:4:9: objects[0]"), "{e}");
}
