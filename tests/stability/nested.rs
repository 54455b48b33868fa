//! The failure matrix's nested-dielectric rows: water inside glass seen from
//! the water and from outside, priorities where volumes overlap, a glass of
//! water built with priorities, absorption by the medium a segment runs in,
//! and a medium stack that overflows or meets inconsistent geometry.

use super::*;

/// Water (1.33) inside glass (1.5): two concentric spheres of the given
/// priorities in the uniform enclosure, camera at `eye`.
fn water_in_glass(eye: &str, look_at: &str, glass_priority: u32, water_priority: u32) -> String {
    format!(
        r#"(camera: (eye: {eye}, look_at: {look_at}, fov_deg: 35), render: (width: 8, height: 8, max_bounces: 64),
        materials: {{ "glass": Dielectric(ior: Constant(1.5)), "water": Dielectric(ior: Constant(1.33)) }},
        objects: [
            (shape: Sphere(center: (0, 0, 0), radius: 1), material: "glass", priority: {glass_priority}),
            (shape: Sphere(center: (0, 0, 0), radius: 0.5), material: "water", priority: {water_priority}),
            {ENCLOSURE},
        ])"#
    )
}

/// Nested dielectrics: a sphere of water (1.33) inside a sphere of glass
/// (1.5), camera at the common centre. The radiance theorem (L/n² is
/// invariant along a ray) gives n_water² L = 1.7689: every camera ray meets
/// both surfaces at normal incidence, and the water → glass weight
/// (1.33/1.5)² times the glass → vacuum weight 1.5² is 1.33². The camera's
/// medium stack starts as [glass, water] (found by probing from the eye).
/// From outside, water in glass is invisible in the enclosure. Image means
/// within 5 s.e. + 0.1%; pixels within [`pixel_tol`] for full-spectrum methods.
/// `lighttrace`: exactly 0 from the water; from outside exactly 0 wherever the
/// view is all sphere, the enclosure beside it 1.
#[test]
fn nested_dielectrics_follow_the_medium_stack() {
    let want = 1.33f64.powi(2);
    for m in METHODS {
        let film = render_str(&water_in_glass("(0, 0, 0)", "(0.3, 0.2, -1)", 0, 0), &method(m, 16, 6));
        if m == "lighttrace" {
            // Seen through glass: exactly 0 inside; from outside only the enclosure around the spheres.
            assert!(y(&film).iter().all(|&v| v == 0.0), "lighttrace: nothing through glass");
            let film = render_str(&water_in_glass("(0, 0, 4)", "(0, 0, 0)", 0, 0), &method(m, 32, 7));
            let cover =
                sphere_cover(glam::Vec3::new(0.0, 0.0, 4.0), glam::Vec3::ZERO, 35.0, 8, &[(glam::Vec3::ZERO, 1.0)]);
            lighttrace_sees_only_the_enclosure(&film, &cover, "water in glass from outside");
            continue;
        }
        let (mean, se) = mean_and_stderr(&film, 1);
        eprintln!("nested, camera in water, {m}: Y = {mean:.4} ± {se:.4} (want {want:.4}; without a stack 3.98)");
        assert!((mean - want).abs() < 5.0 * se + 1e-3 * want, "{m}: {mean} ± {se}");
        if full_spectrum(m) {
            assert!(y(&film).iter().all(|v| (v - want).abs() < pixel_tol(m) * want), "{m}: a pixel is off n_w² L");
        }
        let film = render_str(&water_in_glass("(0, 0, 4)", "(0, 0, 0)", 0, 0), &method(m, 32, 7));
        let (mean, se) = mean_and_stderr(&film, 1);
        eprintln!("nested, from outside, {m}: Y = {mean:.4} ± {se:.4}");
        assert!((mean - 1.0).abs() < 5.0 * se + 1e-3, "{m}: nested glass from outside: {mean} ± {se}");
        if full_spectrum(m) {
            assert!(y(&film).iter().all(|v| (v - 1.0).abs() < pixel_tol(m)), "{m}: not invisible from outside");
        }
    }
}

