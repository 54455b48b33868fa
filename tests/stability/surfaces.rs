//! The failure matrix's other rows: indirect light, grazing angles,
//! coincident surfaces, degenerate meshes, extreme scales, tiny bright lights
//! and colour noise.

use super::*;

// ---------------------------------------------------------------------------
// Indirect light, grazing angles, coincident surfaces, meshes, scales.

/// Whitted misses indirect light: in the canonical Cornell box (16x16,
/// 64 spp) the ceiling (the top three pixel rows; the sphere light hangs
/// 0.3 below it, so it has direct light too) and the whole image are darker
/// than with path tracing by the measured 34% and 25% (tests/README.md);
/// the assertions keep a margin of ~8 points around them (the pixel noise
/// of these sums is about 1-2%).
#[test]
fn whitted_misses_indirect_light_in_the_cornell_box() {
    let scene = std::fs::read_to_string(crate::common::root().join("scenes/cornell-lambert.ron")).unwrap();
    let size = |o: SettingsPatch| SettingsPatch { width: Some(16), height: Some(16), ..o };
    let w = y(&render_str(&scene, &size(method("whitted", 64, 13))));
    let p = y(&render_str(&scene, &size(method("path", 64, 14))));
    let top = |v: &[f64]| v[..48].iter().sum::<f64>();
    let ceiling = 1.0 - top(&w) / top(&p);
    let image = 1.0 - w.iter().sum::<f64>() / p.iter().sum::<f64>();
    eprintln!("cornell: whitted ceiling {:.1}% darker, image {:.1}% darker than path", 100.0 * ceiling, 100.0 * image);
    assert!(ceiling > 0.25 && ceiling < 0.45, "ceiling {ceiling}");
    assert!(image > 0.18 && image < 0.35, "image {image}");
}

/// Grazing incidence on glass: the camera 1 above a glass half-space
/// (n = 1.5; an absorbing plane 1 below catches the refracted light) under
/// a uniform sky sees the Fresnel reflectance R(θ) of each pixel's rays,
/// from 0.4 to 1 as rays approach the horizon. Each sample is 1 (reflect)
/// or 0 (refract), so a pixel's mean has standard error √(R(1−R)/spp); each
/// pixel must lie within half the spread of R over its footprint plus 5
/// standard errors (+0.01) of R at its centre.
/// `lighttrace`: exactly 0 below the horizon (specular only), the sky 1 within
/// 5 s.e. + 2%.
#[test]
fn grazing_incidence_on_glass_follows_fresnel() {
    let scene = format!(
        r#"(
        camera: (eye: (0, 1, 0), look_at: (0, 1, -1), fov_deg: 20),
        render: (width: 16, height: 16, max_bounces: 8),
        materials: {{ "glass": Dielectric(ior: Constant(1.5)), "black": Black }},
        objects: [
            (shape: Plane(point: (0, 0, 0), normal: (0, 1, 0)), material: "glass"),
            (shape: Plane(point: (0, -1, 0), normal: (0, 1, 0)), material: "black"),
            {}
        ],
    )"#,
        ENCLOSURE.replace("radius: 10", "radius: 1000")
    );
    use glam::{Vec2, Vec3};
    let cam = rust_v::camera::Camera::new(Vec3::Y, Vec3::new(0.0, 1.0, -1.0), Vec3::Y, 20.0, 16, 16);
    let fresnel = |x: f32, y: f32| {
        let d = cam.ray(Vec2::new(x, y)).dir;
        if d.y >= 0.0 { 1.0 } else { rust_v::bxdf::fresnel_dielectric(-d.y, 1.5) as f64 }
    };
    let spp = 256;
    for m in METHODS {
        let film = render_str(&scene, &method(m, spp, 15));
        if m == "lighttrace" {
            // Below the horizon the camera sees the glass (reflection or
            // refraction, both specular): exactly 0. Above it, the sky (1). Row 8
            // also sees the sky's sphere between the plane and the eye's height, up
            // to 0.06° below the horizon: skipped.
            let v = y(&film);
            assert!(v[144..].iter().all(|&x| x == 0.0), "lighttrace: a pixel seen in the glass is not 0");
            let (sky, se) = mean_se(&v[..128]);
            eprintln!("grazing glass, lighttrace: sky {sky:.4} ± {se:.4}, want 1; glass exactly 0");
            assert!((sky - 1.0).abs() < 5.0 * se + 0.02, "lighttrace: sky {sky} ± {se}");
            continue;
        }
        let v = y(&film);
        let mut worst = 0.0f64;
        for py in 8..16 {
            for px in 0..16 {
                let (x, y) = (px as f32, py as f32);
                let rs = [fresnel(x, y), fresnel(x + 1.0, y), fresnel(x, y + 1.0), fresnel(x + 1.0, y + 1.0)];
                let (lo, hi) = rs.iter().fold((1.0f64, 0.0f64), |(l, h), &r| (l.min(r), h.max(r)));
                let mid = fresnel(x + 0.5, y + 0.5);
                let noise = if full_spectrum(m) { (mid * (1.0 - mid) / spp as f64).sqrt() } else { 0.2 };
                let err = (v[py * 16 + px] - mid).abs();
                worst = worst.max(err);
                assert!(
                    err < (hi - lo) / 2.0 + 5.0 * noise + 0.01,
                    "{m}: pixel ({px}, {py}) {} vs R {mid}",
                    v[py * 16 + px]
                );
            }
        }
        eprintln!("grazing glass, {m}: worst |pixel − R| = {worst:.3}");
    }
}

