//! The white furnace: inside a closed Lambertian sphere of albedo ρ that
//! emits L_e everywhere (two-sided), radiance is L_e / (1 − ρ) at every point
//! and in every direction (the Neumann series L = L_e Σ ρᵏ). This checks the
//! estimator, light sampling, MIS and Russian roulette together.

use rust_v::settings::SettingsPatch;

use crate::common::{mean_and_stderr, render_str};

fn furnace(material: &str, integrator: &str, rho: f32) -> String {
    format!(
        r#"(
        camera: (eye: (0.1, -0.2, 0.3), look_at: (1, 0.5, -0.3), fov_deg: 70),
        render: (width: 16, height: 16, spp: 64, max_bounces: 10000, integrator: {integrator}),
        materials: {{ "m": {material} }},
        objects: [ (shape: Sphere(center: (0, 0, 0), radius: 1), material: "m", emission: Constant(1), two_sided: true) ],
    )"#
    )
    .replace("RHO", &rho.to_string())
}

/// Checks Y (equal-energy emission of 1 has Y = 1) against 1/(1-ρ). The
/// tolerance is 5 standard errors of the image mean, estimated from the
/// spread of the 256 pixel means themselves (each of 64 samples), plus 0.2%
/// for the f32 arithmetic; a biased estimator (e.g. roulette without the 1/q
/// weight, or MIS weights not summing to 1) is off by far more.
fn check(material: &str, integrator: &str, rho: f32) {
    let film = render_str(&furnace(material, integrator, rho), &SettingsPatch::default());
    let want = 1.0 / (1.0 - rho as f64);
    let (mean, se) = mean_and_stderr(&film, 1);
    let tol = 5.0 * se + 2e-3 * want;
    assert!((mean - want).abs() < tol, "{material} / {integrator}: Y = {mean} ± {se}, want {want} (tol {tol})");
    // X and Z too: the equal-energy spectrum has X = Y = Z to within the CMF normalisation (0.1%).
    for c in [0, 2] {
        let (m, se) = mean_and_stderr(&film, c);
        assert!((m - want).abs() < 5.0 * se + 5e-3 * want, "channel {c}: {m}");
    }
}

#[test]
fn lambertian_furnace_converges_to_le_over_one_minus_rho() {
    check("Lambertian(reflectance: Constant(RHO))", "path", 0.5);
    check("Lambertian(reflectance: Constant(RHO))", "path", 0.8);
}

#[test]
fn oren_nayar_at_sigma_zero_is_the_lambertian_furnace() {
    check("OrenNayar(reflectance: Constant(RHO), sigma_deg: 0)", "path", 0.5);
}

/// Without wavelength dependence, the spectral integrator's packets are
/// unbiased too: hero and random packets give the same furnace radiance.
#[test]
fn spectral_packets_pass_the_furnace() {
    let material = "Lambertian(reflectance: Constant(RHO))";
    for how in ["hero", "random"] {
        let film = render_str(
            &furnace(material, "spectral", 0.5),
            &SettingsPatch {
                wavelengths: Some(match how {
                    "hero" => rust_v::settings::WavelengthsKind::Hero,
                    _ => rust_v::settings::WavelengthsKind::Random,
                }),
                ..Default::default()
            },
        );
        let (mean, se) = mean_and_stderr(&film, 1);
        assert!((mean - 2.0).abs() < 5.0 * se + 4e-3, "{how}: Y = {mean} ± {se}");
    }
}
