//! Tristimulus colour types: CIE XYZ, linear sRGB and encoded sRGB, and conversions between them.
//!
//! The XYZ <-> linear sRGB matrices are the ones Mitsuba 3 uses (IEC 61966-2-1 / Rec. 709
//! primaries, D65 white, no chromatic adaptation), so images are directly comparable with the
//! Mitsuba reference renders. The transfer curve is the IEC 61966-2-1 piecewise sRGB curve.
//! The film turns its exact sums into f64 means, hence the f64 conversion [`xyz_to_linear_srgb_f64`].

use core::ops::{Add, AddAssign, Div, Mul, Sub};

/// XYZ -> linear sRGB matrix (row-major), as used by Mitsuba 3.
// Digits kept exactly as published, even where f32 cannot hold them all.
#[allow(clippy::excessive_precision)]
pub const XYZ_TO_LINEAR_SRGB: [[f32; 3]; 3] =
    [[3.240479, -1.537150, -0.498535], [-0.969256, 1.875991, 0.041556], [0.055648, -0.204043, 1.057311]];

/// Linear sRGB -> XYZ matrix (row-major), the inverse of [`XYZ_TO_LINEAR_SRGB`].
pub const LINEAR_SRGB_TO_XYZ: [[f32; 3]; 3] =
    [[0.412453, 0.357580, 0.180423], [0.212671, 0.715160, 0.072169], [0.019334, 0.119193, 0.950227]];

#[inline]
fn mat_mul(m: &[[f32; 3]; 3], v: [f32; 3]) -> [f32; 3] {
    [
        m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
        m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
        m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2],
    ]
}

/// CIE 1931 XYZ tristimulus values.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Xyz {
    /// X.
    pub x: f32,
    /// Y (luminance).
    pub y: f32,
    /// Z.
    pub z: f32,
}

impl Xyz {
    /// Builds an XYZ triple.
    #[inline]
    pub fn new(x: f32, y: f32, z: f32) -> Self {
        Xyz { x, y, z }
    }

    /// Converts to linear sRGB (Rec. 709 primaries, D65 white, Mitsuba 3 matrix).
    #[inline]
    pub fn to_linear_srgb(self) -> LinearSrgb {
        let [r, g, b] = mat_mul(&XYZ_TO_LINEAR_SRGB, [self.x, self.y, self.z]);
        LinearSrgb { r, g, b }
    }

    /// Chromaticity coordinates (x, y); (0, 0) if X + Y + Z is zero.
    #[inline]
    pub fn chromaticity(self) -> (f32, f32) {
        let s = self.x + self.y + self.z;
        if s == 0.0 { (0.0, 0.0) } else { (self.x / s, self.y / s) }
    }
}

impl Add for Xyz {
    type Output = Xyz;
    #[inline]
    fn add(self, rhs: Xyz) -> Xyz {
        Xyz::new(self.x + rhs.x, self.y + rhs.y, self.z + rhs.z)
    }
}

impl AddAssign for Xyz {
    #[inline]
    fn add_assign(&mut self, rhs: Xyz) {
        self.x += rhs.x;
        self.y += rhs.y;
        self.z += rhs.z;
    }
}

impl Sub for Xyz {
    type Output = Xyz;
    #[inline]
    fn sub(self, rhs: Xyz) -> Xyz {
        Xyz::new(self.x - rhs.x, self.y - rhs.y, self.z - rhs.z)
    }
}

impl Mul<f32> for Xyz {
    type Output = Xyz;
    #[inline]
    fn mul(self, rhs: f32) -> Xyz {
        Xyz::new(self.x * rhs, self.y * rhs, self.z * rhs)
    }
}

impl Mul<Xyz> for f32 {
    type Output = Xyz;
    #[inline]
    fn mul(self, rhs: Xyz) -> Xyz {
        rhs * self
    }
}

