//! Spectral values and their arithmetic, written once for every packet size.
//!
//! [`Sampled<N>`] holds one value per wavelength of a packet of `N`
//! wavelengths; [`Spectrum`] is the 36-bin case, `Sampled<36>`: samples at
//! the centres of 10 nm bins from 380 nm to 730 nm ([`bin_lambda_nm`]).
//! Every radiometric quantity (radiance, reflectance, throughput, emission)
//! is one of these. Fixed-size arrays and plain element-wise loops let LLVM
//! vectorise the arithmetic, so the operators are deliberately simple loops.
//!
//! # Vectorisation
//! With the baseline x86-64 target (SSE2) the element-wise operators compile
//! to packed instructions, nine `mulps`/`addps` for 36 bins, with no help. The
//! reductions do not: a fold is one chain of dependent scalar operations, and
//! an `any`/`all` with an early exit is 36 compares and branches. The
//! reductions that always read every bin ([`Sampled::max_value`],
//! [`Sampled::min_value`], [`Sampled::has_nan_or_inf`]) are therefore written
//! as [`LANES`] independent partial results combined at the end, without early
//! exits. [`Sampled::is_black`] keeps its early exit: a spectrum that is not
//! black almost always says so in its first bin. Their results are exactly those of the
//! sequential folds (a maximum, a minimum or a flag does not depend on the
//! order it is taken in), so no image changes. [`Sampled::average`] stays a
//! sequential sum: a different summation order changes its last bits, it runs
//! only when a scene is loaded (light powers), and keeping it keeps every
//! image bit-identical. Measurements: `docs/performance.md`, "Spectral arithmetic".
//! Which wavelengths a packet holds is [`crate::spectral`]'s business; the
//! colour integral of a spectrum is [`super::cie`]'s.

use core::ops::{Add, AddAssign, Div, DivAssign, Index, IndexMut, Mul, MulAssign, Sub, SubAssign};

/// Number of spectral bins: 380..=730 nm at 10 nm.
pub const N_BINS: usize = 36;
/// Centre wavelength of the first bin, in nm.
pub const LAMBDA_MIN_NM: f32 = 380.0;
/// Spacing between bin centres (and width of each bin), in nm.
pub const LAMBDA_STEP_NM: f32 = 10.0;

/// Partial results a reduction keeps side by side: one SSE register of f32.
const LANES: usize = 4;

/// `f` folded over `v` in [`LANES`] interleaved partial results (lane `j` takes
/// elements `j, j + LANES, ...`), then over the remainder and the partials.
/// Equal to a sequential fold for any associative, commutative `f` (max, min,
/// or); the lanes are independent, so LLVM keeps them in one vector register.
#[inline(always)]
fn fold_lanes<T: Copy>(v: &[f32], init: T, f: impl Fn(T, f32) -> T, combine: impl Fn(T, T) -> T) -> T {
    let mut acc = [init; LANES];
    let mut chunks = v.chunks_exact(LANES);
    for c in &mut chunks {
        for j in 0..LANES {
            acc[j] = f(acc[j], c[j]);
        }
    }
    let tail = chunks.remainder().iter().fold(init, |a, &x| f(a, x));
    acc.into_iter().fold(tail, combine)
}

/// Centre wavelength of bin i in nm (380 + 10 i).
#[inline]
pub fn bin_lambda_nm(i: usize) -> f32 {
    LAMBDA_MIN_NM + LAMBDA_STEP_NM * i as f32
}

/// Per-wavelength values of a packet of `N` wavelengths.
///
/// Aligned to 32 bytes, so that the 36-bin loops' vector loads and stores do
/// not straddle cache lines: 3% of the render time of the Cornell box and
/// glass-spheres (15 alternated runs each), for 16 bytes of padding per spectrum.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(align(32))]
pub struct Sampled<const N: usize>(pub [f32; N]);

/// A spectral quantity sampled at the [`N_BINS`] bin centres (see [`bin_lambda_nm`]).
pub type Spectrum = Sampled<N_BINS>;

impl<const N: usize> Default for Sampled<N> {
    /// Zero everywhere.
    #[inline]
    fn default() -> Self {
        Self::ZERO
    }
}

impl<const N: usize> Sampled<N> {
    /// Zero at every wavelength.
    pub const ZERO: Self = Self::splat(0.0);
    /// One at every wavelength.
    pub const ONE: Self = Self::splat(1.0);

    /// Every value equal to `v`.
    #[inline]
    pub const fn splat(v: f32) -> Self {
        Sampled([v; N])
    }

    /// Values from a function of the index.
    #[inline]
    pub fn from_fn(f: impl FnMut(usize) -> f32) -> Self {
        Sampled(core::array::from_fn(f))
    }

