//! Stability where methods fail (tests/README.md is the failure matrix this
//! file backs): analytic scenes with closed-form answers, and the hard cases
//! of each light transport method, asserting either the right answer or the
//! documented shortfall, and never NaN or infinity (`render_str` asserts that
//! every sample is finite). Images are 8x8 to 16x16; tolerances are stated
//! at each test. This file holds the shared helpers and the analytic scenes;
//! [`glass`] the dielectric and caustic cases, [`nested`] nested dielectrics, [`surfaces`] indirect light,
//! grazing angles, coincident surfaces, meshes, scales and bright lights.

use rust_v::film::Film;
use rust_v::settings::{IntegratorKind, SettingsPatch, WavelengthsKind};

mod bias;
mod environment;
mod glass;
mod lighttrace;
mod materials;
mod media;
mod nested;
mod surfaces;

use crate::common::{mean_and_stderr, render_str, temp_dir};

/// The methods of the failure matrix, one per column. Light tracing
/// (`lighttrace`) cannot connect a specular vertex to the eye: each row says
/// what it must give (the answer on diffuse surfaces, 0 through smooth glass
/// or in a mirror); `lighttrace.rs` holds its rows that need more samples.
const METHODS: [&str; 8] = ["whitted", "path", "hero", "random", "auto", "bdpt", "lighttrace", "caustics"];

fn method(m: &str, spp: u32, seed: u64) -> SettingsPatch {
    let (integrator, wavelengths) = match m {
        "whitted" => (IntegratorKind::Whitted, None),
        "path" => (IntegratorKind::Path, None),
        "hero" => (IntegratorKind::Spectral, Some(WavelengthsKind::Hero)),
        "random" => (IntegratorKind::Spectral, Some(WavelengthsKind::Random)),
        "auto" => (IntegratorKind::Auto, None),
        "bdpt" => (IntegratorKind::Bdpt, None),
        "lighttrace" => (IntegratorKind::LightTrace, None),
        "caustics" => (IntegratorKind::Caustics, None),
        _ => unreachable!(),
    };
    SettingsPatch { integrator: Some(integrator), wavelengths, spp: Some(spp), seed: Some(seed), ..Default::default() }
}

/// Full-spectrum methods give every sample the same colour for a grey
/// scene; the packet samplers (hero, random) add colour noise with the right mean.
fn full_spectrum(m: &str) -> bool {
    matches!(m, "whitted" | "path" | "auto" | "bdpt" | "lighttrace" | "caustics")
}

/// Relative per-pixel tolerance where every path of a full-spectrum method
/// carries the same value: 1%. Russian roulette continues with probability
/// `min(1, β)`, so a path that has lost nothing is never cut and such pixels
/// are exact up to f32 (with Mitsuba's cap of 0.95 one killed or boosted
/// sample moved a pixel of 16-32 samples by up to 6%, and this was 10%).
/// `bdpt` weighs several strategies whose values differ per sample even
/// where the answer is uniform (a light subpath's splat lands in one pixel):
/// 10%.
fn pixel_tol(m: &str) -> f64 {
    if matches!(m, "bdpt" | "lighttrace" | "caustics") { 0.1 } else { 0.01 }
}

/// Per-pixel Y.
fn y(film: &Film) -> Vec<f64> {
    film.mean_xyz().iter().map(|p| p[1]).collect()
}

/// Mean and standard error of the selected pixels' Y.
fn mean_se(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
    (m, (var / n).sqrt())
}

/// A Lambertian sphere (ρ 0.5, R 1) with a point light of intensity 1 at its centre.
const POINT_IN_SPHERE: &str = r#"(
        camera: (eye: (0.1, -0.2, 0.3), look_at: (1, 0.5, -0.3), fov_deg: 70),
        render: (width: 12, height: 12, max_bounces: 10000),
        materials: { "m": Lambertian(reflectance: Constant(0.5)) },
        objects: [ (shape: Sphere(center: (0, 0, 0), radius: 1), material: "m") ],
        lights: [ Point(position: (0, 0, 0), intensity: Constant(1)) ],
    )"#;

/// A closed mirror sphere of reflectance `rho` emitting 1 from its inside.
fn mirror_enclosure(rho: f64) -> String {
    format!(
        r#"(
            camera: (eye: (0.1, -0.2, 0.3), look_at: (1, 0.5, -0.3), fov_deg: 70),
            render: (width: 8, height: 8, max_bounces: 40),
            materials: {{ "m": Mirror(reflectance: Constant({rho})) }},
            objects: [ (shape: Sphere(center: (0, 0, 0), radius: 1), material: "m", emission: Constant(1), two_sided: true) ],
        )"#
    )
}