impl Div<f32> for Xyz {
    type Output = Xyz;
    #[inline]
    fn div(self, rhs: f32) -> Xyz {
        Xyz::new(self.x / rhs, self.y / rhs, self.z / rhs)
    }
}

/// Linear-light sRGB (Rec. 709 primaries, D65 white), not gamma encoded.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct LinearSrgb {
    /// Red.
    pub r: f32,
    /// Green.
    pub g: f32,
    /// Blue.
    pub b: f32,
}

impl LinearSrgb {
    /// Builds a linear sRGB triple.
    #[inline]
    pub fn new(r: f32, g: f32, b: f32) -> Self {
        LinearSrgb { r, g, b }
    }

    /// Converts to CIE XYZ.
    #[inline]
    pub fn to_xyz(self) -> Xyz {
        let [x, y, z] = mat_mul(&LINEAR_SRGB_TO_XYZ, [self.r, self.g, self.b]);
        Xyz { x, y, z }
    }

    /// Applies the sRGB transfer curve per channel after clamping each channel to [0, 1]
    /// (NaN becomes 0).
    #[inline]
    pub fn encode(self) -> Srgb {
        let f = |v: f32| srgb_oetf(if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) });
        Srgb { r: f(self.r), g: f(self.g), b: f(self.b) }
    }

    /// Relative luminance Y (the middle row of [`LINEAR_SRGB_TO_XYZ`]).
    #[inline]
    pub fn luminance(self) -> f32 {
        LINEAR_SRGB_TO_XYZ[1][0] * self.r + LINEAR_SRGB_TO_XYZ[1][1] * self.g + LINEAR_SRGB_TO_XYZ[1][2] * self.b
    }
}

/// sRGB encoded with the IEC 61966-2-1 transfer curve (values in [0, 1] for display).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Srgb {
    /// Red.
    pub r: f32,
    /// Green.
    pub g: f32,
    /// Blue.
    pub b: f32,
}

impl Srgb {
    /// Removes the transfer curve per channel.
    #[inline]
    pub fn decode(self) -> LinearSrgb {
        LinearSrgb { r: srgb_eotf(self.r), g: srgb_eotf(self.g), b: srgb_eotf(self.b) }
    }
}

/// sRGB opto-electronic transfer function (IEC 61966-2-1): linear light -> encoded value.
/// `12.92 x` for `x <= 0.0031308`, else `1.055 x^(1/2.4) - 0.055`. Meant for [0, 1]; negative
/// inputs follow the linear segment.
#[inline]
pub fn srgb_oetf(linear: f32) -> f32 {
    if linear <= 0.003_130_8 { 12.92 * linear } else { 1.055 * linear.powf(1.0 / 2.4) - 0.055 }
}

/// Inverse of [`srgb_oetf`]: encoded value -> linear light. `x / 12.92` for `x <= 0.04045`,
/// else `((x + 0.055) / 1.055)^2.4`.
#[inline]
pub fn srgb_eotf(encoded: f32) -> f32 {
    if encoded <= 0.040_45 { encoded / 12.92 } else { ((encoded + 0.055) / 1.055).powf(2.4) }
}

