//! Sampling: the deterministic per-sample random number source
//! ([`Sampler`]) and the warps from uniform numbers to directions and points
//! ([`warp`]).
//!
//! Every camera sample draws its random numbers from a PCG32 stream keyed by
//! `(seed, pixel, pass)`: the stream's state and increment are hashes of
//! those three numbers. A sample's numbers therefore do not depend on which
//! thread rendered it, on the tile order, or on how many passes ran before in
//! this process; that is what makes renders bit-identical across thread
//! counts, and resume and merge exact. Dimensions are consumed in the fixed
//! order the integrator asks for them.

pub mod warp;

use glam::Vec2;
use rand::Rng;
use rand_pcg::Pcg32;

/// A stream of uniform numbers in [0, 1) for one camera sample.
pub struct Sampler {
    rng: Pcg32,
}

/// SplitMix64's finaliser: a bijective 64-bit mix (Steele et al. 2014).
#[inline]
fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

impl Sampler {
    /// The stream of sample `pass` of pixel `pixel` (row-major index) for `seed`.
    #[inline]
    pub fn new(seed: u64, pixel: u64, pass: u64) -> Self {
        let a = mix64(seed ^ 0x9e37_79b9_7f4a_7c15);
        let b = mix64(a ^ pixel.wrapping_mul(0xd1b5_4a32_d192_ed03));
        let state = mix64(b ^ pass.wrapping_mul(0x8cb9_2ba7_2f3d_8dd7));
        let stream = mix64(state ^ 0x5851_f42d_4c95_7f2d);
        Sampler { rng: Pcg32::new(state, stream) }
    }

    /// One uniform number in [0, 1) (24 random bits, so exactly representable and < 1).
    #[inline]
    pub fn next_1d(&mut self) -> f32 {
        (self.rng.next_u32() >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
    }

    /// Two uniform numbers in [0, 1)².
    #[inline]
    pub fn next_2d(&mut self) -> Vec2 {
        let x = self.next_1d();
        Vec2::new(x, self.next_1d())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_key_same_numbers_different_key_different_numbers() {
        let draw = |s: u64, p: u64, q: u64| {
            let mut r = Sampler::new(s, p, q);
            (0..8).map(|_| r.next_1d()).collect::<Vec<_>>()
        };
        assert_eq!(draw(1, 2, 3), draw(1, 2, 3));
        assert_ne!(draw(1, 2, 3), draw(1, 2, 4));
        assert_ne!(draw(1, 2, 3), draw(1, 3, 3));
        assert_ne!(draw(1, 2, 3), draw(2, 2, 3));
    }

    /// Mean and variance of U[0,1) over 200k draws spread over many streams:
    /// mean 1/2 with standard error sqrt(1/12/2e5) = 6.5e-4, so 4e-3 is > 6 sigma.
    #[test]
    fn numbers_are_uniform() {
        let (mut sum, mut sum2, mut n) = (0.0f64, 0.0f64, 0usize);
        for p in 0..2000 {
            let mut r = Sampler::new(7, p, 0);
            for _ in 0..100 {
                let x = r.next_1d() as f64;
                assert!((0.0..1.0).contains(&x));
                sum += x;
                sum2 += x * x;
                n += 1;
            }
        }
        let mean = sum / n as f64;
        let var = sum2 / n as f64 - mean * mean;
        assert!((mean - 0.5).abs() < 4e-3, "mean {mean}");
        assert!((var - 1.0 / 12.0).abs() < 4e-3, "variance {var}");
    }
}
