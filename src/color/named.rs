//! Spectra a scene file can refer to by name: ColorChecker patches, CIE D65, the equal-energy
//! illuminant E and blackbody emitters, plus the reflectance-under-illuminant colorimetry used
//! to check them.
//!
//! ColorChecker reflectances: BabelColor "ColorChecker average" data by Danny Pascale
//! (babelcolor.com), as shipped by colour-science 0.4.7
//! (`colour.SDS_COLOURCHECKERS['BabelColor Average']`), 380-730 nm at 10 nm, tabulated in
//! shared/data/colorchecker_babel_average.csv. D65: CIE standard illuminant D65 relative SPD via
//! colour-science, tabulated in shared/data/d65_380_730_10nm.csv. Values copied verbatim.

use super::rgb::Xyz;
use super::spectrum::{N_BINS, Sampled, Spectrum, bin_lambda_nm};

/// Names of the 24 ColorChecker patches, exactly the column headers of the BabelColor CSV, in
/// chart order (dark skin ... black 2).
pub const COLOR_CHECKER_NAMES: [&str; 24] = [
    "dark skin",
    "light skin",
    "blue sky",
    "foliage",
    "blue flower",
    "bluish green",
    "orange",
    "purplish blue",
    "moderate red",
    "purple",
    "yellow green",
    "orange yellow",
    "blue",
    "green",
    "red",
    "yellow",
    "magenta",
    "cyan",
    "white 9.5 (.05 D)",
    "neutral 8 (.23 D)",
    "neutral 6.5 (.44 D)",
    "neutral 5 (.70 D)",
    "neutral 3.5 (1.05 D)",
    "black 2 (1.5 D)",
];

