//! The failure-matrix rows of the materials beyond the thesis (issue 16):
//! absorbing glass against the closed-form slab transmittance, rough glass
//! and rough metal near zero roughness against the smooth models, grazing
//! views of rough metal, and total internal reflection in rough (and
//! dispersive rough) glass, every method against every other.

use super::{ENCLOSURE, METHODS, lighttrace_sees_only_the_enclosure, mean_se, method, sphere_cover, y};
use crate::common::{mean_and_stderr, render_str};

/// A slab of thickness d = 1 (n = 1.5, absorption σ per unit length) seen at
/// normal incidence (fov 2°) in front of a large emitting disk (L = 1), with
/// nothing behind the camera: the transmittance with all internal
/// reflections is (1−F)² e^{−σd} / (1 − F² e^{−2σd}), F = 0.04, per bin. For
/// σ(λ) rising across the bins the expected Y is Σ_b T(σ_b) ȳ_b. Image mean
/// within 5 s.e. + 0.5% (each sample is 0 or e^{−(2k+1)σd}: a binary-like
/// estimator with s.e. ~1.5% at 64 samples per pixel).
/// `lighttrace` sees the emitter only through the slab: exactly 0.
#[test]
fn absorbing_slab_matches_the_closed_form() {
    let sigma: Vec<f64> = (0..36).map(|b| 0.2 + 0.03 * b as f64).collect();
    let samples = sigma.iter().map(|s| format!("{s}")).collect::<Vec<_>>().join(", ");
    let scene = format!(
        r#"(
        camera: (eye: (0, 0, 5), look_at: (0, 0, 0), fov_deg: 2),
        render: (width: 8, height: 8, max_bounces: 64),
        materials: {{ "tinted": Dielectric(ior: Constant(1.5), absorption: Samples([{samples}])) }},
        objects: [
            (shape: Cuboid(min: (-100, -100, -0.5), max: (100, 100, 0.5)), material: "tinted"),
            (shape: Disk(center: (0, 0, -3), normal: (0, 0, 1), radius: 50), emission: Constant(1)),
        ],
    )"#
    );
    let f = 0.04f64;
    let t = |s: f64| (1.0 - f).powi(2) * (-s).exp() / (1.0 - f * f * (-2.0 * s).exp());
    let cmf = rust_v::color::color_weights();
    let want: f64 = (0..36).map(|b| t(sigma[b]) * cmf[b][1] as f64).sum();
    for m in METHODS {
        let film = render_str(&scene, &method(m, 64, 21));
        if m == "lighttrace" {
            // The emitter is seen only through the slab's smooth faces: exactly 0.
            assert!(y(&film).iter().all(|&v| v == 0.0), "lighttrace through a smooth slab");
            continue;
        }
        let (mean, se) = mean_and_stderr(&film, 1);
        eprintln!("absorbing slab, {m}: Y = {mean:.4} ± {se:.4}, want {want:.4}");
        assert!((mean - want).abs() < 5.0 * se + 5e-3 * want, "{m}: {mean} ± {se} vs {want}");
    }
}

