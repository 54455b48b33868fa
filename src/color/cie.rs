//! CIE 1931 2-degree colour matching functions, and the exact colour integral of a 36-bin
//! spectrum.
//!
//! A [`Spectrum`] holds 36 samples at 380, 390, ..., 730 nm and means the spectrum that
//! interpolates them linearly, flat beyond the end bins (scene spec). Its colour is the
//! continuous integral `XYZ = ∫ cmf(λ) · L(λ) dλ` over 360-830 nm. Because `L` is linear in its
//! samples, `L(λ) = Σ_b L_b · φ_b(λ)` with `φ_b` the interpolation tent of bin `b` (the end bins'
//! tents extended flat to 360 and 830 nm), the integral is exactly a weighted sum,
//!
//! ```text
//! XYZ = Σ_b W_b · L_b,    W_b = ∫ cmf(λ) · φ_b(λ) dλ / ∫ ȳ(λ) dλ,
//! ```
//!
//! normalised so that a flat spectrum of 1 has Y = 1 (the tents sum to 1 everywhere). The
//! weights [`color_weights`] are computed once from the CIE 1931 table at 1 nm over 360-830 nm
//! (`data/cmf_1931_2deg_360_830_1nm.csv`, compiled into the crate; source: CIE 1931 standard
//! observer as tabulated by colour-science 0.4.7, `colour.MSDS_CMFS['CIE 1931 2 Degree Standard
//! Observer']`, see `../shared/data/SOURCES.md`). Between the 1 nm rows the CMFs are linear and so
//! is each tent, so each 1 nm piece of `cmf · φ_b` is a quadratic, integrated exactly by
//! Simpson's rule in f64: the weights are the exact integral of the tabulated, linearly
//! interpolated CMFs, rounded once to f32.
//!
//! [`CMF`] keeps the raw table values at the 36 bin centres (the point samples the renderer used
//! before the exact integral, 3% off in the weak channel of saturated colours).

use std::sync::LazyLock;

use super::rgb::Xyz;
use super::spectrum::{LAMBDA_MIN_NM, LAMBDA_STEP_NM, N_BINS, Spectrum};

/// The CIE 1931 2-degree table at 1 nm, 360-830 nm: `wavelength_nm,x_bar,y_bar,z_bar`.
const CMF_1NM_CSV: &str = include_str!("data/cmf_1931_2deg_360_830_1nm.csv");

/// The first and last wavelength of the colour integral, in nm.
pub const INTEGRAL_RANGE_NM: (f64, f64) = (360.0, 830.0);

/// The 1 nm table as rows `(λ, [x̄, ȳ, z̄])`. The table is compiled in and checked by the tests,
/// so a malformed row is a build defect, not user input: it is skipped (and a test fails).
/// Parsed once (0.85 M instructions): the colour weights and the default sensor's curves share it.
pub(crate) fn cmf_1nm() -> &'static [(f64, [f64; 3])] {
    static T: LazyLock<Vec<(f64, [f64; 3])>> = LazyLock::new(|| {
        CMF_1NM_CSV
            .lines()
            .skip(1)
            .filter_map(|line| {
                let v: Vec<f64> = line.split(',').filter_map(|c| c.trim().parse().ok()).collect();
                (v.len() == 4).then(|| (v[0], [v[1], v[2], v[3]]))
            })
            .collect()
    });
    &T
}

/// The interpolation tent of bin `b` at `lambda_nm`: 1 at the bin centre, falling linearly to 0
/// at the neighbouring centres; the first and last bins are 1 beyond their centres.
pub fn tent(b: usize, lambda_nm: f64) -> f64 {
    let x = (lambda_nm - LAMBDA_MIN_NM as f64) / LAMBDA_STEP_NM as f64 - b as f64;
    if (b == 0 && x <= 0.0) || (b == N_BINS - 1 && x >= 0.0) { 1.0 } else { (1.0 - x.abs()).max(0.0) }
}

/// Per-bin weights `W_b = ∫ cmf · φ_b` from any piecewise-linear CMF table (rows `(λ, [x̄, ȳ,
/// z̄])` in increasing λ), each 1-row piece integrated exactly by Simpson's rule, normalised so
/// the weights' Y sum to 1. Rows need not be 1 nm apart, but every bin centre must be a row
/// (true for 1 nm and 5 nm tables) so that each piece is a quadratic.
pub fn tent_weights(table: &[(f64, [f64; 3])]) -> [[f64; 3]; N_BINS] {
    let mut w = [[0.0f64; 3]; N_BINS];
    for pair in table.windows(2) {
        let ((l0, c0), (l1, c1)) = (pair[0], pair[1]);
        let lm = 0.5 * (l0 + l1);
        let h = l1 - l0;
        for (b, wb) in w.iter_mut().enumerate() {
            let (t0, tm, t1) = (tent(b, l0), tent(b, lm), tent(b, l1));
            if t0 == 0.0 && tm == 0.0 && t1 == 0.0 {
                continue;
            }
            for k in 0..3 {
                let cm = 0.5 * (c0[k] + c1[k]);
                wb[k] += h / 6.0 * (c0[k] * t0 + 4.0 * cm * tm + c1[k] * t1);
            }
        }
    }
    let y: f64 = w.iter().map(|r| r[1]).sum();
    for r in &mut w {
        for v in r.iter_mut() {
            *v /= y;
        }
    }
    w
}

