//! Measured optical constants (complex index `n + i k`) of the named metals a
//! scene can ask for with `Conductor(metal: "Au")`, sampled at the 36 bin
//! wavelengths (380 to 730 nm every 10 nm) by linear interpolation of the
//! source tables, compiled in.
//!
//! Sources:
//! - Au, Ag, Cu, Al, Cr: the LuxPop optical constants database
//!   (www.luxpop.com), itself compiled from E. D. Palik (ed.), *Handbook of
//!   Optical Constants of Solids*, Academic Press (1985) (Cr: Palik joined
//!   with the LLNL/CXRO tables); these are the same tables Mitsuba ships as
//!   `data/ior/{Au,Ag,Cu,Al,Cr}.{eta,k}.spd` and uses for its conductors'
//!   `material="Au"` etc., so a comparison with Mitsuba compares the models,
//!   not the data.
//! - CuZn (brass): the 10 nm table pbrt-v4 ships as `metal-CuZn-eta` and
//!   `metal-CuZn-k` (`src/pbrt/util/spectrum.cpp`); pbrt-v4 does not name
//!   its measurement.
//!
//! The normal-incidence reflectance `((n−1)² + k²) / ((n+1)² + k²)` these
//! give at 450 / 550 / 650 nm: Au 0.39 / 0.85 / 0.94, Ag 0.92 / 0.96 / 0.97,
//! Cu 0.55 / 0.63 / 0.94, Al 0.92 / 0.92 / 0.91, Cr 0.70 / 0.66 / 0.64,
//! CuZn 0.43 / 0.79 / 0.89 (checked in the tests below).

use crate::color::{N_BINS, Spectrum};