/// Priorities decide which medium fills an overlap. With the glass
/// (priority 1) above the water (0), the water sphere lies inside a
/// higher-priority medium: its surface is a false intersection and the
/// camera at the centre is in glass, seeing 1.5² L = 2.25; with the water
/// above, it sees 1.33² L. Two partially overlapping spheres (1.5 and
/// 1.33, each priority order) are invisible from outside: every region
/// holds one medium, so the enclosure is in equilibrium. Tolerances as above.
/// `lighttrace` sees both concentric views through glass: exactly 0; the
/// overlapping pair from outside: exactly 0 where the view is all sphere,
/// the enclosure beside them 1.
#[test]
fn priority_decides_which_medium_fills_an_overlap() {
    for (glass, water) in [(1, 0), (0, 1)] {
        // Light tracing sees both inside views through glass: exactly 0.
        let film =
            render_str(&water_in_glass("(0, 0, 0)", "(0.3, 0.2, -1)", glass, water), &method("lighttrace", 16, 8));
        assert!(y(&film).iter().all(|&v| v == 0.0), "lighttrace, priorities {glass} {water}");
    }
    for m in ["whitted", "path", "hero", "auto", "bdpt"] {
        for (glass, water, want) in [(1, 0, 2.25f64), (0, 1, 1.7689)] {
            let film = render_str(&water_in_glass("(0, 0, 0)", "(0.3, 0.2, -1)", glass, water), &method(m, 16, 8));
            let (mean, se) = mean_and_stderr(&film, 1);
            eprintln!("priorities glass {glass} water {water}, {m}: Y = {mean:.4} ± {se:.4}, want {want}");
            assert!((mean - want).abs() < 5.0 * se + 1e-3 * want, "{m}: {mean} ± {se}, want {want}");
            if full_spectrum(m) {
                assert!(y(&film).iter().all(|v| (v - want).abs() < pixel_tol(m) * want), "{m}: pixel off {want}");
            }
        }
        for (a, b) in [(0, 1), (1, 0), (0, 0)] {
            let scene = format!(
                r#"(camera: (eye: (0, 0, 4), look_at: (0, 0, 0), fov_deg: 40), render: (width: 10, height: 10, max_bounces: 64),
                materials: {{ "glass": Dielectric(ior: Constant(1.5)), "water": Dielectric(ior: Constant(1.33)) }},
                objects: [
                    (shape: Sphere(center: (-0.35, 0, 0), radius: 0.6), material: "glass", priority: {a}),
                    (shape: Sphere(center: (0.35, 0.1, 0.1), radius: 0.6), material: "water", priority: {b}),
                    {ENCLOSURE},
                ])"#
            );
            if m == "whitted" {
                // Light tracing sees the spheres through glass: exactly 0 there, the enclosure beside them 1.
                let film = render_str(&scene, &method("lighttrace", 32, 9));
                let spheres = [(glam::Vec3::new(-0.35, 0.0, 0.0), 0.6), (glam::Vec3::new(0.35, 0.1, 0.1), 0.6)];
                let cover = sphere_cover(glam::Vec3::new(0.0, 0.0, 4.0), glam::Vec3::ZERO, 40.0, 10, &spheres);
                lighttrace_sees_only_the_enclosure(&film, &cover, &format!("overlapping spheres, priorities {a} {b}"));
            }
            let film = render_str(&scene, &method(m, 32, 9));
            let (mean, se) = mean_and_stderr(&film, 1);
            assert!((mean - 1.0).abs() < 5.0 * se + 1e-3, "{m}, priorities {a} {b}: overlap visible: {mean} ± {se}");
            if full_spectrum(m) {
                // A path trapped by total internal reflection between the spheres past 64
                // bounces is lost: one of 32 samples is 1/32 of a pixel (independent at
                // 256 spp loses 2 samples in two pixels; sobol at 32 spp one in one).
                let tol = pixel_tol(m) + 1.0 / 32.0;
                assert!(y(&film).iter().all(|v| (v - 1.0).abs() < tol), "{m}, priorities {a} {b}");
            }
        }
    }
}