    /// The largest value, ignoring NaNs (`-inf` when every value is NaN, or `N = 0`).
    #[inline]
    pub fn max_value(&self) -> f32 {
        fold_lanes(&self.0, f32::NEG_INFINITY, f32::max, f32::max)
    }

    /// The smallest value, ignoring NaNs (`inf` when every value is NaN, or `N = 0`).
    #[inline]
    pub fn min_value(&self) -> f32 {
        fold_lanes(&self.0, f32::INFINITY, f32::min, f32::min)
    }

    /// Arithmetic mean of the values (a sequential sum: see the module doc).
    #[inline]
    pub fn average(&self) -> f32 {
        self.0.iter().sum::<f32>() / N as f32
    }

    /// True when every value is exactly zero. It stops at the first value that
    /// is not: a spectrum that is not black almost always shows it in its first
    /// bin, so this beats a branch-free scan of all bins (which cost 3% more
    /// instructions in a BDPT render).
    #[inline]
    pub fn is_black(&self) -> bool {
        self.0.iter().all(|&v| v == 0.0)
    }

    /// True when any value is NaN or infinite (exponent bits all set).
    /// Branch-free, so it vectorises.
    #[inline]
    pub fn has_nan_or_inf(&self) -> bool {
        self.0.iter().fold(false, |a, v| a | !v.is_finite())
    }

    /// Element-wise `f`.
    #[inline]
    pub fn map(mut self, f: impl Fn(f32) -> f32) -> Self {
        for v in self.0.iter_mut() {
            *v = f(*v);
        }
        self
    }

    /// Element-wise square root.
    #[inline]
    pub fn sqrt(&self) -> Self {
        self.map(f32::sqrt)
    }

    /// Element-wise exponential (e.g. Beer-Lambert transmittance from `-sigma_t * d`).
    #[inline]
    pub fn exp(&self) -> Self {
        self.map(f32::exp)
    }

    /// Element-wise `max(v, 0)`; NaN values become 0.
    #[inline]
    pub fn clamp_zero(&self) -> Self {
        self.map(|v| v.max(0.0))
    }
}

impl Spectrum {
    /// The spectrum of a table of `(nm, value)` points (wavelengths increasing), linear between
    /// the points and flat beyond the first and last, sampled at the 36 bin centres. Features
    /// narrower than the 10 nm bins are sampled, not averaged. An empty table is zero.
    pub fn from_table(points: &[(f32, f32)]) -> Self {
        Spectrum::from_fn(|b| {
            let l = bin_lambda_nm(b);
            let k = points.partition_point(|p| p.0 <= l);
            match (k, points.get(k)) {
                (_, None) => points.last().map_or(0.0, |p| p.1),
                (0, Some(p)) => p.1,
                (k, Some(&(l1, v1))) => {
                    let (l0, v0) = points[k - 1];
                    let f = (l - l0) / (l1 - l0);
                    v0 + (v1 - v0) * f
                }
            }
        })
    }
}

/// Element-wise binary operators, each with its assigning form.
macro_rules! element_wise {
    ($($op:ident $method:ident $assign:ident $assign_method:ident $sym:tt;)+) => {$(
        impl<const N: usize> $op for Sampled<N> {
            type Output = Self;
            #[inline]
            fn $method(mut self, rhs: Self) -> Self {
                self.$assign_method(rhs);
                self
            }
        }

        impl<const N: usize> $assign for Sampled<N> {
            #[inline]
            fn $assign_method(&mut self, rhs: Self) {
                for i in 0..N {
                    self.0[i] $sym rhs.0[i];
                }
            }
        }
    )+};
}

element_wise! {
    Add add AddAssign add_assign +=;
    Sub sub SubAssign sub_assign -=;
    Mul mul MulAssign mul_assign *=;
    Div div DivAssign div_assign /=;
}

impl<const N: usize> Mul<f32> for Sampled<N> {
    type Output = Self;
    #[inline]
    fn mul(mut self, s: f32) -> Self {
        self *= s;
        self
    }
}

impl<const N: usize> Mul<Sampled<N>> for f32 {
    type Output = Sampled<N>;
    #[inline]
    fn mul(self, rhs: Sampled<N>) -> Sampled<N> {
        rhs * self
    }
}

impl<const N: usize> MulAssign<f32> for Sampled<N> {
    #[inline]
    fn mul_assign(&mut self, s: f32) {
        for v in &mut self.0 {
            *v *= s;
        }
    }
}

/// Division by a scalar multiplies by its reciprocal (one division, then
/// `N` multiplications).
impl<const N: usize> Div<f32> for Sampled<N> {
    type Output = Self;
    #[inline]
    fn div(self, s: f32) -> Self {
        self * (1.0 / s)
    }
}

