//! Participating media (`media:`, an object's `interior:`): transmittance
//! against Beer-Lambert, furnaces, chromatic media against single wavelengths,
//! and what the integrators refuse.

use glam::Vec3;
use rust_v::settings::{IntegratorKind, SettingsPatch, WavelengthsKind};

use crate::common::{mean_and_stderr, render_str};

/// A shadow ray through an index-matched slab (an `Interface` cuboid 0.8
/// thick filled with a medium) is attenuated by exp(−σt d) per bin, to f32
/// rounding (relative 1e-5), for a constant σt and for Rayleigh scattering
/// (σs = s (550/λ)⁴); the same ray beside the slab is clear.
#[test]
fn transmittance_through_an_index_matched_slab_is_beer_lambert_per_bin() {
    for (sigma_s, want) in [
        ("Constant(0.7)", Box::new(|_: f32| 0.3f32 + 0.7) as Box<dyn Fn(f32) -> f32>),
        ("Rayleigh(0.9)", Box::new(|nm: f32| 0.3 + 0.9 * (550.0 / nm).powi(4))),
    ] {
        let text = format!(
            r#"(camera: (eye: (0, 0, 5), look_at: (0, 0, 0), fov_deg: 30),
            media: {{ "m": Homogeneous(sigma_a: Constant(0.3), sigma_s: {sigma_s}) }},
            materials: {{ "clear": Interface }},
            objects: [ (shape: Cuboid(min: (-1, -1, -0.4), max: (1, 1, 0.4)), material: "clear", interior: "m") ],
            lights: [ Point(position: (0, 0, -3), intensity: Constant(1)) ])"#
        );
        let scene = rust_v::scene::load_scene_str(&text, std::path::Path::new("t.ron"), &SettingsPatch::default())
            .expect("scene loads");
        let stack = scene.volumes_at(Vec3::new(0.0, 0.0, 2.0));
        let clear = scene
            .transmittance(Vec3::new(0.0, 0.0, 2.0), Vec3::ZERO, Some(&stack), Vec3::new(0.0, 0.0, -2.0), Vec3::ZERO)
            .expect("index-matched boundaries do not block");
        let t = clear.spectrum().expect("a medium on the way");
        for b in 0..rust_v::color::N_BINS {
            let e = (-want(rust_v::color::bin_lambda_nm(b)) * 0.8).exp();
            assert!((t[b] - e).abs() <= 1e-5 * e + 1e-7, "{sigma_s}, bin {b}: {} vs {e}", t[b]);
        }
        let beside = scene
            .transmittance(Vec3::new(3.0, 0.0, 2.0), Vec3::ZERO, Some(&stack), Vec3::new(3.0, 0.0, -2.0), Vec3::ZERO)
            .expect("clear");
        assert!(beside.spectrum().is_none(), "beside the slab: vacuum");
    }
}

fn furnace(albedo: f32, g: f32) -> String {
    format!(
        r#"(camera: (eye: (0.2, 0.1, 3), look_at: (0, 0, 0), fov_deg: 40),
        render: (width: 16, height: 16, spp: 64, max_bounces: 1000),
        media: {{ "m": Homogeneous(sigma_a: Constant({}), sigma_s: Constant({}), phase: HenyeyGreenstein(g: {g})) }},
        materials: {{ "boundary": Interface }},
        objects: [ (shape: Sphere(center: (0, 0, 0), radius: 1), material: "boundary", interior: "m") ],
        environment: Uniform(Constant(1)))"#,
        2.0 * (1.0 - albedo),
        2.0 * albedo
    )
}