/// The camera at the centre of a glass sphere (n 1.5) in the uniform enclosure.
fn camera_in_glass() -> String {
    format!(
        r#"(
        camera: (eye: (0, 0, 0), look_at: (0.3, 0.2, -1), fov_deg: 60),
        render: (width: 8, height: 8, max_bounces: 64),
        materials: {{ "glass": Dielectric(ior: Constant(1.5)) }},
        objects: [ (shape: Sphere(center: (0, 0, 0), radius: 1), material: "glass"), {ENCLOSURE} ],
    )"#
    )
}

/// The camera 1e-3 above a Lambertian plane (ρ 0.5) under a uniform sky of radius 1000, a 2° view.
fn grazing_plane() -> String {
    format!(
        r#"(
        camera: (eye: (0, 0.001, 0), look_at: (0, 0.001, -1), fov_deg: 2),
        render: (width: 8, height: 8, max_bounces: 8),
        materials: {{ "m": Lambertian(reflectance: Constant(0.5)) }},
        objects: [ (shape: Plane(point: (0, 0, 0), normal: (0, 1, 0)), material: "m"), {} ],
    )"#,
        ENCLOSURE.replace("radius: 10", "radius: 1000")
    )
}

/// For each pixel of a `size`x`size` view from `eye` towards `look_at`
/// (field of view `fov_deg`, up +y): `Some(true)` when the rays through its
/// four corners and its centre all satisfy `hits`, `Some(false)` when none
/// does, `None` when the pixel straddles an outline.
fn cover(
    eye: glam::Vec3,
    look_at: glam::Vec3,
    fov_deg: f32,
    size: u32,
    hits: impl Fn(&rust_v::geometry::Ray) -> bool,
) -> Vec<Option<bool>> {
    let cam = rust_v::camera::Camera::new(eye, look_at, glam::Vec3::Y, fov_deg, size, size);
    let mut cover = Vec::new();
    for py in 0..size {
        for px in 0..size {
            let h = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0), (0.5, 0.5)]
                .map(|(dx, dy)| hits(&cam.ray(glam::Vec2::new(px as f32 + dx, py as f32 + dy))));
            cover.push(if h.iter().all(|&h| h) {
                Some(true)
            } else if h.iter().all(|&h| !h) {
                Some(false)
            } else {
                None
            });
        }
    }
    cover
}

/// [`cover`] by any of `spheres` (centre, radius).
fn sphere_cover(
    eye: glam::Vec3,
    look_at: glam::Vec3,
    fov_deg: f32,
    size: u32,
    spheres: &[(glam::Vec3, f32)],
) -> Vec<Option<bool>> {
    let balls: Vec<_> = spheres.iter().map(|&(c, r)| rust_v::shape::Sphere::new(c, r)).collect();
    cover(eye, look_at, fov_deg, size, |r| balls.iter().any(|b| b.occluded(r, f32::INFINITY)))
}

/// Whether `ray` meets the axis-aligned box `lo`..`hi` (the slab test).
fn hits_box(ray: &rust_v::geometry::Ray, lo: glam::Vec3, hi: glam::Vec3) -> bool {
    let (mut t0, mut t1) = (0.0f32, f32::INFINITY);
    for a in 0..3 {
        let inv = 1.0 / ray.dir[a];
        let (ta, tb) = ((lo[a] - ray.origin[a]) * inv, (hi[a] - ray.origin[a]) * inv);
        t0 = t0.max(ta.min(tb));
        t1 = t1.min(ta.max(tb));
    }
    t0 <= t1
}

/// Light tracing's answer for a view of smooth glass (or a thin sheet) in the
/// uniform enclosure (L = 1): every pixel that sees only the glass is exactly
/// 0 (the camera end of every path there is specular), and the pixels that
/// see only the enclosure average 1 (its emission, the `s = 1` connections)
/// within 5 standard errors of their mean + 2%. Returns the two pixel counts.
fn lighttrace_sees_only_the_enclosure(film: &Film, cover: &[Option<bool>], what: &str) -> (usize, usize) {
    let v = y(film);
    let glass: Vec<f64> = v.iter().zip(cover).filter(|(_, c)| **c == Some(true)).map(|(v, _)| *v).collect();
    let sky: Vec<f64> = v.iter().zip(cover).filter(|(_, c)| **c == Some(false)).map(|(v, _)| *v).collect();
    assert!(glass.iter().all(|&x| x == 0.0), "{what}, lighttrace: a pixel seen through glass is not 0");
    if sky.len() >= 2 {
        let (mean, se) = mean_se(&sky);
        eprintln!(
            "{what}, lighttrace: {} glass pixels 0, enclosure {mean:.4} ± {se:.4} over {} pixels",
            glass.len(),
            sky.len()
        );
        assert!((mean - 1.0).abs() < 5.0 * se + 0.02, "{what}, lighttrace: enclosure {mean} ± {se}");
    }
    (glass.len(), sky.len())
}