/// The exact colour weights in f64 (see the module doc), for fitting and tests.
pub fn color_weights_f64() -> &'static [[f64; 3]; N_BINS] {
    static W: LazyLock<[[f64; 3]; N_BINS]> = LazyLock::new(|| tent_weights(cmf_1nm()));
    &W
}

/// The exact colour weights `W_b` (x, y, z per bin; see the module doc):
/// `XYZ = Σ_b W_b · L_b` is the continuous colour integral of the interpolated spectrum.
pub fn color_weights() -> &'static [[f32; 3]; N_BINS] {
    static W: LazyLock<[[f32; 3]; N_BINS]> = LazyLock::new(|| color_weights_f64().map(|r| r.map(|v| v as f32)));
    &W
}

/// The colour matching functions at any wavelength, for paths that carry a continuous
/// wavelength (after a dispersive split or collapse): the 1 nm table linearly interpolated
/// (the same function the weights integrate) and divided by `∫ ȳ dλ` over 360-830 nm, the
/// weights' normalisation, so that `∫ cmf_at(λ) · L(λ) dλ` is the XYZ of `L` and, for a spectrum
/// given by 36 bins, equals `Σ_b W_b · L_b`. Per nm; zero outside 360-830 nm (and for NaN).
pub fn cmf_at(lambda_nm: f32) -> [f32; 3] {
    curve_at(cmf_table(), lambda_nm)
}

/// The 1 nm CMF table over 360-830 nm divided by `∫ ȳ dλ`, as [`cmf_at`] interpolates it (the
/// default sensor's continuous curves, [`crate::color::Sensor`]).
pub(crate) fn cmf_table() -> &'static [[f32; 3]] {
    static TABLE: LazyLock<Vec<[f32; 3]>> = LazyLock::new(|| normalised_curves(cmf_1nm()));
    &TABLE
}

/// Rows `(λ, [a, b, c])` at 1 nm from 360 nm on, divided by the integral of the second column
/// (`∫ ȳ`, or a sensor's green) of their linear interpolation, as f32.
pub(crate) fn normalised_curves(t: &[(f64, [f64; 3])]) -> Vec<[f32; 3]> {
    // ∫ of the linearly interpolated table: the trapezoidal rule is exact.
    let y: f64 = t.windows(2).map(|p| 0.5 * (p[0].1[1] + p[1].1[1]) * (p[1].0 - p[0].0)).sum();
    t.iter().map(|r| r.1.map(|v| (v / y) as f32)).collect()
}

/// A 1 nm table from 360 nm on ([`cmf_table`], a sensor's) linearly interpolated at
/// `lambda_nm`; zero outside the table (and for NaN).
#[inline]
pub(crate) fn curve_at(table: &[[f32; 3]], lambda_nm: f32) -> [f32; 3] {
    let x = lambda_nm - INTEGRAL_RANGE_NM.0 as f32;
    let last = table.len().saturating_sub(1);
    if !(x >= 0.0 && x <= last as f32) {
        return [0.0; 3];
    }
    let i = (x as usize).min(last.saturating_sub(1));
    let f = x - i as f32;
    let (a, b) = (table[i], table[(i + 1).min(last)]);
    std::array::from_fn(|k| a[k] + (b[k] - a[k]) * f)
}