/// A named metal: its name, `n` and `k` at the 36 bin wavelengths.
pub type MetalTable = (&'static str, [f32; N_BINS], [f32; N_BINS]);

/// The named metals (see the module docs for the sources).
#[rustfmt::skip]
pub const NAMED_METALS: [MetalTable; 6] = [
    ("Au", [1.688, 1.671, 1.658, 1.641, 1.628, 1.61, 1.574, 1.508, 1.419, 1.321, 1.19, 1.02, 0.8512, 0.6997, 0.572, 0.4729, 0.3976, 0.3504, 0.3172, 0.2872, 0.26, 0.2369, 0.2203, 0.2061, 0.1939, 0.1837, 0.1748, 0.1678, 0.1639, 0.1611, 0.1605, 0.1601, 0.1605, 0.1611, 0.1626, 0.1642],
        [1.918, 1.941, 1.956, 1.959, 1.952, 1.935, 1.911, 1.879, 1.843, 1.81, 1.796, 1.814, 1.887, 2.018, 2.184, 2.371, 2.555, 2.714, 2.837, 2.91, 2.948, 2.969, 3.0, 3.03, 3.06, 3.066, 3.09, 3.138, 3.275, 3.443, 3.633, 3.818, 3.964, 4.107, 4.237, 4.365]),
    ("Ag", [0.1986, 0.1879, 0.173, 0.1728, 0.1669, 0.1595, 0.1575, 0.1517, 0.1434, 0.1361, 0.1314, 0.1302, 0.13, 0.13, 0.13, 0.1298, 0.1286, 0.1248, 0.1212, 0.1197, 0.1197, 0.121, 0.124, 0.1274, 0.131, 0.1342, 0.1371, 0.1394, 0.14, 0.1401, 0.14, 0.1403, 0.1425, 0.1446, 0.1464, 0.1479],
        [1.718, 1.838, 1.951, 2.071, 2.183, 2.283, 2.375, 2.47, 2.567, 2.659, 2.746, 2.83, 2.918, 3.01, 3.098, 3.178, 3.258, 3.34, 3.421, 3.501, 3.58, 3.657, 3.731, 3.805, 3.881, 3.963, 4.045, 4.129, 4.21, 4.292, 4.371, 4.449, 4.523, 4.597, 4.671, 4.745]),
    ("Cu", [1.206, 1.178, 1.175, 1.179, 1.178, 1.174, 1.171, 1.166, 1.16, 1.154, 1.148, 1.14, 1.134, 1.127, 1.111, 1.081, 1.033, 0.9582, 0.8614, 0.7376, 0.6027, 0.4732, 0.3902, 0.324, 0.2718, 0.2459, 0.2266, 0.2166, 0.212, 0.2093, 0.2112, 0.2132, 0.2148, 0.2167, 0.22, 0.2234],
        [2.094, 2.196, 2.13, 2.186, 2.248, 2.301, 2.349, 2.394, 2.436, 2.477, 2.515, 2.547, 2.574, 2.595, 2.602, 2.593, 2.582, 2.577, 2.593, 2.638, 2.71, 2.805, 2.943, 3.09, 3.241, 3.378, 3.511, 3.638, 3.752, 3.861, 3.962, 4.062, 4.158, 4.253, 4.345, 4.436]),
    ("Al", [0.4422, 0.4661, 0.4901, 0.5149, 0.5394, 0.5644, 0.5905, 0.618, 0.6463, 0.6749, 0.7046, 0.7359, 0.7686, 0.8028, 0.8387, 0.8764, 0.916, 0.9586, 1.004, 1.049, 1.097, 1.148, 1.197, 1.248, 1.3, 1.357, 1.415, 1.475, 1.536, 1.599, 1.674, 1.75, 1.837, 1.927, 2.037, 2.148],
        [4.615, 4.741, 4.861, 4.98, 5.105, 5.23, 5.348, 5.469, 5.59, 5.716, 5.839, 5.96, 6.078, 6.199, 6.323, 6.447, 6.562, 6.687, 6.807, 6.924, 7.036, 7.146, 7.257, 7.368, 7.481, 7.588, 7.693, 7.794, 7.9, 8.008, 8.115, 8.221, 8.312, 8.403, 8.49, 8.572]),
    ("Cr", [1.436, 1.458, 1.498, 1.546, 1.617, 1.71, 1.82, 1.928, 2.052, 2.199, 2.345, 2.489, 2.606, 2.723, 2.839, 2.956, 3.04, 3.116, 3.19, 3.258, 3.326, 3.379, 3.428, 3.476, 3.517, 3.557, 3.597, 3.638, 3.678, 3.718, 3.758, 3.798, 3.838, 3.872, 3.906, 3.94],
        [3.364, 3.463, 3.591, 3.72, 3.836, 3.958, 4.077, 4.168, 4.258, 4.347, 4.397, 4.44, 4.449, 4.458, 4.456, 4.451, 4.438, 4.423, 4.408, 4.395, 4.383, 4.374, 4.367, 4.361, 4.361, 4.362, 4.363, 4.364, 4.365, 4.367, 4.368, 4.369, 4.37, 4.368, 4.365, 4.362]),
    ("CuZn", [1.487, 1.471, 1.445, 1.405, 1.35, 1.278, 1.191, 1.094, 0.994, 0.9, 0.816, 0.745, 0.686, 0.639, 0.602, 0.573, 0.549, 0.527, 0.505, 0.484, 0.468, 0.46, 0.45, 0.452, 0.449, 0.445, 0.444, 0.444, 0.445, 0.444, 0.444, 0.445, 0.446, 0.448, 0.45, 0.452],
        [1.818, 1.813, 1.805, 1.794, 1.786, 1.784, 1.797, 1.829, 1.883, 1.957, 2.046, 2.145, 2.25, 2.358, 2.464, 2.568, 2.668, 2.765, 2.86, 2.958, 3.059, 3.159, 3.253, 3.345, 3.434, 3.522, 3.609, 3.695, 3.778, 3.86, 3.943, 4.025, 4.106, 4.186, 4.266, 4.346]),
];

/// The complex index `(n, k)` of a named metal (see [`NAMED_METALS`]), or `None`.
pub fn named_metal(name: &str) -> Option<(Spectrum, Spectrum)> {
    NAMED_METALS
        .iter()
        .find(|(n, _, _)| *n == name)
        .map(|(_, eta, k)| (Spectrum::from_fn(|i| eta[i]), Spectrum::from_fn(|i| k[i])))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Spot values against the source tables at wavelengths where a source
    /// sample falls within 0.6 nm of a bin (so interpolation changes nothing
    /// visible), and the normal-incidence reflectances quoted in the module docs.
    #[test]
    fn tables_match_their_sources_and_documented_reflectances() {
        let at = |m: &str, lambda: f32| {
            let (n, k) = named_metal(m).unwrap();
            let i = ((lambda - 380.0) / 10.0).round() as usize;
            (n[i], k[i])
        };
        // LuxPop Au at 590.40 nm: n 0.236, k 2.970; Ag at 399.95 nm: n 0.173, k 1.950.
        let (n, k) = at("Au", 590.0);
        assert!((n - 0.236).abs() < 2e-3 && (k - 2.97).abs() < 5e-3, "Au {n} {k}");
        let (n, k) = at("Ag", 400.0);
        assert!((n - 0.173).abs() < 1e-3 && (k - 1.95).abs() < 1e-3, "Ag {n} {k}");
        // pbrt-v4 CuZn at 550 nm exactly: n 0.527, k 2.765.
        assert_eq!(at("CuZn", 550.0), (0.527, 2.765));
        let r = |m: &str, lambda: f32| {
            let (n, k) = at(m, lambda);
            ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k)
        };
        for (m, want) in [
            ("Au", [0.39, 0.85, 0.94]),
            ("Ag", [0.92, 0.96, 0.97]),
            ("Cu", [0.55, 0.63, 0.94]),
            ("Al", [0.92, 0.92, 0.91]),
            ("Cr", [0.70, 0.66, 0.64]),
            ("CuZn", [0.43, 0.79, 0.89]),
        ] {
            for (lambda, w) in [450.0, 550.0, 650.0].into_iter().zip(want) {
                assert!((r(m, lambda) - w).abs() < 0.006, "{m} at {lambda}: {}", r(m, lambda));
            }
        }
        assert!(named_metal("unobtainium").is_none());
        for (name, n, k) in NAMED_METALS {
            assert!(n.iter().chain(k.iter()).all(|v| v.is_finite() && *v > 0.0), "{name}");
        }
    }
}