/// A uniformly emitting enclosure (radiance 1, equal energy: Y = 1).
/// The camera at the centre of a smooth N-BK7 sphere in the uniform
/// enclosure, and the Y it must see: Σ_b n(λ_b)² ȳ_b (radiance n²L per
/// wavelength inside a lossless dielectric).
fn camera_inside_nbk7() -> (String, f64) {
    let scene = format!(
        r#"(
        camera: (eye: (0, 0, 0), look_at: (0.3, 0.2, -1), fov_deg: 60),
        render: (width: 8, height: 8, max_bounces: 64),
        materials: {{ "glass": Dielectric(ior: Named("N-BK7")) }},
        objects: [ (shape: Sphere(center: (0, 0, 0), radius: 1), material: "glass"), {ENCLOSURE} ],
    )"#
    );
    let ior = rust_v::bxdf::named_glass("N-BK7").unwrap();
    let cmf = rust_v::color::color_weights();
    let y = (0..36).map(|b| (ior.at(rust_v::color::bin_lambda_nm(b)) as f64).powi(2) * cmf[b][1] as f64).sum();
    (scene, y)
}

const ENCLOSURE: &str = "(shape: Sphere(center: (0, 0, 0), radius: 10), emission: Constant(1), two_sided: true)";

// ---------------------------------------------------------------------------
// Analytic scenes.

/// pbrt-v4's test: a Lambertian sphere (ρ = 0.5, R = 1) lit by a point light
/// of intensity I = 1 at its centre has radiance ρ I / (π R² (1 − ρ)) = 1/π
/// everywhere inside with all bounces; `whitted` gives the direct term
/// ρ I / (π R²) = 1/(2π) exactly (one deterministic shadow ray per sample).
/// Tolerance for the sampled methods: 5 standard errors of the image mean
/// (from the pixel spread) plus 0.3% for the CMF normalisation and f32.
/// `lighttrace` is unbiased here (every vertex diffuse) and held to the same
/// tolerance.
#[test]
fn lambertian_sphere_with_a_point_light_at_its_centre() {
    let scene = POINT_IN_SPHERE;
    let pi = std::f64::consts::PI;
    for m in METHODS {
        let film = render_str(scene, &method(m, 32, 1));
        let (mean, se) = mean_and_stderr(&film, 1);
        let want = if m == "whitted" { 0.5 / pi } else { 1.0 / pi };
        eprintln!("point light in sphere, {m}: Y = {mean:.5} ± {se:.5}, want {want:.5}");
        assert!((mean - want).abs() < 5.0 * se + 3e-3 * want, "{m}: Y = {mean} ± {se}, want {want}");
        if m == "whitted" {
            for v in y(&film) {
                assert!((v - want).abs() < 3e-3 * want, "whitted pixel {v}");
            }
        }
    }
}

/// A closed mirror sphere of reflectance ρ that also emits L_e = 1 from its
/// inside: every camera ray picks up L_e at each bounce, so L = L_e / (1 − ρ)
/// (the specular furnace). `whitted` with B specular bounces gives exactly
/// (1 − ρ^(B+1)) / (1 − ρ) (deterministic); path-based methods are exact up
/// to Russian roulette noise after 5 bounces (5 standard errors + 0.3%).
/// `lighttrace` sees the emission (s = 1) and none of its mirror reflections:
/// L_e = 1 for every ρ, same tolerance.
#[test]
fn emitting_mirror_enclosure_is_le_over_one_minus_rho() {
    for rho in [0.5f64, 0.8] {
        let scene = mirror_enclosure(rho);
        for m in METHODS {
            let film = render_str(&scene, &method(m, 32, 2));
            let (mean, se) = mean_and_stderr(&film, 1);
            let want = match m {
                "whitted" => (1.0 - rho.powi(41)) / (1.0 - rho),
                // The emission seen directly (s = 1), none of its mirror reflections.
                "lighttrace" => 1.0,
                _ => 1.0 / (1.0 - rho),
            };
            eprintln!("mirror furnace ρ {rho}, {m}: Y = {mean:.5} ± {se:.5}, want {want:.5}");
            assert!((mean - want).abs() < 5.0 * se + 3e-3 * want, "ρ {rho}, {m}: Y = {mean} ± {se}, want {want}");
        }
    }
}
