//! The `auto` integrator (issue 8): exactly `path` where nothing disperses,
//! and an unbiased spectral estimator where something does.

use rust_v::settings::{IntegratorKind, SettingsPatch, WavelengthsKind};

use crate::common::{mean_and_stderr, render_str, root};

fn with(integrator: IntegratorKind, spp: u32, seed: u64) -> SettingsPatch {
    SettingsPatch {
        integrator: Some(integrator),
        spp: Some(spp),
        seed: Some(seed),
        width: Some(16),
        height: Some(16),
        ..Default::default()
    }
}

/// Without dispersive materials `auto` runs the full-spectrum path tracer:
/// the same random numbers in the same order, so the sums are bit-identical.
#[test]
fn auto_is_bit_identical_to_path_without_dispersion() {
    for file in ["scenes/cornell.ron", "scenes/cornell-lambert.ron"] {
        let scene = std::fs::read_to_string(root().join(file)).unwrap();
        let a = render_str(&scene, &with(IntegratorKind::Auto, 4, 9));
        let p = render_str(&scene, &with(IntegratorKind::Path, 4, 9));
        assert_eq!(a.mean_xyz(), p.mean_xyz(), "{file}");
    }
}

/// On a dispersive scene `auto` converges to the same image as `spectral`
/// with hero packets: block means agree within 6 standard errors measured
/// from 8 seeds each (see `spectral::assert_same_image`).
#[test]
fn auto_matches_spectral_hero_with_dispersion() {
    let scene = std::fs::read_to_string(root().join("scenes/spheres.ron")).unwrap();
    let auto = crate::spectral::block_stats(&scene, |s| with(IntegratorKind::Auto, 32, 300 + s), 8, 4);
    let hero = crate::spectral::block_stats(
        &scene,
        |s| SettingsPatch { wavelengths: Some(WavelengthsKind::Hero), ..with(IntegratorKind::Spectral, 32, 400 + s) },
        8,
        4,
    );
    crate::spectral::assert_same_image(&auto, &hero, "auto vs hero");
}

/// The invisible glass sphere (dispersive N-BK7 in a uniform enclosure) is
/// invisible to `auto` too: the reflect-or-collapse choice and the
/// importance-drawn bins keep every bin's expected weight, so the image mean
/// is the enclosure's radiance.
#[test]
fn auto_sees_through_the_glass_sphere() {
    let scene = r#"(
        camera: (eye: (0, 0, 4), look_at: (0, 0, 0), fov_deg: 30),
        render: (max_bounces: 64),
        materials: { "glass": Dielectric(ior: Named("N-BK7")) },
        objects: [
            (shape: Sphere(center: (0, 0, 0), radius: 1), material: "glass"),
            (shape: Sphere(center: (0, 0, 0), radius: 10), emission: Constant(1), two_sided: true),
        ],
    )"#;
    let film = render_str(scene, &with(IntegratorKind::Auto, 64, 11));
    let (mean, se) = mean_and_stderr(&film, 1);
    assert!((mean - 1.0).abs() < 5.0 * se + 2e-3, "Y = {mean} ± {se}");
}

/// At 1 spp `auto` is as bright on average as converged, on a dispersive
/// scene: the mean of 64 one-sample renders of spheres.ron against hero at
/// 256 spp, within 5 combined standard errors (from the 64 render means and
/// the pixel spread of the converged image).
#[test]
fn auto_one_spp_is_as_bright_as_converged() {
    let scene = std::fs::read_to_string(root().join("scenes/spheres.ron")).unwrap();
    let converged = render_str(
        &scene,
        &SettingsPatch { wavelengths: Some(WavelengthsKind::Hero), ..with(IntegratorKind::Spectral, 256, 5) },
    );
    let (want, want_se) = mean_and_stderr(&converged, 1);
    let means: Vec<f64> =
        (0..64).map(|s| mean_and_stderr(&render_str(&scene, &with(IntegratorKind::Auto, 1, 2000 + s)), 1).0).collect();
    let n = means.len() as f64;
    let mean = means.iter().sum::<f64>() / n;
    let se = (means.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / (n - 1.0) / n).sqrt();
    let tol = 5.0 * (se * se + want_se * want_se).sqrt();
    assert!((mean - want).abs() < tol, "1-spp mean Y {mean:.5} vs converged {want:.5} (tol {tol:.5})");
}

/// Inside glass (the camera in a dense flint sphere, looking out at a
/// coloured enclosure and a coloured wall, through total internal reflection
/// near the rim) `auto` takes the branch that weighs every bin's reflectance
/// before choosing reflection or refraction. It must estimate the same image
/// as hero packets, which never take that branch: block means within 6
/// standard errors from 8 seeds each (see `spectral::assert_same_image`).
#[test]
fn auto_matches_hero_from_inside_glass() {
    let scene = r#"(
        camera: (eye: (0.3, 0.2, 1.2), look_at: (0, 0, -3), fov_deg: 100),
        render: (max_bounces: 24),
        materials: {
            "flint": Dielectric(ior: Named("N-SF11")),
            "wall": Lambertian(reflectance: ColorChecker("cyan")),
        },
        objects: [
            (shape: Sphere(center: (0, 0, 0), radius: 1.6), material: "flint"),
            (shape: Sphere(center: (0, 0, -2.5), radius: 0.6), material: "wall"),
            (shape: Sphere(center: (0, 0, 0), radius: 10), emission: Blackbody(3000), two_sided: true),
        ],
    )"#;
    let auto = crate::spectral::block_stats(scene, |s| with(IntegratorKind::Auto, 16, 500 + s), 8, 4);
    let hero = crate::spectral::block_stats(
        scene,
        |s| SettingsPatch { wavelengths: Some(WavelengthsKind::Hero), ..with(IntegratorKind::Spectral, 16, 600 + s) },
        8,
        4,
    );
    crate::spectral::assert_same_image(&auto, &hero, "auto vs hero inside glass");
}
