//! The sky model against an independent double-precision evaluation of the
//! published model (`scripts/hosek_reference.py`, tables in `reference.rs`),
//! its sun against numeric and closed-form integrals, and its edges.

use core::f32::consts::FRAC_PI_2;

use super::{CHANNEL_NM, N_CHANNELS, SkyModel, data, reference};
use crate::color::{N_BINS, bin_lambda_nm};

/// Relative tolerance against the f64 reference (f32 evaluation).
const REL: f64 = 1e-4;

/// Relative error of `got` against `want`, with `want` clamped at 0 (the
/// model dips slightly below 0 in places; ours is clamped, see the module
/// docs) and an absolute floor of `floor` for values near 0.
fn rel_err(got: f32, want: f64, floor: f64) -> f64 {
    let want = want.max(0.0);
    (f64::from(got) - want).abs() / want.abs().max(floor)
}

fn model(turbidity: f64, albedo: f64, elevation: f64) -> SkyModel {
    SkyModel::new(turbidity as f32, albedo as f32, elevation as f32).expect("in range")
}

#[test]
fn sky_channels_match_the_python_reference() {
    let mut worst = (0.0f64, String::new());
    let mut negative = 0;
    for &(t, a, e, theta, gamma, want) in &reference::SKY {
        let got = model(t, a, e).channels(theta as f32, gamma as f32);
        // Near-zero values (the negative dips) are compared against a floor
        // of 1e-4 of the row's largest value.
        let floor = want.iter().fold(0.0f64, |m, &v| m.max(v.abs())) * 1e-4;
        for c in 0..N_CHANNELS {
            negative += usize::from(want[c] < 0.0);
            let err = rel_err(got[c], want[c], floor);
            if err > worst.0 {
                worst =
                    (err, format!("T {t} albedo {a} elevation {e} theta {theta} gamma {gamma} {} nm", CHANNEL_NM[c]));
            }
            assert!(
                err <= REL,
                "T {t} albedo {a} elevation {e} theta {theta} gamma {gamma} channel {c}: {} vs reference {}",
                got[c],
                want[c]
            );
        }
    }
    println!("sky channels: largest relative error {:.2e} at {}; {negative} reference values < 0", worst.0, worst.1);
    // The table does exercise the clamp (the model dips below 0 at 320 nm on the horizon).
    assert!(negative > 0);
}

#[test]
fn sky_bins_match_the_python_reference() {
    let mut worst = 0.0f64;
    for &(t, a, e, theta, gamma, want) in &reference::SKY_BINS {
        let got = model(t, a, e).radiance(theta as f32, gamma as f32);
        for i in 0..N_BINS {
            let err = rel_err(got[i], want[i], 1e-12);
            worst = worst.max(err);
            assert!(err <= REL, "T {t} albedo {a} elevation {e} {} nm: {} vs {}", bin_lambda_nm(i), got[i], want[i]);
        }
        // 730 nm holds the 720 nm value.
        assert_eq!(got[N_BINS - 1], got[N_BINS - 2]);
    }
    println!("sky bins: largest relative error {worst:.2e}");
}

#[test]
fn bins_on_a_channel_take_that_channel() {
    let sky = model(4.0, 0.2, 0.5);
    let ch = sky.channels(0.8, 0.9);
    let bins = sky.radiance(0.8, 0.9);
    for (c, &nm) in CHANNEL_NM.iter().enumerate().skip(2) {
        let i = ((nm - 380.0) / 10.0) as usize;
        assert_eq!(bin_lambda_nm(i), nm);
        assert_eq!(bins[i], ch[c], "{nm} nm");
    }
    // 380 nm is halfway between 360 and 400 nm.
    assert!((bins[0] - 0.5 * (ch[1] + ch[2])).abs() <= 1e-6 * bins[0]);
}

#[test]
fn sun_points_match_the_python_reference() {
    let mut worst = 0.0f64;
    for &(t, e, theta, gamma, want) in &reference::SUN_POINT {
        let got = model(t, 0.0, e).sun_radiance(theta as f32, gamma as f32);
        for i in 0..N_BINS {
            let err = rel_err(got[i], want[i], 1e-12);
            worst = worst.max(err);
            assert!(err <= REL, "T {t} elevation {e} {} nm: {} vs {}", bin_lambda_nm(i), got[i], want[i]);
        }
    }
    println!("sun points: largest relative error {worst:.2e}");
}

