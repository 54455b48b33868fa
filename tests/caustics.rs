//! `--integrator caustics` (issue 35): path tracing plus aimed light
//! subpaths for the caustics of the environment and distant lights through
//! specular surfaces. Checked against the other integrators' converged
//! means (independent estimators of the same image), for bit-identity
//! with `path` where there is nothing to aim, and for determinism.

use rust_v::film::Film;
use rust_v::scene::load_scene_str;
use rust_v::settings::IntegratorKind;

use crate::common::{assert_threads_and_merge_exact, render_into, render_str, root, seeded_blocks, square_settings};

/// Asserts every block of `a` within 4.5 combined standard errors (+1e-4)
/// of `b`'s (16 blocks: all pass by chance with probability > 99.9%), and
/// the image means (mean of the blocks, errors in quadrature: an upper
/// bound for independent blocks) within 4.5 combined s.e. too.
fn assert_blocks_agree(what: &str, a: &[(f64, f64)], b: &[(f64, f64)]) {
    for (k, (x, y)) in a.iter().zip(b).enumerate() {
        let se = (x.1 * x.1 + y.1 * y.1).sqrt();
        assert!((x.0 - y.0).abs() <= 4.5 * se + 1e-4, "{what}, block {k}: {:.4} vs {:.4} (se {se:.4})", x.0, y.0);
    }
    let n = a.len() as f64;
    let (ma, mb) = (a.iter().map(|x| x.0).sum::<f64>() / n, b.iter().map(|x| x.0).sum::<f64>() / n);
    let se = (a.iter().chain(b).map(|x| x.1 * x.1).sum::<f64>()).sqrt() / n;
    eprintln!(
        "{what}: image {ma:.4} vs {mb:.4}, differ {:+.2}%, s.e. {:.2}%",
        100.0 * (ma / mb - 1.0),
        100.0 * se / mb
    );
    assert!((ma - mb).abs() <= 4.5 * se + 1e-5, "{what}: image {ma} vs {mb} (se {se})");
}

/// Per-block (mean, standard error) over the seeds ([`seeded_blocks`]).
type Blocks = Vec<(f64, f64)>;

/// `caustics`' blocks and `reference`'s for scene `text` (24 renders each,
/// 16x16, 16 spp), asserted to agree ([`assert_blocks_agree`]); both returned.
fn caustics_agrees_with(text: &str, reference: IntegratorKind, what: &str) -> (Blocks, Blocks) {
    let other = seeded_blocks(text, reference, 16, 16, 24).0;
    let caustics = seeded_blocks(text, IntegratorKind::Caustics, 16, 16, 24).0;
    assert_blocks_agree(what, &caustics, &other);
    (caustics, other)
}

/// A smooth glass sphere over a diffuse floor (its focus, 1.5 radii from
/// its centre for an index of 1.5, on the floor), lit by `light` (a RON line).
fn glass_over_floor(light: &str) -> String {
    format!(
        r#"(
        camera: (eye: (0, 1.3, 2.6), look_at: (0, 0.25, 0), fov_deg: 45),
        render: (max_bounces: 8),
        materials: {{ "glass": Dielectric(ior: Constant(1.5)), "floor": Lambertian(reflectance: Constant(0.7)) }},
        objects: [
            (shape: Quad(origin: (-3, 0, 3), edge_u: (6, 0, 0), edge_v: (0, 0, -6)), material: "floor"),
            (shape: Sphere(center: (0, 0.75, 0), radius: 0.5), material: "glass"),
        ],
        {light}
    )"#
    )
}

/// Under a uniform environment the two sides of the partition add up to
/// path tracing's image: every 4x4 block of 24 `caustics` renders agrees
/// with 24 `path` renders (16x16, 16 spp each), the floor under and around
/// the sphere (where the light side's paths land) included.
#[test]
fn caustics_matches_path_under_a_uniform_environment() {
    let text = glass_over_floor("environment: Uniform(Constant(1)),");
    caustics_agrees_with(&text, IntegratorKind::Path, "uniform environment, caustics vs path");
}