/// XYZ -> linear sRGB in f64 (same matrix as [`Xyz::to_linear_srgb`]), for the film, whose
/// per-pixel means are f64.
#[inline]
pub fn xyz_to_linear_srgb_f64(xyz: [f64; 3]) -> [f64; 3] {
    let m = &XYZ_TO_LINEAR_SRGB;
    let mut out = [0.0f64; 3];
    for (o, row) in out.iter_mut().zip(m.iter()) {
        *o = row[0] as f64 * xyz[0] + row[1] as f64 * xyz[1] + row[2] as f64 * xyz[2];
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matrices_are_inverse() {
        // Both matrices are published to 6 decimals, so their product is identity to ~1e-5.
        for i in 0..3 {
            let mut e = [0.0f32; 3];
            e[i] = 1.0;
            let x = LinearSrgb::new(e[0], e[1], e[2]).to_xyz().to_linear_srgb();
            let got = [x.r, x.g, x.b];
            for j in 0..3 {
                assert!((got[j] - e[j]).abs() < 2e-5, "{i} {j} {got:?}");
            }
        }
    }

    #[test]
    fn srgb_white_is_d65() {
        // Linear sRGB white must map to the D65 white point xy = (0.3127, 0.3290) (IEC 61966-2-1).
        let (x, y) = LinearSrgb::new(1.0, 1.0, 1.0).to_xyz().chromaticity();
        assert!((x - 0.3127).abs() < 1e-4 && (y - 0.3290).abs() < 1e-4, "{x} {y}");
        assert!((LinearSrgb::new(1.0, 1.0, 1.0).luminance() - 1.0).abs() < 1e-6);
    }

    #[test]
    fn transfer_known_points() {
        assert_eq!(srgb_oetf(0.0), 0.0);
        assert!((srgb_oetf(1.0) - 1.0).abs() < 1e-6);
        assert_eq!(srgb_eotf(0.0), 0.0);
        assert!((srgb_eotf(1.0) - 1.0).abs() < 1e-6);
        // 1.055 * 0.5^(1/2.4) - 0.055 = 0.735357 (computed by hand / any calculator).
        assert!((srgb_oetf(0.5) - 0.7354).abs() < 1e-4, "{}", srgb_oetf(0.5));
        // The two segments meet at 0.0031308 to ~1e-8 (the standard's constants are rounded).
        let below = 12.92 * 0.003_130_8f32;
        let above = 1.055 * 0.003_130_8f32.powf(1.0 / 2.4) - 0.055;
        assert!((below - above).abs() < 1e-6, "{below} {above}");
        assert!((srgb_oetf(0.003_130_8) - srgb_oetf(0.003_130_81)).abs() < 1e-6);
    }

    #[test]
    fn transfer_round_trip() {
        for k in 0..=1000 {
            let v = k as f32 / 1000.0;
            let back = srgb_eotf(srgb_oetf(v));
            // f32 powf round trip: a few ulps relative, plus an absolute floor near 0.
            assert!((back - v).abs() <= 1e-6 + 1e-5 * v, "{v} -> {back}");
            let enc = srgb_oetf(srgb_eotf(v));
            assert!((enc - v).abs() <= 1e-6 + 1e-5 * v, "{v} -> {enc}");
        }
    }

    #[test]
    fn encode_clamps_and_decode_inverts() {
        let s = LinearSrgb::new(-0.5, 2.0, f32::NAN).encode();
        assert_eq!(s, Srgb { r: 0.0, g: srgb_oetf(1.0), b: 0.0 });
        let l = LinearSrgb::new(0.2, 0.5, 0.9);
        let d = l.encode().decode();
        assert!((d.r - 0.2).abs() < 1e-5 && (d.g - 0.5).abs() < 1e-5 && (d.b - 0.9).abs() < 1e-5);
    }

    #[test]
    fn f64_matches_f32() {
        let xyz = Xyz::new(0.3, 0.6, 0.1);
        let a = xyz.to_linear_srgb();
        let b = xyz_to_linear_srgb_f64([0.3, 0.6, 0.1]);
        assert!((a.r as f64 - b[0]).abs() < 1e-6);
        assert!((a.g as f64 - b[1]).abs() < 1e-6);
        assert!((a.b as f64 - b[2]).abs() < 1e-6);
    }

    #[test]
    fn xyz_ops() {
        let mut a = Xyz::new(1.0, 2.0, 3.0);
        a += Xyz::new(1.0, 1.0, 1.0);
        assert_eq!(a * 2.0, Xyz::new(4.0, 6.0, 8.0));
        assert_eq!(a + a, 2.0 * a);
        assert_eq!(a - a, Xyz::default());
        assert_eq!(a / 2.0, Xyz::new(1.0, 1.5, 2.0));
    }
}
