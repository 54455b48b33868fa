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

pub mod grid;
pub mod nested;
pub mod phase;

pub use grid::DensityGrid;
pub use nested::{Crossing, VOLUME_STACK_DEPTH, Volume, VolumeStack};
pub use phase::HenyeyGreenstein;

use std::sync::Arc;

use glam::Vec3;
use rand::RngExt;

use crate::color::{Sampled, Spectrum};
use crate::error::Result;
use crate::scene::check::Check;
use crate::scene::desc::{MediumDesc, PhaseDesc};
use crate::spectral::Lambdas;

/// The medium of a description at `field` (`media."milk"`): coefficients
/// non-negative and finite, `g` within ±[`phase::MAX_G`].
pub(crate) fn from_desc(check: &Check, field: &str, d: &MediumDesc) -> Result<Medium> {
    let (sigma_a, sigma_s, phase) = match d {
        MediumDesc::Homogeneous { sigma_a, sigma_s, phase } | MediumDesc::Grid { sigma_a, sigma_s, phase, .. } => {
            (sigma_a, sigma_s, phase)
        }
    };
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
    let medium = Medium::new(sigma_a, sigma_s, HenyeyGreenstein { g });
    Ok(match d {
        MediumDesc::Homogeneous { .. } => medium,
        MediumDesc::Grid { path, density_scale, .. } => {
            let scale = check.positive(&format!("{field}.density_scale"), *density_scale)?;
            let path_field = format!("{field}.path");
            let (_, bytes) = check.read_input(&path_field, path)?;
            let grid = DensityGrid::parse_vol(&bytes).map_err(|m| check.err(&path_field, format!("{path}: {m}")))?;
            medium.with_grid(Arc::new(grid), scale)
        }
    })
}

/// A medium: absorption `σa(λ)` and scattering `σs(λ)` per scene unit, times
/// a density that is 1 everywhere (homogeneous) or given on a voxel grid over
/// its object's bounds, and a Henyey-Greenstein phase function.
#[derive(Clone, Debug, PartialEq)]
pub struct Medium {
    sigma_a: Spectrum,
    sigma_s: Spectrum,
    /// `σt = σa + σs`.
    sigma_t: Spectrum,
    phase: HenyeyGreenstein,
    scatters: bool,
    grid: Option<Placed>,
}