/// Under the sky with its sun (half a degree: path tracing finds its caustic
/// only by hitting it through the glass), `caustics` agrees with BDPT block
/// by block (24 renders each, 16x16, 16 spp).
#[test]
fn caustics_matches_bdpt_under_the_sky_with_its_sun() {
    let text = glass_over_floor(
        "environment: Sky(sun_elevation_deg: 50, sun_azimuth_deg: 20, turbidity: 3, ground_albedo: 0.3, scale: 0.05),",
    );
    caustics_agrees_with(&text, IntegratorKind::Bdpt, "sky with sun, caustics vs bdpt");
}

/// A distant light over the glass sphere: path tracing cannot see its
/// caustic (no camera path hits a delta light), `caustics` and BDPT do.
/// Every block of `caustics` agrees with BDPT's; the block where BDPT
/// exceeds path tracing most (the caustic) is brighter than path tracing's
/// by more than 10 combined standard errors, and `caustics` has it too.
#[test]
fn a_distant_lights_caustic_that_path_tracing_misses() {
    let text = glass_over_floor("lights: [ Distant(direction: (0.25, -1, -0.3), irradiance: Constant(3)) ],");
    let (caustics, bdpt) = caustics_agrees_with(&text, IntegratorKind::Bdpt, "distant light, caustics vs bdpt");
    let path = seeded_blocks(&text, IntegratorKind::Path, 16, 16, 24).0;
    let (k, gap) =
        bdpt.iter().zip(&path).map(|(b, p)| b.0 - p.0).enumerate().max_by(|a, b| a.1.total_cmp(&b.1)).unwrap();
    let se = |a: &(f64, f64), b: &(f64, f64)| (a.1 * a.1 + b.1 * b.1).sqrt();
    eprintln!("caustic block {k}: bdpt {:.4}, caustics {:.4}, path {:.4}", bdpt[k].0, caustics[k].0, path[k].0);
    assert!(gap > 10.0 * se(&bdpt[k], &path[k]), "no caustic that path misses: {gap}");
    assert!(caustics[k].0 - path[k].0 > 10.0 * se(&caustics[k], &path[k]), "caustics misses the caustic");
}

/// A point light and a spot light over the glass sphere: their caustics
/// (which path tracing cannot see) come from light subpaths aimed by the
/// cone mixture; every block agrees with BDPT's, the caustic's included.
#[test]
fn point_and_spot_light_caustics_match_bdpt() {
    for light in [
        "lights: [ Point(position: (0.3, 2.2, 0.2), intensity: Constant(4)) ],",
        "lights: [ Spot(position: (0.3, 2.2, 0.2), look_at: (0, 0, 0), cone_deg: 30, falloff_deg: 10, intensity: Constant(4)) ],",
    ] {
        let text = glass_over_floor(light);
        caustics_agrees_with(&text, IntegratorKind::Bdpt, &format!("{light} caustics vs bdpt"));
    }
}

