//! Issue 33, target 2: every integrator and wavelength mode has a test with
//! the statistical power to detect a 1% bias in a closed-form quantity.
//!
//! Each test renders the same small image with `SEEDS` independent seeds;
//! the standard error is that of the mean of the per-seed image means
//! (s.e. = s.d. of the seed means / √SEEDS), so it measures the estimator's
//! noise, not the spread of pixel values over an image. The assertion is
//! `|mean − want| < 4 s.e. + 0.1% of want` (the 0.1% covers f32 and the
//! colour-matching normalisation, measured below 0.05% for a constant
//! spectrum). Each test also asserts its own power: the s.e. must be small
//! enough that `4 s.e. + 0.1% + 2 s.e. ≤ 1%` of the answer, so a 1% bias is
//! beyond the threshold by at least 2 s.e. and fails the test with
//! probability at least 97.7% (one-sided normal tail); the smallest bias
//! detected with that probability is printed per method
//! (`detects ≥ x%`) and quoted in tests/README.md.

use rust_v::settings::{IntegratorKind, SettingsPatch, WavelengthsKind};

use super::method;
use crate::common::render_str;

/// Independent seeds per estimate.
const SEEDS: u64 = 16;

/// The lighting mode `m` of the failure matrix, plus `continuous`
/// (`--integrator spectral --wavelengths continuous`).
fn patch(m: &str, spp: u32, seed: u64) -> SettingsPatch {
    if m == "continuous" {
        return SettingsPatch {
            integrator: Some(IntegratorKind::Spectral),
            wavelengths: Some(WavelengthsKind::Continuous),
            spp: Some(spp),
            seed: Some(seed),
            ..Default::default()
        };
    }
    method(m, spp, seed)
}

/// Mean over `SEEDS` seeds of the image mean of Y, and its standard error
/// from the spread of the seed means.
fn over_seeds(scene: &str, m: &str, spp: u32) -> (f64, f64) {
    let means: Vec<f64> = (0..SEEDS)
        .map(|s| {
            let film = render_str(scene, &patch(m, spp, 1000 + 7919 * s));
            let v = super::y(&film);
            v.iter().sum::<f64>() / v.len() as f64
        })
        .collect();
    super::mean_se(&means)
}

/// Asserts `mean` within 4 s.e. + 0.1% of `want`, and that the test can see a
/// 1% bias (6 s.e. + 0.1% ≤ 1%). Returns the smallest relative bias detected
/// with probability ≥ 97.7%.
fn check(what: &str, m: &str, (mean, se): (f64, f64), want: f64) -> f64 {
    let tol = 4.0 * se + 1e-3 * want;
    let detects = (tol + 2.0 * se) / want;
    eprintln!(
        "{what}, {m}: Y = {mean:.5} ± {se:.5} ({:.3}%), want {want:.5}, off {:+.3}%, detects ≥ {:.2}%",
        100.0 * se / want,
        100.0 * (mean / want - 1.0),
        100.0 * detects
    );
    assert!((mean - want).abs() < tol, "{what}, {m}: Y = {mean} ± {se}, want {want} (tol {tol})");
    assert!(detects <= 0.01, "{what}, {m}: s.e. {se} too large to detect a 1% bias ({:.2}%)", 100.0 * detects);
    detects
}

/// The white furnace (as `tests/furnace.rs`): a closed Lambertian sphere of
/// albedo 0.5 emitting L_e = 1 (equal energy, Y = 1) on both sides, the
/// camera inside: L = L_e / (1 − ρ) = 2 in every pixel and direction (the
/// Neumann series L_e Σ ρᵏ). `bdpt` was biased there until a fix (see
/// [`bdpt_sphere_furnace_gives_two`]) and its 1% test runs in [`BOX_FURNACE`].
const FURNACE: &str = r#"(
    camera: (eye: (0.1, -0.2, 0.3), look_at: (1, 0.5, -0.3), fov_deg: 70),
    render: (width: 8, height: 8, max_bounces: 10000),
    materials: { "m": Lambertian(reflectance: Constant(0.5)) },
    objects: [ (shape: Sphere(center: (0, 0, 0), radius: 1), material: "m", emission: Constant(1), two_sided: true) ],
)"#;