impl<const N: usize> DivAssign<f32> for Sampled<N> {
    #[inline]
    fn div_assign(&mut self, s: f32) {
        *self *= 1.0 / s;
    }
}

impl<const N: usize> Index<usize> for Sampled<N> {
    type Output = f32;
    #[inline]
    fn index(&self, i: usize) -> &f32 {
        &self.0[i]
    }
}

impl<const N: usize> IndexMut<usize> for Sampled<N> {
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
    fn table_is_linear_between_points_and_flat_beyond() {
        let s = Spectrum::from_table(&[(400.0, 0.1), (550.0, 0.8), (700.0, 0.3)]);
        assert_eq!(s[0], 0.1); // 380 nm: flat before 400
        assert_eq!(s[2], 0.1); // 400 nm
        assert!((s[9] - (0.1 + 0.7 * 70.0 / 150.0)).abs() < 1e-6); // 470 nm
        assert_eq!(s[17], 0.8); // 550 nm
        assert!((s[26] - (0.8 - 0.5 * 90.0 / 150.0)).abs() < 1e-6); // 640 nm
        assert_eq!(s[35], 0.3); // 730 nm: flat after 700
        // Points exactly at the bin centres give the samples back.
        let v = Spectrum::from_fn(|i| (i as f32 * 0.3).sin().abs());
        let pts: Vec<(f32, f32)> = (0..N_BINS).map(|i| (bin_lambda_nm(i), v[i])).collect();
        assert_eq!(Spectrum::from_table(&pts), v);
        assert_eq!(Spectrum::from_table(&[]), Spectrum::ZERO);
        assert_eq!(Spectrum::from_table(&[(555.0, 2.0)]), Spectrum::splat(2.0));
    }

    #[test]
    fn bin_centres() {
        assert_eq!(bin_lambda_nm(0), 380.0);
        assert_eq!(bin_lambda_nm(17), 550.0);
        assert_eq!(bin_lambda_nm(N_BINS - 1), 730.0);
    }

    #[test]
    fn a_spectrum_is_36_floats() {
        // 36 floats (144 bytes) padded to the 32-byte alignment; a packet of 4, one register's worth.
        assert_eq!(core::mem::size_of::<[f32; N_BINS]>(), 144);
        assert_eq!(core::mem::size_of::<Spectrum>(), 160);
        assert_eq!(core::mem::align_of::<Spectrum>(), 32);
        assert_eq!(core::mem::size_of::<Sampled<4>>(), 32);
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

    /// The lane-parallel reductions against the sequential definitions, for packet sizes with and
    /// without a remainder, on values that include NaN, infinities, signed zeros and subnormals
    /// at every position (exact equality: a maximum, minimum or flag has one right answer).
    #[test]
    fn lane_reductions_equal_sequential_folds() {
        fn check<const N: usize>() {
            let special = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -0.0, 0.0, 1e-45, -3.5, 2.0];
            let mut state = 0x9e37_79b9_u32;
            let mut next = || {
                state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                state
            };
            for case in 0..2000 {
                let s = Sampled::<N>::from_fn(|_| {
                    let r = next();
                    match (case % 4, r % 7) {
                        (0, _) => 0.0,
                        (1, 0) => special[(r >> 8) as usize % special.len()],
                        (2, _) if r % 3 == 0 => f32::NAN,
                        _ => ((r >> 8) as f32 / (1 << 24) as f32 - 0.3) * 10.0,
                    }
                });
                let max = s.0.iter().copied().fold(f32::NEG_INFINITY, f32::max);
                let min = s.0.iter().copied().fold(f32::INFINITY, f32::min);
                let (got_max, got_min) = (s.max_value(), s.min_value());
                assert!(got_max == max || (got_max.is_nan() && max.is_nan()), "{N} {s:?}");
                assert!(got_min == min || (got_min.is_nan() && min.is_nan()), "{N} {s:?}");
                assert_eq!(s.is_black(), s.0.iter().all(|&v| v == 0.0), "{N} {s:?}");
                assert_eq!(s.has_nan_or_inf(), s.0.iter().any(|v| !v.is_finite()), "{N} {s:?}");
            }
        }
        check::<1>();
        check::<3>();
        check::<4>();
        check::<8>();
        check::<N_BINS>();
        assert!(Sampled::<N_BINS>::splat(-0.0).is_black());
        assert_eq!(Sampled::<N_BINS>::splat(f32::NAN).max_value(), f32::NEG_INFINITY);
        assert_eq!(Sampled::<0>::ZERO.max_value(), f32::NEG_INFINITY);
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