/// Glossy surfaces (GGX α at most 0.1) over a diffuse floor: a gold sphere
/// (α 0.05), a rough glass one (α 0.08) and a copper one whose roughness is
/// a checkerboard of 0.05 and 0.4 (glossy on half its hits). Their caustics on
/// the floor are the light side's, each path exactly once; the rest the
/// camera side's. Under a distant light `caustics` agrees with BDPT, under a
/// uniform environment with `path`, block by block (24 renders each).
#[test]
fn glossy_caustics_go_to_the_light_side_unbiased() {
    let scene = |light: &str| {
        format!(
            r#"(
            camera: (eye: (0, 1.4, 2.8), look_at: (0, 0.3, 0), fov_deg: 50),
            render: (max_bounces: 8),
            materials: {{
                "gold": Conductor(metal: "Au", roughness: 0.05),
                "frost": Dielectric(ior: Constant(1.5), roughness: 0.08),
                "copper": Conductor(metal: "Cu", roughness: Checkerboard(even: 0.05, odd: 0.4, scale: 4)),
                "floor": Lambertian(reflectance: Constant(0.7)),
            }},
            objects: [
                (shape: Quad(origin: (-3, 0, 3), edge_u: (6, 0, 0), edge_v: (0, 0, -6)), material: "floor"),
                (shape: Sphere(center: (-0.7, 0.4, 0), radius: 0.4), material: "gold"),
                (shape: Sphere(center: (0.1, 0.4, -0.3), radius: 0.4), material: "frost"),
                (shape: Sphere(center: (0.8, 0.35, 0.3), radius: 0.35), material: "copper"),
            ],
            {light}
        )"#
        )
    };
    let distant = scene("lights: [ Distant(direction: (0.4, -1, -0.5), irradiance: Constant(3)) ],");
    caustics_agrees_with(&distant, IntegratorKind::Bdpt, "glossy spheres under a distant light, caustics vs bdpt");
    let uniform = scene("environment: Uniform(Constant(1)),");
    caustics_agrees_with(
        &uniform,
        IntegratorKind::Path,
        "glossy spheres under a uniform environment, caustics vs path",
    );
}

/// A glossy gold panel (α 0.05) standing on a floor throws a distant light's
/// beam onto the floor in front of it, as bright there as the light's own:
/// the floor the camera sees is mostly that glossy caustic, so counting it
/// twice or not at all (either side's share of the partition wrong) moves the
/// image far outside the tolerance. `caustics` agrees with BDPT under the
/// distant light, and with `path` under a uniform environment.
#[test]
fn a_glossy_panels_caustic_is_counted_once() {
    let scene = |light: &str| {
        format!(
            r#"(
            camera: (eye: (-1.6, 2.2, 0), look_at: (0.3, 0, 0), up: (0, 1, 0), fov_deg: 50),
            render: (max_bounces: 6),
            materials: {{ "gold": Conductor(metal: "Au", roughness: 0.05), "floor": Lambertian(reflectance: Constant(0.7)) }},
            objects: [
                (shape: Quad(origin: (-3, 0, 3), edge_u: (6, 0, 0), edge_v: (0, 0, -6)), material: "floor"),
                (shape: Quad(origin: (1, 0.1, 0.8), edge_u: (0, 0, -1.6), edge_v: (0, 1.2, 0)), material: "gold"),
            ],
            {light}
        )"#
        )
    };
    let distant = scene("lights: [ Distant(direction: (1, -1, 0.1), irradiance: Constant(3)) ],");
    caustics_agrees_with(&distant, IntegratorKind::Bdpt, "a glossy panel under a distant light, caustics vs bdpt");
    let uniform = scene("environment: Uniform(Constant(1)),");
    caustics_agrees_with(
        &uniform,
        IntegratorKind::Path,
        "a glossy panel under a uniform environment, caustics vs path",
    );
}