/// Roughness near 0: glass of α just above the smooth threshold (1.001e-3)
/// seen from a camera at the centre of a sphere in the uniform enclosure
/// gives the smooth answer n²L = 2.25 (the rough lobe loses under 0.1%),
/// and a metal plane of that α under a uniform sky gives the smooth
/// metal's F(θ) per pixel, computed here from the complex Fresnel at each
/// pixel's centre ray (within 2%: F varies across a pixel and the lobe's
/// width adds a little). Every method; image means within 5 s.e. + 0.5%.
/// `lighttrace` fails by variance on the glass: a light vertex meets the eye
/// inside the α 1e-3 lobe almost never, so the image stays below 1% of n²L at
/// 32 spp (asserted; measured 7.6e-6).
#[test]
fn roughness_near_zero_gives_the_smooth_answer() {
    let glass = format!(
        r#"(
        camera: (eye: (0, 0, 0), look_at: (0.3, 0.2, -1), fov_deg: 60),
        render: (width: 8, height: 8, max_bounces: 64),
        materials: {{ "glass": Dielectric(ior: Constant(1.5), roughness: 0.001001) }},
        objects: [ (shape: Sphere(center: (0, 0, 0), radius: 1), material: "glass"), {ENCLOSURE} ],
    )"#
    );
    for m in METHODS {
        let film = render_str(&glass, &method(m, 32, 22));
        let (mean, se) = mean_and_stderr(&film, 1);
        eprintln!("rough glass α 1.001e-3, camera inside, {m}: Y = {mean:.4} ± {se:.4}, want 2.25");
        if m == "whitted" {
            // Rough glass ends a Whitted chain (direct light only); the enclosure is not sampled through it.
            continue;
        }
        if m == "lighttrace" {
            // Light tracing's variance failure: a light vertex on the glass meets the
            // eye's direction inside the lobe (α 1e-3) almost never; the rare hits
            // carry the mean. At 32 spp the image is below 1% of n²L (measured
            // 7.6e-6: one pixel lit).
            assert!(mean < 0.01 * 2.25, "lighttrace: {mean} ± {se}");
            continue;
        }
        assert!((mean - 2.25).abs() < 5.0 * se + 5e-3 * 2.25, "{m}: {mean} ± {se}");
    }
    // A metal plane seen at 60° from the normal, smooth and nearly smooth.
    let metal = |alpha: f32| {
        format!(
            r#"(
            camera: (eye: (0, 1, 0), look_at: (0, 0, -1.7320508), fov_deg: 4),
            render: (width: 8, height: 8, max_bounces: 8),
            materials: {{ "m": Conductor(eta: Constant(0.2), k: Constant(3.0), roughness: {alpha}) }},
            objects: [ (shape: Plane(point: (0, 0, 0), normal: (0, 1, 0)), material: "m"), {} ],
        )"#,
            ENCLOSURE.replace("radius: 10", "radius: 1000")
        )
    };
    let want = rust_v::bxdf::fresnel_conductor(0.5, 0.2, 3.0) as f64;
    for m in ["path", "hero", "auto"] {
        let smooth = y(&render_str(&metal(0.0), &method(m, 16, 23)));
        let rough = y(&render_str(&metal(0.001001), &method(m, 16, 23)));
        let (ms, _) = mean_se(&smooth);
        let (mr, ser) = mean_se(&rough);
        eprintln!("metal at 60°, {m}: smooth {ms:.4}, α 1.001e-3 {mr:.4} ± {ser:.4}, F(60°) = {want:.4}");
        assert!((ms - want).abs() < 0.02 * want, "{m}: smooth {ms} vs F {want}");
        assert!((mr - ms).abs() < 5.0 * ser + 5e-3 * ms, "{m}: near-smooth {mr} vs smooth {ms}");
    }
}

/// Grazing views of rough metal: a camera 1e-3 above an infinite plane of
/// a nearly perfect metal (n 0.2, k 3: F ≥ 0.92) at α = 0.3 under a uniform
/// sky, cosines down to 1e-4: no NaN (every render), every pixel's albedo at
/// most 1 (within 5 s.e.), and below the smooth metal's (single-scattering
/// GGX loses energy at grazing angles; the smooth metal gives F → 1).
/// `lighttrace` fails by variance as on the diffuse plane: at most a tenth of
/// the plane's pixels lit (asserted; none at 64 spp).
#[test]
fn grazing_view_of_a_rough_metal_plane() {
    let scene = |alpha: f32| {
        format!(
            r#"(
            camera: (eye: (0, 0.001, 0), look_at: (0, 0.001, -1), fov_deg: 2),
            render: (width: 8, height: 8, max_bounces: 8),
            materials: {{ "m": Conductor(eta: Constant(0.2), k: Constant(3.0), roughness: {alpha}) }},
            objects: [ (shape: Plane(point: (0, 0, 0), normal: (0, 1, 0)), material: "m"), {} ],
        )"#,
            ENCLOSURE.replace("radius: 10", "radius: 1000")
        )
    };
    // The smooth metal (full spectrum: no colour noise) at grazing sees F ≈ 1.
    let smooth = y(&render_str(&scene(0.0), &method("path", 8, 24)));
    let (ms, _) = mean_se(&smooth[40..]);
    assert!(ms > 0.99 && ms <= 1.0 + 1e-3, "smooth metal at grazing sees F ≈ 1: {ms}");
    for m in METHODS {
        let rough = y(&render_str(&scene(0.3), &method(m, 64, 24)));
        if m == "lighttrace" {
            // Light tracing's variance failure, as for the diffuse plane
            // (stability/surfaces.rs): at most a tenth of the plane's pixels lit.
            let lit = rough[40..].iter().filter(|&&x| x > 0.0).count();
            eprintln!("grazing rough metal, lighttrace: {lit} of 24 plane pixels lit");
            assert!(lit * 10 <= 24, "lighttrace: {lit} plane pixels lit");
            continue;
        }
        let (mr, ser) = mean_se(&rough[40..]);
        eprintln!("grazing rough metal, {m}: Y = {mr:.4} ± {ser:.4} (smooth {ms:.4})");
        assert!(mr > 0.0 && mr <= 1.0 + 5.0 * ser, "{m}: {mr} ± {ser}");
        if m != "whitted" {
            // Whitted's direct-light-only estimate is too noisy here to order the two.
            assert!(mr + 3.0 * ser < ms, "{m}: rough {mr} ± {ser} not below smooth {ms}");
        }
    }
}