/// CIE 1931 2-degree x̄ ȳ z̄ at the 36 bin centres (raw table values, not the colour weights).
///
/// Source: CIE 1931 2-degree CMFs, 380-730 nm at 10 nm, from colour-science 0.4.7 as tabulated
/// in shared/data/cmf_1931_2deg.csv.
#[allow(clippy::excessive_precision)]
pub const CMF: [[f32; 3]; N_BINS] = [
    [0.001368, 3.9e-05, 0.006450001],    // 380 nm
    [0.004243, 0.00012, 0.02005001],     // 390 nm
    [0.01431, 0.000396, 0.06785001],     // 400 nm
    [0.04351, 0.00121, 0.2074],          // 410 nm
    [0.13438, 0.004, 0.6456],            // 420 nm
    [0.2839, 0.0116, 1.3856],            // 430 nm
    [0.34828, 0.023, 1.74706],           // 440 nm
    [0.3362, 0.038, 1.77211],            // 450 nm
    [0.2908, 0.06, 1.6692],              // 460 nm
    [0.19536, 0.09098, 1.28764],         // 470 nm
    [0.09564, 0.13902, 0.8129501],       // 480 nm
    [0.03201, 0.20802, 0.46518],         // 490 nm
    [0.0049, 0.323, 0.272],              // 500 nm
    [0.0093, 0.503, 0.1582],             // 510 nm
    [0.06327, 0.71, 0.07824999],         // 520 nm
    [0.1655, 0.862, 0.04216],            // 530 nm
    [0.2904, 0.954, 0.0203],             // 540 nm
    [0.4334499, 0.9949501, 0.008749999], // 550 nm
    [0.5945, 0.995, 0.0039],             // 560 nm
    [0.7621, 0.952, 0.0021],             // 570 nm
    [0.9163, 0.87, 0.001650001],         // 580 nm
    [1.0263, 0.757, 0.0011],             // 590 nm
    [1.0622, 0.631, 0.0008],             // 600 nm
    [1.0026, 0.503, 0.00034],            // 610 nm
    [0.8544499, 0.381, 0.00019],         // 620 nm
    [0.6424, 0.265, 4.999999e-05],       // 630 nm
    [0.4479, 0.175, 2e-05],              // 640 nm
    [0.2835, 0.107, 0.0],                // 650 nm
    [0.1649, 0.061, 0.0],                // 660 nm
    [0.0874, 0.032, 0.0],                // 670 nm
    [0.04677, 0.017, 0.0],               // 680 nm
    [0.0227, 0.00821, 0.0],              // 690 nm
    [0.01135916, 0.004102, 0.0],         // 700 nm
    [0.005790346, 0.002091, 0.0],        // 710 nm
    [0.002899327, 0.001047, 0.0],        // 720 nm
    [0.001439971, 0.00052, 0.0],         // 730 nm
];

/// XYZ of bin i alone (`color_weights()[i]` as [`Xyz`]): the colour one unit of radiance in
/// bin `i` adds, used by wavelength-sampling integrators. Panics if `i >= N_BINS` (an internal
/// index, never user input).
#[inline]
pub fn bin_xyz(i: usize) -> Xyz {
    let [x, y, z] = color_weights()[i];
    Xyz::new(x, y, z)
}

impl Spectrum {
    /// CIE XYZ of this spectrum, the exact integral of its linear interpolation:
    /// `Σ_b self[b] · W_b` ([`color_weights`]). A flat spectrum of 1 has Y = 1.
    #[inline]
    pub fn to_xyz(&self) -> Xyz {
        let (mut x, mut y, mut z) = (0.0f32, 0.0f32, 0.0f32);
        for (&s, w) in self.0.iter().zip(color_weights().iter()) {
            x += s * w[0];
            y += s * w[1];
            z += s * w[2];
        }
        Xyz::new(x, y, z)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::color::spectrum::{Spectrum, bin_lambda_nm};
    use crate::error::show_path;
    use std::path::Path;

    #[test]
    fn y_bar_near_555_matches_table() {
        // Raw table values either side of 555 nm, from shared/data/cmf_1931_2deg.csv; the CIE
        // ȳ peaks at exactly 1.0 at 555 nm, which has no 10 nm bin.
        assert_eq!(bin_lambda_nm(17), 550.0);
        assert_eq!(CMF[17][1], 0.9949501);
        assert_eq!(CMF[18][1], 0.995);
        let max_y = CMF.iter().map(|r| r[1]).fold(0.0f32, f32::max);
        assert!(max_y < 1.0 && max_y > 0.99);
    }

    #[test]
    fn y_bar_555_is_one_in_5nm_table() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/cmf_1931_2deg_360_830_5nm.csv");
        let Ok(text) = std::fs::read_to_string(&path) else {
            println!("skipping: {} not found", show_path(&path));
            return;
        };
        let mut found = None;
        for line in text.lines().skip(1) {
            let cols: Vec<&str> = line.split(',').collect();
            if cols.first().map(|c| c.trim()) == Some("555") {
                found = cols.get(2).and_then(|v| v.trim().parse::<f64>().ok());
            }
        }
        // The CIE definition: ȳ(555 nm) = 1 exactly (V(λ) normalisation).
        assert_eq!(found, Some(1.0));
        // Our 10 nm bins are a subset of the 5 nm table: spot-check that they agree exactly.
        for line in text.lines().skip(1) {
            let cols: Vec<f64> = line.split(',').filter_map(|c| c.trim().parse().ok()).collect();
            if cols.len() != 4 {
                continue;
            }
            let nm = cols[0];
            if (380.0..=730.0).contains(&nm) && (nm - 380.0) % 10.0 == 0.0 {
                let i = ((nm - 380.0) / 10.0) as usize;
                for k in 0..3 {
                    assert_eq!(CMF[i][k], cols[k + 1] as f32, "bin {i} channel {k}");
                }
            }
        }
    }

