//! Bidirectional path tracing and light tracing (issue 17) against
//! independent truths: agreement with path tracing where both are unbiased,
//! irradiance from delta lights in closed form, the ball-lens caustic against
//! a numerical trace through the sphere written here, the prism rainbow
//! against Snell's law (scripts/rainbow_geometry.py), and bit-exact
//! determinism with splats.

use std::f64::consts::PI;

use glam::Vec3;

use rust_v::film::Film;
use rust_v::scene::{load_scene, load_scene_str};
use rust_v::settings::{IntegratorKind, SettingsPatch};

use crate::common::{assert_threads_and_merge_exact, render_into, render_str, root, seeded_blocks, square_settings};

/// The expected falloff at a floor point, given `cos θ` from the light (None: skip the pixel).
type Falloff = Box<dyn Fn(f64) -> Option<f64>>;

/// Asserts two image sums (mean, s.e. from seeds) within 4.5 combined s.e.;
/// prints the difference and the smallest relative bias detected with
/// probability ≥ 97.7%, (4.5 + 2) combined s.e.
fn assert_same_sum(what: &str, (sa, sea): (f64, f64), (sb, seb): (f64, f64)) {
    let se = (sea * sea + seb * seb).sqrt();
    eprintln!(
        "{what}: image sum {sa:.4} ± {sea:.4} vs {sb:.4} ± {seb:.4}, differ {:+.2}%, s.e. {:.2}%, detects ≥ {:.1}%",
        100.0 * (sa / sb - 1.0),
        100.0 * se / sb,
        100.0 * 6.5 * se / sb
    );
    assert!((sa - sb).abs() < 4.5 * se, "{what}: image sum {sa} vs {sb} (se {se})");
}

fn scene_text(name: &str) -> String {
    let text = std::fs::read_to_string(root().join("scenes").join(name)).unwrap();
    text.replace("\"../meshes/", &format!("\"{}/", root().join("meshes").display()))
}

/// BDPT, light tracing and path tracing are unbiased for the same image:
/// on the Cornell box (all diffuse: every method sees every path), each
/// 4×4 block's Y from 32 one-spp BDPT renders (seeds differ: the mean of
/// 1-spp renders, so bias at low sample counts would show), from 64 light
/// tracing renders of 16 spp, and from 64 path tracing renders of 16 spp
/// agree within 4.5 combined standard errors (estimated from the seeds'
/// spread), which 64 blocks × 2 comparisons pass by chance with
/// probability > 99.9%; and the image sums within 4.5 combined standard
/// errors, from the seeds' image sums ([`assert_same_sum`]; it was the
/// blocks' errors in quadrature from 32 one-spp BDPT renders and 16 of 4 spp,
/// 0.5% s.e., detecting 3.5%: about the issue's "10%" of a one-spp check). A fixed 1% on the image
/// mean was here before the sobol sampler: that realization of light
/// tracing landed 1.2% above path (48 seeds: 0.2804 ± 0.0008 against path's
/// 0.2785 ± 0.0016, 1.1 standard errors, with the independent sampler
/// 0.2799 ± 0.0010 against 0.2791 ± 0.0025).
#[test]
fn bdpt_lighttrace_and_path_agree_on_the_cornell_box() {
    let text = scene_text("cornell.ron");
    let (path, path_sum) = seeded_blocks(&text, IntegratorKind::Path, 32, 16, 64);
    for (integrator, spp, seeds) in [(IntegratorKind::Bdpt, 1, 512), (IntegratorKind::LightTrace, 16, 64)] {
        let (other, other_sum) = seeded_blocks(&text, integrator, 32, spp, seeds);
        for (k, (a, b)) in other.iter().zip(&path).enumerate() {
            let se = (a.1 * a.1 + b.1 * b.1).sqrt();
            assert!(
                (a.0 - b.0).abs() <= 4.5 * se + 1e-4,
                "{integrator:?} block {k}: {:.4} vs path {:.4} (se {se:.4})",
                a.0,
                b.0
            );
        }
        assert_same_sum(&format!("cornell, {integrator:?} vs path"), other_sum, path_sum);
    }
}