/// Reflectances of the patches, same order as [`COLOR_CHECKER_NAMES`].
// Measured data, not constants: 0.318 is a reflectance, not 1/pi.
#[allow(clippy::approx_constant)]
const COLOR_CHECKER_REFLECTANCE: [[f32; N_BINS]; 24] = [
    // dark skin
    [
        0.055, 0.058, 0.061, 0.062, 0.062, 0.062, 0.062, 0.062, 0.062, 0.062, 0.062, 0.063, 0.065, 0.07, 0.076, 0.079,
        0.081, 0.084, 0.091, 0.103, 0.119, 0.134, 0.143, 0.147, 0.151, 0.158, 0.168, 0.179, 0.188, 0.19, 0.186, 0.181,
        0.182, 0.187, 0.196, 0.209,
    ],
    // light skin
    [
        0.117, 0.143, 0.175, 0.191, 0.196, 0.199, 0.204, 0.213, 0.228, 0.251, 0.28, 0.309, 0.329, 0.333, 0.315, 0.286,
        0.273, 0.276, 0.277, 0.289, 0.339, 0.42, 0.488, 0.525, 0.546, 0.562, 0.578, 0.595, 0.612, 0.625, 0.638, 0.656,
        0.678, 0.7, 0.717, 0.734,
    ],
    // blue sky
    [
        0.13, 0.177, 0.251, 0.306, 0.324, 0.33, 0.333, 0.331, 0.323, 0.311, 0.298, 0.285, 0.269, 0.25, 0.231, 0.214,
        0.199, 0.185, 0.169, 0.157, 0.149, 0.145, 0.142, 0.141, 0.141, 0.141, 0.143, 0.147, 0.152, 0.154, 0.15, 0.144,
        0.136, 0.132, 0.135, 0.147,
    ],
    // foliage
    [
        0.051, 0.054, 0.056, 0.057, 0.058, 0.059, 0.06, 0.061, 0.062, 0.063, 0.065, 0.067, 0.075, 0.101, 0.145, 0.178,
        0.184, 0.17, 0.149, 0.133, 0.122, 0.115, 0.109, 0.105, 0.104, 0.106, 0.109, 0.112, 0.114, 0.114, 0.112, 0.112,
        0.115, 0.12, 0.125, 0.13,
    ],
    // blue flower
    [
        0.144, 0.198, 0.294, 0.375, 0.408, 0.421, 0.426, 0.426, 0.419, 0.403, 0.379, 0.346, 0.311, 0.281, 0.254, 0.229,
        0.214, 0.208, 0.202, 0.194, 0.193, 0.2, 0.214, 0.23, 0.241, 0.254, 0.279, 0.313, 0.348, 0.366, 0.366, 0.359,
        0.358, 0.365, 0.377, 0.398,
    ],
    // bluish green
    [
        0.136, 0.179, 0.247, 0.297, 0.32, 0.337, 0.355, 0.381, 0.419, 0.466, 0.51, 0.546, 0.567, 0.574, 0.569, 0.551,
        0.524, 0.488, 0.445, 0.4, 0.35, 0.299, 0.252, 0.221, 0.204, 0.196, 0.191, 0.188, 0.191, 0.199, 0.212, 0.223,
        0.232, 0.233, 0.229, 0.229,
    ],
    // orange
    [
        0.054, 0.054, 0.053, 0.054, 0.054, 0.055, 0.055, 0.055, 0.056, 0.057, 0.058, 0.061, 0.068, 0.089, 0.125, 0.154,
        0.174, 0.199, 0.248, 0.335, 0.444, 0.538, 0.587, 0.595, 0.591, 0.587, 0.584, 0.584, 0.59, 0.603, 0.62, 0.639,
        0.655, 0.663, 0.663, 0.667,
    ],
    // purplish blue
    [
        0.122, 0.164, 0.229, 0.286, 0.327, 0.361, 0.388, 0.4, 0.392, 0.362, 0.316, 0.26, 0.209, 0.168, 0.138, 0.117,
        0.104, 0.096, 0.09, 0.086, 0.084, 0.084, 0.084, 0.084, 0.084, 0.085, 0.09, 0.098, 0.109, 0.123, 0.143, 0.169,
        0.205, 0.244, 0.287, 0.332,
    ],
    // moderate red
    [
        0.096, 0.115, 0.131, 0.135, 0.133, 0.132, 0.13, 0.128, 0.125, 0.12, 0.115, 0.11, 0.105, 0.1, 0.095, 0.093,
        0.092, 0.093, 0.096, 0.108, 0.156, 0.265, 0.399, 0.5, 0.556, 0.579, 0.588, 0.591, 0.593, 0.594, 0.598, 0.602,
        0.607, 0.609, 0.609, 0.61,
    ],
    // purple
    [
        0.092, 0.116, 0.146, 0.169, 0.178, 0.173, 0.158, 0.139, 0.119, 0.101, 0.087, 0.075, 0.066, 0.06, 0.056, 0.053,
        0.051, 0.051, 0.052, 0.052, 0.051, 0.052, 0.058, 0.073, 0.096, 0.119, 0.141, 0.166, 0.194, 0.227, 0.265, 0.309,
        0.355, 0.396, 0.436, 0.478,
    ],
    // yellow green
    [
        0.061, 0.061, 0.062, 0.063, 0.064, 0.066, 0.069, 0.075, 0.085, 0.105, 0.139, 0.192, 0.271, 0.376, 0.476, 0.531,
        0.549, 0.546, 0.528, 0.504, 0.471, 0.428, 0.381, 0.347, 0.327, 0.318, 0.312, 0.31, 0.314, 0.327, 0.345, 0.363,
        0.376, 0.381, 0.378, 0.379,
    ],
    // orange yellow
    [
        0.063, 0.063, 0.063, 0.064, 0.064, 0.064, 0.065, 0.066, 0.067, 0.068, 0.071, 0.076, 0.087, 0.125, 0.206, 0.305,
        0.383, 0.431, 0.469, 0.518, 0.568, 0.607, 0.628, 0.637, 0.64, 0.642, 0.645, 0.648, 0.651, 0.653, 0.657, 0.664,
        0.673, 0.68, 0.684, 0.688,
    ],
    // blue
    [
        0.066, 0.079, 0.102, 0.146, 0.2, 0.244, 0.282, 0.309, 0.308, 0.278, 0.231, 0.178, 0.13, 0.094, 0.07, 0.054,
        0.046, 0.042, 0.039, 0.038, 0.038, 0.038, 0.038, 0.039, 0.039, 0.04, 0.041, 0.042, 0.044, 0.045, 0.046, 0.046,
        0.048, 0.052, 0.057, 0.065,
    ],
    // green
    [
        0.052, 0.053, 0.054, 0.055, 0.057, 0.059, 0.061, 0.066, 0.075, 0.093, 0.125, 0.178, 0.246, 0.307, 0.337, 0.334,
        0.317, 0.293, 0.262, 0.23, 0.198, 0.165, 0.135, 0.115, 0.104, 0.098, 0.094, 0.092, 0.093, 0.097, 0.102, 0.108,
        0.113, 0.115, 0.114, 0.114,
    ],
    // red
    [
        0.05, 0.049, 0.048, 0.047, 0.047, 0.047, 0.047, 0.047, 0.046, 0.045, 0.044, 0.044, 0.045, 0.046, 0.047, 0.048,
        0.049, 0.05, 0.054, 0.06, 0.072, 0.104, 0.178, 0.312, 0.467, 0.581, 0.644, 0.675, 0.69, 0.698, 0.706, 0.715,
        0.724, 0.73, 0.734, 0.738,
    ],
    // yellow
    [
        0.058, 0.054, 0.052, 0.052, 0.053, 0.054, 0.056, 0.059, 0.067, 0.081, 0.107, 0.152, 0.225, 0.336, 0.462, 0.559,
        0.616, 0.65, 0.672, 0.694, 0.71, 0.723, 0.731, 0.739, 0.746, 0.752, 0.758, 0.764, 0.769, 0.771, 0.776, 0.782,
        0.79, 0.796, 0.799, 0.804,
    ],
    // magenta
    [
        0.145, 0.195, 0.283, 0.346, 0.362, 0.354, 0.334, 0.306, 0.276, 0.248, 0.218, 0.19, 0.168, 0.149, 0.127, 0.107,
        0.1, 0.102, 0.104, 0.109, 0.137, 0.2, 0.29, 0.4, 0.516, 0.615, 0.687, 0.732, 0.76, 0.774, 0.783, 0.793, 0.803,
        0.812, 0.817, 0.825,
    ],
    // cyan
    [
        0.108, 0.141, 0.192, 0.236, 0.261, 0.286, 0.317, 0.353, 0.39, 0.426, 0.446, 0.444, 0.423, 0.385, 0.337, 0.283,
        0.231, 0.185, 0.146, 0.118, 0.101, 0.09, 0.082, 0.076, 0.074, 0.073, 0.073, 0.074, 0.076, 0.077, 0.076, 0.075,
        0.073, 0.072, 0.074, 0.079,
    ],
    // white 9.5 (.05 D)
    [
        0.189, 0.255, 0.423, 0.66, 0.811, 0.862, 0.877, 0.884, 0.891, 0.896, 0.899, 0.904, 0.907, 0.909, 0.911, 0.91,
        0.911, 0.914, 0.913, 0.916, 0.915, 0.916, 0.914, 0.915, 0.918, 0.919, 0.921, 0.923, 0.924, 0.922, 0.922, 0.925,
        0.927, 0.93, 0.93, 0.933,
    ],
    // neutral 8 (.23 D)
    [
        0.171, 0.232, 0.365, 0.507, 0.567, 0.583, 0.588, 0.59, 0.591, 0.59, 0.588, 0.588, 0.589, 0.589, 0.591, 0.59,
        0.59, 0.59, 0.589, 0.591, 0.59, 0.59, 0.587, 0.585, 0.583, 0.58, 0.578, 0.576, 0.574, 0.572, 0.571, 0.569,
        0.568, 0.568, 0.566, 0.566,
    ],
    // neutral 6.5 (.44 D)
    [
        0.144, 0.192, 0.272, 0.331, 0.35, 0.357, 0.361, 0.363, 0.363, 0.361, 0.359, 0.358, 0.358, 0.359, 0.36, 0.36,
        0.361, 0.361, 0.36, 0.362, 0.362, 0.361, 0.359, 0.358, 0.355, 0.352, 0.35, 0.348, 0.345, 0.343, 0.34, 0.338,
        0.335, 0.334, 0.332, 0.331,
    ],
    // neutral 5 (.70 D)
    [
        0.105, 0.131, 0.163, 0.18, 0.186, 0.19, 0.193, 0.194, 0.194, 0.192, 0.191, 0.191, 0.191, 0.192, 0.192, 0.192,
        0.192, 0.192, 0.192, 0.193, 0.192, 0.192, 0.191, 0.189, 0.188, 0.186, 0.184, 0.182, 0.181, 0.179, 0.178, 0.176,
        0.174, 0.173, 0.172, 0.171,
    ],
    // neutral 3.5 (1.05 D)
    [
        0.068, 0.077, 0.084, 0.087, 0.089, 0.09, 0.092, 0.092, 0.091, 0.09, 0.09, 0.09, 0.09, 0.09, 0.09, 0.09, 0.09,
        0.09, 0.09, 0.09, 0.09, 0.089, 0.089, 0.088, 0.087, 0.086, 0.086, 0.085, 0.084, 0.084, 0.083, 0.083, 0.082,
        0.081, 0.081, 0.081,
    ],
    // black 2 (1.5 D)
    [
        0.031, 0.032, 0.032, 0.033, 0.033, 0.033, 0.033, 0.033, 0.032, 0.032, 0.032, 0.032, 0.032, 0.032, 0.032, 0.032,
        0.032, 0.032, 0.032, 0.032, 0.032, 0.032, 0.032, 0.032, 0.032, 0.032, 0.032, 0.032, 0.032, 0.032, 0.032, 0.032,
        0.032, 0.032, 0.032, 0.033,
    ],
];

