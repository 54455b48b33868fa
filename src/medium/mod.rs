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
//! A medium that only absorbs (σs = 0: a dielectric's `absorption:`) attenuates
//! a segment exactly per wavelength and no distance is sampled: every path
//! reaches the next surface. A scattering medium (`media:` in the scene file,
//! an object's `interior:`) is homogeneous: `σa(λ)`, `σs(λ)` and a
//! Henyey-Greenstein phase function ([`phase`]); a path samples where it
//! scatters with [`Medium::sample_distance`] (spectral MIS over its
//! wavelengths) from the sampler's per-bounce distance slot, and a scattering
//! vertex takes its light sample as a surface does (transmittance of the
//! shadow ray `exp(−σt d)`, exact per wavelength) and its next direction from
//! the phase function (the BSDF slot).

pub mod nested;
pub mod phase;

pub use nested::{Crossing, VOLUME_STACK_DEPTH, Volume, VolumeStack};
pub use phase::HenyeyGreenstein;

use crate::color::{Sampled, Spectrum};
use crate::error::Result;
use crate::scene::check::Check;
use crate::scene::desc::{MediumDesc, PhaseDesc};
use crate::spectral::Lambdas;

/// The medium of a description at `field` (`media."milk"`): coefficients
/// non-negative and finite, `g` within ±[`phase::MAX_G`].
pub(crate) fn from_desc(check: &Check, field: &str, d: &MediumDesc) -> Result<Medium> {
    let MediumDesc::Homogeneous { sigma_a, sigma_s, phase } = d;
    let sigma_a = check.spectrum(&format!("{field}.sigma_a"), sigma_a)?;
    let sigma_s = check.spectrum(&format!("{field}.sigma_s"), sigma_s)?;
    for (name, s) in [("sigma_a", &sigma_a), ("sigma_s", &sigma_s)] {
        if s.has_nan_or_inf() || s.min_value() < 0.0 || s.max_value() > 1e15 {
            return Err(check.err(
                format!("{field}.{name}"),
                "expected a finite, non-negative coefficient per scene unit (at most 1e15)",
            ));
        }
    }
    let g = match phase {
        PhaseDesc::Isotropic => 0.0,
        PhaseDesc::HenyeyGreenstein { g } => {
            if !(g.is_finite() && g.abs() <= phase::MAX_G) {
                return Err(check.err(
                    format!("{field}.phase.g"),
                    format!("expected a mean cosine in [-{0}, {0}], found {g}", phase::MAX_G),
                ));
            }
            *g
        }
    };
    Ok(Medium::new(sigma_a, sigma_s, HenyeyGreenstein { g }))
}

/// A homogeneous medium: absorption `σa(λ)` and scattering `σs(λ)` per scene
/// unit, and a Henyey-Greenstein phase function.
#[derive(Clone, Debug, PartialEq)]
pub struct Medium {
    sigma_a: Spectrum,
    sigma_s: Spectrum,
    /// `σt = σa + σs`.
    sigma_t: Spectrum,
    phase: HenyeyGreenstein,
    scatters: bool,
}

/// Where a path's segment through a scattering medium ends ([`Medium::sample_distance`]).
#[derive(Clone, Copy, Debug)]
pub struct DistanceSample<const N: usize> {
    /// The distance travelled.
    pub t: f32,
    /// The factor on the path's throughput, per wavelength of the packet.
    pub weight: Sampled<N>,
    /// True when the path scatters in the medium at `t`; false when it reaches
    /// the end of the segment (the surface).
    pub scattered: bool,
}

impl Medium {
    /// An absorbing medium of coefficient `sigma_a` (per scene unit, per bin).
    pub fn absorbing(sigma_a: Spectrum) -> Medium {
        Medium::new(sigma_a, Spectrum::ZERO, HenyeyGreenstein { g: 0.0 })
    }

    /// A medium that absorbs `sigma_a`, scatters `sigma_s` (both per scene
    /// unit, per bin) with phase function `phase`.
    pub fn new(sigma_a: Spectrum, sigma_s: Spectrum, phase: HenyeyGreenstein) -> Medium {
        Medium { sigma_t: sigma_a + sigma_s, sigma_a, sigma_s, phase, scatters: !sigma_s.is_black() }
    }

    /// The absorption coefficient.
    #[inline]
    pub fn sigma_a(&self) -> &Spectrum {
        &self.sigma_a
    }

    /// The extinction coefficient `σt = σa + σs`.
    #[inline]
    pub fn sigma_t(&self) -> &Spectrum {
        &self.sigma_t
    }

    /// The scattering coefficient.
    #[inline]
    pub fn sigma_s(&self) -> &Spectrum {
        &self.sigma_s
    }

    /// The phase function.
    #[inline]
    pub fn phase(&self) -> &HenyeyGreenstein {
        &self.phase
    }

    /// True when the medium scatters (σs > 0 somewhere): paths through it
    /// sample where they scatter; a medium that only absorbs attenuates
    /// every segment exactly instead.
    #[inline]
    pub fn scatters(&self) -> bool {
        self.scatters
    }

    /// The transmittance `exp(−σt(λ) d)` of a segment of length `d`, at the
    /// packet's wavelengths (σt interpolated at each, then exponentiated).
    #[inline]
    pub fn transmittance<const N: usize>(&self, d: f32, lambdas: &Lambdas<N>) -> Sampled<N> {
        (lambdas.sample(&self.sigma_t) * -d).exp()
    }

    /// Samples where a path travelling `t_max` through the medium scatters
    /// first, with spectral MIS over the packet's wavelengths (the one-sample
    /// balance heuristic over `N` exponential densities, Miller, Georgiev and
    /// Jarosz 2019 §5 for a homogeneous medium): a wavelength `j` is chosen
    /// uniformly with `u`, the distance from `σt(λj) exp(−σt(λj) t)`, and the
    /// density of the distance is the mean over the packet,
    /// `p(t) = (1/N) Σᵢ σt,i exp(−σt,i t)`. Scattering at `t < t_max` weighs
    /// wavelength `i` by `σs,i exp(−σt,i t) / p(t)`; reaching `t_max` by
    /// `exp(−σt,i t_max) / P`, `P = (1/N) Σᵢ exp(−σt,i t_max)` the
    /// probability of getting there. Both are unbiased for every wavelength,
    /// however much σt varies across the packet (a single wavelength's
    /// distance would be biased or noisy where σt(λ) differs).
    #[inline]
    pub fn sample_distance<const N: usize>(&self, t_max: f32, lambdas: &Lambdas<N>, u: f32) -> DistanceSample<N> {
        let sigma_t = lambdas.sample(&self.sigma_t);
        let uj = u * N as f32;
        let j = (uj as usize).min(N - 1);
        let ut = (uj - j as f32).clamp(0.0, 1.0 - f32::EPSILON);
        let t = if sigma_t[j] > 0.0 { -(1.0 - ut).ln() / sigma_t[j] } else { f32::INFINITY };
        if t < t_max {
            let tr = (sigma_t * -t).exp();
            let pdf = (sigma_t * tr).average();
            let sigma_s = lambdas.sample(&self.sigma_s);
            let weight = if pdf > 0.0 { sigma_s * tr / pdf } else { Sampled::splat(0.0) };
            DistanceSample { t, weight, scattered: true }
        } else {
            let tr = (sigma_t * -t_max).exp();
            let p = tr.average();
            let weight = if p > 0.0 { tr / p } else { Sampled::splat(0.0) };
            DistanceSample { t: t_max, weight, scattered: false }
        }
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