/// A glass of water built the Schmidt-Budge way, as in
/// `scenes/glass-of-water.ron`: a solid glass block (priority 1), a water
/// block (priority 3) that carves the lower cavity out of it, and a vacuum
/// block (index 1, priority 2) that carves the upper cavity and overlaps
/// the water a little (the water wins there). Every region holds one
/// medium, so in the uniform enclosure it is invisible from every side
/// (image mean within 5 s.e. + 0.2%; `whitted`, without roulette, per pixel
/// within 1%).
/// `lighttrace`: exactly 0 wherever the view is all block, the enclosure beside
/// it 1.
#[test]
fn a_glass_of_water_is_invisible_in_a_furnace() {
    for (eye, seed) in [("(0.3, 0.9, 4)", 10), ("(0.2, 3.5, 1.5)", 11)] {
        let scene = format!(
            r#"(camera: (eye: {eye}, look_at: (0, 0.6, 0), fov_deg: 35), render: (width: 12, height: 12, max_bounces: 64),
            materials: {{
                "glass": Dielectric(ior: Constant(1.5)),
                "water": Dielectric(ior: Constant(1.33)),
                "vacuum": Dielectric(ior: Constant(1)),
            }},
            objects: [
                (shape: Cuboid(min: (-0.5, 0, -0.5), max: (0.5, 1.4, 0.5)), material: "glass", priority: 1),
                (shape: Cuboid(min: (-0.44, 0.1, -0.44), max: (0.44, 0.9, 0.44)), material: "water", priority: 3),
                (shape: Cuboid(min: (-0.44, 0.89, -0.44), max: (0.44, 1.6, 0.44)), material: "vacuum", priority: 2),
                {ENCLOSURE},
            ])"#
        );
        // Light tracing: exactly 0 wherever the view is all glass block (or the
        // vacuum block above it), the enclosure beside it 1.
        let film = render_str(&scene, &method("lighttrace", 32, seed));
        let (glass, vacuum) = (
            (glam::Vec3::new(-0.5, 0.0, -0.5), glam::Vec3::new(0.5, 1.4, 0.5)),
            (glam::Vec3::new(-0.44, 0.89, -0.44), glam::Vec3::new(0.44, 1.6, 0.44)),
        );
        let eye_v = {
            let c: Vec<f32> = eye.trim_matches(['(', ')']).split(',').map(|x| x.trim().parse().unwrap()).collect();
            glam::Vec3::new(c[0], c[1], c[2])
        };
        let cover = cover(eye_v, glam::Vec3::new(0.0, 0.6, 0.0), 35.0, 12, |r| {
            hits_box(r, glass.0, glass.1) || hits_box(r, vacuum.0, vacuum.1)
        });
        lighttrace_sees_only_the_enclosure(&film, &cover, &format!("glass of water from {eye}"));
        for m in ["whitted", "path", "auto", "bdpt"] {
            let film = render_str(&scene, &method(m, 32, seed));
            let (mean, se) = mean_and_stderr(&film, 1);
            let worst = y(&film).iter().map(|v| (v - 1.0).abs()).fold(0.0, f64::max);
            eprintln!("glass of water from {eye}, {m}: Y = {mean:.4} ± {se:.4}, worst pixel off by {worst:.4}");
            assert!((mean - 1.0).abs() < 5.0 * se + 2e-3, "{m} from {eye}: {mean} ± {se}");
            // Paths trapped by total internal reflection in the blocks bounce
            // long past the roulette depth, so only whitted is checked per pixel.
            assert!(m != "whitted" || worst < pixel_tol(m), "{m} from {eye}: a pixel is off 1 by {worst}");
        }
    }
}

