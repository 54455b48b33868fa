//! Textures where a spectrum or a scalar stands besides a reflectance
//! (issue 35): emission textures on every emitting shape, through every
//! method that reads an emitter's radiance (a hit, next-event estimation,
//! BDPT's light subpaths and connections, light tracing).

use glam::{Vec2, Vec3};

use rust_v::film::Film;
use rust_v::scene::load_scene_str;
use rust_v::settings::{IntegratorKind, SettingsPatch};

use crate::common::{render_str, temp_dir};

fn settings(integrator: IntegratorKind, size: u32, spp: u32) -> SettingsPatch {
    SettingsPatch {
        width: Some(size),
        height: Some(size),
        spp: Some(spp),
        integrator: Some(integrator),
        ..Default::default()
    }
}

/// A grey floor, a white sphere and the emitter `emitter` (an object's
/// shape and emission), seen from the side below the emitter.
fn lit_floor(emitter: &str) -> String {
    format!(
        r#"(
    camera: (eye: (2.5, 0.6, 1.5), look_at: (0, 0.5, 0), fov_deg: 60),
    materials: {{ "floor": Lambertian(reflectance: Constant(0.5)), "ball": Lambertian(reflectance: Rgb(0.8, 0.6, 0.3)) }},
    objects: [
        (shape: Quad(origin: (-3, 0, 3), edge_u: (6, 0, 0), edge_v: (0, 0, -6)), material: "floor"),
        (shape: Sphere(center: (0.6, 0.3, 0.5), radius: 0.3), material: "ball"),
        {emitter},
    ],
)"#
    )
}