/// Total internal reflection in rough glass: a camera off centre inside a
/// rough glass sphere (α 0.3, n 1.5; N-SF11 for the dispersive case) in
/// the uniform enclosure. There is no closed form (single-scattering
/// microfacets lose energy, mostly in TIR-bound paths), so the methods are
/// checked against each other: `path`, `hero` and `auto` agree within 5
/// combined s.e. + 1%, and none exceeds the smooth glass's n²L (within 5
/// s.e.). For dispersive rough glass `auto` (which collapses the path to 4
/// wavelengths at the rough surface) agrees with `hero`.
/// `bdpt` joins the comparison, and `lighttrace` in an enclosure of radius 1.05
/// at 8192 spp (the same furnace, where light paths reach the sphere).
#[test]
fn total_internal_reflection_in_rough_glass() {
    for (ior, n2) in [("Constant(1.5)", 2.25f64), ("Named(\"N-SF11\")", 1.785f64.powi(2))] {
        let scene = format!(
            r#"(
            camera: (eye: (0.5, 0, 0), look_at: (1, 0.3, -0.6), fov_deg: 60),
            render: (width: 8, height: 8, max_bounces: 64),
            materials: {{ "glass": Dielectric(ior: {ior}, roughness: 0.3) }},
            objects: [ (shape: Sphere(center: (0, 0, 0), radius: 1), material: "glass"), {ENCLOSURE} ],
        )"#
        );
        let mut results = Vec::new();
        for m in ["path", "hero", "auto", "bdpt", "lighttrace"] {
            // Light tracing, whose light paths rarely reach the sphere from an
            // enclosure of radius 10 (64 spp: 0.13 ± 0.08), in one of radius
            // 1.05: the same furnace, the same answer.
            let film = if m == "lighttrace" {
                render_str(&scene.replace("radius: 10)", "radius: 1.05)"), &method(m, 8192, 25))
            } else {
                render_str(&scene, &method(m, 64, 25))
            };
            let (mean, se) = mean_and_stderr(&film, 1);
            eprintln!("rough glass {ior}, camera inside off centre, {m}: Y = {mean:.4} ± {se:.4} (smooth n²L {n2:.3})");
            assert!(mean <= n2 + 5.0 * se, "{m}: {mean} above n²L {n2}");
            results.push((m, mean, se));
        }
        let dispersive = ior.contains("SF11");
        for &(a, ma, sa) in &results {
            for &(b, mb, sb) in &results {
                if dispersive && (a == "path" || b == "path") {
                    continue; // path refracts every wavelength like 589.3 nm: its documented bias
                }
                let tol = 5.0 * (sa * sa + sb * sb).sqrt() + 0.01 * ma;
                assert!((ma - mb).abs() < tol, "{ior}: {a} {ma} ± {sa} vs {b} {mb} ± {sb}");
            }
        }
    }
}