/// 4x4 blocks of 12 BDPT renders (4 spp) and 12 `auto` renders (8 spp) of a
/// 16x16 view agree within 4.5 combined s.e. (from the seeds' spread), the
/// image means within 3%. That is only about 2 combined s.e. of the image
/// sums from the seeds (1.3% on the glass spheres, 1.4% in the glass of
/// water: glass fireflies), tighter than 4.5 s.e. would be, and kept: it
/// passes with these seeds, and any change of the random numbers that makes
/// it fail should be looked at, not the bound widened. Returns `auto`'s sum
/// of block means.
fn bdpt_agrees_with_auto(text: &str, what: &str) -> f64 {
    let (auto, auto_sum) = seeded_blocks(text, IntegratorKind::Auto, 16, 8, 12);
    let (bdpt, bdpt_sum) = seeded_blocks(text, IntegratorKind::Bdpt, 16, 4, 12);
    for (k, (a, b)) in bdpt.iter().zip(&auto).enumerate() {
        let se = (a.1 * a.1 + b.1 * b.1).sqrt();
        assert!((a.0 - b.0).abs() <= 4.5 * se + 1e-4, "block {k}: bdpt {:.4} vs auto {:.4} (se {se:.4})", a.0, b.0);
    }
    let (sa, sb) = (bdpt_sum.0, auto_sum.0);
    let se = (bdpt_sum.1.powi(2) + auto_sum.1.powi(2)).sqrt();
    eprintln!(
        "{what}, bdpt vs auto: image sum {sa:.4} vs {sb:.4}, differ {:+.2}%, s.e. {:.2}% (from the seeds)",
        100.0 * (sa / sb - 1.0),
        100.0 * se / sb
    );
    assert!((sa / sb - 1.0).abs() < 0.03, "{what}: image sum {sa} vs auto {sb}");
    sb
}

/// On the glass spheres (specular chains seen by the camera and lit through
/// the glass) BDPT agrees with `auto` the same way. Light tracing cannot
/// connect a specular vertex to the camera, so it misses the glass seen
/// directly: darker by design (the failure matrix's row).
#[test]
fn bdpt_agrees_with_auto_on_the_glass_spheres() {
    let text = scene_text("spheres.ron");
    let sb = bdpt_agrees_with_auto(&text, "glass spheres");
    let sl = seeded_blocks(&text, IntegratorKind::LightTrace, 16, 8, 4).1.0;
    assert!(sl < 0.99 * sb && sl > 0.5 * sb, "light tracing {sl} vs auto {sb}");
}

/// Among nested dielectrics (`scenes/glass-of-water.ron`: a tumbler of
/// N-BK7 and absorbing water built from overlapping blocks with priorities,
/// a red ball half under the water's surface, lit by the box's light) BDPT,
/// whose subpaths carry the medium stack, agrees with `auto` the same way
/// as on the glass spheres (4x4 blocks within 4.5 combined s.e., image mean
/// within 3%). Without the stack (this crate's BDPT before it had one:
/// water → glass refracted as water → vacuum, false intersections were
/// surfaces) the image mean was 4.2% low and 4x4 blocks up to 14% low
/// (16x16, 256 spp against 512 spp of `auto`); with it, 0.06% and 3%.
#[test]
fn bdpt_agrees_with_auto_among_nested_dielectrics() {
    let text = scene_text("glass-of-water.ron");
    bdpt_agrees_with_auto(&text, "glass of water");
}

