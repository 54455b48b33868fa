//! Native instancing (`groups:`, `Instance(group: ...)`, `transform: (matrix: ...)`):
//! instances render like copies of their group, a mirror keeps normals outward, the
//! triangles are stored once however often they are placed, a placement that cancels
//! large coordinates stays free of self-intersection, and every mistake is one error
//! line naming the field.

use std::path::Path;
use std::sync::Arc;

use rust_v::scene::load_scene_str;
use rust_v::settings::SettingsPatch;
use rust_v::shape::Shape;

use crate::common::{block_means, render_str, root};

/// The corners and outward-wound triangles of the box `[lo, hi]³` as `Triangles(...)`,
/// each vertex moved by `f` (`f` mirrors: the winding is then reversed, so the copy
/// stays outward).
fn box_triangles(lo: [f32; 3], hi: [f32; 3], f: impl Fn([f32; 3]) -> [f32; 3], mirrored: bool) -> String {
    let corners: Vec<[f32; 3]> = (0..8)
        .map(|i| {
            let c = [
                if i & 1 != 0 { hi[0] } else { lo[0] },
                if i & 2 != 0 { hi[1] } else { lo[1] },
                if i & 4 != 0 { hi[2] } else { lo[2] },
            ];
            f(c)
        })
        .collect();
    let faces = [[0, 4, 6, 2], [1, 3, 7, 5], [0, 1, 5, 4], [2, 6, 7, 3], [0, 2, 3, 1], [4, 5, 7, 6]];
    let tris: Vec<[u32; 3]> = faces.iter().flat_map(|&[a, b, c, d]| [[a, b, c], [a, c, d]]).collect();
    let pos: Vec<String> = corners.iter().map(|p| format!("({}, {}, {})", p[0], p[1], p[2])).collect();
    let idx: Vec<String> = tris
        .iter()
        .map(|t| {
            if mirrored { format!("({}, {}, {})", t[0], t[2], t[1]) } else { format!("({}, {}, {})", t[0], t[1], t[2]) }
        })
        .collect();
    format!("Triangles(positions: [{}], indices: [{}])", pos.join(", "), idx.join(", "))
}

/// An irregular closed tetrahedron (no mirror symmetry) as `Triangles`, wound outward;
/// with `negate_x` mirrored in x, and with `reverse` each triangle's winding reversed
/// (a mirrored copy needs both to stay outward).
fn wedge(negate_x: bool, reverse: bool) -> String {
    let p = [[-0.6f32, -0.5, -0.4], [0.8, -0.5, -0.2], [-0.1, -0.5, 0.7], [0.3, 0.7, 0.1]];
    // Each face turned to wind counter-clockwise seen from outside (the centroid inside).
    let centroid = p.iter().map(|v| glam::Vec3::from(*v)).sum::<glam::Vec3>() / 4.0;
    let mut faces = vec![[0u32, 1, 2], [0, 3, 1], [1, 3, 2], [2, 3, 0]];
    for f in &mut faces {
        let [a, b, d] = f.map(|i| glam::Vec3::from(p[i as usize]));
        if (b - a).cross(d - a).dot(a - centroid) < 0.0 {
            f.swap(1, 2);
        }
        if reverse {
            f.swap(1, 2);
        }
    }
    let pos: Vec<String> =
        p.iter().map(|v| format!("({}, {}, {})", if negate_x { -v[0] } else { v[0] }, v[1], v[2])).collect();
    let idx: Vec<String> = faces.iter().map(|f| format!("({}, {}, {})", f[0], f[1], f[2])).collect();
    format!("Triangles(positions: [{}], indices: [{}])", pos.join(", "), idx.join(", "))
}

fn bunny() -> String {
    root().join("meshes/bunny.obj").to_string_lossy().into_owned()
}

/// The largest difference of the 8×8 block means of two renders.
fn max_block_difference(a: &str, b: &str) -> (f64, f64) {
    max_block_difference_with(a, b, &SettingsPatch::default())
}