/// Thin films at extreme thickness: a soap bubble (`ThinSheet` on a sphere)
/// in the uniform enclosure is invisible at 0 nm, 400 nm and 1e7 nm (10 mm,
/// a phase of ~10⁵ rad), because it reflects R(λ) and transmits 1 − R(λ)
/// undeviated (the furnace sees L = 1 whichever way a path goes). Every
/// method, image mean within 5 s.e. + 0.5% (the lobe is chosen by the
/// packet's mean R, so a path's colour varies: colour noise, right mean);
/// at 0 nm (R = 0: all transmitted) full-spectrum pixels are 1 within 1e-3.
/// And a metal coated with a 0 nm film is the bare metal (same pixels).
/// `lighttrace`: a sheet is a delta surface, so exactly 0 wherever the view is
/// all sphere, the enclosure beside it 1.
#[test]
fn thin_films_at_extreme_thickness() {
    for d in [0.0f32, 400.0, 1e7] {
        let scene = format!(
            r#"(
            camera: (eye: (0, 0, 3), look_at: (0, 0, 0), fov_deg: 40),
            render: (width: 8, height: 8, max_bounces: 16),
            materials: {{ "soap": ThinSheet(thickness_nm: {d}, ior: Constant(1.33)) }},
            objects: [ (shape: Sphere(center: (0, 0, 0), radius: 1), material: "soap"), {ENCLOSURE} ],
        )"#
        );
        for m in METHODS {
            let film = render_str(&scene, &method(m, 16, 26));
            if m == "lighttrace" {
                // A thin sheet is a delta surface: what is seen through it or in it is 0.
                let cover =
                    sphere_cover(glam::Vec3::new(0.0, 0.0, 3.0), glam::Vec3::ZERO, 40.0, 8, &[(glam::Vec3::ZERO, 1.0)]);
                lighttrace_sees_only_the_enclosure(&film, &cover, &format!("soap bubble {d} nm"));
                continue;
            }
            let (mean, se) = mean_and_stderr(&film, 1);
            eprintln!("soap bubble {d} nm, {m}: Y = {mean:.4} ± {se:.4}, want 1");
            assert!((mean - 1.0).abs() < 5.0 * se + 5e-3, "{m} {d} nm: {mean} ± {se}");
            if d == 0.0 && matches!(m, "whitted" | "path" | "auto") {
                assert!(y(&film).iter().all(|v| (v - 1.0).abs() < 1e-3), "{m} {d} nm: a pixel is not 1");
            }
        }
    }
    let metal = |coating: &str| {
        format!(
            r#"(
            camera: (eye: (0, 0, 3), look_at: (0, 0, 0), fov_deg: 40),
            render: (width: 8, height: 8, max_bounces: 4),
            materials: {{ "m": Conductor(metal: "Cu"{coating}) }},
            objects: [ (shape: Sphere(center: (0, 0, 0), radius: 1), material: "m"), {ENCLOSURE} ],
        )"#
        )
    };
    let bare = y(&render_str(&metal(""), &method("path", 4, 27)));
    let zero =
        y(&render_str(&metal(", coating: ThinFilm(thickness_nm: 0, ior: Constant(1.5))"), &method("path", 4, 27)));
    for (a, b) in bare.iter().zip(&zero) {
        assert!((a - b).abs() < 1e-4 * a.max(1e-3), "0 nm film changed the metal: {a} vs {b}");
    }
}

/// A coated dispersive glass sphere (N-BK7 under 120 nm of n 1.38, the
/// classic MgF2 anti-reflection coat) in the uniform enclosure is invisible
/// from outside for every method: the film changes how light divides between
/// reflection and refraction per wavelength, never how much there is (R + T
/// = 1 per wavelength, the 1/η² weights cancel on the way out). This runs
/// `auto`'s collapse with the film's per-bin reflectances. Image mean within
/// 5 s.e. + 0.5%.
/// `lighttrace`: exactly 0 wherever the view is all sphere, the enclosure
/// beside it 1.
#[test]
fn coated_glass_is_invisible_in_a_furnace() {
    let scene = format!(
        r#"(
        camera: (eye: (0, 0, 3), look_at: (0, 0, 0), fov_deg: 40),
        render: (width: 8, height: 8, max_bounces: 64),
        materials: {{ "lens": Dielectric(ior: Named("N-BK7"), coating: ThinFilm(thickness_nm: 120, ior: Constant(1.38))) }},
        objects: [ (shape: Sphere(center: (0, 0, 0), radius: 1), material: "lens"), {ENCLOSURE} ],
    )"#
    );
    for m in METHODS {
        let film = render_str(&scene, &method(m, 32, 28));
        if m == "lighttrace" {
            let cover =
                sphere_cover(glam::Vec3::new(0.0, 0.0, 3.0), glam::Vec3::ZERO, 40.0, 8, &[(glam::Vec3::ZERO, 1.0)]);
            lighttrace_sees_only_the_enclosure(&film, &cover, "coated N-BK7 sphere");
            continue;
        }
        let (mean, se) = mean_and_stderr(&film, 1);
        eprintln!("coated N-BK7 sphere in a furnace, {m}: Y = {mean:.4} ± {se:.4}, want 1");
        assert!((mean - 1.0).abs() < 5.0 * se + 5e-3, "{m}: {mean} ± {se}");
    }
}