/// The sun's irradiance on the horizontal, `∫ L_sun cos θ dω` over the disk,
/// by the midpoint rule in `(α, φ)` around the sun (`sin γ = sin R sin α`,
/// so that the limb cosine is `cos α`; `dω = tan γ sin R cos α dα dφ`), from
/// the public [`SkyModel::sun_radiance`] only.
fn sun_irradiance(sky: &SkyModel, n_alpha: usize, n_phi: usize) -> [f64; N_BINS] {
    let r = f64::from(SkyModel::SUN_ANGULAR_RADIUS);
    let theta_s = core::f64::consts::FRAC_PI_2 - f64::from(sky.sun_elevation());
    let mut e = [0.0f64; N_BINS];
    for ia in 0..n_alpha {
        let alpha = (ia as f64 + 0.5) / n_alpha as f64 * core::f64::consts::FRAC_PI_2;
        let gamma = (r.sin() * alpha.sin()).asin();
        let d_alpha = core::f64::consts::FRAC_PI_2 / n_alpha as f64;
        let jacobian = gamma.tan() * r.sin() * alpha.cos();
        for ip in 0..n_phi {
            let phi = (ip as f64 + 0.5) / n_phi as f64 * core::f64::consts::TAU;
            let cos_theta = theta_s.cos() * gamma.cos() + theta_s.sin() * gamma.sin() * phi.cos();
            let d_omega = jacobian * d_alpha * core::f64::consts::TAU / n_phi as f64;
            let l = sky.sun_radiance(cos_theta.clamp(-1.0, 1.0).acos() as f32, gamma as f32);
            for i in 0..N_BINS {
                e[i] += f64::from(l[i]) * cos_theta.max(0.0) * d_omega;
            }
        }
    }
    e
}

#[test]
fn sun_irradiance_matches_the_python_quadrature_and_the_closed_form() {
    let r = f64::from(SkyModel::SUN_ANGULAR_RADIUS);
    let (mut worst_py, mut worst_closed) = (0.0f64, 0.0f64);
    for &(t, e, want, _) in &reference::SUN {
        let sky = model(t, 0.0, e);
        let got = sun_irradiance(&sky, 200, 128);
        for i in 0..N_BINS {
            let err = (got[i] - want[i]).abs() / want[i];
            worst_py = worst_py.max(err);
            assert!(err <= 2e-4, "T {t} elevation {e} {} nm: {} vs Python {}", bin_lambda_nm(i), got[i], want[i]);
        }
        // Closed form where a bin is a channel: the unlimbed radiance (the
        // centre's over the darkening at μ = 1, Σ c_k) times cos θ_s times
        // ∫ Σ c_k μ^k dω = 2π sin²R Σ c_k / (k + 2) (to O(R²)), from the raw
        // limb-darkening data. It ignores the change of elevation across the
        // disk, so it is checked at 30° and 60° only.
        if e < 0.5 {
            continue;
        }
        let theta_s = core::f64::consts::FRAC_PI_2 - e;
        let centre = sky.sun_radiance(theta_s as f32, 0.0);
        for (c, &nm) in CHANNEL_NM.iter().enumerate().skip(2) {
            let i = ((nm - 380.0) / 10.0) as usize;
            let ld = &data::LIMB_DARKENING[c];
            let at_centre: f64 = ld.iter().sum();
            let disk: f64 = ld.iter().enumerate().map(|(k, c)| c / (k as f64 + 2.0)).sum::<f64>()
                * core::f64::consts::TAU
                * r.sin().powi(2);
            let closed = f64::from(centre[i]) / at_centre * theta_s.cos() * disk;
            let err = (got[i] - closed).abs() / closed;
            worst_closed = worst_closed.max(err);
            assert!(err <= 1e-3, "T {t} elevation {e} {nm} nm: quadrature {} vs closed form {closed}", got[i]);
        }
    }
    // The irradiance facing the sun that `new` integrates, against Python's.
    let mut worst_api = 0.0f64;
    for &(t, e, _, want) in &reference::SUN {
        let normal = model(t, 0.0, e).sun_irradiance();
        for i in 0..N_BINS {
            let err = (f64::from(normal[i]) - want[i]).abs() / want[i];
            worst_api = worst_api.max(err);
            assert!(
                err <= 2e-4,
                "T {t} elevation {e} {} nm: sun_irradiance {} vs {}",
                bin_lambda_nm(i),
                normal[i],
                want[i]
            );
        }
    }
    let (t, e, want, normal) = reference::SUN[7]; // T 9, 30°
    println!(
        "sun irradiance: largest relative error {worst_py:.2e} vs Python, {worst_closed:.2e} vs the closed form; \
         sun_irradiance(): {worst_api:.2e} vs Python; T {t}, elevation {e}: E(550 nm) = {:.4} W m^-2 nm^-1 on the \
         horizontal, {:.4} facing the sun",
        want[17], normal[17]
    );
}