/// CIE D65 relative SPD at the bin centres, D65(560 nm) = 100 (source: see module doc).
const D65_TABLE: [f32; N_BINS] = [
    49.9755, // 380 nm
    54.6482, // 390 nm
    82.7549, // 400 nm
    91.486,  // 410 nm
    93.4318, // 420 nm
    86.6823, // 430 nm
    104.865, // 440 nm
    117.008, // 450 nm
    117.812, // 460 nm
    114.861, // 470 nm
    115.923, // 480 nm
    108.811, // 490 nm
    109.354, // 500 nm
    107.802, // 510 nm
    104.79,  // 520 nm
    107.689, // 530 nm
    104.405, // 540 nm
    104.046, // 550 nm
    100.0,   // 560 nm
    96.3342, // 570 nm
    95.788,  // 580 nm
    88.6856, // 590 nm
    90.0062, // 600 nm
    89.5991, // 610 nm
    87.6987, // 620 nm
    83.2886, // 630 nm
    83.6992, // 640 nm
    80.0268, // 650 nm
    80.2146, // 660 nm
    82.2778, // 670 nm
    78.2842, // 680 nm
    69.7213, // 690 nm
    71.6091, // 700 nm
    74.349,  // 710 nm
    61.604,  // 720 nm
    69.8856, // 730 nm
];