/// Absorption follows the medium a segment runs in, not the surface it ends
/// on. The camera sits in absorbing water (σ = 1 per unit, a sphere of
/// radius 3) with a light inside it: (a) a sphere light of radiance 1 seen
/// directly (its body is black, so the path ends there) gives e^{−σt} for
/// the distance t to its surface; (b) a white Lambertian quad lit by a
/// point light of intensity 1 at the eye, seen at its centre straight down
/// from height h = 0.5, gives (1/π) (1/h²) e^{−σh} e^{−σh} (shadow ray and
/// camera segment), exactly for `whitted` and for `path`/`auto` limited to
/// one bounce (a point light: no sampling noise). Tolerance 1e-3 relative:
/// f32 and the pixel's footprint. `bdpt` statistically (below).
#[test]
fn absorption_follows_the_medium_a_segment_runs_in() {
    let water = r#""water": Dielectric(ior: Constant(1.33), absorption: Constant(1))"#;
    let direct = format!(
        r#"(camera: (eye: (0, 0, 0), look_at: (0, 0, -1), fov_deg: 1), render: (width: 3, height: 3, max_bounces: 4),
        materials: {{ {water} }},
        objects: [
            (shape: Sphere(center: (0, 0, 0), radius: 3), material: "water"),
            (shape: Sphere(center: (0, 0, -1), radius: 0.3), emission: Constant(1)),
        ])"#
    );
    let lit = format!(
        r#"(camera: (eye: (0, 0.5, 0), look_at: (0, 0, 0), up: (0, 0, -1), fov_deg: 1), render: (width: 3, height: 3, max_bounces: 1),
        materials: {{ {water}, "white": Lambertian(reflectance: Constant(1)) }},
        objects: [
            (shape: Sphere(center: (0, 0, 0), radius: 3), material: "water"),
            (shape: Quad(origin: (-1, 0, 1), edge_u: (2, 0, 0), edge_v: (0, 0, -2)), material: "white"),
        ],
        lights: [ Point(position: (0, 0.5, 0), intensity: Constant(1)) ])"#
    );
    let centre = |film: &Film| film.mean_xyz()[4][1];
    for m in ["whitted", "path", "auto"] {
        let seen = centre(&render_str(&direct, &method(m, 4, 12)));
        let want = (-0.7f64).exp();
        assert!((seen - want).abs() < 1e-3 * want, "{m}: light in water seen as {seen}, want {want}");
        let floor = centre(&render_str(&lit, &method(m, 4, 13)));
        let want = 4.0 / std::f64::consts::PI * (-1.0f64).exp();
        eprintln!("absorbing water, {m}: light {seen:.5}, lit floor {floor:.5} (want {want:.5})");
        assert!((floor - want).abs() < 1e-3 * want, "{m}: floor in water {floor}, want {want}");
    }
    // BDPT weighs the strategies that see the light (camera path, light
    // subpath to the eye, next-event estimation): unbiased, not exact, so
    // the 3x3 image's mean (every pixel sees the same value to 1e-4) is
    // checked within 5 s.e. + 0.2%.
    for (scene, want, seed) in
        [(&direct, (-0.7f64).exp(), 12), (&lit, 4.0 / std::f64::consts::PI * (-1.0f64).exp(), 13)]
    {
        let (mean, se) = mean_and_stderr(&render_str(scene, &method("bdpt", 256, seed)), 1);
        eprintln!("absorbing water, bdpt: {mean:.5} ± {se:.5} (want {want:.5})");
        assert!((mean - want).abs() < 5.0 * se + 2e-3 * want, "bdpt: {mean} ± {se}, want {want}");
    }
}