/// A glossy gold `Plane` (unbounded: no disk to aim at) as a back wall
/// behind a glass sphere on a diffuse floor, lit by a point light: the
/// plane's glossy caustics stay the camera side's and the glass is still
/// aimed at (the light side splats: the image is not `path`'s), and
/// `caustics` agrees with BDPT block by block. (A point light: BDPT's
/// subpaths from a distant light start on a disk around the bounded scene
/// and miss the plane beyond it.)
#[test]
fn an_unbounded_glossy_plane_leaves_the_glass_aimed() {
    let text = r#"(
        camera: (eye: (0, 1.3, 2.6), look_at: (0, 0.25, 0), fov_deg: 45),
        render: (max_bounces: 8),
        materials: { "glass": Dielectric(ior: Constant(1.5)), "floor": Lambertian(reflectance: Constant(0.7)),
                     "gold": Conductor(metal: "Au", roughness: 0.05) },
        objects: [
            (shape: Quad(origin: (-3, 0, 3), edge_u: (6, 0, 0), edge_v: (0, 0, -6)), material: "floor"),
            (shape: Sphere(center: (0, 0.75, 0), radius: 0.5), material: "glass"),
            (shape: Plane(point: (0, 0, -1.5), normal: (0, 0, 1)), material: "gold"),
        ],
        lights: [ Point(position: (0.3, 2.2, 0.2), intensity: Constant(4)) ],
    )"#;
    caustics_agrees_with(text, IntegratorKind::Bdpt, "a glossy plane behind the glass, caustics vs bdpt");
    let path = render_str(text, &square_settings(IntegratorKind::Path, 16, 4, 3));
    let light_side = render_str(text, &square_settings(IntegratorKind::Caustics, 16, 4, 3));
    assert_ne!(light_side, path, "caustics rendered as path: the glass was not aimed at");
}

/// A wall with a hole between a distant light and the glass sphere: most
/// aimed rays hit the wall, so a light subpath is traced for more of the
/// samples (and weighted less); `caustics` still agrees with BDPT block by
/// block, the caustic through the hole included.
#[test]
fn a_blocked_target_raises_the_rate_and_stays_unbiased() {
    let text = r#"(
        camera: (eye: (0, 1.3, 2.6), look_at: (0, 0.25, 0), fov_deg: 45),
        render: (max_bounces: 8),
        materials: { "glass": Dielectric(ior: Constant(1.5)), "floor": Lambertian(reflectance: Constant(0.7)) },
        objects: [
            (shape: Quad(origin: (-3, 0, 3), edge_u: (6, 0, 0), edge_v: (0, 0, -6)), material: "floor"),
            (shape: Sphere(center: (0, 0.75, 0), radius: 0.5), material: "glass"),
            // A roof at y = 1.6 over the sphere, open over x in (-0.25, 0.25).
            (shape: Quad(origin: (-1, 1.6, -1), edge_u: (0.75, 0, 0), edge_v: (0, 0, 2)), material: "floor"),
            (shape: Quad(origin: (0.25, 1.6, -1), edge_u: (0.75, 0, 0), edge_v: (0, 0, 2)), material: "floor"),
        ],
        lights: [ Distant(direction: (0, -1, 0), irradiance: Constant(3)) ],
    )"#;
    caustics_agrees_with(text, IntegratorKind::Bdpt, "a roof with a slot, caustics vs bdpt");
}

/// The camera inside a large glass sphere (a target that encloses the eye)
/// around a small glass sphere on a floor, under a uniform environment:
/// camera paths start inside the glass, light subpaths pass its surface
/// (and totally reflect inside it at grazing angles); `caustics` agrees
/// with `path` block by block.
#[test]
fn a_target_that_encloses_the_camera() {
    let text = r#"(
        camera: (eye: (0, 1.3, 2.6), look_at: (0, 0.25, 0), fov_deg: 45),
        render: (max_bounces: 8),
        materials: { "glass": Dielectric(ior: Constant(1.5)), "dome": Dielectric(ior: Constant(1.2)),
                     "floor": Lambertian(reflectance: Constant(0.7)) },
        objects: [
            (shape: Quad(origin: (-2, 0, 3), edge_u: (4, 0, 0), edge_v: (0, 0, -5)), material: "floor"),
            (shape: Sphere(center: (0, 0.5, 0), radius: 0.5), material: "glass"),
            (shape: Sphere(center: (0, 0.5, 0.5), radius: 4), material: "dome"),
        ],
        environment: Uniform(Constant(1)),
    )"#;
    caustics_agrees_with(text, IntegratorKind::Path, "camera inside a glass dome, caustics vs path");
}