/// A sphere of medium of albedo 1 (σs 2, σa 0: about four mean free paths
/// across) with an index-matched boundary in `Uniform(Constant(1))` loses
/// nothing: every pixel is 1, with isotropic and forward (g 0.7) scattering,
/// for `path`, `auto` and hero packets. Tolerance: 5 standard errors of the
/// image mean plus 0.3%. With albedo 0.5 the sphere's pixels are darker,
/// and the centre pixel's radiance at least the single-scattering-free
/// transmittance exp(−2σt) (the unscattered sky behind) and at most 1.
#[test]
fn a_sphere_of_albedo_one_in_a_uniform_environment_is_invisible() {
    for g in [0.0f32, 0.7] {
        for (integrator, wavelengths) in [
            (IntegratorKind::Path, None),
            (IntegratorKind::Auto, None),
            (IntegratorKind::Spectral, Some(WavelengthsKind::Hero)),
        ] {
            let film = render_str(
                &furnace(1.0, g),
                &SettingsPatch { integrator: Some(integrator), wavelengths, ..Default::default() },
            );
            let (mean, se) = mean_and_stderr(&film, 1);
            eprintln!("albedo 1, g {g}, {integrator:?}: Y = {mean:.5} ± {se:.5}");
            assert!((mean - 1.0).abs() < 5.0 * se + 3e-3, "g {g}, {integrator:?}: Y = {mean} ± {se}");
        }
    }
    let film = render_str(&furnace(0.5, 0.0), &SettingsPatch::default());
    let xyz = film.mean_xyz();
    let centre = (xyz[7 * 16 + 7][1] + xyz[8 * 16 + 8][1] + xyz[7 * 16 + 8][1] + xyz[8 * 16 + 7][1]) / 4.0;
    let floor = (-2.0f64 * 2.0).exp();
    eprintln!("albedo 0.5: centre Y = {centre}, unscattered part {floor}");
    assert!(centre > floor && centre < 0.9, "albedo 0.5: centre {centre}");
}

/// A chromatic medium (σs rising to the blue, Rayleigh; σa a ramp) seen in a
/// uniform environment: the full-spectrum path tracer (one distance per path
/// by spectral MIS over 36 bins) agrees with hero packets of 4 wavelengths
/// and with single-wavelength packets, per channel, within 5 standard errors
/// of the difference plus 0.5%.
#[test]
fn a_chromatic_medium_agrees_across_wavelength_sampling() {
    let scene = r#"(camera: (eye: (0.2, 0.1, 3), look_at: (0, 0, 0), fov_deg: 40),
        render: (width: 16, height: 16, spp: 64, max_bounces: 64),
        media: { "m": Homogeneous(sigma_a: Table([(380, 0.1), (730, 1.2)]), sigma_s: Rayleigh(1.5), phase: HenyeyGreenstein(g: 0.3)) },
        materials: { "boundary": Interface, "floor": Lambertian(reflectance: Constant(0.5)) },
        objects: [
            (shape: Sphere(center: (0, 0, 0), radius: 1), material: "boundary", interior: "m"),
            (shape: Quad(origin: (-3, -1, 3), edge_u: (6, 0, 0), edge_v: (0, 0, -6)), material: "floor"),
        ],
        environment: Uniform(Constant(1)))"#;
    let full = render_str(scene, &SettingsPatch { integrator: Some(IntegratorKind::Path), ..Default::default() });
    for (packet, wavelengths) in [(4, WavelengthsKind::Hero), (1, WavelengthsKind::Random)] {
        let other = render_str(
            scene,
            &SettingsPatch {
                integrator: Some(IntegratorKind::Spectral),
                wavelengths: Some(wavelengths),
                packet_size: Some(packet),
                spp: Some(256),
                ..Default::default()
            },
        );
        for c in 0..3 {
            let (a, sa) = mean_and_stderr(&full, c);
            let (b, sb) = mean_and_stderr(&other, c);
            let tol = 5.0 * (sa * sa + sb * sb).sqrt() + 5e-3 * a;
            eprintln!("packet {packet}, channel {c}: full {a:.5} ± {sa:.5}, packets {b:.5} ± {sb:.5}");
            assert!((a - b).abs() < tol, "packet {packet}, channel {c}: {a} ± {sa} vs {b} ± {sb}");
        }
    }
}