/// Grazing view of a diffuse plane: camera 1e-3 above an infinite
/// Lambertian plane (ρ = 0.5) under a uniform sky; pixels wholly below the
/// horizon see ρ L = 0.5 (the plane sees only sky), at incidence cosines
/// down to 1e-4. Image mean of those pixels within 5 s.e. + 0.5%.
/// `lighttrace` fails by variance: at most a tenth of the plane's pixels lit
/// (the sky at 256 spp: `lighttrace.rs`).
#[test]
fn grazing_view_of_a_diffuse_plane() {
    let scene = grazing_plane();
    for m in METHODS {
        let v = y(&render_str(&scene, &method(m, 32, 16)));
        if m == "lighttrace" {
            // Light tracing's variance failure (almost no light path lands in a
            // 2° view of a radius-1000 sky): at most a tenth of the plane's
            // pixels lit; the sky's mean at 256 spp: `lighttrace.rs`.
            let lit = v[40..].iter().filter(|&&x| x > 0.0).count();
            eprintln!("grazing diffuse, lighttrace: {lit} of 24 plane pixels lit");
            assert!(lit * 10 <= 24, "lighttrace: {lit} plane pixels lit");
            continue;
        }
        let (mean, se) = mean_se(&v[40..]);
        eprintln!("grazing diffuse, {m}: Y = {mean:.4} ± {se:.4}, want 0.5");
        assert!((mean - 0.5).abs() < 5.0 * se + 2.5e-3, "{m}: {mean} ± {se}");
        if full_spectrum(m) {
            assert!(v[..32].iter().all(|&x| (x - 1.0).abs() < 1e-3), "{m}: the sky above the horizon");
        }
    }
}