/// With nothing to aim at (no specular surface, or no environment or
/// distant light) `caustics` is path tracing: bit-identical images.
#[test]
fn nothing_to_aim_at_renders_as_path() {
    let diffuse = r#"(
        camera: (eye: (0, 1.3, 2.6), look_at: (0, 0.25, 0), fov_deg: 45),
        materials: { "clay": Lambertian(reflectance: Constant(0.5)), "floor": Lambertian(reflectance: Constant(0.7)) },
        objects: [
            (shape: Quad(origin: (-3, 0, 3), edge_u: (6, 0, 0), edge_v: (0, 0, -6)), material: "floor"),
            (shape: Sphere(center: (0, 0.5, 0), radius: 0.5), material: "clay"),
        ],
        environment: Uniform(Constant(1)),
    )"#;
    let area_light = r#"(
        camera: (eye: (0, 1.3, 2.6), look_at: (0, 0.25, 0), fov_deg: 45),
        materials: { "glass": Dielectric(ior: Constant(1.5)), "floor": Lambertian(reflectance: Constant(0.7)) },
        objects: [
            (shape: Quad(origin: (-3, 0, 3), edge_u: (6, 0, 0), edge_v: (0, 0, -6)), material: "floor"),
            (shape: Sphere(center: (0, 0.5, 0), radius: 0.5), material: "glass"),
            (shape: Sphere(center: (0.5, 2, 0), radius: 0.3), emission: Constant(4)),
        ],
    )"#;
    for (what, text) in [("no specular surface", diffuse.to_string()), ("only an area light", area_light.to_string())] {
        let path = render_str(&text, &square_settings(IntegratorKind::Path, 16, 4, 3));
        let caustics = render_str(&text, &square_settings(IntegratorKind::Caustics, 16, 4, 3));
        assert!(path.mean_xyz().iter().any(|p| p[1] > 0.0), "{what}: black");
        assert_eq!(caustics, path, "{what}");
    }
}

/// Splats keep every guarantee: the image is bit-identical for 1 and 2
/// threads, and passes 0..6 equal merge(0..3, 3..6).
#[test]
fn caustics_is_deterministic_and_merges_exactly() {
    let text = glass_over_floor("lights: [ Distant(direction: (0.25, -1, -0.3), irradiance: Constant(3)) ],");
    let scene =
        load_scene_str(&text, &root().join("t.ron"), &square_settings(IntegratorKind::Caustics, 24, 6, 5)).unwrap();
    let whole1 = assert_threads_and_merge_exact(&scene, 24, 6, "caustics");
    // The light side splatted something: the image differs from path tracing's.
    let path = load_scene_str(&text, &root().join("t.ron"), &square_settings(IntegratorKind::Path, 24, 6, 5)).unwrap();
    let mut p = Film::new(24, 24);
    render_into(&path, &mut p, 0..6);
    assert_ne!(p, whole1);
}

/// A scattering medium is refused with the field and what to use instead.
#[test]
fn scattering_media_are_refused() {
    let text = r#"(
        camera: (eye: (0, 0, 4), look_at: (0, 0, 0), fov_deg: 40),
        media: { "fog": Homogeneous(sigma_a: Constant(0.1), sigma_s: Constant(1)) },
        materials: { "glass": Dielectric(ior: Constant(1.5)) },
        objects: [ (shape: Sphere(center: (0, 0, 0), radius: 1), material: "glass", interior: "fog") ],
        environment: Uniform(Constant(1)),
    )"#;
    let Err(e) = load_scene_str(text, &root().join("t.ron"), &square_settings(IntegratorKind::Caustics, 8, 1, 1))
    else {
        panic!("a scattering medium loads with caustics");
    };
    let msg = e.to_string();
    assert!(msg.contains("objects[0].interior") && msg.contains("caustics") && msg.contains("bdpt"), "{msg}");
    assert!(load_scene_str(text, &root().join("t.ron"), &square_settings(IntegratorKind::Bdpt, 8, 1, 1)).is_ok());
}