/// The stack overflows without harm: ten concentric glass spheres (n 1.5,
/// more than the stack's 8 entries) with the camera at the centre still
/// show 1.5² L = 2.25, because the unrecorded inner spheres take the 8th
/// as their outside, which has the same index; from outside they are
/// invisible. Inconsistent geometry: a camera behind a glass quad (an open
/// surface) leaves a medium it never entered, which refracts glass →
/// vacuum: at near-normal incidence R + (1 − R) n² with R = 0.04, i.e. 2.2.
/// Tolerances as in the tests above (1% for the quad: R varies over the 4° view).
/// `lighttrace`: exactly 0 wherever glass is in view, the enclosure beside it
/// 1.
#[test]
fn medium_stack_overflow_and_inconsistent_geometry() {
    let spheres: Vec<String> = (0..10)
        .map(|i| format!("(shape: Sphere(center: (0, 0, 0), radius: {}), material: \"glass\")", 1.0 - 0.08 * i as f64))
        .collect();
    let parse = |v: &str| {
        let c: Vec<f32> = v.trim_matches(['(', ')']).split(',').map(|x| x.trim().parse().unwrap()).collect();
        glam::Vec3::new(c[0], c[1], c[2])
    };
    for (eye, look_at, want) in [("(0, 0, 0)", "(0.3, 0.2, -1)", 2.25), ("(0, 0, 4)", "(0, 0, 0)", 1.0)] {
        let scene = format!(
            r#"(camera: (eye: {eye}, look_at: {look_at}, fov_deg: 35), render: (width: 8, height: 8, max_bounces: 64),
            materials: {{ "glass": Dielectric(ior: Constant(1.5)) }},
            objects: [ {}, {ENCLOSURE} ])"#,
            spheres.join(", ")
        );
        let film = render_str(&scene, &method("lighttrace", 16, 14));
        let cover = sphere_cover(parse(eye), parse(look_at), 35.0, 8, &[(glam::Vec3::ZERO, 1.0)]);
        lighttrace_sees_only_the_enclosure(&film, &cover, &format!("ten nested spheres from {eye}"));
        for m in ["whitted", "path", "auto", "bdpt"] {
            let film = render_str(&scene, &method(m, 16, 14));
            let (mean, se) = mean_and_stderr(&film, 1);
            eprintln!("ten nested spheres from {eye}, {m}: Y = {mean:.4} ± {se:.4}, want {want}");
            assert!((mean - want).abs() < 5.0 * se + 1e-3 * want, "{m} from {eye}: {mean} ± {se}");
        }
    }
    let quad = format!(
        r#"(camera: (eye: (0, 0, -1), look_at: (0, 0, 1), fov_deg: 4), render: (width: 4, height: 4, max_bounces: 8),
        materials: {{ "glass": Dielectric(ior: Constant(1.5)) }},
        objects: [ (shape: Quad(origin: (-1, -1, 0), edge_u: (2, 0, 0), edge_v: (0, 2, 0)), material: "glass"), {ENCLOSURE} ])"#
    );
    // Light tracing sees the enclosure only through the quad: exactly 0.
    assert!(y(&render_str(&quad, &method("lighttrace", 16, 15))).iter().all(|&v| v == 0.0), "lighttrace, quad");
    for m in ["whitted", "path", "auto", "bdpt"] {
        let film = render_str(&quad, &method(m, 64, 15));
        let (mean, se) = mean_and_stderr(&film, 1);
        eprintln!("back of a glass quad, {m}: Y = {mean:.4} ± {se:.4}, want 2.2");
        assert!((mean - 2.2).abs() < 5.0 * se + 0.01 * 2.2, "{m}: {mean} ± {se}");
    }
}

/// MIS past a false intersection: a white Lambertian ball (ρ 1) inside a
/// hidden water sphere (priority 0 inside glass of priority 1), lit by a
/// uniform emitting sphere that is also inside the glass. Everything sits in
/// one medium, so the ball is invisible (L = 1). Shadow rays from the ball
/// stop at the water's surface, so light sampling never reaches the
/// emitter; the BSDF samples that pass the false intersection must carry
/// the full weight (with an MIS weight below 1 there, `path` gave an image
/// mean of 0.937 ± 0.010).
/// Image mean within 5 s.e. + 0.2%.
/// `lighttrace` (1024 spp) too: the ball is diffuse, and its eye connections
/// pass the false intersections.
#[test]
fn a_false_intersection_leaves_the_emitter_to_bsdf_sampling() {
    let scene = r#"(camera: (eye: (-0.3, 0, 0), look_at: (0.2, 0, 0), fov_deg: 50), render: (width: 8, height: 8, max_bounces: 64),
        materials: { "glass": Dielectric(ior: Constant(1.5)), "water": Dielectric(ior: Constant(1.33)),
                     "white": Lambertian(reflectance: Constant(1)) },
        objects: [
            (shape: Sphere(center: (0, 0, 0), radius: 2), material: "glass", priority: 1),
            (shape: Sphere(center: (0, 0, 0), radius: 0.5), material: "water"),
            (shape: Sphere(center: (0.2, 0, 0), radius: 0.15), material: "white"),
            (shape: Sphere(center: (0, 0, 0), radius: 1.5), emission: Constant(1), two_sided: true),
        ])"#;
    for m in ["path", "hero", "auto", "bdpt", "lighttrace"] {
        let film = render_str(scene, &method(m, if m == "lighttrace" { 1024 } else { 64 }, 16));
        let (mean, se) = mean_and_stderr(&film, 1);
        eprintln!("white ball past a false intersection, {m}: Y = {mean:.4} ± {se:.4}, want 1");
        assert!((mean - 1.0).abs() < 5.0 * se + 2e-3, "{m}: {mean} ± {se}");
    }
}