/// A density grid placed over a box: the coefficients are multiplied by
/// `scale · density((p − min) / extent)`.
#[derive(Clone, Debug, PartialEq)]
struct Placed {
    grid: Arc<DensityGrid>,
    scale: f32,
    min: Vec3,
    inv_extent: Vec3,
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
        Medium { sigma_t: sigma_a + sigma_s, sigma_a, sigma_s, phase, scatters: !sigma_s.is_black(), grid: None }
    }

    /// The same coefficients times `scale · grid` (not yet placed: see [`Medium::placed`]).
    pub fn with_grid(mut self, grid: Arc<DensityGrid>, scale: f32) -> Medium {
        self.grid = Some(Placed { grid, scale, min: Vec3::ZERO, inv_extent: Vec3::ONE });
        self
    }

    /// This medium with its grid (if any) filling the box `min`..`max` (an object's bounds).
    pub fn placed(&self, min: Vec3, max: Vec3) -> Medium {
        let mut m = self.clone();
        if let Some(p) = &mut m.grid {
            p.min = min;
            p.inv_extent = (max - min).max(Vec3::splat(1e-30)).recip();
        }
        m
    }

    /// True when the density varies (a grid): segments are tracked, not
    /// attenuated in closed form.
    #[inline]
    pub fn is_grid(&self) -> bool {
        self.grid.is_some()
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

    /// The transmittance `exp(−σt(λ) d)` of a segment of length `d` of a
    /// homogeneous medium, at the packet's wavelengths (σt interpolated at
    /// each, then exponentiated). A grid's segments go through
    /// [`Medium::optical_depth`] instead.
    #[inline]
    pub fn transmittance<const N: usize>(&self, d: f32, lambdas: &Lambdas<N>) -> Sampled<N> {
        (lambdas.sample(&self.sigma_t) * -d).exp()
    }

    /// The optical depth per bin of the segment `from`..`to`, `−ln T` of a
    /// ratio-tracking estimate `T` of its transmittance (Novák et al. 2014):
    /// tentative collisions, cell by cell of the grid's majorant cells
    /// ([`DensityGrid::segments`]), at `max_λ σt(λ) · scale · bound`, each
    /// multiplying bin `b`'s estimate by `1 − σt,b d(x) / μ̄`. Unbiased per
    /// bin; its random numbers come from a generator seeded by `seed` (derived
    /// from the path's sampler and the segment, so renders stay
    /// deterministic). For a homogeneous medium the exact `σt d`.
    pub fn optical_depth(&self, from: Vec3, to: Vec3, seed: u64) -> Spectrum {
        let d = (to - from).length();
        let Some(g) = &self.grid else {
            return self.sigma_t * d;
        };
        let sigma_max = self.sigma_t.max_value() * g.scale;
        if !(sigma_max > 0.0 && d > 0.0) {
            return Spectrum::ZERO;
        }
        let (o, du) = ((from - g.min) * g.inv_extent, (to - from) / d * g.inv_extent);
        let mut rng = rand_pcg::Pcg32::new(seed, 0x0a02_bdbf_7bb3_c0a7);
        let mut t = Spectrum::ONE;
        'walk: for (t0, t1, bound) in g.grid.segments(o, du, d) {
            let mu = sigma_max * bound;
            if mu.is_nan() || mu <= 0.0 {
                continue;
            }
            let mut s = t0;
            loop {
                s -= (1.0 - rng.random::<f32>()).ln() / mu;
                if s >= t1 {
                    break;
                }
                let density = g.scale * g.grid.density(o + du * s);
                for b in 0..crate::color::N_BINS {
                    t[b] *= 1.0 - self.sigma_t[b] * density / mu;
                }
                if t.max_value() <= 0.0 {
                    break 'walk;
                }
            }
        }
        Spectrum::from_fn(|b| if t[b] > 0.0 { -t[b].ln() } else { f32::INFINITY })
    }

    /// [`Medium::sample_distance`] for the ray from `origin` along `dir`, for
    /// either kind of medium: in a grid, delta tracking with spectral MIS
    /// (`Medium::track`) from a generator seeded by `u` and the ray.
    #[inline]
    pub fn sample_distance_along<const N: usize>(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        lambdas: &Lambdas<N>,
        u: f32,
    ) -> DistanceSample<N> {
        match &self.grid {
            None => self.sample_distance(t_max, lambdas, u),
            Some(_) => {
                let seed = (u.to_bits() as u64) << 32
                    ^ (origin.x.to_bits() as u64).rotate_left(7)
                    ^ (origin.y.to_bits() as u64).rotate_left(19)
                    ^ (origin.z.to_bits() as u64).rotate_left(41)
                    ^ dir.x.to_bits() as u64;
                self.track(origin, dir, t_max, lambdas, u, seed)
            }
        }
    }

    /// Delta tracking through a grid with spectral MIS over the packet: a
    /// wavelength `j` chosen uniformly with `u`; through each majorant cell
    /// ([`DensityGrid::segments`]) tentative collisions at its majorant
    /// `μj = σt(λj) · scale · bound`; at each, a real one with probability
    /// `d(x) / bound` (the same at every wavelength: the density scales all of
    /// them alike). For wavelength `i` the sequence of `K` tentative
    /// collisions has density `pᵢ = Πₖ μᵢ(tₖ) exp(−∫ μᵢ)`, and since every
    /// wavelength's majorant is `σt(λ) · scale` times the same piecewise
    /// bound, `pᵢ / pj = (σt,i / σt,j)^K exp(−(σt,i − σt,j) · scale · B)`
    /// with `B = ∫ bound dt` over the walked part: two scalars to carry, the
    /// ratios formed once at the end ([`ratios`]). Each wavelength's
    /// null-scattering contribution over `pᵢ` is the albedo `σs,i/σt,i` at a
    /// real collision and 1 otherwise, so its weight is that times
    /// `pᵢ / mean_m p_m` (the one-sample balance heuristic over the packet;
    /// for a constant density it is exactly [`Medium::sample_distance`]'s).
    fn track<const N: usize>(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        lambdas: &Lambdas<N>,
        u: f32,
        seed: u64,
    ) -> DistanceSample<N> {
        let g = self.grid.as_ref().expect("a grid");
        let sigma_t = lambdas.sample(&self.sigma_t);
        let j = ((u * N as f32) as usize).min(N - 1);
        let sigma_j = sigma_t[j] * g.scale;
        let (o, du) = ((origin - g.min) * g.inv_extent, dir * g.inv_extent);
        let mut rng = rand_pcg::Pcg32::new(seed, 0x5851_f42d_4c95_7f2d);
        let (mut collisions, mut walked) = (0u32, 0.0f32);
        for (t0, t1, bound) in g.grid.segments(o, du, t_max) {
            // A hero that does not interact, or an empty cell, has no collision.
            let mu = sigma_j * bound;
            if mu.is_nan() || mu <= 0.0 {
                walked += bound * (t1 - t0);
                continue;
            }
            let mut s = t0;
            loop {
                let dt = -(1.0 - rng.random::<f32>()).ln() / mu;
                if s + dt >= t1 {
                    walked += bound * (t1 - s);
                    break;
                }
                s += dt;
                walked += bound * dt;
                collisions += 1;
                let density = g.grid.density(o + du * s);
                if rng.random::<f32>() * bound < density {
                    let q = ratios(&sigma_t, j, collisions, g.scale * walked);
                    let mean = q.average();
                    let sigma_s = lambdas.sample(&self.sigma_s);
                    let weight = Sampled::from_fn(|m| {
                        if sigma_t[m] > 0.0 && mean > 0.0 { sigma_s[m] / sigma_t[m] * q[m] / mean } else { 0.0 }
                    });
                    return DistanceSample { t: s, weight, scattered: true };
                }
            }
        }
        let q = ratios(&sigma_t, j, collisions, g.scale * walked);
        let mean = q.average();
        let weight = if mean > 0.0 { q / mean } else { Sampled::splat(0.0) };
        DistanceSample { t: t_max, weight, scattered: false }
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

/// The ratios `pᵢ / pj` of [`Medium::track`], up to a common factor (the
/// largest is 1): `(σt,i / σt,j)^K exp(−(σt,i − σt,j) · W)` for `K` tentative
/// collisions and a walked majorant length `W` (in units of σt), formed in
/// logarithms so that neither many collisions nor a thick medium overflows.
fn ratios<const N: usize>(sigma_t: &Sampled<N>, j: usize, collisions: u32, walked: f32) -> Sampled<N> {
    let k = collisions as f32;
    let log = Sampled::<N>::from_fn(|m| {
        let power = if collisions == 0 { 0.0 } else { k * (sigma_t[m] / sigma_t[j]).ln() };
        power - (sigma_t[m] - sigma_t[j]) * walked
    });
    let top = log.max_value();
    if !top.is_finite() {
        return Sampled::splat(0.0);
    }
    Sampled::from_fn(|m| (log[m] - top).exp())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Per bin, the mean of `runs` ratio-tracking estimates of the transmittance
    /// from `from` to `to` (`exp(−τ)` of [`Medium::optical_depth`], run `k` its
    /// own random sequence) and its standard error.
    fn mean_transmittance(m: &Medium, from: Vec3, to: Vec3, runs: u64) -> Vec<(f64, f64)> {
        let (mut sum, mut sum2) = (vec![0.0f64; N_BINS], vec![0.0f64; N_BINS]);
        for k in 0..runs {
            let tau = m.optical_depth(from, to, k);
            for b in 0..N_BINS {
                let t = (-tau[b] as f64).exp();
                sum[b] += t;
                sum2[b] += t * t;
            }
        }
        (0..N_BINS)
            .map(|b| {
                let mean = sum[b] / runs as f64;
                (mean, ((sum2[b] / runs as f64 - mean * mean).max(0.0) / runs as f64).sqrt())
            })
            .collect()
    }

    /// Ratio tracking through a grid whose density is a linear ramp along x
    /// (64 voxels, value (i + ½)/64: the trilinear density is x itself between
    /// the first and last voxel centres, flat beyond) is unbiased against the
    /// closed-form optical depth σt ∫ d(x) dx along the box's axis: the mean
    /// of 4000 estimates of T per bin within 5 standard errors (+1e-4) of
    /// exp(−τ), for σt from 0.4 to 3.9 across the bins (a Rayleigh-like slope).
    #[test]
    fn ratio_tracking_is_unbiased_on_a_linear_ramp() {
        let n = 64usize;
        let data: Vec<f32> = (0..n).map(|i| (i as f32 + 0.5) / n as f32).collect();
        let grid = Arc::new(DensityGrid::new([n, 1, 1], data).unwrap());
        let sigma_s = Spectrum::from_fn(|b| 0.3 + 0.1 * b as f32);
        let m = Medium::new(Spectrum::splat(0.1), sigma_s, HenyeyGreenstein { g: 0.0 })
            .with_grid(grid, 1.0)
            .placed(Vec3::new(0.0, -1.0, -1.0), Vec3::new(2.0, 1.0, 1.0));
        // Along x from 0 to 2 (the box is 2 long: ∫ d dx over the box doubles the unit integral).
        let (c0, c1) = (0.5 / n as f64, 1.0 - 0.5 / n as f64);
        let unit = (c1 * c1 - c0 * c0) / 2.0 + c0 * c0 + (1.0 - c1) * c1;
        let (from, to) = (Vec3::new(0.0, 0.0, 0.0), Vec3::new(2.0, 0.0, 0.0));
        let t = mean_transmittance(&m, from, to, 4000);
        for (b, &(mean, se)) in t.iter().enumerate() {
            let want = (-(0.1 + 0.3 + 0.1 * b as f64) * 2.0 * unit).exp();
            assert!((mean - want).abs() < 5.0 * se + 1e-4, "bin {b}: T = {mean} ± {se}, want {want}");
        }
    }
    use crate::color::N_BINS;

    /// A sparse grid: one dense blob near a corner of a 40x32x24 grid (a
    /// Gaussian of radius 0.12 around (0.75, 0.7, 0.3), cut to 0 below 1e-3),
    /// zero elsewhere: most majorant cells are empty.
    fn sparse_blob() -> Medium {
        let n = [40usize, 32, 24];
        let data: Vec<f32> = (0..n[0] * n[1] * n[2])
            .map(|k| {
                let v = [k % n[0], (k / n[0]) % n[1], k / (n[0] * n[1])];
                let p: [f32; 3] = std::array::from_fn(|a| (v[a] as f32 + 0.5) / n[a] as f32);
                let d2 = (p[0] - 0.75).powi(2) + (p[1] - 0.7).powi(2) + (p[2] - 0.3).powi(2);
                let d = 3.0 * (-d2 / (0.12f32 * 0.12)).exp();
                if d < 1e-3 { 0.0 } else { d }
            })
            .collect();
        let grid = Arc::new(DensityGrid::new(n, data).unwrap());
        Medium::new(Spectrum::from_fn(|b| 0.2 + 0.02 * b as f32), Spectrum::splat(1.0), HenyeyGreenstein { g: 0.0 })
            .with_grid(grid, 2.0)
            .placed(Vec3::new(-1.0, 0.0, 0.0), Vec3::new(1.0, 1.5, 1.0))
    }

    /// The optical depth per unit σt along a segment by quadrature of the
    /// density itself (200,000 midpoints: an independent check of tracking).
    fn quadrature(m: &Medium, from: Vec3, to: Vec3) -> f64 {
        let g = m.grid.as_ref().unwrap();
        let k = 200_000;
        let len = (to - from).length() as f64;
        (0..k)
            .map(|i| {
                let p = from + (to - from) * ((i as f32 + 0.5) / k as f32);
                g.scale as f64 * g.grid.density((p - g.min) * g.inv_extent) as f64
            })
            .sum::<f64>()
            * len
            / k as f64
    }

    /// Ratio tracking through the majorant cells of a sparse grid is unbiased
    /// per bin against the quadrature of the density, on rays through the blob
    /// at odd angles, one that starts inside the box and one that grazes it:
    /// the mean of 3000 estimates of T within 5 standard errors (+1e-4) of
    /// exp(−σt τ).
    #[test]
    fn ratio_tracking_through_majorant_cells_is_unbiased() {
        let m = sparse_blob();
        let rays = [
            (Vec3::new(-1.5, 0.2, 0.1), Vec3::new(1.6, 1.3, 0.7)),
            (Vec3::new(0.4, 1.0, 0.35), Vec3::new(0.6, -0.2, 0.2)),
            (Vec3::new(0.3, 1.05, -0.5), Vec3::new(0.7, 1.05, 1.5)),
        ];
        for (from, to) in rays {
            let tau = quadrature(&m, from, to);
            assert!(tau > 0.05, "the ray crosses the blob: {tau}");
            let t = mean_transmittance(&m, from, to, 3000);
            for b in (0..N_BINS).step_by(5) {
                let (mean, se) = t[b];
                let want = (-(m.sigma_t[b] as f64) * tau).exp();
                assert!(
                    (mean - want).abs() < 5.0 * se + 1e-4,
                    "{from} → {to}, bin {b}: T = {mean} ± {se}, want {want}"
                );
            }
        }
    }

    /// Delta tracking with spectral MIS through the majorant cells reaches the
    /// end of the segment with expected weight T per wavelength (the
    /// quadrature's exp(−σt τ)), for a packet of 4 wavelengths whose σt
    /// differ: the mean over 20,000 walks of `weight · [not scattered]` within
    /// 5 standard errors (+2e-4), on a ray through the blob's centre (T about 0.05 and
    /// below; a majorant 0.6 times too small gives 0.10 for 0.054).
    #[test]
    fn delta_tracking_through_majorant_cells_transmits_t() {
        let m = sparse_blob();
        // Through the blob's centre, (0.5, 1.05, 0.3) in the scene.
        let (from, to) = (Vec3::new(-1.5, 0.9, 0.1), Vec3::new(1.5, 1.125, 0.4));
        let tau = quadrature(&m, from, to);
        assert!(tau > 1.0, "through the blob: {tau}");
        let d = (to - from).length();
        let dir = (to - from) / d;
        let check = |lambdas: &Lambdas<4>, sigma: [f32; 4]| {
            let runs = 20_000;
            let (mut sum, mut sum2) = ([0.0f64; 4], [0.0f64; 4]);
            for k in 0..runs {
                let u = (k as f32 + 0.5) / runs as f32;
                let s = m.track(from, dir, d, lambdas, u, k as u64 * 0x9e37_79b9);
                if !s.scattered {
                    for i in 0..4 {
                        sum[i] += s.weight[i] as f64;
                        sum2[i] += (s.weight[i] as f64).powi(2);
                    }
                }
            }
            for i in 0..4 {
                let mean = sum[i] / runs as f64;
                let se = ((sum2[i] / runs as f64 - mean * mean).max(0.0) / runs as f64).sqrt();
                let want = (-(sigma[i] as f64) * tau).exp();
                assert!((mean - want).abs() < 5.0 * se + 2e-4, "wavelength {i}: {mean} ± {se}, want {want}");
            }
        };
        // Four bins' centres (the packet's wavelengths at bins 0, 12, 24, 35).
        let packet = Lambdas { pos: [0.0, 12.0, 24.0, 35.0], weight: 9.0, readout: crate::spectral::Readout::Spectral };
        check(&packet, [0, 12, 24, 35].map(|b| m.sigma_t[b]));
    }

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