/// A diffuse floor (ρ = 0.5) under a point light of intensity 2 at height 1
/// and under a spot light (cone 20°, falloff 5°): radiance ρ I f cos θ / (π r²).
/// Light tracing estimates each pixel from the light paths that land in it
/// (here about 60 per pixel at 1024 spp: ~13% per pixel), so the test compares
/// quadrants of 64 pixels (~1.6% standard error) within 6%; BDPT (MIS of
/// next-event estimation and light tracing) within 4% at 1024 spp: over 8
/// seeds its quadrant sums (falloff band excluded) spread by 2.7-6.0% at 64
/// spp and 0.7-2.1% at 256, so about 0.4-1.1% here and 4% is > 3.5 sigma.
/// The whole image (every pixel with a closed form) against the closed form,
/// over 8 seeds of 1024 spp, within 4 s.e. (from the seeds) + 0.2% (the
/// closed form is taken at pixel centres, the render averages each pixel's
/// footprint: measured −0.07% for the point light and −0.11% for the spot,
/// the same for both methods): ratios 0.99934 ± 0.00004 (light tracing) and
/// 0.99935 ± 0.00000 (bdpt) for the point light, 0.99886 ± 0.00008 and
/// 0.99887 ± 0.00007 for the spot; detects a bias of 0.25% (6 s.e. + 0.2%).
/// The s.e. is this small because the sobol sampler stratifies the light's
/// directions (which pixels are hit is nearly fixed) and BDPT's connections
/// to a point light vary only with the pixel jitter.
/// Independent seeds for the whole-image check of [`delta_lights_give_the_closed_form_irradiance_by_light_tracing_and_bdpt`].
const SEEDS: u64 = 8;

#[test]
fn delta_lights_give_the_closed_form_irradiance_by_light_tracing_and_bdpt() {
    let base = r#"(
        camera: (eye: (0, 2, 0), look_at: (0, 0, 0), up: (0, 0, -1), fov_deg: 30),
        render: (max_bounces: 1),
        materials: { "floor": Lambertian(reflectance: Constant(0.5)) },
        objects: [ (shape: Quad(origin: (-5, 0, 5), edge_u: (10, 0, 0), edge_v: (0, 0, -10)), material: "floor") ],
        lights: [ LIGHT ],
    )"#;
    let (cos_total, cos_start) = (20f64.to_radians().cos(), 15f64.to_radians().cos());
    let cases: [(&str, Falloff); 2] = [
        ("Point(position: (0, 1, 0), intensity: Constant(2))", Box::new(|_| Some(1.0))),
        (
            "Spot(position: (0, 1, 0), look_at: (0, 0, 0), cone_deg: 20, falloff_deg: 5, intensity: Constant(2))",
            Box::new(move |cos| {
                if cos >= cos_start + 0.02 {
                    Some(1.0)
                } else if cos <= cos_total - 0.02 {
                    Some(0.0)
                } else {
                    None
                }
            }),
        ),
    ];
    for (light, falloff) in &cases {
        let text = base.replace("LIGHT", light);
        let scene = load_scene_str(
            &text,
            std::path::Path::new("t.ron"),
            &square_settings(IntegratorKind::LightTrace, 16, 1024, 1),
        )
        .unwrap();
        let want: Vec<Option<f64>> = (0..256)
            .map(|k| {
                let (x, y) = ((k % 16) as f32 + 0.5, (k / 16) as f32 + 0.5);
                let ray = scene.camera.ray(glam::Vec2::new(x, y));
                let p = ray.origin + ray.dir * (2.0 / -ray.dir.y);
                let d = Vec3::new(0.0, 1.0, 0.0) - p;
                let r2 = d.length_squared() as f64;
                let cos = 1.0 / r2.sqrt();
                falloff(cos).map(|f| 0.5 * 2.0 * f * cos / r2 / PI)
            })
            .collect();
        // Each method's ratio of the whole image to the closed form (the pixels that
        // have one), per seed, and per quadrant for the first seed.
        for (name, integrator, tol) in
            [("light tracing", IntegratorKind::LightTrace, 0.06), ("bdpt", IntegratorKind::Bdpt, 0.04)]
        {
            let ratios: Vec<f64> = (0..SEEDS)
                .map(|seed| {
                    let img = render_str(&text, &square_settings(integrator, 16, 1024, 1 + seed)).mean_xyz();
                    let (mut got, mut exp) = (0.0, 0.0);
                    for q in 0..4 {
                        let (mut gq, mut eq) = (0.0, 0.0);
                        for k in (0..256).filter(|k| (k % 16 >= 8) as usize + 2 * ((k / 16 >= 8) as usize) == q) {
                            if let Some(w) = want[k] {
                                gq += img[k][1];
                                eq += w;
                            }
                        }
                        if seed == 0 {
                            assert!((gq - eq).abs() <= tol * eq + 1e-3, "{light}: {name} quadrant {q}: {gq} vs {eq}");
                        }
                        got += gq;
                        exp += eq;
                    }
                    got / exp
                })
                .collect();
            let n = SEEDS as f64;
            let mean = ratios.iter().sum::<f64>() / n;
            let se = (ratios.iter().map(|r| (r - mean).powi(2)).sum::<f64>() / (n - 1.0) / n).sqrt();
            eprintln!(
                "{light}: {name} image / closed form {mean:.5} ± {se:.5} ({SEEDS} seeds), detects ≥ {:.2}%",
                100.0 * (6.0 * se + 2e-3)
            );
            assert!((mean - 1.0).abs() < 4.0 * se + 2e-3, "{light}: {name} image / closed form {mean} ± {se}");
        }
    }
}