/// Dispersive media on both sides: water (`water_20C`) inside dense flint
/// (N-SF11), camera at the centre. Each wavelength crosses both surfaces at
/// normal incidence with weights (n_w(λ)/n_g(λ))² and n_g(λ)², so the
/// spectral methods see Σ_b n_w(λ_b)² ȳ_b and `path` (every wavelength at
/// 589.3 nm) n_w(589.3)². Using the glass's index at the wrong wavelength
/// would leave a factor (n_g(λ)/n_g(589.3))², up to ±2% per bin.
/// Image mean within 5 s.e. + 0.1%.
/// `lighttrace`: exactly 0 (seen through glass).
#[test]
fn dispersive_water_in_dispersive_glass() {
    let scene = format!(
        r#"(camera: (eye: (0, 0, 0), look_at: (0.3, 0.2, -1), fov_deg: 35), render: (width: 8, height: 8, max_bounces: 64),
        materials: {{ "glass": Dielectric(ior: Named("N-SF11")), "water": Dielectric(ior: Named("water_20C")) }},
        objects: [
            (shape: Sphere(center: (0, 0, 0), radius: 1), material: "glass"),
            (shape: Sphere(center: (0, 0, 0), radius: 0.5), material: "water"),
            {ENCLOSURE},
        ])"#
    );
    let water = rust_v::bxdf::named_glass("water_20C").unwrap();
    let cmf = rust_v::color::color_weights();
    let spectral: f64 =
        (0..36).map(|b| (water.at(rust_v::color::bin_lambda_nm(b)) as f64).powi(2) * cmf[b][1] as f64).sum();
    let reference = (water.at(589.3) as f64).powi(2);
    // Light tracing: everything through glass, exactly 0.
    assert!(y(&render_str(&scene, &method("lighttrace", 16, 17))).iter().all(|&v| v == 0.0), "lighttrace");
    for m in ["path", "hero", "auto", "bdpt"] {
        let film = render_str(&scene, &method(m, 32, 17));
        let (mean, se) = mean_and_stderr(&film, 1);
        let want = if m == "path" { reference } else { spectral };
        eprintln!("water in N-SF11, {m}: Y = {mean:.5} ± {se:.5}, want {want:.5}");
        assert!((mean - want).abs() < 5.0 * se + 1e-3 * want, "{m}: {mean} ± {se}, want {want}");
    }
}

/// With a point light and glass, `auto` picks `caustics` (aimed light
/// subpaths, BDPT's walk) also where media nest (its subpaths carry the
/// medium stack; the answers are checked by the tests above, which run
/// `bdpt`, `auto` and `caustics`), and says so.
#[test]
fn auto_picks_caustics_among_nested_media() {
    let scene = water_in_glass("(0, 0, 0)", "(0.3, 0.2, -1)", 0, 0);
    let lit = format!(
        "{}], lights: [ Point(position: (0, 3, 0), intensity: Constant(1)) ])",
        scene.trim_end().trim_end_matches("])")
    );
    let loaded = rust_v::scene::load_scene_str(&lit, std::path::Path::new("t.ron"), &Default::default()).unwrap();
    assert!(loaded.has_nested_volumes());
    let said = rust_v::integrator::describe(&loaded);
    assert!(said.starts_with("auto: ") && said.contains("light subpaths aimed"), "{said}");
}