/// Reflectance of a ColorChecker patch by its CSV name; None for an unknown name.
///
/// The match is exact (case-sensitive), e.g. `"dark skin"`, `"white 9.5 (.05 D)"`.
pub fn color_checker(name: &str) -> Option<Spectrum> {
    COLOR_CHECKER_NAMES.iter().position(|&n| n == name).map(|i| Sampled(COLOR_CHECKER_REFLECTANCE[i]))
}

/// CIE D65 relative SPD sampled at the bins, scaled so that D65(560 nm) = 1.
pub fn d65() -> Spectrum {
    Spectrum::from_fn(|i| D65_TABLE[i] / 100.0)
}

/// The equal-energy illuminant E: 1 in every bin.
pub fn equal_energy() -> Spectrum {
    Spectrum::ONE
}

/// Planck constant h in J s (SI 2019 exact value).
const PLANCK_H: f64 = 6.626_070_15e-34;
/// Speed of light in vacuum c in m/s (exact).
const SPEED_OF_LIGHT: f64 = 299_792_458.0;
/// Boltzmann constant k in J/K (SI 2019 exact value).
const BOLTZMANN_K: f64 = 1.380_649e-23;
/// Wien's displacement constant b in m K (CODATA 2018).
pub const WIEN_B_M_K: f64 = 2.897_771_955e-3;

/// Planck's law: spectral radiance of a blackbody in W sr^-1 m^-3 at wavelength `lambda_nm`
/// (nm) and temperature `kelvin`. Unnormalised; NaN or 0 for non-physical inputs.
pub fn planck(lambda_nm: f64, kelvin: f64) -> f64 {
    let l = lambda_nm * 1e-9;
    let c1 = 2.0 * PLANCK_H * SPEED_OF_LIGHT * SPEED_OF_LIGHT;
    let c2 = PLANCK_H * SPEED_OF_LIGHT / BOLTZMANN_K;
    c1 / (l.powi(5) * (c2 / (l * kelvin)).exp_m1())
}