#[test]
fn every_value_is_finite_and_non_negative() {
    let mut count = 0;
    for it in 0..=18 {
        let t = 1.0 + 0.5 * it as f32;
        for ie in 0..=18 {
            let e = if ie == 18 { FRAC_PI_2 } else { (5.0 * ie as f32).to_radians() };
            for a in [0.0, 0.5, 1.0] {
                let sky = SkyModel::new(t, a, e).unwrap();
                for ith in 0..=12 {
                    let theta = if ith == 12 { FRAC_PI_2 } else { ith as f32 * FRAC_PI_2 / 12.0 };
                    for ig in 0..=16 {
                        let gamma = ig as f32 * core::f32::consts::PI / 16.0;
                        let l = sky.radiance(theta, gamma);
                        assert!(
                            !l.has_nan_or_inf() && l.min_value() >= 0.0,
                            "T {t} a {a} e {e} theta {theta} gamma {gamma}"
                        );
                        count += 1;
                    }
                }
                // The sun at its centre, at its limb, and across the disk's vertical.
                let theta_s = FRAC_PI_2 - e;
                for (dt, g) in [(0.0, 0.0), (0.0, 1.0), (0.7, 0.7), (-0.7, 0.7)] {
                    let r = SkyModel::SUN_ANGULAR_RADIUS;
                    let s = sky.sun_radiance(theta_s + dt * r, g * r);
                    assert!(!s.has_nan_or_inf() && s.min_value() >= 0.0, "sun: T {t} e {e}");
                }
                // The sun is there: not black at its centre unless on the horizon.
                if e > 0.05 {
                    assert!(sky.sun_radiance(theta_s, 0.0).max_value() > 0.0, "T {t} e {e}");
                }
            }
        }
    }
    assert_eq!(count, 19 * 19 * 3 * 13 * 17);
}

#[test]
fn below_the_horizon_and_outside_the_disk_is_black() {
    let sky = model(3.0, 0.3, 0.2);
    assert!(sky.radiance(FRAC_PI_2, 1.0).max_value() > 0.0);
    for theta in [FRAC_PI_2 + 1e-6, 2.0, core::f32::consts::PI, f32::NAN] {
        assert!(sky.radiance(theta, 1.0).is_black(), "theta {theta}");
        assert_eq!(sky.channels(theta, 1.0), [0.0; N_CHANNELS]);
    }
    let theta_s = FRAC_PI_2 - 0.2;
    let r = SkyModel::SUN_ANGULAR_RADIUS;
    assert!(sky.sun_radiance(theta_s, 0.99 * r).max_value() > 0.0);
    assert!(sky.sun_radiance(theta_s, 1.01 * r).is_black());
    assert!(sky.sun_radiance(theta_s, 0.5).is_black());
    // A sun on the horizon: its lower half is below it.
    let low = model(3.0, 0.3, 0.0);
    assert!(low.sun_radiance(FRAC_PI_2 + 0.5 * r, 0.5 * r).is_black());
}