/// The same furnace built as a closed box (a cube of side 2): also L = 2.
fn box_furnace() -> String {
    FURNACE.replace("Sphere(center: (0, 0, 0), radius: 1)", "Cuboid(min: (-1, -1, -1), max: (1, 1, 1))")
}

/// Every sampled method against the white furnace, L = 2 (`whitted`,
/// direct light only: L_e + ρ L_e = 1.5, the sphere lighting itself with
/// irradiance π L_e); `bdpt` in the box. Samples per pixel per method chosen
/// so that the s.e. over 16 seeds of 8x8 is at most about 0.1%: the whole
/// test renders in about a second.
#[test]
fn white_furnace_detects_a_one_percent_bias_in_every_method() {
    for (m, spp) in [
        ("whitted", 128),
        ("path", 128),
        ("hero", 128),
        ("random", 128),
        ("continuous", 128),
        ("auto", 128),
        ("bdpt", 256),
        ("lighttrace", 1024),
    ] {
        let (scene, want) = match m {
            "whitted" => (FURNACE.to_string(), 1.5),
            "bdpt" => (box_furnace(), 2.0),
            _ => (FURNACE.to_string(), 2.0),
        };
        let what = if m == "bdpt" { "white furnace ρ 0.5 (box)" } else { "white furnace ρ 0.5" };
        check(what, m, over_seeds(&scene, m, spp), want);
    }
}

/// Dispersive glass, where `auto` and the packets split or collapse: the
/// camera at the centre of an N-BK7 sphere in the uniform enclosure (L = 1)
/// sees Σ_b n(λ_b)² ȳ_b = 2.3051 (the radiance gains n² entering glass).
/// `hero`, `random`, `auto` and `bdpt` against that sum (`path` and `whitted`
/// trace 589.3 nm only: n(589.3)², exact per pixel, asserted in
/// `glass.rs`).
#[test]
fn dispersive_glass_detects_a_one_percent_bias() {
    let (scene, want) = super::camera_inside_nbk7();
    for (m, spp) in [("hero", 64), ("random", 64), ("auto", 64), ("bdpt", 64)] {
        check("camera in N-BK7", m, over_seeds(&scene, m, spp), want);
    }
}

/// A bug this test found (issue 33), fixed: `bdpt` in the white furnace of
/// a closed, two-sided emitting Lambertian *sphere* (ρ 0.5, camera inside;
/// `tests/furnace.rs`'s scene) gave 1.770 ± 0.003 instead of L_e / (1 − ρ) =
/// 2 (−11.5%), while `path` and `lighttrace` agreed with 2. The shading
/// points lie on the emitting sphere, which `SphereLight::sample_li` took for
/// outside by rounding: the cone it sampled was a hemisphere whose point was
/// the shading point itself, at distance 0. Points on the sphere within
/// rounding now sample it by area (`src/light/sphere.rs`, `by_area`): 2.0005 ±
/// 0.0012.
#[test]
fn bdpt_sphere_furnace_gives_two() {
    check("white furnace ρ 0.5 (sphere)", "bdpt", over_seeds(FURNACE, "bdpt", 256), 2.0);
}

/// A second bug found beside the first, fixed with it: a closed *one-sided*
/// emitting sphere (`two_sided: false`: it emits outward only) seen from
/// inside must give exactly 0 (the cube built the same way does with every
/// method), but light sampling leaked its emission in: `whitted` 0.2587 ±
/// 0.0016, `path` 0.2038 ± 0.0008, `bdpt` 0.00075 ± 0.00001 (16 seeds of 8x8
/// at 32 spp, ρ 0.5). Same cause (a point on the sphere taken for outside);
/// and by area a one-sided sphere now gives nothing from a point its outside
/// does not face. Exactly 0 with every method.
#[test]
fn one_sided_sphere_emitter_is_dark_inside() {
    let scene = FURNACE.replace("two_sided: true", "two_sided: false");
    for m in ["whitted", "path", "bdpt", "lighttrace"] {
        let (mean, se) = over_seeds(&scene, m, 32);
        eprintln!("one-sided sphere emitter seen from inside, {m}: Y = {mean:.5} ± {se:.5}, want 0");
        assert_eq!(mean, 0.0, "{m}: {mean} ± {se}");
    }
}