/// Back-to-back surfaces: two coincident quads with opposite normals make a
/// zero-thickness wall with a disk light on one side; seen from the other
/// side the wall is exactly black for every method (diffuse models never
/// transmit, and ray offsets move to the side the ray leaves). Coincident
/// surfaces of different reflectance (0.2 and 0.8, same orientation) under a
/// uniform sky: which one wins a ray is decided by the order of the objects
/// (not documented); the first listed wins here in every method, so the image
/// mean is 0.2 within 5 s.e. + 1% (`lighttrace` in an enclosure of radius 3
/// at 4096 spp), never NaN.
#[test]
fn back_to_back_and_coincident_surfaces() {
    let wall = r#"(
        camera: (eye: (0, 0, -2), look_at: (0, 0, 0), fov_deg: 30),
        render: (width: 8, height: 8, max_bounces: 8),
        materials: { "white": Lambertian(reflectance: Constant(0.9)) },
        objects: [
            (shape: Quad(origin: (-2, -2, 0), edge_u: (4, 0, 0), edge_v: (0, 4, 0)), material: "white"),
            (shape: Quad(origin: (-2, -2, 0), edge_u: (0, 4, 0), edge_v: (4, 0, 0)), material: "white"),
            (shape: Disk(center: (0, 0, 0.5), normal: (0, 0, -1), radius: 0.5), emission: Constant(10)),
        ],
    )"#;
    for m in METHODS {
        let v = y(&render_str(wall, &method(m, 16, 17)));
        assert!(v.iter().all(|&x| x == 0.0), "{m}: light leaks through a zero-thickness wall");
    }
    let coincident = format!(
        r#"(
        camera: (eye: (0.1, 1, 0.2), look_at: (0, 0, 0), fov_deg: 30),
        render: (width: 8, height: 8, max_bounces: 8),
        materials: {{ "dark": Lambertian(reflectance: Constant(0.2)), "light": Lambertian(reflectance: Constant(0.8)) }},
        objects: [
            (shape: Quad(origin: (-2, 0, -2), edge_u: (0, 0, 4), edge_v: (4, 0, 0)), material: "dark"),
            (shape: Quad(origin: (-2, 0, -2), edge_u: (0, 0, 4), edge_v: (4, 0, 0)), material: "light"),
            {ENCLOSURE}
        ],
    )"#
    );
    for m in ["whitted", "path", "auto", "bdpt", "lighttrace"] {
        // Light tracing in an enclosure of radius 3 (the same sky for the
        // quads), where more light paths land in view, at 4096 spp.
        let v = if m == "lighttrace" {
            y(&render_str(&coincident.replace("radius: 10)", "radius: 3)"), &method(m, 4096, 18)))
        } else {
            y(&render_str(&coincident, &method(m, 64, 18)))
        };
        let (mean, se) = mean_se(&v);
        eprintln!("coincident quads, {m}: mean {mean:.4} ± {se:.4} (0.2: the first listed wins)");
        assert!((mean - 0.2).abs() < 5.0 * se + 0.01 * 0.2, "{m}: {mean} ± {se}, want 0.2");
    }
}

/// Writes an OBJ: a unit cube missing its top face (a hole), plus three
/// degenerate triangles (a repeated vertex, collinear vertices, a point).
fn open_cube_obj() -> std::path::PathBuf {
    let dir = temp_dir("stability-mesh");
    let path = dir.join("open_cube.obj");
    let obj = "v -0.5 0 -0.5\nv 0.5 0 -0.5\nv 0.5 0 0.5\nv -0.5 0 0.5\n\
               v -0.5 1 -0.5\nv 0.5 1 -0.5\nv 0.5 1 0.5\nv -0.5 1 0.5\nv 0 0.5 0\n\
               f 1 2 3\nf 1 3 4\n\
               f 1 5 6\nf 1 6 2\nf 2 6 7\nf 2 7 3\nf 3 7 8\nf 3 8 4\nf 4 8 5\nf 4 5 1\n\
               f 1 1 2\nf 1 9 7\nf 9 9 9\n";
    std::fs::write(&path, obj).unwrap();
    path
}

