//! The environment light (`environment:`): furnaces against closed forms,
//! a constant map against `Uniform(Rgb(...))`, and bad maps.
//!
//! A convex object under a uniform environment of radiance 1 sees only the
//! environment: a Lambertian surface of reflectance ρ reflects ρ (∫ L cos/π dω
//! over the hemisphere is 1), and every pixel that misses it sees 1.

use rust_v::settings::SettingsPatch;

use crate::common::{mean_and_stderr, render_file, render_str, temp_dir};

fn furnace(rho: f32, integrator: &str) -> String {
    format!(
        r#"(
        camera: (eye: (0.2, 0.1, 3), look_at: (0, 0, 0), fov_deg: 40),
        render: (width: 16, height: 16, spp: 64, max_bounces: 100, integrator: {integrator}),
        materials: {{ "m": Lambertian(reflectance: Constant({rho})) }},
        objects: [ (shape: Sphere(center: (0, 0, 0), radius: 1), material: "m") ],
        environment: Uniform(Constant(1)),
    )"#
    )
}

/// Per-pixel: a pixel whose samples all hit the sphere is ρ, one whose samples
/// all miss is 1 (edge pixels mix). The image mean is checked against the
/// exact mean computed from the sphere's covered fraction of each pixel, which
/// the test does not know; so instead each pixel is checked against the
/// interval [ρ, 1] and the mean of the fully-covered centre block against ρ.
/// Tolerance: 5 standard errors of the block mean (spread of its pixel means)
/// plus 0.2% for f32 arithmetic.
fn check(rho: f32, integrator: &str) {
    let film = render_str(&furnace(rho, integrator), &SettingsPatch::default());
    let xyz = film.mean_xyz();
    // The sphere (radius 1 at distance ~3, fov 40°) covers the centre 8x8 block fully.
    let block: Vec<f64> = (4..12).flat_map(|y| (4..12).map(move |x| (x, y))).map(|(x, y)| xyz[y * 16 + x][1]).collect();
    let n = block.len() as f64;
    let mean = block.iter().sum::<f64>() / n;
    let se = (block.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0) / n).sqrt();
    let tol = 5.0 * se + 2e-3;
    assert!((mean - rho as f64).abs() < tol, "{integrator}, ρ {rho}: centre Y = {mean} ± {se}");
    // Corner pixels see only the environment: 1 with no noise over the full
    // spectrum; sampled wavelength packets (`spectral`) read a flat spectrum out
    // with a little colour noise (measured 0.3% at 64 spp), so 2% there.
    let corner_tol = if integrator == "spectral" { 0.02 } else { 2e-3 };
    for (x, y) in [(0, 0), (15, 0), (0, 15), (15, 15)] {
        let y_val = xyz[y * 16 + x][1];
        assert!((y_val - 1.0).abs() < corner_tol, "{integrator}: corner ({x}, {y}) Y = {y_val}");
    }
}

#[test]
fn white_sphere_in_a_uniform_environment_renders_one_with_every_integrator() {
    for integrator in ["path", "bdpt", "lighttrace", "spectral", "auto"] {
        check(1.0, integrator);
    }
}

#[test]
fn half_grey_sphere_renders_one_half() {
    for integrator in ["path", "bdpt", "lighttrace"] {
        check(0.5, integrator);
    }
}