/// Planck's law at the bin centres for temperature `kelvin`, normalised so that its maximum over
/// all wavelengths (Wien's peak, not only the bins) is 1, like pbrt-v4's BlackbodySpectrum.
/// Returns None for kelvin <= 0 or non-finite.
pub fn blackbody(kelvin: f32) -> Option<Spectrum> {
    if !kelvin.is_finite() || kelvin <= 0.0 {
        return None;
    }
    let t = kelvin as f64;
    let peak_nm = WIEN_B_M_K / t * 1e9;
    let peak = planck(peak_nm, t);
    if !(peak.is_finite() && peak > 0.0) {
        // Extremely low temperatures underflow; such an emitter is black at our wavelengths.
        return Some(Spectrum::ZERO);
    }
    Some(Spectrum::from_fn(|i| {
        let v = planck(bin_lambda_nm(i) as f64, t) / peak;
        if v.is_finite() { v as f32 } else { 0.0 }
    }))
}

/// XYZ of a reflectance seen under an illuminant, normalised so the perfect white reflector has
/// Y = 1. Returns zero XYZ if the illuminant has zero luminance.
pub fn reflectance_to_xyz(reflectance: &Spectrum, illuminant: &Spectrum) -> Xyz {
    let white_y = illuminant.to_xyz().y;
    if white_y == 0.0 || !white_y.is_finite() {
        return Xyz::default();
    }
    (*reflectance * *illuminant).to_xyz() * (1.0 / white_y)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_lookup() {
        assert_eq!(COLOR_CHECKER_NAMES[0], "dark skin");
        assert_eq!(COLOR_CHECKER_NAMES[18], "white 9.5 (.05 D)");
        assert_eq!(COLOR_CHECKER_NAMES[23], "black 2 (1.5 D)");
        // First CSV row (380 nm) and last (730 nm) of "dark skin".
        let ds = color_checker("dark skin");
        assert_eq!(ds.map(|s| (s[0], s[35])), Some((0.055, 0.209)));
        assert_eq!(color_checker("Dark Skin"), None);
        assert_eq!(color_checker(""), None);
        for n in COLOR_CHECKER_NAMES {
            let s = color_checker(n);
            assert!(s.is_some_and(|s| s.min_value() > 0.0 && s.max_value() < 1.0), "{n}");
        }
    }

    #[test]
    fn d65_and_e() {
        assert_eq!(d65()[18], 1.0); // 560 nm
        assert_eq!(equal_energy(), Spectrum::ONE);
    }

    #[test]
    fn d65_white_point() {
        let xyz = d65().to_xyz();
        let (x, y) = xyz.chromaticity();
        // CIE D65 white point (0.31271, 0.32902) from the continuous 1 nm tables; ours is the
        // exact colour integral of the 10 nm D65 samples interpolated linearly, which differs
        // from the 1 nm D65 between the samples: allow 1e-3 (D65 -> sRGB white is checked to 1e-4
        // below).
        assert!((x - 0.31271).abs() < 1e-3, "x = {x}");
        assert!((y - 0.32902).abs() < 1e-3, "y = {y}");
    }

    #[test]
    fn d65_maps_to_srgb_white() {
        // sRGB's white is D65, so D65 at Y = 1 must give linear (1, 1, 1) within 1e-4.
        let xyz = d65().to_xyz();
        let rgb = (xyz * (1.0 / xyz.y)).to_linear_srgb();
        for (c, v) in [("r", rgb.r), ("g", rgb.g), ("b", rgb.b)] {
            assert!((v - 1.0).abs() < 1e-4, "{c} = {v}");
        }
        let w = reflectance_to_xyz(&Spectrum::ONE, &d65());
        assert!((w.y - 1.0).abs() < 1e-6);
    }

    #[test]
    fn color_checker_matches_babelcolor_srgb() {
        // BabelColor's published 8-bit sRGB (D65) values for the "average" data set. They were
        // computed from D50 spectral data plus a chromatic adaptation (Bradford) to D65 and a
        // finer wavelength grid, whereas we integrate the reflectance directly under D65 with
        // 10 nm bins. An independent Python reproduction on a 1 nm grid (CMFs and D65 at 1 nm,
        // reflectance interpolated linearly) agrees with our 10 nm result to < 0.7 units, so the
        // residual is the adaptation path, not sampling. It is largest where an encoded channel
        // is near 0 (steep sRGB curve): general tolerance 4.5/255 (measured worst 3.97/255,
        // "red" G); "blue" R is 13.8/255 off (ours 42.2 vs 56) and gets 15/255.
        let published: [(&str, [f32; 3]); 8] = [
            ("dark skin", [115.0, 82.0, 68.0]),
            ("light skin", [194.0, 150.0, 130.0]),
            ("blue", [56.0, 61.0, 150.0]),
            ("green", [70.0, 148.0, 73.0]),
            ("red", [175.0, 54.0, 60.0]),
            ("white 9.5 (.05 D)", [243.0, 243.0, 242.0]),
            ("neutral 5 (.70 D)", [122.0, 122.0, 121.0]),
            ("black 2 (1.5 D)", [52.0, 52.0, 52.0]),
        ];
        let illum = d65();
        let mut worst = (0.0f32, "", 0);
        for (name, want) in published {
            let refl = color_checker(name);
            assert!(refl.is_some(), "{name}");
            let refl = refl.unwrap_or(Spectrum::ZERO);
            let s = reflectance_to_xyz(&refl, &illum).to_linear_srgb().encode();
            let got = [s.r * 255.0, s.g * 255.0, s.b * 255.0];
            for c in 0..3 {
                let err = (got[c] - want[c]).abs();
                let tol = if name == "blue" && c == 0 { 15.0 } else { 4.5 };
                assert!(err <= tol, "{name} channel {c}: got {got:?} want {want:?}");
                if !(name == "blue" && c == 0) && err > worst.0 {
                    worst = (err, name, c);
                }
            }
        }
        println!("worst ColorChecker error (excluding blue R): {worst:?}");
    }

    #[test]
    fn blackbody_invalid() {
        assert_eq!(blackbody(0.0), None);
        assert_eq!(blackbody(-100.0), None);
        assert_eq!(blackbody(f32::NAN), None);
        assert_eq!(blackbody(f32::INFINITY), None);
        assert!(blackbody(1.0).is_some_and(|s| !s.has_nan_or_inf()));
    }

    #[test]
    fn wien_displacement() {
        // Locate the maximum of planck() numerically by golden-section search and compare with
        // Wien's law lambda_max = b / T (b = 2.8977719e-3 m K). Relative tolerance 1e-5: the
        // search converges far below that, and b is known to 9 digits.
        for t in [3000.0f64, 5000.0, 6504.0, 10000.0] {
            let (mut a, mut b) = (100.0f64, 2000.0f64);
            let g = (5f64.sqrt() - 1.0) / 2.0;
            for _ in 0..200 {
                let c = b - g * (b - a);
                let d = a + g * (b - a);
                if planck(c, t) > planck(d, t) {
                    b = d;
                } else {
                    a = c;
                }
            }
            let peak = 0.5 * (a + b);
            let expect = 2.897_771_9e-3 / t * 1e9;
            assert!(((peak - expect) / expect).abs() < 1e-5, "T={t}: {peak} vs {expect}");
        }
    }

    #[test]
    fn blackbody_normalisation_and_ratios() {
        let bb = blackbody(5000.0);
        assert!(bb.is_some());
        let bb = bb.unwrap_or(Spectrum::ZERO);
        // Peak at 579.6 nm is between bins, so the bin maximum is just under 1.
        assert!(bb.max_value() <= 1.0 && bb.max_value() > 0.99, "{}", bb.max_value());

        // Independent Planck ratio between 450 nm (bin 7) and 650 nm (bin 27) at 5000 K, using
        // the second radiation constant c2 = hc/k = 1.438776877e-2 m K (CODATA 2018); the 2hc^2
        // factor cancels. Tolerance 1e-4 relative: f32 storage gives ~1e-7.
        let t = 5000.0f64;
        let c2 = 1.438_776_877e-2;
        let p = |nm: f64| {
            let l = nm * 1e-9;
            1.0 / (l.powi(5) * ((c2 / (l * t)).exp() - 1.0))
        };
        let want = p(450.0) / p(650.0);
        let got = (bb[7] / bb[27]) as f64;
        assert!(((got - want) / want).abs() < 1e-4, "{got} vs {want}");

        // A temperature whose Wien peak falls on the 560 nm bin: that bin must be 1.
        let t_on_bin = (WIEN_B_M_K / 560e-9) as f32;
        let on = blackbody(t_on_bin).unwrap_or(Spectrum::ZERO);
        assert!((on[18] - 1.0).abs() < 1e-5, "{}", on[18]);
    }
}
