//! The 36-bin spectral quantity used throughout the renderer.
//!
//! Every radiometric quantity (radiance, reflectance, throughput, emission) is carried as a
//! [`Spectrum`]: 36 samples at the centres of 10 nm bins from 380 nm to 730 nm. Fixed-size,
//! 32-byte-aligned arrays and plain loops let LLVM auto-vectorise the arithmetic, so the
//! operators below are deliberately written as simple element-wise loops.

use core::ops::{Add, AddAssign, Div, DivAssign, Index, IndexMut, Mul, MulAssign, Sub, SubAssign};

use super::cie::CMF_NORMALISED;
use super::rgb::Xyz;

/// Number of spectral bins: 380..=730 nm at 10 nm.
pub const N_BINS: usize = 36;
/// Centre wavelength of the first bin, in nm.
pub const LAMBDA_MIN_NM: f32 = 380.0;
/// Spacing between bin centres (and width of each bin), in nm.
pub const LAMBDA_STEP_NM: f32 = 10.0;

/// Centre wavelength of bin i in nm (380 + 10 i).
#[inline]
pub fn bin_lambda_nm(i: usize) -> f32 {
    LAMBDA_MIN_NM + LAMBDA_STEP_NM * i as f32
}

/// A spectral quantity sampled at the [`N_BINS`] bin centres (see [`bin_lambda_nm`]).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct Spectrum(pub [f32; N_BINS]);

impl Default for Spectrum {
    /// The zero spectrum.
    #[inline]
    fn default() -> Self {
        Spectrum::ZERO
    }
}

impl Spectrum {
    /// Zero in every bin.
    pub const ZERO: Spectrum = Spectrum::splat(0.0);
    /// One in every bin.
    pub const ONE: Spectrum = Spectrum::splat(1.0);

    /// The same value `v` in every bin.
    #[inline]
    pub const fn splat(v: f32) -> Spectrum {
        Spectrum([v; N_BINS])
    }

    /// Builds a spectrum from a function of the bin index.
    #[inline]
    pub fn from_fn(f: impl FnMut(usize) -> f32) -> Spectrum {
        Spectrum(core::array::from_fn(f))
    }

    /// Largest bin value.
    #[inline]
    pub fn max_value(&self) -> f32 {
        self.0.iter().copied().fold(f32::NEG_INFINITY, f32::max)
    }

    /// Smallest bin value.
    #[inline]
    pub fn min_value(&self) -> f32 {
        self.0.iter().copied().fold(f32::INFINITY, f32::min)
    }

    /// Arithmetic mean of the bins.
    #[inline]
    pub fn average(&self) -> f32 {
        self.0.iter().sum::<f32>() / N_BINS as f32
    }

    /// True if every bin is exactly zero.
    #[inline]
    pub fn is_black(&self) -> bool {
        self.0.iter().all(|&v| v == 0.0)
    }

    /// True if any bin is NaN or infinite.
    #[inline]
    pub fn has_nan_or_inf(&self) -> bool {
        self.0.iter().any(|v| !v.is_finite())
    }

    /// CIE XYZ of this spectrum: `sum_i self[i] * CMF_NORMALISED[i]`.
    ///
    /// With this normalisation the equal-energy spectrum of value 1 has Y = 1 (see
    /// [`crate::color::cie`]).
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

    /// Element-wise square root.
    #[inline]
    pub fn sqrt(&self) -> Spectrum {
        let mut out = *self;
        for v in out.0.iter_mut() {
            *v = v.sqrt();
        }
        out
    }

    /// Element-wise exponential (e.g. Beer-Lambert transmittance from `-sigma_t * d`).
    #[inline]
    pub fn exp(&self) -> Spectrum {
        let mut out = *self;
        for v in out.0.iter_mut() {
            *v = v.exp();
        }
        out
    }

    /// Element-wise `max(v, 0)`; NaN bins become 0.
    #[inline]
    pub fn clamp_zero(&self) -> Spectrum {
        let mut out = *self;
        for v in out.0.iter_mut() {
            *v = v.max(0.0);
        }
        out
    }
}

impl Add for Spectrum {
    type Output = Spectrum;
    #[inline]
    fn add(mut self, rhs: Spectrum) -> Spectrum {
        self += rhs;
        self
    }
}

impl AddAssign for Spectrum {
    #[inline]
    fn add_assign(&mut self, rhs: Spectrum) {
        for i in 0..N_BINS {
            self.0[i] += rhs.0[i];
        }
    }
}

impl Sub for Spectrum {
    type Output = Spectrum;
    #[inline]
    fn sub(mut self, rhs: Spectrum) -> Spectrum {
        self -= rhs;
        self
    }
}

impl SubAssign for Spectrum {
    #[inline]
    fn sub_assign(&mut self, rhs: Spectrum) {
        for i in 0..N_BINS {
            self.0[i] -= rhs.0[i];
        }
    }
}

impl Mul for Spectrum {
    type Output = Spectrum;
    #[inline]
    fn mul(mut self, rhs: Spectrum) -> Spectrum {
        self *= rhs;
        self
    }
}

