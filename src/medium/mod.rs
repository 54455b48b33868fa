//! Media: what fills a volume, as pbrt-v4 and Mitsuba 3 mean the word, and the
//! stack of nested dielectric volumes a path is inside ([`nested`]).
//!
//! # Data flow
//! A dielectric object's inside is a *volume* ([`Volume`]); a path records the
//! volumes it is inside on a [`VolumeStack`], whose current entry decides the
//! relative index at the next dielectric surface and which medium a segment
//! runs in. The scene keeps one [`Medium`] per material whose volume is not
//! clear (today: a dielectric with `absorption:`), and answers
//! [`Scene::medium_in`](crate::scene::Scene::medium_in) for the current
//! volume. Every integrator attenuates a segment through
//! [`Medium::transmittance`], and a shadow ray or BDPT connection through
//! [`Scene::transmittance`](crate::scene::Scene::transmittance): Beer-Lambert
//! is written once, here.
//!
//! Today a medium absorbs and does not scatter (σs = 0), so a segment's
//! transmittance is exact per wavelength and no distance is sampled: every
//! path reaches the next surface. A scattering medium adds its variant here,
//! with its own `transmittance` and a distance sampler (the sampler's layout
//! reserves per-bounce dimensions for a distance and a phase draw: see
//! `crate::sampler`).

pub mod nested;

pub use nested::{Crossing, VOLUME_STACK_DEPTH, Volume, VolumeStack};

use crate::color::{Sampled, Spectrum};
use crate::spectral::Lambdas;

/// A homogeneous medium that absorbs: `σa(λ)` per scene unit, no scattering.
#[derive(Clone, Debug, PartialEq)]
pub struct Medium {
    sigma_a: Spectrum,
}

impl Medium {
    /// An absorbing medium of coefficient `sigma_a` (per scene unit, per bin).
    pub fn absorbing(sigma_a: Spectrum) -> Medium {
        Medium { sigma_a }
    }

    /// The absorption coefficient.
    #[inline]
    pub fn sigma_a(&self) -> &Spectrum {
        &self.sigma_a
    }

    /// The transmittance `exp(−σa(λ) d)` of a segment of length `d`, at the
    /// packet's wavelengths (σa interpolated at each, then exponentiated).
    #[inline]
    pub fn transmittance<const N: usize>(&self, d: f32, lambdas: &Lambdas<N>) -> Sampled<N> {
        (lambdas.sample(&self.sigma_a) * -d).exp()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::color::N_BINS;

    /// Beer-Lambert per bin against `exp` written out, for the full spectrum and
    /// for one wavelength between two bins (interpolated coefficient).
    #[test]
    fn transmittance_is_beer_lambert_per_wavelength() {
        let sigma = Sampled(std::array::from_fn(|b| 0.1 + b as f32 * 0.05));
        let m = Medium::absorbing(sigma);
        let t = m.transmittance(2.0, &Lambdas::full());
        for b in 0..N_BINS {
            assert_eq!(t[b], (-(0.1 + b as f32 * 0.05) * 2.0f32).exp());
        }
        let mut one = Lambdas::full().single(3);
        one.pos = [3.5];
        let s = (0.1 + 3.0 * 0.05 + 0.1 + 4.0 * 0.05) / 2.0;
        assert!((m.transmittance(2.0, &one)[0] - (-s * 2.0f32).exp()).abs() < 1e-6);
        assert_eq!(m.transmittance(0.0, &Lambdas::full()), Sampled::splat(1.0));
    }
}