/// The ball-lens caustic. A glass sphere (R 0.5, n 1.5) whose centre is
/// 0.882 above a diffuse floor (ρ 0.8), lit by a spot light 5 above the centre
/// whose cone (5.7°) just fits inside the sphere's silhouette (every light
/// path refracts; a point light does the same inside the cone). The camera
/// sits under the sphere, 0.3 above the floor, looking down at the shadow,
/// where only light through the sphere arrives (max 3 bounces: in, out, floor).
///
/// The truth, written here in f64: 400 × 400 stratified directions of the
/// cone traced through the sphere by Snell's law, each carrying
/// `I dω T_in T_out` (Fresnel) to the floor and binned into the camera's
/// pixels. The paraxial rays cross the axis where the ball-lens formula
/// puts the focus (checked). The render's flux over the view (light tracing:
/// 1024 × 32 paths through the lens; noise ≈ 0.5%) matches within 2%, and
/// the 4 × 4 pixels at the focus within 5%, with BDPT as with light tracing.
#[test]
fn ball_lens_caustic_matches_a_numerical_trace_and_the_focal_formula() {
    let (r, n, intensity, rho, cam_h) = (0.5f64, 1.5f64, 2.0f64, 0.8f64, 0.3f64);
    let f = n * r / (2.0 * (n - 1.0));
    let u = 5.0f64;
    let v = 1.0 / (1.0 / f - 1.0 / u);
    let (yc, yl) = (v, v + u);
    let cone = 5.7f64;
    let text = format!(
        r#"(
        camera: (eye: (0, {cam_h}, 0), look_at: (0, 0, 0), up: (0, 0, -1), fov_deg: 90),
        render: (max_bounces: 3),
        materials: {{ "floor": Lambertian(reflectance: Constant({rho})), "glass": Dielectric(ior: Constant({n})) }},
        objects: [
            (shape: Quad(origin: (-5, 0, 5), edge_u: (10, 0, 0), edge_v: (0, 0, -10)), material: "floor"),
            (shape: Sphere(center: (0, {yc}, 0), radius: {r}), material: "glass"),
        ],
        lights: [ Spot(position: (0, {yl}, 0), look_at: (0, 0, 0), cone_deg: {cone}, falloff_deg: 0, intensity: Constant({intensity})) ],
    )"#
    );
    // The independent trace.
    let size = 32usize;
    let half = cam_h; // fov 90: the view covers |x|, |z| < cam_h
    let pixel_area = (2.0 * half / size as f64).powi(2);
    let mut flux = vec![0.0f64; size * size];
    let cos_max = cone.to_radians().cos();
    let m = 400;
    let d_omega = 2.0 * PI * (1.0 - cos_max) / (m * m) as f64;
    let fresnel = |ci: f64, eta: f64| {
        let st2 = (1.0 - ci * ci) / (eta * eta);
        let ct = (1.0 - st2).sqrt();
        let rs = (ci - eta * ct) / (ci + eta * ct);
        let rp = (eta * ci - ct) / (eta * ci + ct);
        (0.5 * (rs * rs + rp * rp), ct)
    };
    let mut paraxial_focus = 0.0;
    for i in 0..m {
        for j in 0..m {
            let cos_t = 1.0 - (1.0 - cos_max) * (i as f64 + 0.5) / m as f64;
            let sin_t = (1.0 - cos_t * cos_t).sqrt();
            let phi = 2.0 * PI * (j as f64 + 0.5) / m as f64;
            let d = [sin_t * phi.cos(), -cos_t, sin_t * phi.sin()];
            // Entry: the ray from (0, yl, 0) meets the sphere centred (0, yc, 0).
            let oc = [0.0, yl - yc, 0.0];
            let b = oc[0] * d[0] + oc[1] * d[1] + oc[2] * d[2];
            let c = (yl - yc).powi(2) - r * r;
            let t = -b - (b * b - c).sqrt();
            let p1 = [d[0] * t, yl - yc + d[1] * t, d[2] * t]; // relative to the centre
            let n1 = [p1[0] / r, p1[1] / r, p1[2] / r];
            let ci = -(d[0] * n1[0] + d[1] * n1[1] + d[2] * n1[2]);
            let (f1, ct) = fresnel(ci, n);
            let k = ci / n - ct;
            let d2 = [d[0] / n + k * n1[0], d[1] / n + k * n1[1], d[2] / n + k * n1[2]];
            // Exit: the chord, then refraction out (the same angles by symmetry).
            let t2 = -2.0 * (d2[0] * p1[0] + d2[1] * p1[1] + d2[2] * p1[2]);
            let p2 = [p1[0] + d2[0] * t2, p1[1] + d2[1] * t2, p1[2] + d2[2] * t2];
            let n2 = [p2[0] / r, p2[1] / r, p2[2] / r];
            let ci2 = d2[0] * n2[0] + d2[1] * n2[1] + d2[2] * n2[2];
            let (f2, ct2) = fresnel(ci2, 1.0 / n);
            let k2 = ci2 * n - ct2;
            let d3 = [d2[0] * n - k2 * n2[0], d2[1] * n - k2 * n2[1], d2[2] * n - k2 * n2[2]];
            let py = p2[1] + yc;
            let s = -py / d3[1];
            let (x, z) = (p2[0] + d3[0] * s, p2[2] + d3[2] * s);
            if i == 0 && j == 0 {
                // The most paraxial ray: where it crosses the axis.
                let rho_xz = (p2[0] * p2[0] + p2[2] * p2[2]).sqrt();
                let slope = (d3[0] * d3[0] + d3[2] * d3[2]).sqrt() / -d3[1];
                paraxial_focus = yc - (py - rho_xz / slope);
            }
            let fx = ((x / half + 1.0) * 0.5 * size as f64).floor();
            let fy = ((1.0 + z / half) * 0.5 * size as f64).floor();
            if fx >= 0.0 && fy >= 0.0 && (fx as usize) < size && (fy as usize) < size {
                flux[fy as usize * size + fx as usize] += intensity * d_omega * (1.0 - f1) * (1.0 - f2);
            }
        }
    }
    assert!((paraxial_focus - v).abs() < 2e-3 * v, "paraxial focus {paraxial_focus} vs ball-lens formula {v}");
    let want_total: f64 = flux.iter().sum();
    let centre: Vec<usize> = (14..18).flat_map(|y| (14..18).map(move |x| y * size + x)).collect();
    let want_centre: f64 = centre.iter().map(|&k| flux[k]).sum();
    assert!(want_centre > 0.3 * want_total, "the focus holds most of the flux");
    for integrator in [IntegratorKind::LightTrace, IntegratorKind::Bdpt] {
        let film = render_str(&text, &square_settings(integrator, size as u32, 32, 3));
        // Pixel radiance ρE/π, so the flux through a pixel is π L / ρ × its area.
        let got: Vec<f64> = film.mean_xyz().iter().map(|p| PI * p[1] / rho * pixel_area).collect();
        let total: f64 = got.iter().sum();
        let at_centre: f64 = centre.iter().map(|&k| got[k]).sum();
        assert!((total / want_total - 1.0).abs() < 0.02, "{integrator:?}: flux {total} vs traced {want_total}");
        assert!((at_centre / want_centre - 1.0).abs() < 0.05, "{integrator:?}: focus {at_centre} vs {want_centre}");
    }
    // Path tracing cannot find this caustic at all (the failure matrix's row).
    let path = render_str(&text, &square_settings(IntegratorKind::Path, size as u32, 4, 3));
    assert!(path.mean_xyz().iter().all(|p| p[1] == 0.0));
}