impl MulAssign for Spectrum {
    #[inline]
    fn mul_assign(&mut self, rhs: Spectrum) {
        for i in 0..N_BINS {
            self.0[i] *= rhs.0[i];
        }
    }
}

impl Mul<f32> for Spectrum {
    type Output = Spectrum;
    #[inline]
    fn mul(mut self, rhs: f32) -> Spectrum {
        self *= rhs;
        self
    }
}

impl Mul<Spectrum> for f32 {
    type Output = Spectrum;
    #[inline]
    fn mul(self, rhs: Spectrum) -> Spectrum {
        rhs * self
    }
}

impl MulAssign<f32> for Spectrum {
    #[inline]
    fn mul_assign(&mut self, rhs: f32) {
        for i in 0..N_BINS {
            self.0[i] *= rhs;
        }
    }
}

impl Div<f32> for Spectrum {
    type Output = Spectrum;
    #[inline]
    fn div(mut self, rhs: f32) -> Spectrum {
        self /= rhs;
        self
    }
}

impl DivAssign<f32> for Spectrum {
    #[inline]
    fn div_assign(&mut self, rhs: f32) {
        for i in 0..N_BINS {
            self.0[i] /= rhs;
        }
    }
}

impl Div for Spectrum {
    type Output = Spectrum;
    /// Element-wise IEEE division (0/0 gives NaN).
    #[inline]
    fn div(mut self, rhs: Spectrum) -> Spectrum {
        for i in 0..N_BINS {
            self.0[i] /= rhs.0[i];
        }
        self
    }
}

impl Index<usize> for Spectrum {
    type Output = f32;
    #[inline]
    fn index(&self, i: usize) -> &f32 {
        &self.0[i]
    }
}

impl IndexMut<usize> for Spectrum {
    #[inline]
    fn index_mut(&mut self, i: usize) -> &mut f32 {
        &mut self.0[i]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp() -> Spectrum {
        Spectrum::from_fn(|i| i as f32 + 1.0)
    }

    #[test]
    fn bin_centres() {
        assert_eq!(bin_lambda_nm(0), 380.0);
        assert_eq!(bin_lambda_nm(17), 550.0);
        assert_eq!(bin_lambda_nm(N_BINS - 1), 730.0);
    }

    #[test]
    fn alignment_is_32() {
        assert_eq!(core::mem::align_of::<Spectrum>(), 32);
        // 144 bytes of data padded up to a multiple of the 32-byte alignment.
        assert_eq!(core::mem::size_of::<Spectrum>(), 160);
    }

    #[test]
    fn element_wise_operators() {
        let a = ramp();
        let b = Spectrum::splat(2.0);
        // Exact: all values are small integers or halves, representable in f32.
        for i in 0..N_BINS {
            let v = i as f32 + 1.0;
            assert_eq!((a + b)[i], v + 2.0);
            assert_eq!((a - b)[i], v - 2.0);
            assert_eq!((a * b)[i], v * 2.0);
            assert_eq!((a / b)[i], v / 2.0);
            assert_eq!((a * 3.0)[i], v * 3.0);
            assert_eq!((3.0 * a)[i], v * 3.0);
            assert_eq!((a / 4.0)[i], v / 4.0);
            assert_eq!((a * a)[i], v * v);
        }
        let mut c = a;
        c += b;
        c -= Spectrum::ONE;
        c *= b;
        c *= 0.5;
        c /= 1.0;
        c[0] = -7.0;
        assert_eq!(c[0], -7.0);
        assert_eq!(c[1], 2.0 + 2.0 - 1.0);
    }

    #[test]
    fn reductions_and_predicates() {
        let a = ramp();
        assert_eq!(a.max_value(), N_BINS as f32);
        assert_eq!(a.min_value(), 1.0);
        // Mean of 1..=36 is 18.5.
        assert_eq!(a.average(), 18.5);
        assert!(Spectrum::ZERO.is_black());
        assert!(!a.is_black());
        assert!(!a.has_nan_or_inf());
        let mut n = a;
        n[5] = f32::NAN;
        assert!(n.has_nan_or_inf());
        n[5] = f32::INFINITY;
        assert!(n.has_nan_or_inf());
        assert!((Spectrum::ZERO / Spectrum::ZERO)[0].is_nan());
    }

    #[test]
    fn unary_functions() {
        let a = Spectrum::from_fn(|i| (i * i) as f32);
        assert_eq!(a.sqrt()[7], 7.0);
        assert_eq!(Spectrum::ZERO.exp(), Spectrum::ONE);
        assert!((Spectrum::ONE.exp()[3] - core::f32::consts::E).abs() < 1e-6);
        let mut m = Spectrum::splat(-1.0);
        m[2] = 3.0;
        m[4] = f32::NAN;
        let c = m.clamp_zero();
        assert_eq!(c[0], 0.0);
        assert_eq!(c[2], 3.0);
        assert_eq!(c[4], 0.0);
    }
}