/// Grid media (`Grid(path: "x.vol", ...)`): a grid of constant density is the
/// homogeneous medium (delta tracking with spectral MIS against the
/// closed-form distance sampling: image means per channel within 5 standard
/// errors of the difference + 0.5%, chromatic coefficients); a grid of albedo
/// 1 with a varying density (a blob) in a uniform environment is invisible
/// (1, 5 s.e. + 0.3%).
#[test]
fn grid_media_match_homogeneous_and_keep_energy() {
    let dir = crate::common::temp_dir("media_grid");
    let n = 8usize;
    std::fs::write(dir.join("flat.vol"), rust_v::medium::grid::write_vol([n, n, n], &vec![1.0; n * n * n])).unwrap();
    let blob: Vec<f32> = (0..n * n * n)
        .map(|k| {
            let p = Vec3::new((k % n) as f32, ((k / n) % n) as f32, (k / (n * n)) as f32) / (n as f32 - 1.0) - 0.5;
            (3.0 - 10.0 * p.length_squared()).max(0.0)
        })
        .collect();
    std::fs::write(dir.join("blob.vol"), rust_v::medium::grid::write_vol([n, n, n], &blob)).unwrap();
    let scene = |medium: &str, floor: bool| {
        let floor = if floor {
            r#"(shape: Quad(origin: (-3, -1, 3), edge_u: (6, 0, 0), edge_v: (0, 0, -6)), material: "floor"),"#
        } else {
            ""
        };
        format!(
            r#"(camera: (eye: (0.2, 0.1, 3), look_at: (0, 0, 0), fov_deg: 40),
            render: (width: 16, height: 16, spp: 64, max_bounces: 1000),
            media: {{ "m": {medium} }},
            materials: {{ "b": Interface, "floor": Lambertian(reflectance: Constant(0.5)) }},
            objects: [ (shape: Sphere(center: (0, 0, 0), radius: 1), material: "b", interior: "m"), {floor} ],
            environment: Uniform(Constant(1)))"#
        )
    };
    let render = |medium: &str, seed: u64, floor: bool| {
        let path = dir.join(format!("s{seed}.ron"));
        std::fs::write(&path, scene(medium, floor)).unwrap();
        crate::common::render_file(&path, &SettingsPatch { seed: Some(seed), ..Default::default() })
    };
    let coeffs = "sigma_a: Table([(380, 0.1), (730, 0.6)]), sigma_s: Rayleigh(1.2), phase: HenyeyGreenstein(g: 0.4)";
    let homogeneous = render(&format!("Homogeneous({coeffs})"), 1, true);
    let grid = render(&format!(r#"Grid(path: "flat.vol", {coeffs})"#), 2, true);
    for c in 0..3 {
        let (a, sa) = mean_and_stderr(&homogeneous, c);
        let (b, sb) = mean_and_stderr(&grid, c);
        eprintln!("channel {c}: homogeneous {a:.5} ± {sa:.5}, grid {b:.5} ± {sb:.5}");
        assert!((a - b).abs() < 5.0 * (sa * sa + sb * sb).sqrt() + 5e-3 * a, "channel {c}: {a} vs {b}");
    }
    // Albedo 1, a blob of density up to 3 scaled by 2, alone in the environment.
    let white = render(r#"Grid(path: "blob.vol", sigma_a: Constant(0), sigma_s: Constant(2))"#, 3, false);
    let (mean, se) = mean_and_stderr(&white, 1);
    eprintln!("albedo-1 blob: Y = {mean:.5} ± {se:.5}");
    assert!((mean - 1.0).abs() < 5.0 * se + 3e-3, "albedo-1 blob: {mean} ± {se}");
}

/// Bidirectional methods with media: medium vertices on both subpaths,
/// connections through media. The albedo-1 sphere in a uniform environment
/// renders 1 with `bdpt` and `lighttrace` (5 s.e. + 0.5%), and on the chromatic
/// medium over a floor `bdpt` and `lighttrace` agree with `path` per channel
/// (5 s.e. of the difference + 1%).
#[test]
fn bidirectional_methods_render_media() {
    for g in [0.0f32, 0.7] {
        for integrator in [IntegratorKind::Bdpt, IntegratorKind::LightTrace] {
            let film = render_str(
                &furnace(1.0, g),
                &SettingsPatch { integrator: Some(integrator), spp: Some(64), ..Default::default() },
            );
            let (mean, se) = mean_and_stderr(&film, 1);
            eprintln!("albedo 1, g {g}, {integrator:?}: Y = {mean:.5} ± {se:.5}");
            assert!((mean - 1.0).abs() < 5.0 * se + 5e-3, "g {g}, {integrator:?}: Y = {mean} ± {se}");
        }
    }
    let scene = r#"(camera: (eye: (0.2, 0.1, 3), look_at: (0, 0, 0), fov_deg: 40),
        render: (width: 16, height: 16, spp: 128, max_bounces: 32),
        media: { "m": Homogeneous(sigma_a: Table([(380, 0.1), (730, 1.2)]), sigma_s: Rayleigh(1.5), phase: HenyeyGreenstein(g: 0.3)) },
        materials: { "boundary": Interface, "floor": Lambertian(reflectance: Constant(0.5)) },
        objects: [
            (shape: Sphere(center: (0, 0, 0), radius: 1), material: "boundary", interior: "m"),
            (shape: Quad(origin: (-3, -1, 3), edge_u: (6, 0, 0), edge_v: (0, 0, -6)), material: "floor"),
        ],
        lights: [ Point(position: (1.5, 2, 0.5), intensity: Constant(6)) ],
        environment: Uniform(Constant(0.3)))"#;
    let path = render_str(scene, &SettingsPatch { integrator: Some(IntegratorKind::Path), ..Default::default() });
    for integrator in [IntegratorKind::Bdpt, IntegratorKind::LightTrace] {
        let other = render_str(scene, &SettingsPatch { integrator: Some(integrator), ..Default::default() });
        for c in 0..3 {
            let (a, sa) = mean_and_stderr(&path, c);
            let (b, sb) = mean_and_stderr(&other, c);
            eprintln!("{integrator:?}, channel {c}: path {a:.5} ± {sa:.5}, {b:.5} ± {sb:.5}");
            assert!((a - b).abs() < 5.0 * (sa * sa + sb * sb).sqrt() + 0.01 * a, "{integrator:?} channel {c}");
        }
    }
}

/// Single scattering in an optically thin slab against its closed form: an
/// index-matched slab of thickness h (σs 0.02, σa 0.01, isotropic; optical
/// thickness 0.03 along the view) lit by a distant light of irradiance E at
/// incidence μi = cos 60°, seen straight down (μv = 1) with nothing below:
/// L = σs p E / μv · (1 − exp(−σt h (1/μi + 1/μv))) / (σt (1/μi + 1/μv)),
/// p = 1/4π. Multiple scattering adds at most about the albedo times the
/// largest optical thickness a path crosses (2/3 · (0.06 + 0.03): 6%), so
/// the image mean (path and bdpt, 1024 spp) must lie within [L, 1.06 L]
/// widened by 5 standard errors.
#[test]
fn a_thin_slab_matches_single_scattering() {
    let (sigma_s, sigma_a, h, e) = (0.02f64, 0.01f64, 1.0f64, 50.0f64);
    let scene = format!(
        r#"(camera: (eye: (0, 3, 0), look_at: (0, 0, 0), up: (0, 0, -1), fov_deg: 10),
        render: (width: 16, height: 16, spp: 1024, max_bounces: 16),
        media: {{ "m": Homogeneous(sigma_a: Constant({sigma_a}), sigma_s: Constant({sigma_s})) }},
        materials: {{ "b": Interface }},
        objects: [ (shape: Cuboid(min: (-50, -{h}, -50), max: (50, 0, 50)), material: "b", interior: "m") ],
        lights: [ Distant(direction: (0.8660254, -0.5, 0), irradiance: Constant({e})) ])"#
    );
    let (mu_i, mu_v) = (0.5f64, 1.0f64);
    let sigma_t = sigma_s + sigma_a;
    let k = 1.0 / mu_i + 1.0 / mu_v;
    let want = sigma_s / (4.0 * std::f64::consts::PI) * e / mu_v * (1.0 - (-sigma_t * h * k).exp()) / (sigma_t * k);
    for integrator in [IntegratorKind::Path, IntegratorKind::Bdpt] {
        let film = render_str(&scene, &SettingsPatch { integrator: Some(integrator), ..Default::default() });
        let (mean, se) = mean_and_stderr(&film, 1);
        eprintln!("thin slab, {integrator:?}: Y = {mean:.6} ± {se:.6}, single scattering {want:.6}");
        assert!(mean > want - 5.0 * se && mean < 1.06 * want + 5.0 * se, "{integrator:?}: {mean} vs {want}");
    }
}