/// Degenerate triangles are dropped at load (3 of 13 here) and a mesh with
/// a hole renders without NaN. A perfectly white (ρ = 1) open diffuse cube
/// in a uniform enclosure is invisible (the white furnace: any white
/// geometry has radiance L), seen through its hole too: image mean within
/// 5 s.e. + 0.5% of 1. A glass mesh with a hole is not: a path entering
/// through a face and leaving through the hole keeps the 1/n² of the
/// entry, one entering through the hole and leaving through a face gains
/// n² = 2.25: pixels range from below 0.95 to above 2.2 and the image mean
/// is off 1 by more than 5 s.e. (measured in tests/README.md).
/// `lighttrace`: the white cube in an enclosure of radius 3 at 1024 spp.
#[test]
fn degenerate_triangles_and_meshes_with_holes() {
    let path = open_cube_obj();
    let mesh = rust_v::shape::Mesh::load(
        &path,
        &rust_v::shape::Transform { scale: glam::Vec3::ONE, rotate_deg: glam::Vec3::ZERO, translate: glam::Vec3::ZERO },
    )
    .expect("loads");
    assert_eq!((mesh.triangle_count(), mesh.degenerate_dropped()), (10, 3));
    let scene = |material: &str| {
        format!(
            r#"(
            camera: (eye: (0.3, 2.2, 1.6), look_at: (0, 0.4, 0), fov_deg: 40),
            render: (width: 12, height: 12, max_bounces: 1000),
            materials: {{ "white": Lambertian(reflectance: Constant(1)), "glass": Dielectric(ior: Constant(1.5)) }},
            objects: [ (shape: Mesh(path: "{}"), material: "{material}"), {ENCLOSURE} ],
        )"#,
            path.display()
        )
    };
    for m in METHODS {
        let film = if m == "lighttrace" {
            // In an enclosure of radius 3 (the same furnace), where more light paths reach the cube.
            render_str(&scene("white").replace("radius: 10)", "radius: 3)"), &method(m, 1024, 19))
        } else {
            render_str(&scene("white"), &method(m, 16, 19))
        };
        let (mean, se) = mean_and_stderr(&film, 1);
        if m == "whitted" {
            // Direct light only: a white surface in the enclosure sees it except where the cube occludes.
            assert!(mean < 1.0 && mean > 0.3, "whitted {mean}");
            continue;
        }
        eprintln!("white open cube, {m}: Y = {mean:.4} ± {se:.4}, want 1");
        assert!((mean - 1.0).abs() < 5.0 * se + 5e-3, "{m}: Y = {mean} ± {se}");
    }
    let film = render_str(&scene("glass"), &method("path", 32, 20));
    let (mean, se) = mean_and_stderr(&film, 1);
    let v = y(&film);
    let (lo, hi) = v.iter().fold((f64::MAX, 0.0f64), |(l, h), &x| (l.min(x), h.max(x)));
    eprintln!("glass open cube, path: Y = {mean:.4} ± {se:.4}, pixels {lo:.3} to {hi:.3}");
    assert!((mean - 1.0).abs() > 5.0 * se && lo < 0.95 && hi > 2.2, "a glass mesh with a hole is not invisible");
}

/// The scene of `extreme_scales_give_the_same_image` at scale `s`.
fn scaled_scene(s: f64) -> String {
    let v = |x: f64, y: f64, z: f64| format!("({}, {}, {})", x * s, y * s, z * s);
    format!(
        r#"(
        camera: (eye: {}, look_at: {}, fov_deg: 45),
        render: (width: 16, height: 16, max_bounces: 6),
        materials: {{ "white": Lambertian(reflectance: Constant(0.7)), "red": Lambertian(reflectance: Constant(0.3)), "glass": Dielectric(ior: Constant(1.5)) }},
        objects: [
            (shape: Quad(origin: {}, edge_u: {}, edge_v: {}), material: "white"),
            (shape: Quad(origin: {}, edge_u: {}, edge_v: {}), material: "white"),
            (shape: Quad(origin: {}, edge_u: {}, edge_v: {}), material: "red"),
            (shape: Sphere(center: {}, radius: {}), material: "white"),
            (shape: Sphere(center: {}, radius: {}), material: "glass"),
            (shape: Disk(center: {}, normal: (0, -1, 0), radius: {}), emission: Constant(8)),
        ],
    )"#,
        v(0.0, 1.0, 3.5),
        v(0.0, 1.0, 0.0),
        v(-1.0, 0.0, -1.0),
        v(0.0, 0.0, 2.0),
        v(2.0, 0.0, 0.0),
        v(-1.0, 0.0, -1.0),
        v(2.0, 0.0, 0.0),
        v(0.0, 2.0, 0.0),
        v(-1.0, 0.0, -1.0),
        v(0.0, 2.0, 0.0),
        v(0.0, 0.0, 2.0),
        v(0.4, 0.35, -0.2),
        0.35 * s,
        v(-0.4, 0.3, 0.3),
        0.3 * s,
        v(0.0, 1.9, 0.0),
        0.4 * s
    )
}