/// A 4x2 PNG map of one colour renders like `Uniform(Rgb(...))` of that colour:
/// bit for bit with the path tracer (the same spectrum in every direction, and
/// the same sampling: both draw directions, the map by its density, which is
/// uniform per solid angle only in expectation, so compare means, not bits).
/// Tolerance: 5 standard errors of the difference of the two image means.
#[test]
fn a_constant_image_map_renders_like_uniform_rgb() {
    let dir = temp_dir("env_constant_map");
    let (r, g, b) = (0.8f32, 0.5f32, 0.25f32);
    // Linear values written as 16-bit sRGB codes, decoded back on load.
    let rgb = [r, g, b];
    let px: Vec<u16> =
        (0..8).flat_map(|_| rgb.map(|v| (rust_v::color::srgb_oetf(v) * 65535.0).round() as u16)).collect();
    let decoded = rgb.map(|v| rust_v::color::srgb_eotf(((rust_v::color::srgb_oetf(v) * 65535.0).round()) / 65535.0));
    image::ImageBuffer::<image::Rgb<u16>, Vec<u16>>::from_raw(4, 2, px).unwrap().save(dir.join("map.png")).unwrap();
    let scene = |env: &str| {
        format!(
            r#"(
            camera: (eye: (0, 0, 3), look_at: (0, 0, 0), fov_deg: 40),
            render: (width: 16, height: 16, spp: 64, integrator: path),
            materials: {{ "m": Lambertian(reflectance: Rgb(0.2, 0.6, 0.9)) }},
            objects: [ (shape: Sphere(center: (0, 0, 0), radius: 1), material: "m") ],
            environment: {env},
        )"#
        )
    };
    let path = dir.join("scene.ron");
    std::fs::write(&path, scene(r#"Image(path: "map.png")"#)).unwrap();
    let film = render_file(&path, &SettingsPatch::default());
    let uniform = render_str(
        &scene(&format!("Uniform(Rgb({}, {}, {}))", decoded[0], decoded[1], decoded[2])),
        &SettingsPatch::default(),
    );
    for c in 0..3 {
        let (a, sa) = mean_and_stderr(&film, c);
        let (b, sb) = mean_and_stderr(&uniform, c);
        let tol = 5.0 * (sa * sa + sb * sb).sqrt() + 1e-4;
        assert!((a - b).abs() < tol, "channel {c}: map {a} ± {sa} vs uniform {b} ± {sb}");
    }
    // Corner pixels (environment only) agree exactly.
    assert_eq!(film.mean_xyz()[0], uniform.mean_xyz()[0]);
}

/// A map with a small bright "sun" and a dim sky lights a diffuse floor and
/// sphere: path tracing (MIS of map sampling and BSDF sampling), BDPT (every
/// strategy, light subpaths from the environment's disk) and light tracing
/// (only light subpaths from the environment, plus the sky seen directly)
/// must agree. Compared on the differences of 4x4-pixel block means (64
/// blocks), so that the image's own content cancels: the mean difference
/// must be within 5 standard errors (from the spread of the differences)
/// plus 0.5% of the image mean.
#[test]
fn path_bdpt_and_light_tracing_agree_under_an_image_map() {
    let dir = temp_dir("env_three_methods");
    let (w, h) = (32u32, 16u32);
    let mut px = vec![0.0f32; (w * h * 3) as usize];
    for j in 0..h {
        for i in 0..w {
            let k = ((j * w + i) * 3) as usize;
            let sky = if j < h / 2 { [0.3, 0.5, 0.9] } else { [0.1, 0.08, 0.05] };
            px[k..k + 3].copy_from_slice(&sky);
        }
    }
    // The sun: two texels, 200x brighter, up and to the side.
    for i in [5u32, 6] {
        let k = ((3 * w + i) * 3) as usize;
        px[k..k + 3].copy_from_slice(&[60.0, 55.0, 45.0]);
    }
    image::Rgb32FImage::from_raw(w, h, px).unwrap().save(dir.join("map.exr")).unwrap();
    let scene = |integrator: &str, spp: u32| {
        format!(
            r#"(
            camera: (eye: (0, 1, 4), look_at: (0, 0.5, 0), fov_deg: 40),
            render: (width: 32, height: 32, spp: {spp}, max_bounces: 6, integrator: {integrator}),
            materials: {{ "floor": Lambertian(reflectance: Constant(0.6)), "ball": Lambertian(reflectance: Rgb(0.7, 0.3, 0.2)) }},
            objects: [
                (shape: Quad(origin: (-2, 0, 2), edge_u: (4, 0, 0), edge_v: (0, 0, -4)), material: "floor"),
                (shape: Sphere(center: (0, 0.6, 0), radius: 0.6), material: "ball"),
            ],
            environment: Image(path: "map.exr", rotate_deg: (0, 30, 0)),
        )"#
        )
    };
    let render = |integrator: &str, spp: u32| {
        let path = dir.join(format!("{integrator}.ron"));
        std::fs::write(&path, scene(integrator, spp)).unwrap();
        crate::common::block_means(&render_file(&path, &SettingsPatch::default()), 4)
    };
    let reference = render("path", 128);
    let mean_ref = reference.iter().sum::<f64>() / reference.len() as f64;
    for (integrator, spp) in [("bdpt", 64), ("lighttrace", 128)] {
        let d: Vec<f64> = render(integrator, spp).iter().zip(&reference).map(|(a, b)| a - b).collect();
        let n = d.len() as f64;
        let m = d.iter().sum::<f64>() / n;
        let se = (d.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0) / n).sqrt();
        let tol = 5.0 * se + 5e-3 * mean_ref;
        eprintln!("{integrator}: {m} ± {se}, tol {tol}, mean {mean_ref}");
        assert!(m.abs() < tol, "{integrator}: mean Y differs from path by {m} ± {se} (image mean {mean_ref})");
    }
}