/// [`max_block_difference`] with `overrides` (an integrator, say) on both renders.
fn max_block_difference_with(a: &str, b: &str, overrides: &SettingsPatch) -> (f64, f64) {
    let (fa, fb) = (render_str(a, overrides), render_str(b, overrides));
    let (ma, mb) = (block_means(&fa, 8), block_means(&fb, 8));
    let diff = ma.iter().zip(&mb).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
    (diff, ma.iter().sum::<f64>() / ma.len() as f64)
}

const HEAD: &str = r#"camera: (eye: (0, 1.2, 4), look_at: (0, 0.4, 0), fov_deg: 40),
    render: (width: 32, height: 32, spp: 16, seed: 3, max_bounces: 6, integrator: path),
    materials: { "white": Lambertian(reflectance: Constant(0.7)), "red": Lambertian(reflectance: Rgb(0.7, 0.1, 0.1)),
                 "glass": Dielectric(ior: Constant(1.5)) },
    lights: [ Point(position: (2, 4, 3), intensity: Constant(20)) ],
    environment: Uniform(Constant(0.3)),"#;

/// Three instances of a group (the bunny and a box, each with its own material) render
/// like the same meshes written out as objects placed by the same transforms. The two
/// renders draw the same samples (same seed), so they differ only where the f32
/// rounding of the two placements (about 1e-6 relative) moves a hit point or across a
/// triangle edge: 8×8 block means agree within 0.1% of the image mean (measured: 3e-8
/// relative), while moving one instance by 0.05 (a twentieth of its width) changes some
/// block by 1.1% (measured), so the tolerance tells a misplaced instance from rounding.
/// Three instances of a group (the bunny and a box, each with its own material) on a
/// floor, the second moved by `moved` in x; and the same meshes written out as objects
/// placed by the same transforms (the copies).
fn instances_and_copies(moved: f32) -> (String, String) {
    let (b, cube) = (bunny(), box_triangles([-0.1, 0.0, -0.1], [0.1, 0.2, 0.1], |p| p, false));
    let places = [
        "scale: 0.1, rotate_deg: (0, 30, 0), translate: (-0.8, 0, 0)",
        "scale: (0.12, 0.08, 0.1), rotate_deg: (10, -40, 5), translate: (0.1, 0.2, 0.3)",
        "scale: 0.07, translate: (0.9, 0.1, -0.5)",
    ];
    let floor = r#"(shape: Quad(origin: (-3, 0, 3), edge_u: (6, 0, 0), edge_v: (0, 0, -6)), material: "white")"#;
    let instanced = || {
        let objects: Vec<String> = places
            .iter()
            .enumerate()
            .map(|(k, p)| {
                let p = if k == 1 {
                    p.replace("0.1, 0.2, 0.3", &format!("{}, 0.2, 0.3", 0.1 + moved))
                } else {
                    p.to_string()
                };
                format!(r#"(shape: Instance(group: "g"), transform: ({p}))"#)
            })
            .collect();
        format!(
            r#"({HEAD}
            groups: {{ "g": [ (shape: Mesh(path: "{b}"), material: "white"),
                              (shape: {cube}, material: "red", transform: (scale: 10, translate: (0, 0, 20))) ] }},
            objects: [ {floor}, {} ])"#,
            objects.join(", ")
        )
    };
    // The copies: each member placed by its own transform then the instance's; the
    // box's own transform (scale 10, then +20 in z) written out into its vertices.
    let copy_box = box_triangles([-1.0, 0.0, 19.0], [1.0, 2.0, 21.0], |p| p, false);
    let copies: Vec<String> = places
        .iter()
        .map(|p| {
            format!(
                r#"(shape: Mesh(path: "{b}"), material: "white", transform: ({p})), (shape: {copy_box}, material: "red", transform: ({p}))"#
            )
        })
        .collect();
    let copies = format!(r#"({HEAD} objects: [ {floor}, {} ])"#, copies.join(", "));
    (instanced(), copies)
}

#[test]
fn instances_render_like_copies() {
    let (instanced, copies) = instances_and_copies(0.0);
    let (diff, mean) = max_block_difference(&instanced, &copies);
    println!("instances vs copies: largest block difference {diff:.2e}, image mean {mean:.4}");
    assert!(mean > 0.02, "something is lit: {mean}");
    assert!(diff < 1e-3 * mean, "block means differ by {diff} (image mean {mean})");
    let (moved, _) = max_block_difference(&instances_and_copies(0.05).0, &copies);
    println!("an instance moved by 0.05: largest block difference {moved:.2e}");
    assert!(moved > 5e-3 * mean, "the comparison does not see a moved instance: {moved}");
}

/// The failure matrix's row: every integrator and wavelength mode renders the instances
/// of [`instances_render_like_copies`] like the copies, 8×8 block means within 0.1% of
/// the image mean (the same samples on both sides; rounding alone differs, measured
/// below 1e-6 relative with path). Light tracing and BDPT hit the instances from the
/// lights' side too, and Whitted's delta paths through the point light check shadow
/// rays against them.
#[test]
fn instances_render_like_copies_with_every_integrator() {
    use rust_v::settings::{IntegratorKind, WavelengthsKind};
    let (instanced, copies) = instances_and_copies(0.0);
    let modes: [(IntegratorKind, Option<WavelengthsKind>); 7] = [
        (IntegratorKind::Whitted, None),
        (IntegratorKind::Path, None),
        (IntegratorKind::Spectral, Some(WavelengthsKind::Hero)),
        (IntegratorKind::Spectral, Some(WavelengthsKind::Random)),
        (IntegratorKind::Auto, None),
        (IntegratorKind::Bdpt, None),
        (IntegratorKind::LightTrace, None),
    ];
    for (integrator, wavelengths) in modes {
        let o = SettingsPatch { integrator: Some(integrator), wavelengths, ..SettingsPatch::default() };
        let (diff, mean) = max_block_difference_with(&instanced, &copies, &o);
        println!("{integrator:?} {wavelengths:?}: largest block difference {diff:.2e}, image mean {mean:.4}");
        assert!(mean > 0.02, "{integrator:?}: something is lit: {mean}");
        assert!(diff < 1e-3 * mean, "{integrator:?} {wavelengths:?}: block means differ by {diff} (image mean {mean})");
    }
}

/// A glass wedge instanced through a mirroring matrix (determinant −1) refracts like
/// the wedge mirrored by hand (x negated, winding reversed so that its normals stay
/// outward): glass tells inside from outside by the normal, so inward normals would
/// swap the indices and change the image. The hand-made copy with the winding kept
/// (inward normals) is the negative control: it differs by far more than the tolerance.
/// Same samples (same seed), but paths through glass amplify rounding differences
/// (another BVH order, another rounding of the normal): tolerance 1% of the image mean
/// per 8×8 block (measured 0.2%).
#[test]
fn a_mirrored_instance_shades_like_its_mirrored_copy() {
    let scene = |object: &str, groups: &str| {
        format!(
            r#"({HEAD}
            groups: {{ {groups} }},
            objects: [ (shape: Quad(origin: (-3, -0.5, 3), edge_u: (6, 0, 0), edge_v: (0, 0, -6)), material: "white"),
                       (shape: Quad(origin: (-2, -0.5, -1.5), edge_u: (4, 0, 0), edge_v: (0, 3, 0)), material: "red"),
                       {object} ])"#
        )
    };
    let instance = scene(
        r#"(shape: Instance(group: "w"), transform: (matrix: ((-1, 0, 0, 0.2), (0, 1, 0, 0.5), (0, 0, 1, 0))))"#,
        &format!(r#""w": [ (shape: {}, material: "glass") ]"#, wedge(false, false)),
    );
    let placed =
        |w: String| scene(&format!(r#"(shape: {w}, material: "glass", transform: (translate: (0.2, 0.5, 0)))"#), "");
    let copy = placed(wedge(true, true));
    let inward = placed(wedge(true, false));
    let (diff, mean) = max_block_difference(&instance, &copy);
    println!("mirrored instance vs mirrored copy: largest block difference {diff:.2e}, image mean {mean:.4}");
    assert!(diff < 1e-2 * mean, "block means differ by {diff} (image mean {mean})");
    let (wrong, _) = max_block_difference(&instance, &inward);
    println!("against the inward copy: {wrong:.2e}");
    assert!(wrong > 0.05 * mean, "the control with inward normals should differ: {wrong}");
}

/// 1000 instances of the bunny are 1000 objects that share one mesh: one `Arc`, whose
/// strong count is the number of instances (the loader's own reference is gone).
#[test]
fn a_thousand_instances_keep_one_copy_of_the_triangles() {
    let objects: Vec<String> = (0..1000)
        .map(|k| {
            let (x, z) = ((k % 40) as f32 * 0.3 - 6.0, (k / 40) as f32 * 0.3 - 8.0);
            format!(r#"(shape: Instance(group: "b"), transform: (scale: 0.02, rotate_deg: (0, {k}, 0), translate: ({x}, 0, {z})))"#)
        })
        .collect();
    let text = format!(
        r#"({HEAD} groups: {{ "b": [ (shape: Mesh(path: "{}"), material: "white") ] }}, objects: [ {} ])"#,
        bunny(),
        objects.join(", ")
    );
    let scene = load_scene_str(&text, Path::new("test.ron"), &SettingsPatch::default()).unwrap();
    assert_eq!(scene.object_count(), 1000);
    let meshes: Vec<&Arc<rust_v::shape::Mesh>> = scene
        .objects
        .iter()
        .map(|o| match &o.shape {
            Shape::Instance(i) => i.mesh(),
            s => panic!("expected an instance, found {s:?}"),
        })
        .collect();
    assert!(meshes.iter().all(|m| Arc::ptr_eq(m, meshes[0])));
    assert_eq!(Arc::strong_count(meshes[0]), 1000);
    // The bunny's triangles, once (3674 in the file, less the degenerate ones).
    assert_eq!(meshes[0].triangle_count() + meshes[0].degenerate_dropped(), 3674);
    // And they render (one camera ray per pixel through the scene's BVH).
    let small = SettingsPatch { width: Some(8), height: Some(8), spp: Some(1), ..Default::default() };
    let film = render_str(&text, &small);
    assert!(film.mean_xyz().iter().all(|p| p[1].is_finite()));
}

/// The furnace: a closed convex box of reflectance ½ under a uniform white environment
/// reflects exactly ½ (every ray leaving it escapes); a ray that re-hits the surface it
/// leaves is darkened to ¼ or less, so self-intersection shows as a centre block below ½.
/// Tolerance: 5 standard errors of the block mean (its pixels' spread) plus 0.2%.
fn furnace(groups: &str, object: &str, eye: [f32; 3]) -> (String, f64) {
    furnace_with(groups, object, eye, &SettingsPatch::default())
}

/// [`furnace`] with `overrides` (another integrator).
fn furnace_with(groups: &str, object: &str, eye: [f32; 3], overrides: &SettingsPatch) -> (String, f64) {
    let [x, y, z] = eye;
    let text = format!(
        r#"(camera: (eye: ({}, {}, {}), look_at: ({x}, {y}, {z}), fov_deg: 30),
        render: (width: 16, height: 16, spp: 64, max_bounces: 100, integrator: path),
        materials: {{ "m": Lambertian(reflectance: Constant(0.5)) }},
        groups: {{ {groups} }},
        objects: [ {object} ],
        environment: Uniform(Constant(1)))"#,
        x + 0.3,
        y + 0.2,
        z + 4.0
    );
    let film = render_str(&text, overrides);
    let xyz = film.mean_xyz();
    let block: Vec<f64> = (5..11).flat_map(|y| (5..11).map(move |x| (x, y))).map(|(x, y)| xyz[y * 16 + x][1]).collect();
    let n = block.len() as f64;
    let mean = block.iter().sum::<f64>() / n;
    let se = (block.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0) / n).sqrt();
    assert!((mean - 0.5).abs() < 5.0 * se + 2e-3, "centre Y = {mean} ± {se}");
    (text, mean)
}

#[test]
fn an_instance_that_cancels_large_coordinates_does_not_self_intersect() {
    // Group coordinates near −10⁴ moved back to the origin: the instance would round at
    // 10⁴ while rays leave it offset for points near 1; it is placed as a copy. (Measured
    // with the copy disabled, `MAX_CANCELLATION` infinite: centre Y 0.390 ± 0.007, the
    // self-intersection this guards against; with it 0.5001.)
    let far = box_triangles([-10_001.0; 3], [-9_999.0; 3], |p| p, false);
    let (text, mean) = furnace(
        &format!(r#""far": [ (shape: {far}, material: "m") ]"#),
        r#"(shape: Instance(group: "far"), transform: (translate: (10000, 10000, 10000)))"#,
        [0.0; 3],
    );
    println!("cancelling instance: centre Y {mean}");
    let scene = load_scene_str(&text, Path::new("test.ron"), &SettingsPatch::default()).unwrap();
    assert!(matches!(scene.objects[0].shape, Shape::Mesh(_)), "placed as a copy");
    // The same box at the group origin moved far away stays an instance, and is as robust.
    let near = box_triangles([-1.0; 3], [1.0; 3], |p| p, false);
    let (text, mean) = furnace(
        &format!(r#""near": [ (shape: {near}, material: "m") ]"#),
        r#"(shape: Instance(group: "near"), transform: (matrix: ((0.8, -0.6, 0, 10000), (0.6, 0.8, 0, 10000), (0, 0, 1, 10000))))"#,
        [10_000.0; 3],
    );
    println!("far instance: centre Y {mean}");
    let scene = load_scene_str(&text, Path::new("test.ron"), &SettingsPatch::default()).unwrap();
    assert!(matches!(scene.objects[0].shape, Shape::Instance(_)));
    // Light subpaths leave the far instance too (BDPT and light tracing), and the
    // cancelling one (a copy) as well: the same ½ (the failure matrix's row).
    use rust_v::settings::IntegratorKind;
    for integrator in [IntegratorKind::Bdpt, IntegratorKind::LightTrace] {
        // Light tracing's pixels are noisier (each light path reaches one pixel): 1024 spp.
        let spp = if integrator == IntegratorKind::LightTrace { 1024 } else { 64 };
        let o = SettingsPatch { integrator: Some(integrator), spp: Some(spp), ..SettingsPatch::default() };
        for (name, shape, object, eye) in [
            (
                "near",
                &near,
                r#"(shape: Instance(group: "near"), transform: (matrix: ((0.8, -0.6, 0, 10000), (0.6, 0.8, 0, 10000), (0, 0, 1, 10000))))"#,
                [10_000.0; 3],
            ),
            (
                "far",
                &far,
                r#"(shape: Instance(group: "far"), transform: (translate: (10000, 10000, 10000)))"#,
                [0.0; 3],
            ),
        ] {
            let (_, mean) = furnace_with(&format!(r#""{name}": [ (shape: {shape}, material: "m") ]"#), object, eye, &o);
            println!("{integrator:?}, {name}: centre Y {mean}");
        }
    }
}

/// Every mistake is one error line with the file, line:column and the field path.
#[test]
fn mistakes_are_one_error_naming_the_field() {
    let tri = r#"Triangles(positions: [(0, 0, 0), (1, 0, 0), (0, 1, 0)], indices: [(0, 1, 2)])"#;
    let good = format!(r#""g": [ (shape: {tri}, material: "white") ]"#);
    let cases: Vec<(String, String, &str, &str)> = vec![
        (good.clone(), r#"(shape: Instance(group: "nope"))"#.into(), "objects[0].shape.group", "defined: g"),
        (good.clone(), r#"(shape: Instance(group: "g"), material: "white")"#.into(), "objects[0].material", "Instance"),
        (good.clone(), r#"(shape: Instance(group: "g"), emission: Constant(1))"#.into(), "objects[0].emission", "Instance"),
        (
            format!(r#""g": [ (shape: {tri}, material: "white", emission: Constant(1)) ]"#),
            r#"(shape: Instance(group: "g"))"#.into(),
            r#"groups."g"[0].emission"#,
            "emission",
        ),
        (
            format!(r#""g": [ (shape: {tri}, material: "glass", interior: "fog") ]"#),
            r#"(shape: Instance(group: "g"))"#.into(),
            r#"groups."g"[0].interior"#,
            "interior",
        ),
        (
            good.clone(),
            r#"(shape: Instance(group: "g"), transform: (matrix: ((1, 0, 0, 0), (2, 0, 0, 0), (0, 0, 1, 0))))"#.into(),
            "objects[0].transform.matrix",
            "singular",
        ),
        (
            good.clone(),
            r#"(shape: Instance(group: "g"), transform: (matrix: ((1, 0, 0, 0), (0, NaN, 0, 0), (0, 0, 1, 0))))"#.into(),
            "objects[0].transform.matrix",
            "finite",
        ),
        (
            good.clone(),
            r#"(shape: Instance(group: "g"), transform: (scale: 2, matrix: ((1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0))))"#
                .into(),
            "objects[0].transform.matrix",
            "not with",
        ),
        (
            good.clone(),
            r#"(shape: Sphere(center: (0, 0, 0), radius: 1), material: "white", transform: (matrix: ((1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0))))"#
                .into(),
            "objects[0].transform.matrix",
            "Instance, a Mesh or Triangles",
        ),
        (
            r#""g": [ (shape: Instance(group: "g")) ]"#.into(),
            r#"(shape: Instance(group: "g"))"#.into(),
            r#"groups."g"[0].shape"#,
            "do not nest",
        ),
        (r#""g": [ ]"#.into(), r#"(shape: Instance(group: "g"))"#.into(), r#"groups."g""#, "empty"),
        (
            r#""g": [ (shape: Sphere(center: (0, 0, 0), radius: 1), material: "white") ]"#.into(),
            r#"(shape: Instance(group: "g"))"#.into(),
            r#"groups."g"[0].shape"#,
            "Mesh or Triangles",
        ),
        (
            format!(r#""g": [ (shape: {tri}, material: "chalk") ]"#),
            r#"(shape: Instance(group: "g"))"#.into(),
            r#"groups."g"[0].material"#,
            "unknown material",
        ),
        (
            format!(r#""g": [ (shape: {tri}, material: "white") ], "g": [ (shape: {tri}, material: "white") ]"#),
            r#"(shape: Instance(group: "g"))"#.into(),
            "",
            "duplicate group \"g\"",
        ),
    ];
    for (groups, object, field, words) in cases {
        let text = format!(
            r#"(camera: (eye: (0, 0, 4), look_at: (0, 0, 0), fov_deg: 30),
            materials: {{ "white": Lambertian(reflectance: Constant(0.5)), "glass": Dielectric(ior: Constant(1.5)) }},
            media: {{ "fog": Homogeneous(sigma_a: Constant(0.1), sigma_s: Constant(0.1)) }},
            groups: {{ {groups} }},
            objects: [ {object} ])"#
        );
        let e = match load_scene_str(&text, Path::new("test.ron"), &SettingsPatch::default()) {
            Ok(_) => panic!("{field}: loaded"),
            Err(e) => e.to_string(),
        };
        assert!(!e.contains('\n') && e.starts_with("test.ron:"), "{field}: {e}");
        assert!(e.contains(field) && e.contains(words), "expected {field} and {words:?}: {e}");
    }
}
