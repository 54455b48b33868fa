//! Output colour spaces for EXR images: linear sRGB, Rec. 2020, ACEScg, or CIE XYZ.
//!
//! The film holds CIE XYZ whose white is D65 (a spectrally flat reflector under D65 has the
//! chromaticity of D65). `--color-space` picks the RGB space an EXR is written in; PNG output is
//! always sRGB. Each matrix is built here from the space's published primaries and white point
//! (`RGB -> XYZ` from the primaries scaled so that RGB (1, 1, 1) is the white, then inverted);
//! where the space's white is not D65 (ACEScg's is the ACES white, about D60), the D65 XYZ is
//! first adapted to it with the Bradford transform, so a D65 white renders as (1, 1, 1) in every
//! RGB space. sRGB keeps the matrix Mitsuba 3 uses ([`super::XYZ_TO_LINEAR_SRGB`]), so images
//! stay comparable with the Mitsuba references.
//!
//! ```sh
//! rust-v render scenes/cornell.ron -o cornell.exr --color-space acescg
//! ```

use super::rgb::xyz_to_linear_srgb_f64;

/// A colour space for EXR output.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ColorSpace {
    /// Linear sRGB / Rec. 709 primaries, D65 white (the default; the only one for PNG).
    #[default]
    Srgb,
    /// ITU-R BT.2020 primaries, D65 white.
    Rec2020,
    /// ACES AP1 primaries, ACES white (x, y) = (0.32168, 0.33767); Bradford-adapted from D65.
    AcesCg,
    /// CIE 1931 XYZ itself (channels X, Y, Z), D65-referred.
    Xyz,
    /// A sensor's raw camera RGB (`--sensor FILE`), before its colour correction: the film's
    /// sums as they are, no conversion from XYZ (`crate::film::Film::write`), and no
    /// `chromaticities` attribute (camera RGB has no primaries).
    Camera,
}

/// CIE xy chromaticities of red, green, blue and white.
type Primaries = [[f64; 2]; 4];

/// D65 as CIE 1931 xy (ITU-R BT.709 / BT.2020).
const D65_XY: [f64; 2] = [0.3127, 0.3290];
/// BT.2020 primaries with the D65 white.
const REC2020: Primaries = [[0.708, 0.292], [0.170, 0.797], [0.131, 0.046], D65_XY];
/// ACES AP1 primaries with the ACES white (SMPTE ST 2065-1).
const AP1: Primaries = [[0.713, 0.293], [0.165, 0.830], [0.128, 0.044], [0.32168, 0.33767]];
/// The Bradford cone response matrix.
#[allow(clippy::excessive_precision)]
const BRADFORD: [[f64; 3]; 3] = [[0.8951, 0.2664, -0.1614], [-0.7502, 1.7135, 0.0367], [0.0389, -0.0685, 1.0296]];

impl ColorSpace {
    /// Every space, in the order of [`ColorSpace::NAMES`].
    pub const ALL: [ColorSpace; 5] =
        [ColorSpace::Srgb, ColorSpace::Rec2020, ColorSpace::AcesCg, ColorSpace::Xyz, ColorSpace::Camera];
    /// The names on the command line.
    pub const NAMES: [&'static str; 5] = ["srgb", "rec2020", "acescg", "xyz", "camera"];

    /// The command-line name.
    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }

    /// The space of a command-line name.
    pub fn from_name(s: &str) -> Option<Self> {
        Self::NAMES.iter().position(|&n| n == s).map(|i| Self::ALL[i])
    }

    /// The xy chromaticities of the primaries and white (what an EXR's `chromaticities`
    /// attribute records); XYZ is the OpenEXR convention (1, 0), (0, 1), (0, 0), (1/3, 1/3), and so
    /// is camera RGB, for which no attribute is written.
    pub fn chromaticities(self) -> Primaries {
        match self {
            ColorSpace::Srgb => [[0.64, 0.33], [0.30, 0.60], [0.15, 0.06], D65_XY],
            ColorSpace::Rec2020 => REC2020,
            ColorSpace::AcesCg => AP1,
            ColorSpace::Xyz | ColorSpace::Camera => [[1.0, 0.0], [0.0, 1.0], [0.0, 0.0], [1.0 / 3.0, 1.0 / 3.0]],
        }
    }

    /// The channel names in an EXR.
    pub fn channels(self) -> [&'static str; 3] {
        if self == ColorSpace::Xyz { ["X", "Y", "Z"] } else { ["R", "G", "B"] }
    }

    /// D65-referred XYZ to this space (camera RGB is not made from XYZ: unchanged).
    pub fn from_xyz(self, xyz: [f64; 3]) -> [f64; 3] {
        match self {
            ColorSpace::Srgb => xyz_to_linear_srgb_f64(xyz),
            ColorSpace::Xyz | ColorSpace::Camera => xyz,
            ColorSpace::Rec2020 | ColorSpace::AcesCg => mul(&self.matrix(), xyz),
        }
    }

    /// The XYZ (D65) -> RGB matrix of a primaries-based space, with Bradford adaptation where
    /// its white is not D65.
    pub fn matrix(self) -> [[f64; 3]; 3] {
        let p = self.chromaticities();
        let to_rgb = invert(&rgb_to_xyz(&p)).unwrap_or(IDENTITY);
        if p[3] == D65_XY { to_rgb } else { mat_mul(&to_rgb, &bradford(xy_to_xyz(D65_XY), xy_to_xyz(p[3]))) }
    }
}