/// `auto` treats a map's peak as a sun (and picks `caustics` over specular
/// surfaces) when its brightest texels holding `SUN_SHARE` (half) of its power
/// span at most `SUN_SOLID_ANGLE` (1% of the sphere). Grey maps, so a texel's
/// power is its value times its solid angle up to one constant; the shares and
/// solid angles are computed here, independently of the renderer's histogram.
#[test]
fn a_map_has_a_sun_when_half_its_power_lies_within_one_percent_of_the_sphere() {
    use rust_v::light::{EnvironmentLight, SUN_SHARE, SUN_SOLID_ANGLE};
    use std::f64::consts::PI;
    let (w, h) = (64usize, 32usize);
    let solid = |j: usize| {
        let (t0, t1) = (PI * j as f64 / h as f64, PI * (j + 1) as f64 / h as f64);
        2.0 * PI / w as f64 * (t0.cos() - t1.cos())
    };
    // A dim background of 0.01 and a square spot of `side` texels at the equator.
    let map = |side: usize, value: f32| {
        let mut px = vec![[0.01f32; 3]; w * h];
        for j in h / 2 - side / 2..h / 2 - side / 2 + side {
            for i in 10..10 + side {
                px[j * w + i] = [value; 3];
            }
        }
        let (mut spot, mut spot_solid, mut total) = (0.0, 0.0, 0.0);
        for j in 0..h {
            for i in 0..w {
                let p = px[j * w + i][0] as f64 * solid(j);
                total += p;
                if px[j * w + i][0] == value {
                    spot += p;
                    spot_solid += solid(j);
                }
            }
        }
        let sun = EnvironmentLight::map(w, h, &px, 1.0, glam::Mat3::IDENTITY).unwrap().has_sun();
        (sun, spot / total, spot_solid)
    };
    // 2x2 texels (0.039 sr) holding 84%: a sun.
    let (sun, share, sr) = map(2, 17.0);
    assert!(share > SUN_SHARE && sr < SUN_SOLID_ANGLE && sun, "{share} in {sr} sr");
    // The same spot holding 33%: the brightest texels holding half the power
    // take in background texels: most of the sphere. No sun.
    let (sun, share, _) = map(2, 1.6);
    assert!(share < SUN_SHARE && !sun, "{share}");
    // A 6x6 spot (0.35 sr, 2.7% of the sphere) holding 92%: too broad for a sun.
    let (sun, share, sr) = map(6, 4.0);
    assert!(share > SUN_SHARE && sr > SUN_SOLID_ANGLE && !sun, "{share} in {sr} sr");
    // A uniform map, a uniform environment and the sky.
    assert!(!EnvironmentLight::map(w, h, &vec![[1.0; 3]; w * h], 1.0, glam::Mat3::IDENTITY).unwrap().has_sun());
    assert!(!EnvironmentLight::uniform(rust_v::color::Spectrum::splat(1.0)).has_sun());
}

/// Over a glass sphere, `auto` picks `caustics` under a map with a sun and path
/// tracing under the same map with its spot dimmed below half the power.
#[test]
fn auto_aims_at_glass_from_a_map_with_a_sun_only() {
    let dir = temp_dir("env_auto_sun");
    let (w, h) = (64u32, 32u32);
    for (name, spot) in [("sun.exr", 17.0f32), ("dim.exr", 1.6)] {
        let mut px = vec![0.01f32; (w * h * 3) as usize];
        for j in 15..17 {
            for i in 10..12 {
                let k = ((j * w + i) * 3) as usize;
                px[k..k + 3].fill(spot);
            }
        }
        image::Rgb32FImage::from_raw(w, h, px).unwrap().save(dir.join(name)).unwrap();
    }
    let line = |map: &str| {
        let text = format!(
            r#"(camera: (eye: (0, 0, 5), look_at: (0, 0, 0), fov_deg: 30),
            materials: {{ "glass": Dielectric(ior: Constant(1.5)), "floor": Lambertian(reflectance: Constant(0.5)) }},
            objects: [ (shape: Sphere(center: (0, 0, 0), radius: 1), material: "glass"),
                       (shape: Quad(origin: (-3, -1, 3), edge_u: (6, 0, 0), edge_v: (0, 0, -6)), material: "floor") ],
            environment: Image(path: "{map}"))"#
        );
        let path = dir.join("scene.ron");
        std::fs::write(&path, text).unwrap();
        rust_v::integrator::describe(&rust_v::scene::load_scene(&path, &SettingsPatch::default()).unwrap())
    };
    let sun = line("sun.exr");
    assert!(sun.contains("the environment's sun") && sun.contains("light subpaths aimed"), "{sun}");
    let dim = line("dim.exr");
    assert!(dim.contains("full-spectrum path tracing") && !dim.contains("aimed"), "{dim}");
}