/// The same scene at scale 1e-4, 1 and 1e4 (geometry and camera scaled
/// together; radiance is scale-free): with the same seed the paths are the
/// same up to rounding, so the images agree far more tightly than the noise:
/// image mean within 1% and the mean absolute pixel difference below 5% of
/// the mean (measured values in tests/README.md).
#[test]
fn extreme_scales_give_the_same_image() {
    for m in ["whitted", "path", "auto"] {
        let base = y(&render_str(&scaled_scene(1.0), &method(m, 16, 21)));
        let base_mean = base.iter().sum::<f64>() / base.len() as f64;
        for s in [1e-4, 1e4] {
            let v = y(&render_str(&scaled_scene(s), &method(m, 16, 21)));
            let mean = v.iter().sum::<f64>() / v.len() as f64;
            let mad = v.iter().zip(&base).map(|(a, b)| (a - b).abs()).sum::<f64>() / v.len() as f64;
            eprintln!(
                "scale {s:e}, {m}: mean {mean:.4} vs {base_mean:.4}, mean |diff| {:.2}% of the mean",
                100.0 * mad / base_mean
            );
            assert!((mean / base_mean - 1.0).abs() < 0.01, "{m} at scale {s}: {mean} vs {base_mean}");
            assert!(mad < 0.05 * base_mean, "{m} at scale {s}: mean |diff| {mad}");
        }
    }
}

// ---------------------------------------------------------------------------
// Bright small lights and colour noise.