/// An emission image of one colour renders exactly like that colour as
/// `Rgb(...)`: the texel is uplifted as `Rgb` emission is (the same
/// coefficients and factor: `emission_uplift`), the texture's mean (the
/// light's power) is that spectrum exactly, and a lookup between four equal
/// texels returns the texel itself. So the images are bit for bit the same,
/// for every emitting shape (quad, cuboid, mesh with and without uvs,
/// sphere, disk) and every method (hit emission, next-event estimation,
/// BDPT's emitted rays and connections, light tracing, Whitted). The EXR's
/// (0.75, 0.5, 0.25) times `scale: 4` is (3, 2, 1) exactly in f32.
#[test]
fn a_one_colour_emission_image_renders_exactly_like_its_rgb() {
    let dir = temp_dir("textures_one_colour");
    let exr = dir.join("one.exr");
    image::Rgb32FImage::from_raw(3, 2, [0.75f32, 0.5, 0.25].repeat(6)).unwrap().save(&exr).unwrap();
    std::fs::write(
        dir.join("lamp.obj"),
        "v -0.4 1.5 -0.4\nv 0.4 1.5 -0.4\nv 0.4 1.5 0.4\nv -0.4 1.5 0.4\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n",
    )
    .unwrap();
    std::fs::write(dir.join("bare.obj"), "v -0.4 1.5 -0.4\nv 0.4 1.5 -0.4\nv 0.4 1.5 0.4\nf 1 2 3\n").unwrap();
    let image = format!(r#"Image(path: "{}", scale: 4)"#, exr.display());
    let shapes = [
        "Quad(origin: (-0.4, 1.5, -0.4), edge_u: (0.8, 0, 0), edge_v: (0, 0, 0.8))".to_string(),
        "Cuboid(min: (-0.3, 1.2, -0.3), max: (0.2, 1.5, 0.1))".to_string(),
        format!(r#"Mesh(path: "{}")"#, dir.join("lamp.obj").display()),
        format!(r#"Mesh(path: "{}")"#, dir.join("bare.obj").display()),
        "Sphere(center: (-0.5, 1.2, -0.3), radius: 0.25)".to_string(),
        "Disk(center: (0, 1.5, 0), normal: (0, -1, 0), radius: 0.4)".to_string(),
    ];
    let methods = [IntegratorKind::Path, IntegratorKind::Bdpt, IntegratorKind::LightTrace, IntegratorKind::Whitted];
    for shape in &shapes {
        for &method in &methods {
            let o = settings(method, 12, 4);
            let textured = render_str(&lit_floor(&format!("(shape: {shape}, emission: {image})")), &o);
            let rgb = render_str(&lit_floor(&format!("(shape: {shape}, emission: Rgb(3, 2, 1))")), &o);
            let (a, b) = (textured.mean_xyz(), rgb.mean_xyz());
            assert!(b.iter().any(|p| p[1] > 0.01), "{shape} {method:?}: the emitter lights the scene");
            assert_eq!(a, b, "{shape} {method:?}: the one-colour image differs from its Rgb");
        }
    }
}

/// The signed corner term of the irradiance from a rectangle parallel to the
/// receiving point's tangent plane, at height `c` above it: the rectangle
/// `[0, x] × [0, y]` (measured from the foot of the normal) of radiance 1
/// gives `E = G(x, y) / 2`, where `G` is the point-to-rectangle form factor's
/// corner case times 2π (Howell's catalogue, case B-3); `G` is odd in `x`
/// and in `y`, so any rectangle is four signed corners.
fn corner(x: f64, y: f64, c: f64) -> f64 {
    let (x, y) = (x / c, y / c);
    let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
    x / sx * (y / sx).atan() + y / sy * (x / sy).atan()
}

/// Irradiance at `p` (normal +y) from the axis-aligned rectangle `[x0, x1] ×
/// [z0, z1]` at height `h` facing down with radiance `l`.
pub(crate) fn rectangle(p: Vec3, (x0, x1): (f64, f64), (z0, z1): (f64, f64), h: f64, l: f64) -> f64 {
    let (px, pz, c) = (p.x as f64, p.z as f64, h - p.y as f64);
    let g = |x: f64, z: f64| corner(x - px, z - pz, c);
    l / 2.0 * (g(x1, z1) - g(x0, z1) - g(x1, z0) + g(x0, z0))
}

/// A checkerboard emitter's irradiance on the floor below it against the
/// closed form summed square by square. The emitter: the unit square at
/// height 1 facing down (u along +x, v along +z), `Checkerboard(even:
/// Constant(4), odd: Constant(1), scale: 2)`: the squares (i, j) of side ½
/// with i + j even at radiance 4. A floor pixel of reflectance ρ has Y = ρ E
/// / π. The camera sees the floor obliquely from below the emitter; the
/// floor pixels within 0.9 of the emitter's centre are checked (101 of
/// them), by every method: Whitted and path tracing (next-event estimation
/// with the texture at the sampled point; path tracing's MIS with emission
/// at hits), spectral hero and random, auto, BDPT (emitted rays from the
/// texture, connections, emission at hits) and light tracing (emitted rays
/// only). Path tracing at 256 spp: every pixel within 5% (its per-pixel
/// error is 0.7% on average, 3% at worst, as with a constant emitter).
/// BDPT and light tracing are noisier per pixel here (with a constant
/// emitter of the same power, 1.2% and 1.9% on average, up to 5.5% and 7%
/// at 1024 and 4096 spp; random wavelengths run 2048 spp), so for every
/// method the pixels where the pattern
/// matters are summed in two groups: where swapping even and odd would
/// lower E by more than 10%, and where it would raise E by more than 10%;
/// each group's sum must be within 2% of the closed form's (so a texture
/// swapped, transposed or flipped fails: it moves each group's sum by more
/// than 10%).
#[test]
fn a_checkerboard_emitter_gives_the_closed_form_irradiance() {
    const RHO: f64 = 0.5;
    let text = r#"(
    camera: (eye: (1.6, 0.5, 0.3), look_at: (0, 0, 0.1), fov_deg: 50),
    materials: { "floor": Lambertian(reflectance: Constant(0.5)) },
    objects: [
        (shape: Quad(origin: (-5, 0, 5), edge_u: (10, 0, 0), edge_v: (0, 0, -10)), material: "floor"),
        (shape: Quad(origin: (-0.5, 1, -0.5), edge_u: (1, 0, 0), edge_v: (0, 0, 1)),
            emission: Checkerboard(even: Constant(4), odd: Constant(1), scale: 2)),
    ],
)"#;
    // Square (i, j) covers x in [-0.5 + i/2, i/2], z in [-0.5 + j/2, j/2].
    let irradiance = |p: Vec3, swap: bool| -> f64 {
        let mut e = 0.0;
        for i in 0..2 {
            for j in 0..2 {
                let even = (i + j) % 2 == 0;
                let l = if even != swap { 4.0 } else { 1.0 };
                let x = (-0.5 + i as f64 * 0.5, i as f64 * 0.5);
                let z = (-0.5 + j as f64 * 0.5, j as f64 * 0.5);
                e += rectangle(p, x, z, 1.0, l);
            }
        }
        e
    };
    use rust_v::settings::WavelengthsKind;
    let spectral = |w| (IntegratorKind::Spectral, Some(w));
    for ((method, wavelengths), spp) in [
        ((IntegratorKind::Whitted, None), 256),
        ((IntegratorKind::Path, None), 256),
        (spectral(WavelengthsKind::Hero), 256),
        (spectral(WavelengthsKind::Random), 2048),
        ((IntegratorKind::Auto, None), 256),
        ((IntegratorKind::Bdpt, None), 1024),
        ((IntegratorKind::LightTrace, None), 4096),
    ] {
        let o = SettingsPatch { max_bounces: Some(1), wavelengths, ..settings(method, 16, spp) };
        let method = wavelengths.map_or(format!("{method:?}"), |w| format!("{method:?} {w:?}"));
        let scene = load_scene_str(text, std::path::Path::new("checker.ron"), &o).unwrap();
        let film: Film = render_str(text, &o);
        let mut checked = 0;
        // Per group (swapping lowers E, raises it): pixels, Σ got, Σ want, Σ swapped.
        let mut groups = [(0, 0.0, 0.0, 0.0); 2];
        for (k, xyz) in film.mean_xyz().iter().enumerate() {
            let (x, y) = (k % 16, k / 16);
            let ray = scene.camera.ray(Vec2::new(x as f32 + 0.5, y as f32 + 0.5));
            let Some(hit) = scene.intersect(&ray, f32::INFINITY) else { continue };
            let p = hit.hit.p;
            if p.y.abs() > 1e-4 || (p.x.powi(2) + p.z.powi(2)).sqrt() > 0.9 {
                continue;
            }
            let want = RHO * irradiance(p, false) / std::f64::consts::PI;
            let swapped = RHO * irradiance(p, true) / std::f64::consts::PI;
            let got = xyz[1];
            if method.starts_with("Path") {
                assert!((got - want).abs() <= 0.05 * want + 2e-3, "pixel ({x}, {y}) at {p}: Y {got} vs {want}");
            }
            checked += 1;
            if (swapped / want - 1.0).abs() > 0.1 {
                let g = &mut groups[usize::from(swapped > want)];
                *g = (g.0 + 1, g.1 + got, g.2 + want, g.3 + swapped);
            }
        }
        assert!(checked >= 100, "{method:?}: {checked} pixels checked");
        for (n, got, want, swapped) in groups {
            assert!(n >= 5, "{method:?}: only {n} pixels in a group");
            assert!((got / want - 1.0).abs() < 0.02, "{method:?}: {n} pixels sum to {got}, want {want}");
            assert!((swapped / want - 1.0).abs() > 0.1);
            eprintln!(
                "{method:?}: {n} pixels, {:.4} of the closed form, {:.4} of the swapped",
                got / want,
                got / swapped
            );
        }
    }
}

/// A plane of material `material` (with `{A}` standing for its scalar
/// parameter) under a uniform sky and a sphere light, seen from above at an
/// angle (no surface sees another: each pixel's paths meet the plane once).
fn plane(material: &str, value: &str) -> String {
    let material = material.replace("{A}", value);
    format!(
        r#"(
    camera: (eye: (0, 1.6, 1.6), look_at: (0, 0, 0), fov_deg: 50),
    materials: {{ "m": {material} }},
    objects: [
        (shape: Quad(origin: (-2, 0, 2), edge_u: (4, 0, 0), edge_v: (0, 0, -4)), material: "m"),
        (shape: Sphere(center: (0.4, 1.2, -0.8), radius: 0.25), emission: Constant(8)),
    ],
    environment: Uniform(Rgb(0.3, 0.5, 0.9)),
)"#
    )
}

/// The materials whose scalar parameters may be textures, `{A}` for the
/// parameter, and the checkerboard's two values.
const SCALAR_CASES: [(&str, f32, f32); 6] = [
    (r#"Conductor(metal: "Au", roughness: {A})"#, 0.1, 0.4),
    (r#"Plastic(reflectance: Rgb(0.7, 0.2, 0.1), ior: Constant(1.5), roughness: {A})"#, 0.05, 0.3),
    (r#"Dielectric(ior: Constant(1.5), roughness: {A})"#, 0.2, 0.6),
    (
        r#"Conductor(metal: "Cu", roughness: 0.2, coating: ThinFilm(thickness_nm: {A}, ior: Constant(1.45)))"#,
        120.0,
        480.0,
    ),
    (r#"Dielectric(ior: Constant(1.5), coating: ThinFilm(thickness_nm: {A}, ior: Constant(1.38)))"#, 0.0, 300.0),
    (r#"ThinSheet(thickness_nm: {A}, ior: Constant(1.33))"#, 250.0, 700.0),
];

/// A checkerboard of roughness (GGX α of a conductor, a plastic's coat, rough
/// glass) or of thin-film thickness (a coating on metal and on glass, a thin
/// sheet) renders every pixel that lies within one square bit for bit like
/// the same material with that square's value as a constant: the texture is
/// evaluated once per hit into the lobe, which is then exactly the constant
/// material's. A pixel lies within one square when the (u, v) its four
/// corners see fall in the same square (the squares are convex and a pixel's
/// footprint on the plane is a convex quadrilateral). Methods whose pixels
/// depend only on the surface point they see (path tracing, Whitted, spectral
/// hero, auto, light tracing: the plane meets each path once); BDPT's
/// connections join a pixel's camera vertex with light vertices anywhere on
/// the plane, so it is not asserted here. At least 40 pixels per square kind.
#[test]
fn a_scalar_checkerboard_renders_each_square_like_its_constant() {
    use rust_v::settings::WavelengthsKind;
    let methods = [
        (IntegratorKind::Path, None),
        (IntegratorKind::Whitted, None),
        (IntegratorKind::Spectral, Some(WavelengthsKind::Hero)),
        (IntegratorKind::Auto, None),
        (IntegratorKind::LightTrace, None),
    ];
    let n = 24;
    for (material, even, odd) in SCALAR_CASES {
        let textured = plane(material, &format!("Checkerboard(even: {even:?}, odd: {odd:?}, scale: 2)"));
        let o = settings(IntegratorKind::Path, n, 4);
        let scene = load_scene_str(&textured, std::path::Path::new("plane.ron"), &o).unwrap();
        // The square (i, j) each pixel lies within, if one.
        let squares = crate::common::pixel_squares(&scene, n, 2.0);
        for (method, wavelengths) in methods {
            let o = SettingsPatch { wavelengths, ..settings(method, n, 4) };
            let got = render_str(&textured, &o).mean_xyz();
            let want_even = render_str(&plane(material, &format!("{even:?}")), &o).mean_xyz();
            let want_odd = render_str(&plane(material, &format!("{odd:?}")), &o).mean_xyz();
            let mut counts = [0; 2];
            for (k, sq) in squares.iter().enumerate() {
                let Some((i, j)) = sq else { continue };
                let odd_square = (i + j).rem_euclid(2) == 1;
                let want = if odd_square { want_odd[k] } else { want_even[k] };
                assert_eq!(got[k], want, "{material} {method:?}: pixel {k} in square ({i}, {j})");
                counts[usize::from(odd_square)] += 1;
            }
            assert!(counts[0] >= 40 && counts[1] >= 40, "{material}: {counts:?} pixels within a square");
        }
        // The two constants render differently (the test can fail).
        let o = settings(IntegratorKind::Path, n, 4);
        let (a, b) = (
            render_str(&plane(material, &format!("{even:?}")), &o).mean_xyz(),
            render_str(&plane(material, &format!("{odd:?}")), &o).mean_xyz(),
        );
        let differ = squares.iter().zip(a.iter().zip(&b)).filter(|(s, (a, b))| s.is_some() && a != b).count();
        assert!(differ >= 40, "{material}: the two values differ in only {differ} pixels");
    }
}

/// A roughness or thickness image of one grey renders bit for bit like that
/// number (a grey texel's value is the grey itself, times `scale`; a lookup
/// between equal texels returns the texel); an EXR of 0.25 times `scale: 0.8`
/// is α 0.2 and 200 nm exactly at scale 800.
#[test]
fn a_one_grey_scalar_image_renders_exactly_like_its_number() {
    let dir = temp_dir("textures_one_grey");
    let exr = dir.join("grey.exr");
    image::Rgb32FImage::from_raw(3, 2, vec![0.25f32; 18]).unwrap().save(&exr).unwrap();
    for (material, scale, value) in [(SCALAR_CASES[0].0, 0.8, "0.2"), (SCALAR_CASES[5].0, 800.0, "200")] {
        let image = format!(r#"Image(path: "{}", scale: {scale:?})"#, exr.display());
        for method in [IntegratorKind::Path, IntegratorKind::Bdpt] {
            let o = settings(method, 12, 4);
            let a = render_str(&plane(material, &image), &o).mean_xyz();
            let b = render_str(&plane(material, value), &o).mean_xyz();
            assert_eq!(a, b, "{material} {method:?}");
        }
    }
}