/// The prism rainbow (scenes/prism-rainbow.ron, rendered small with a
/// spectral film): for each bin from 420 to 680 nm, the brightness-weighted
/// centre of that bin's channel on the screen sits where
/// scripts/rainbow_geometry.py (an independent 2-D f64 tracer with the
/// N-SF11 Sellmeier equation) puts the band, projected by the camera,
/// within 1.5 px (the beam is 0.06 wide: ~3 px), and shorter wavelengths
/// land further along the screen's axis.
#[test]
fn prism_rainbow_bands_sit_where_snell_puts_them() {
    // nm → offset along the screen's axis, from scripts/rainbow_geometry.py.
    const BANDS: [(usize, f64); 8] = [
        (420, 0.624684),
        (450, 0.424829),
        (480, 0.284783),
        (520, 0.151366),
        (560, 0.055099),
        (600, -0.017663),
        (640, -0.074564),
        (680, -0.120264),
    ];
    let centre = Vec3::new(-5.23491, 0.0, -5.700785);
    let axis = Vec3::new(-0.401803, 0.0, 0.915726);
    let o = SettingsPatch { width: Some(320), height: Some(160), spp: Some(12), ..Default::default() };
    let scene = load_scene(&root().join("scenes/prism-rainbow.ron"), &o).expect("the scene loads");
    let mut film = Film::new_spectral(320, 160, 0);
    render_into(&scene, &mut film, 0..12);
    let sums = film.spectral_sums().unwrap();
    let w = 320usize;
    let mut last: Option<(f64, f64, f64, f64)> = None;
    for (nm, off) in BANDS {
        let bin = (nm - 380) / 10;
        let p = centre + axis * off as f32;
        let want = scene.camera.project((p - scene.camera.eye()).normalize()).expect("the band is in view");
        // Brightness-weighted mean column and row of this bin near its peak.
        let v: Vec<f64> = sums.iter().map(|s| s[bin] as f64).collect();
        let peak = (0..v.len()).max_by(|&a, &b| v[a].total_cmp(&v[b])).unwrap();
        let (px, py) = ((peak % w) as i64, (peak / w) as i64);
        let (mut sx, mut sy, mut total) = (0.0, 0.0, 0.0);
        for y in (py - 6).max(0)..(py + 7).min(160) {
            for x in (px - 6).max(0)..(px + 7).min(320) {
                let val = v[y as usize * w + x as usize].max(0.0);
                sx += val * (x as f64 + 0.5);
                sy += val * (y as f64 + 0.5);
                total += val;
            }
        }
        assert!(total > 0.0, "{nm} nm: no light");
        let (cx, cy) = (sx / total, sy / total);
        let err = ((cx - want.x as f64).powi(2) + (cy - want.y as f64).powi(2)).sqrt();
        assert!(err < 1.5, "{nm} nm: band at ({cx:.2}, {cy:.2}), Snell says ({:.2}, {:.2})", want.x, want.y);
        // The measured band moves the way the predicted one does from the previous wavelength.
        if let Some((lx, ly, wx, wy)) = last {
            let step = (cx - lx) * (want.x as f64 - wx) + (cy - ly) * (want.y as f64 - wy);
            assert!(step > 0.0, "{nm} nm: the band does not move the way Snell says");
        }
        last = Some((cx, cy, want.x as f64, want.y as f64));
    }
}

/// Splats keep every guarantee: the image is bit-identical for 1 and 2
/// threads, and passes 0..6 equal merge(0..3, 3..6), for BDPT and light tracing.
#[test]
fn bdpt_is_deterministic_and_merges_exactly() {
    let text = scene_text("caustic-point.ron");
    for integrator in [IntegratorKind::Bdpt, IntegratorKind::LightTrace] {
        let o = square_settings(integrator, 24, 6, 5);
        let scene = load_scene_str(&text, &root().join("scenes/caustic-point.ron"), &o).unwrap();
        let whole1 = assert_threads_and_merge_exact(&scene, 24, 6, &format!("{integrator:?}"));
        assert!(whole1.mean_xyz().iter().any(|p| p[1] > 0.0));
    }
}