/// A very small, very bright sphere light (r = 1e-3 at distance 1, radiance
/// 1e6: a firefly source for BSDF sampling) over a Lambertian floor (ρ = 0.5)
/// gives the exact irradiance E = π L (r/d)² cos θ (d to the centre), so
/// the floor's radiance is ρ E / π. Next-event estimation by cone sampling
/// makes every sample nearly exact: each pixel of the full-spectrum methods
/// is within 2% of the closed form at the pixel centre (the closed form
/// varies by < 1% across a pixel here), packets on the image mean.
/// `lighttrace` (2048 spp): the mean of pixel / closed form within 5 s.e. + 1%.
#[test]
fn tiny_bright_sphere_light_gives_the_exact_irradiance() {
    let scene = r#"(
        camera: (eye: (0, 0.5, 0.01), look_at: (0, 0, 0), fov_deg: 40),
        render: (width: 8, height: 8, max_bounces: 4),
        materials: { "m": Lambertian(reflectance: Constant(0.5)) },
        objects: [
            (shape: Plane(point: (0, 0, 0), normal: (0, 1, 0)), material: "m"),
            (shape: Sphere(center: (0, 1, 0), radius: 0.001), emission: Constant(1000000)),
        ],
    )"#;
    use glam::{Vec2, Vec3};
    let cam = rust_v::camera::Camera::new(Vec3::new(0.0, 0.5, 0.01), Vec3::ZERO, Vec3::Y, 40.0, 8, 8);
    let want: Vec<f64> = (0..64)
        .map(|i| {
            let r = cam.ray(Vec2::new((i % 8) as f32 + 0.5, (i / 8) as f32 + 0.5));
            let p = r.at(-r.origin.y / r.dir.y);
            let to = Vec3::new(0.0, 1.0, 0.0) - p;
            let d2 = to.length_squared() as f64;
            let cos = to.y as f64 / d2.sqrt();
            0.5 * 1e6 * 1e-6 / d2 * cos // ρ/π · π L r²/d² cos
        })
        .collect();
    for m in METHODS {
        let v = y(&render_str(scene, &method(m, 16, 22)));
        if m == "lighttrace" {
            // Each light path lands anywhere on the infinite floor: more samples.
            let v = y(&render_str(scene, &method(m, 2048, 22)));
            let r: Vec<f64> = v.iter().zip(&want).map(|(a, b)| a / b).collect();
            let (rm, rs) = mean_se(&r);
            eprintln!("tiny bright light, lighttrace (2048 spp): pixel / closed form = {rm:.4} ± {rs:.4}");
            assert!((rm - 1.0).abs() < 5.0 * rs + 0.01, "lighttrace: {rm} ± {rs}");
            continue;
        }
        let worst = v.iter().zip(&want).map(|(a, b)| (a / b - 1.0).abs()).fold(0.0, f64::max);
        let ratio = v.iter().sum::<f64>() / want.iter().sum::<f64>();
        eprintln!("tiny bright light, {m}: image / closed form = {ratio:.4}, worst pixel {:.2}%", 100.0 * worst);
        if full_spectrum(m) {
            assert!(worst < 0.02, "{m}: worst pixel off by {worst}");
        } else {
            assert!((ratio - 1.0).abs() < 0.05, "{m}: {ratio}");
        }
    }
}

/// Colour noise of the wavelength samplers in a grey white furnace (ρ = 0.5,
/// 16 spp): full-spectrum methods have none (x and z chromaticity identical
/// in every pixel, to rounding); random packets have more than hero packets
/// (hero's evenly spaced bins cover the CMFs better). Measured per-pixel
/// standard deviation of the chromaticity x, in tests/README.md; the
/// assertion is the ordering with a 20% margin.
/// `bdpt` and `lighttrace` (over their lit pixels) have none either.
#[test]
fn colour_noise_of_the_wavelength_samplers() {
    let scene = r#"(
        camera: (eye: (0.1, -0.2, 0.3), look_at: (1, 0.5, -0.3), fov_deg: 70),
        render: (width: 16, height: 16, max_bounces: 10000),
        materials: { "m": Lambertian(reflectance: Constant(0.5)) },
        objects: [ (shape: Sphere(center: (0, 0, 0), radius: 1), material: "m", emission: Constant(1), two_sided: true) ],
    )"#;
    let mut sd = std::collections::BTreeMap::new();
    for m in METHODS {
        let film = render_str(scene, &method(m, 16, 23));
        // Light tracing leaves some pixels unlit at 16 spp: those have no chromaticity.
        let x: Vec<f64> = film.mean_xyz().iter().filter(|p| p[1] > 0.0).map(|p| p[0] / (p[0] + p[1] + p[2])).collect();
        assert!(x.len() >= 128, "{m}: {} pixels lit", x.len());
        let (mean, se) = mean_se(&x);
        let s = se * (x.len() as f64).sqrt();
        eprintln!("colour noise, {m}: chromaticity x = {mean:.4}, per-pixel s.d. {s:.5}");
        sd.insert(m, s);
    }
    for m in ["whitted", "path", "auto", "bdpt", "lighttrace"] {
        assert!(sd[m] < 1e-5, "{m}: colour noise {}", sd[m]);
    }
    assert!(sd["hero"] * 1.2 < sd["random"], "hero {} vs random {}", sd["hero"], sd["random"]);
}