    #[test]
    fn weights_y_sum_to_one_and_table_is_whole() {
        // 471 rows, 360..=830 nm at 1 nm: a malformed row would be skipped silently otherwise.
        let t = cmf_1nm();
        assert_eq!(t.len(), 471);
        assert!(t.iter().enumerate().all(|(i, r)| r.0 == 360.0 + i as f64));
        let sum: f64 = color_weights_f64().iter().map(|r| r[1]).sum();
        assert!((sum - 1.0).abs() < 1e-12, "sum = {sum}");
        let y = Spectrum::ONE.to_xyz().y;
        // f32 sum of 36 products: a few ulps.
        assert!((y - 1.0).abs() < 1e-6, "Y(E) = {y}");
    }

    /// The continuous integral of the 1 nm CMFs gives X = Y = Z for the equal-energy spectrum
    /// up to the table's own rounding (the CIE defines them equal): x = y = 1/3 within 1e-4.
    #[test]
    fn equal_energy_chromaticity() {
        let e = Spectrum::ONE.to_xyz();
        let s = e.x + e.y + e.z;
        assert!((e.x / s - 1.0 / 3.0).abs() < 1e-4, "x = {}", e.x / s);
        assert!((e.y / s - 1.0 / 3.0).abs() < 1e-4, "y = {}", e.y / s);
    }

    /// The colour integral computed independently: the 36-bin spectrum interpolated linearly at
    /// every 1 nm row (flat beyond 380 and 730 nm), times the tabulated CMFs, summed by the
    /// trapezoidal rule, divided by the same sum of ȳ. Reads the table through its own parser.
    fn integral_1nm(s: &Spectrum) -> [f64; 3] {
        let mut acc = [0.0f64; 3];
        let mut y = 0.0f64;
        let rows: Vec<Vec<f64>> =
            CMF_1NM_CSV.lines().skip(1).map(|l| l.split(',').map(|c| c.parse::<f64>().unwrap()).collect()).collect();
        for (i, r) in rows.iter().enumerate() {
            let end = if i == 0 || i == rows.len() - 1 { 0.5 } else { 1.0 };
            let pos = ((r[0] - 380.0) / 10.0).clamp(0.0, 35.0);
            let i0 = (pos.floor() as usize).min(34);
            let f = pos - i0 as f64;
            let v = s[i0] as f64 * (1.0 - f) + s[i0 + 1] as f64 * f;
            for k in 0..3 {
                acc[k] += end * v * r[k + 1];
            }
            y += end * r[2];
        }
        acc.map(|a| a / y)
    }

    /// Part 1's acceptance test: every ColorChecker patch under D65 and under E, XYZ within 0.05%
    /// of the independent 1 nm integral in every channel. The trapezoidal rule at 1 nm differs
    /// from the exact integral of the piecewise-quadratic integrand by h²/12 · f'' ≈ 1e-5
    /// relative; the old point-sampled sum was off by up to 3% (the test fails on it).
    #[test]
    fn color_checker_matches_1nm_integral() {
        use crate::color::{COLOR_CHECKER_NAMES, color_checker, d65, equal_energy};
        let mut worst = 0.0f64;
        for light in [d65(), equal_energy()] {
            for name in COLOR_CHECKER_NAMES {
                let s = color_checker(name).unwrap() * light;
                let got = s.to_xyz();
                let want = integral_1nm(&s);
                for (g, w) in [got.x, got.y, got.z].into_iter().zip(want) {
                    let rel = (g as f64 - w).abs() / w;
                    worst = worst.max(rel);
                    assert!(rel < 5e-4, "{name}: {g} vs {w} ({rel:e})");
                }
            }
        }
        eprintln!("worst relative difference: {worst:e}");
    }

    #[test]
    fn tents_partition_unity() {
        for l in 360..=830 {
            let s: f64 = (0..N_BINS).map(|b| tent(b, l as f64 + 0.3)).sum();
            assert!((s - 1.0).abs() < 1e-12, "{l}: {s}");
        }
    }

    #[test]
    fn bin_xyz_sums_to_to_xyz() {
        let s = Spectrum::from_fn(|i| (i % 5) as f32 * 0.25);
        let mut acc = Xyz::default();
        for i in 0..N_BINS {
            acc += bin_xyz(i) * s[i];
        }
        let d = s.to_xyz();
        // Same sums in the same order: only rounding differences from separate multiplies.
        assert!((acc.x - d.x).abs() < 1e-6 && (acc.y - d.y).abs() < 1e-6);
        assert!((acc.z - d.z).abs() < 1e-6);
    }
}