#[test]
fn the_sun_is_limb_darkened_and_the_sky_brightest_near_the_sun() {
    let sky = model(3.0, 0.1, 0.6);
    let theta_s = FRAC_PI_2 - 0.6;
    let r = SkyModel::SUN_ANGULAR_RADIUS;
    let centre = sky.sun_radiance(theta_s, 0.0);
    let limb = sky.sun_radiance(theta_s, 0.98 * r);
    for i in 0..N_BINS {
        assert!(limb[i] < 0.7 * centre[i], "{} nm", bin_lambda_nm(i));
    }
    // Blue darkens more towards the limb than red (the solar spectrum's known trend).
    assert!(limb[6] / centre[6] < limb[30] / centre[30]);
    // The circumsolar sky outshines the opposite sky, and the sun outshines both.
    let near = sky.radiance(theta_s, 0.02);
    let far = sky.radiance(theta_s, 2.5);
    assert!(near[17] > far[17] && centre[17] > 100.0 * near[17]);
}

#[test]
fn out_of_range_parameters_are_named_errors() {
    let cases: [(f32, f32, f32, &str, &str); 10] = [
        (0.5, 0.3, 0.5, "turbidity", "[1, 10]"),
        (11.0, 0.3, 0.5, "turbidity", "[1, 10]"),
        (f32::NAN, 0.3, 0.5, "turbidity", "[1, 10]"),
        (3.0, -0.1, 0.5, "ground_albedo", "[0, 1]"),
        (3.0, 1.5, 0.5, "ground_albedo", "[0, 1]"),
        (3.0, f32::NAN, 0.5, "ground_albedo", "[0, 1]"),
        (3.0, 0.3, -0.01, "sun_elevation", "[0, 90] degrees"),
        (3.0, 0.3, 1.6, "sun_elevation", "[0, 90] degrees"),
        (3.0, 0.3, f32::NAN, "sun_elevation", "[0, 90] degrees"),
        (3.0, 0.3, f32::INFINITY, "sun_elevation", "[0, 90] degrees"),
    ];
    for (t, a, e, name, range) in cases {
        let err = SkyModel::new(t, a, e).expect_err(name);
        assert!(err.starts_with(name) && err.contains(range), "{err}");
    }
    // The ends of each range are in it.
    for (t, a, e) in [(1.0, 0.0, 0.0), (10.0, 1.0, FRAC_PI_2)] {
        assert!(SkyModel::new(t, a, e).is_ok());
    }
    let msg = SkyModel::new(3.0, 0.3, 95f32.to_radians()).unwrap_err();
    assert!(msg.contains("got 95"), "{msg}");
}

#[test]
fn cost_of_one_radiance_call() {
    // A measurement to print (`--nocapture`), not an asserted time.
    let sky = model(3.0, 0.3, 0.4);
    let n = 200_000;
    let start = std::time::Instant::now();
    let mut acc = 0.0f32;
    for k in 0..n {
        let x = k as f32 / n as f32;
        let l = sky.radiance(std::hint::black_box(x * FRAC_PI_2), std::hint::black_box(x * 3.0));
        acc += l[17];
    }
    let per_call = start.elapsed().as_secs_f64() / n as f64;
    let start = std::time::Instant::now();
    for k in 0..n {
        let x = k as f32 / n as f32;
        let l = sky.sun_radiance(
            std::hint::black_box(FRAC_PI_2 - 0.4),
            std::hint::black_box(x * SkyModel::SUN_ANGULAR_RADIUS),
        );
        acc += l[17];
    }
    let sun_per_call = start.elapsed().as_secs_f64() / n as f64;
    let start = std::time::Instant::now();
    for k in 0..100 {
        acc += SkyModel::new(std::hint::black_box(1.0 + 0.09 * k as f32), 0.3, 0.4).unwrap().sun_irradiance()[17];
    }
    let new_per_call = start.elapsed().as_secs_f64() / 100.0;
    println!(
        "radiance(): {:.0} ns per call; sun_radiance(): {:.0} ns per call; new(): {:.0} µs",
        per_call * 1e9,
        sun_per_call * 1e9,
        new_per_call * 1e6
    );
    assert!(acc.is_finite() && acc > 0.0);
}