/// A white plastic (ρ = 1 under a smooth coat of n 1.5) conserves energy
/// exactly (plastic.rs: F(θo) plus the diffuse albedo is 1 at every angle),
/// so a sphere of it in the uniform enclosure is invisible for every method
/// that follows all bounces; image mean within 5 s.e. + 0.5%. `whitted`
/// ends at the plastic with direct light only and misses the coat's mirror
/// lobe (documented shortfall): at most 1 within 5 s.e.
/// `lighttrace` sees only the diffuse base, 1 − F(θo) on the sphere (computed
/// per pixel here): within 5 s.e. of the per-pixel differences + 1%, in an
/// enclosure of radius 3.5 at 4096 spp.
#[test]
fn white_plastic_is_invisible_in_a_furnace() {
    let scene = format!(
        r#"(
        camera: (eye: (0, 0, 3), look_at: (0, 0, 0), fov_deg: 40),
        render: (width: 8, height: 8, max_bounces: 10000),
        materials: {{ "p": Plastic(reflectance: Constant(1), ior: Constant(1.5)) }},
        objects: [ (shape: Sphere(center: (0, 0, 0), radius: 1), material: "p"), {ENCLOSURE} ],
    )"#
    );
    for m in METHODS {
        if m == "lighttrace" {
            // Light tracing sees the diffuse base only (the camera end of the
            // coat's mirror lobe is specular): 1 − F(θo) on the sphere (F + diffuse
            // albedo = 1), 1 beside it. Expected per pixel from a 6x6 grid of rays.
            // In an enclosure of radius 3.5 (the same furnace), where 8 times more light
            // paths reach the sphere than from radius 10, at 4096 spp.
            let film = render_str(&scene.replace("radius: 10)", "radius: 3.5)"), &method(m, 4096, 29));
            let (mean, se) = mean_and_stderr(&film, 1);
            let cam = rust_v::camera::Camera::new(
                glam::Vec3::new(0.0, 0.0, 3.0),
                glam::Vec3::ZERO,
                glam::Vec3::Y,
                40.0,
                8,
                8,
            );
            let want: Vec<f64> = (0..64)
                .map(|i| {
                    let mut sum = 0.0;
                    for k in 0..36 {
                        let f = glam::Vec2::new(
                            (i % 8) as f32 + ((k % 6) as f32 + 0.5) / 6.0,
                            (i / 8) as f32 + ((k / 6) as f32 + 0.5) / 6.0,
                        );
                        let r = cam.ray(f);
                        let (o, d) = (r.origin.as_dvec3(), r.dir.as_dvec3());
                        // The nearer root of |o + t d| = 1.
                        let (b, c) = (o.dot(d), o.length_squared() - 1.0);
                        let disc = b * b - c;
                        sum += if disc > 0.0 {
                            let p = o + d * (-b - disc.sqrt());
                            1.0 - rust_v::bxdf::fresnel_dielectric((-p.normalize().dot(d)) as f32, 1.5) as f64
                        } else {
                            1.0
                        };
                    }
                    sum / 36.0
                })
                .collect();
            let v = y(&film);
            let diff: Vec<f64> = v.iter().zip(&want).map(|(a, b)| a - b).collect();
            let (d, ds) = mean_se(&diff);
            let w = want.iter().sum::<f64>() / 64.0;
            eprintln!(
                "white plastic in a furnace, lighttrace: Y = {mean:.4} ± {se:.4}, want {w:.4} (1 − F on the sphere), diff {d:.4} ± {ds:.4}"
            );
            assert!(d.abs() < 5.0 * ds + 0.01, "lighttrace: {mean} ± {se}, want {w} (diff {d} ± {ds})");
            continue;
        }
        let film = render_str(&scene, &method(m, 32, 29));
        let (mean, se) = mean_and_stderr(&film, 1);
        eprintln!("white plastic in a furnace, {m}: Y = {mean:.4} ± {se:.4}, want 1");
        if m == "whitted" {
            assert!(mean <= 1.0 + 5.0 * se, "{m}: {mean} ± {se}");
        } else {
            assert!((mean - 1.0).abs() < 5.0 * se + 5e-3, "{m}: {mean} ± {se}");
        }
    }
}