const IDENTITY: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// XYZ with Y = 1 of a chromaticity.
fn xy_to_xyz([x, y]: [f64; 2]) -> [f64; 3] {
    [x / y, 1.0, (1.0 - x - y) / y]
}

fn mul(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2])
}

fn mat_mul(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

fn invert(m: &[[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let c = |i: usize, j: usize| {
        let (r0, r1) = ((i + 1) % 3, (i + 2) % 3);
        let (c0, c1) = ((j + 1) % 3, (j + 2) % 3);
        m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]
    };
    let det = m[0][0] * c(0, 0) + m[0][1] * c(0, 1) + m[0][2] * c(0, 2);
    (det.abs() > 1e-12).then(|| std::array::from_fn(|i| std::array::from_fn(|j| c(j, i) / det)))
}

/// RGB -> XYZ of primaries and white: the primaries' XYZ columns scaled so RGB (1, 1, 1) is the
/// white at Y = 1.
fn rgb_to_xyz(p: &Primaries) -> [[f64; 3]; 3] {
    let cols = [xy_to_xyz(p[0]), xy_to_xyz(p[1]), xy_to_xyz(p[2])];
    let m: [[f64; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| cols[j][i]));
    let s = mul(&invert(&m).unwrap_or(IDENTITY), xy_to_xyz(p[3]));
    std::array::from_fn(|i| std::array::from_fn(|j| m[i][j] * s[j]))
}

/// The Bradford chromatic adaptation from white `src` to white `dst` (XYZ).
fn bradford(src: [f64; 3], dst: [f64; 3]) -> [[f64; 3]; 3] {
    let (a, b) = (mul(&BRADFORD, src), mul(&BRADFORD, dst));
    let scale = [[b[0] / a[0], 0.0, 0.0], [0.0, b[1] / a[1], 0.0], [0.0, 0.0, b[2] / a[2]]];
    mat_mul(&invert(&BRADFORD).unwrap_or(IDENTITY), &mat_mul(&scale, &BRADFORD))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3], tol: f64) {
        for i in 0..3 {
            for j in 0..3 {
                assert!((a[i][j] - b[i][j]).abs() < tol, "[{i}][{j}]: {} vs {}\n{a:?}", a[i][j], b[i][j]);
            }
        }
    }

    /// Against the published XYZ -> BT.2020 matrix (ITU-R BT.2087, as tabulated by
    /// colour-science), to its 1e-6 rounding plus ours.
    #[test]
    fn rec2020_matches_the_published_matrix() {
        #[allow(clippy::excessive_precision)]
        let published = [
            [1.7166511880, -0.3556707838, -0.2533662814],
            [-0.6666843518, 1.6164812366, 0.0157685458],
            [0.0176398574, -0.0427706133, 0.9421031212],
        ];
        close(&ColorSpace::Rec2020.matrix(), &published, 1e-6);
    }

    /// ACEScg against two published matrices: the ACES specification's XYZ -> AP1 (no
    /// adaptation: the inverse of AP1's primaries matrix with the ACES white), to 1e-6; and the
    /// widely used linear sRGB -> ACEScg with Bradford adaptation (as in colour-science and
    /// OCIO configs), to its 4 decimals.
    #[test]
    fn acescg_matches_the_published_matrices() {
        #[allow(clippy::excessive_precision)]
        let xyz_to_ap1 = [
            [1.6410233797, -0.3248032942, -0.2364246952],
            [-0.6636628587, 1.6153315917, 0.0167563477],
            [0.0117218943, -0.0082844420, 0.9883948585],
        ];
        close(&invert(&rgb_to_xyz(&AP1)).unwrap(), &xyz_to_ap1, 1e-6);
        let srgb_to_acescg = [[0.6131, 0.3395, 0.0474], [0.0702, 0.9164, 0.0135], [0.0206, 0.1096, 0.8698]];
        let m = mat_mul(&ColorSpace::AcesCg.matrix(), &rgb_to_xyz(&ColorSpace::Srgb.chromaticities()));
        close(&m, &srgb_to_acescg, 1e-4);
    }

    /// D65 is (1, 1, 1) in every RGB space (adapted where the white differs); the Bradford
    /// matrix maps a white to itself when source and destination agree.
    #[test]
    fn d65_is_white_everywhere() {
        let d65 = xy_to_xyz(D65_XY);
        for cs in [ColorSpace::Srgb, ColorSpace::Rec2020, ColorSpace::AcesCg] {
            let rgb = cs.from_xyz(d65);
            for v in rgb {
                // sRGB uses Mitsuba's 6-decimal matrix, whose white is 3.2e-4 off this D65 xy.
                assert!((v - 1.0).abs() < 5e-4, "{cs:?}: {rgb:?}");
            }
        }
        close(&bradford(d65, d65), &IDENTITY, 1e-12);
        assert_eq!(ColorSpace::Xyz.from_xyz([0.1, 0.2, 0.3]), [0.1, 0.2, 0.3]);
        for cs in ColorSpace::ALL {
            assert_eq!(ColorSpace::from_name(cs.name()), Some(cs));
        }
        assert_eq!(ColorSpace::from_name("p3"), None);
    }
}
