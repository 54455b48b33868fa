//! CIE 1931 2-degree colour matching functions sampled at the renderer's bins.
//!
//! [`CMF`] holds the raw tabulated x̄ ȳ z̄ at the 36 bin centres (380-730 nm at 10 nm), from
//! colour-science 0.4.7 (`colour.MSDS_CMFS['CIE 1931 2 Degree Standard Observer']`) as
//! tabulated in `shared/data/cmf_1931_2deg.csv`, copied verbatim without interpolation.
//!
//! [`CMF_NORMALISED`] is the same table divided by the sum of the ȳ column, so that
//! `Spectrum::to_xyz(s) = sum_i s[i] * CMF_NORMALISED[i]` and the equal-energy spectrum of
//! value 1 has Y = 1 exactly (to f32 precision). The bin width (10 nm) is absorbed into the
//! normalisation, so XYZ is a plain weighted sum of bins.
//!
//! Consequence: a spectrally flat emitter of radiance L has Y = L. The continuous 360-830 nm
//! integral normalised the same way (as in Mitsuba 3) gives Y = 1.001 L for the same emitter,
//! because our 36-bin sum truncates the CMF tails and samples them coarsely; comparisons with
//! Mitsuba should allow for this ~0.1 % difference.

use super::rgb::Xyz;
use super::spectrum::{N_BINS, Spectrum};

/// CIE 1931 2-degree x̄ ȳ z̄ at the 36 bin centres (raw table values).
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

/// Divides every entry of `cmf` by the sum of its ȳ column (summed in f64).
const fn normalise_cmf(cmf: &[[f32; 3]; N_BINS]) -> [[f32; 3]; N_BINS] {
    let mut sum_y = 0.0f64;
    let mut i = 0;
    while i < N_BINS {
        sum_y += cmf[i][1] as f64;
        i += 1;
    }
    let mut out = [[0.0f32; 3]; N_BINS];
    let mut i = 0;
    while i < N_BINS {
        let mut k = 0;
        while k < 3 {
            out[i][k] = (cmf[i][k] as f64 / sum_y) as f32;
            k += 1;
        }
        i += 1;
    }
    out
}

/// The CMF rows scaled so that sum over bins of row.y == 1 exactly (to f32 precision):
/// `Spectrum::to_xyz(s) = sum_i s[i] * CMF_NORMALISED[i]`. Normalisation: the equal-energy
/// spectrum of value 1 has Y = 1.
pub const CMF_NORMALISED: [[f32; 3]; N_BINS] = normalise_cmf(&CMF);

/// XYZ of bin i alone (`CMF_NORMALISED[i]` as [`Xyz`]), used by wavelength-sampling
/// integrators. Panics if `i >= N_BINS` (an internal index, never user input).
#[inline]
pub fn bin_xyz(i: usize) -> Xyz {
    let [x, y, z] = CMF_NORMALISED[i];
    Xyz::new(x, y, z)
}

impl Spectrum {
    /// CIE XYZ of this spectrum: `sum_i self[i] * CMF_NORMALISED[i]`.
    ///
    /// With this normalisation the equal-energy spectrum of value 1 has Y = 1.
    #[inline]
    pub fn to_xyz(&self) -> Xyz {
        let (mut x, mut y, mut z) = (0.0f32, 0.0f32, 0.0f32);
        for (&s, cmf) in self.0.iter().zip(CMF_NORMALISED.iter()) {
            x += s * cmf[0];
            y += s * cmf[1];
            z += s * cmf[2];
        }
        Xyz::new(x, y, z)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::color::spectrum::{Spectrum, bin_lambda_nm};
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
            println!("skipping: {} not found", path.display());
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
    fn normalised_y_sums_to_one() {
        let sum: f32 = CMF_NORMALISED.iter().map(|r| r[1]).sum();
        // f32 summation of 36 values each rounded to 0.5 ulp: error well below 1e-6.
        assert!((sum - 1.0).abs() < 1e-6, "sum = {sum}");
        let y = Spectrum::ONE.to_xyz().y;
        assert!((y - 1.0).abs() < 1e-6, "Y(E) = {y}");
    }

    #[test]
    fn equal_energy_chromaticity() {
        let e = Spectrum::ONE.to_xyz();
        let s = e.x + e.y + e.z;
        // The continuous integrals of x̄ ȳ z̄ are equal by definition, giving x = y = 1/3. The
        // 10 nm sum over 380-730 nm truncates and coarsely samples them, so allow 2e-3
        // (measured: x = 0.33336, y = 0.33345).
        assert!((e.x / s - 1.0 / 3.0).abs() < 2e-3, "x = {}", e.x / s);
        assert!((e.y / s - 1.0 / 3.0).abs() < 2e-3, "y = {}", e.y / s);
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
