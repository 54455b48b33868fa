//! Path tracing with next-event estimation and multiple importance sampling
//! (power heuristic), Russian roulette, and wavelength packets that split at
//! dispersive surfaces (thesis §2.4.1-2.4.2, pbrt-v4 §13.4).
//!
//! One walk serves the `path`, `spectral` and `auto` integrators:
//! 0. intersect; a segment inside an absorbing medium (the current medium
//!    of the path's medium stack, [`crate::medium::nested`]) is attenuated by
//!    `exp(−σ t)` (Beer-Lambert);
//! 1. at an emitter add `β · L_e`, MIS-weighted against light
//!    sampling unless the previous bounce was delta (or this is the camera ray);
//!    a false intersection of nested dielectrics is passed straight through
//!    here (no bounce, no light sample); a real dielectric interface scatters
//!    with the relative index against the medium outside it;
//! 2. stop after `max_bounces` scattering events;
//! 3. at a dispersive surface, when dispersion is on and the packet has more
//!    than one wavelength, continue as `N` single-wavelength walks from this
//!    very hit (each keeps its own throughput and weight; their colours add;
//!    they draw the same per-bounce dimensions of the sampler's layout, so
//!    with `independent` they continue one stream in turn and with `sobol`
//!    they share their numbers, as a hero packet shares its directions:
//!    each walk's estimate is unbiased on its own, so their sum is). The full spectrum (`auto`) first chooses
//!    between reflection, which is the same direction for every wavelength
//!    and keeps the full spectrum, and refraction, which collapses the path
//!    to `C` bins drawn in proportion to throughput × visual importance
//!    (`PathTracer::collapse`). At a *rough* dispersive dielectric every
//!    lobe's direction depends on the wavelength, so `auto` collapses the
//!    whole path there, to `C` bins drawn the same way, each walking on from
//!    this hit (light sample and BSDF sample at its own index). For colour
//!    output these single wavelengths are continuous (`crate::spectral`,
//!    "Continuous wavelengths"): each drawn within its bin's tent, at the
//!    interpolated throughput, refracting at its exact index; spectral output
//!    keeps the bin centres;
//! 4. at a non-delta surface add direct light (one light sample, MIS);
//! 5. sample the BSDF for the next direction and update `β ← β f |cos| / pdf`;
//! 6. after [`RR_DEPTH`] bounces continue with probability
//!    `q = min(max_λ β · η², 1)` and divide `β` by `q` (unbiased; pbrt-v4's
//!    rule: a path that has lost nothing, a chain through clear glass, is
//!    never cut).

use crate::bxdf::{BsdfSample, Dispersion};
use crate::color::{N_BINS, Sampled, Spectrum};
use crate::geometry::Ray;
use crate::medium::VolumeStack;
use crate::sampler::warp::power_heuristic;
use crate::sampler::{Dim, Sampler};
use crate::scene::{Scene, SurfaceHit};
use crate::spectral::{
    BinDistribution, Contribution, Lambdas, Readout, bin_importance, for_each_rotated, for_each_rotated_continuous,
};

use super::{Interface, MAX_PASSES, Shading, interface, sample_direct};

/// Bounces after which Russian roulette starts. Mitsuba's default is 5;
/// measured on 64x64 renders (callgrind instructions per sample times the
/// linear MSE at 64 spp over 8 seeds, against 8192/4096-spp references),
/// starting after 2 bounces is 1.19x as efficient on `cornell-lambert.ron`
/// and 1.21x on `spheres.ron` (after 1: 1.18x and 1.17x; after 3: 1.14x
/// and 1.13x). The cap at 1 instead of Mitsuba's 0.95 costs nothing there
/// and keeps lossless specular chains exact.
pub const RR_DEPTH: u32 = 2;

/// The largest probability of reflection at a collapse with continuous
/// wavelengths: every bin may be totally reflected while wavelengths beyond
/// 730 nm (lower index) still refract, so refraction keeps at least 2⁻¹⁰.
const MAX_CONTINUOUS_P_REFLECT: f32 = 1.0 - 1.0 / 1024.0;

/// The unidirectional path tracer.
#[derive(Clone, Copy, Debug)]
pub struct PathTracer {
    /// Maximum number of scattering events.
    pub max_bounces: u32,
    /// Whether packets split at dispersive surfaces (the `spectral` and
    /// `auto` integrators); without it every wavelength refracts like 589.3 nm.
    pub disperse: bool,
    /// How many wavelengths a full-spectrum path collapses to where it
    /// refracts at a dispersive surface (`auto`); packets smaller than the
    /// full spectrum split into all their wavelengths.
    pub collapse_to: u32,
    /// `--integrator caustics`' camera side: on a path whose first vertex
    /// scattered through a lobe neither delta nor glossy, an escape to the
    /// environment through a delta lobe or off a glossy surface, and a glossy
    /// surface's light sample of an aimed light, add nothing (light subpaths
    /// aimed at the specular and glossy surfaces carry those paths:
    /// `super::caustics`). False for every other integrator.
    pub light_caustics: bool,
}

/// What the walk remembers about the previous vertex, for MIS at emitters.
#[derive(Clone, Copy, Debug)]
struct Prev {
    p: glam::Vec3,
    pdf_bsdf: f32,
    delta: bool,
    /// The surface scattered off is glossy ([`Scene::glossy_at`];
    /// only looked at for a path `caustics`' light side may own, [`Walk::owned`]).
    glossy: bool,
}

/// The state of a walk between vertices.
#[derive(Clone, Copy, Debug)]
struct Walk<const N: usize> {
    beta: Sampled<N>,
    /// Product of η² over refractions, to undo their radiance scaling in roulette.
    eta_scale: f32,
    bounces: u32,
    prev: Prev,
    /// The dielectric media the path is inside.
    media: VolumeStack,
    /// The light side of `caustics` owns this path's escapes through a delta
    /// lobe or off a glossy surface, and a glossy surface's light samples of
    /// aimed lights: [`PathTracer::light_caustics`] is set and the first
    /// vertex scattered through a lobe neither delta nor glossy.
    owned: bool,
}

impl PathTracer {
    /// Radiance arriving along `ray` for the packet `lambdas`, as XYZ.
    pub(crate) fn li<const N: usize, O: Contribution>(
        &self,
        scene: &Scene,
        ray: Ray,
        lambdas: &Lambdas<N>,
        sampler: &mut Sampler,
    ) -> O {
        let Some(si) = scene.intersect(&ray, f32::INFINITY) else {
            // The camera sees the environment (or black).
            return match scene.escaped(ray.dir) {
                Some((_, le)) if scene.medium_in(scene.camera_volumes.current()).is_none() => {
                    O::from_packet(&scene.sensor, lambdas, &lambdas.sample(&le))
                }
                _ => O::default(),
            };
        };
        let walk = Walk {
            beta: Sampled::splat(1.0),
            eta_scale: 1.0,
            bounces: 0,
            prev: Prev { p: ray.origin, pdf_bsdf: 0.0, delta: true, glossy: false },
            media: scene.camera_volumes,
            owned: false,
        };
        self.walk(scene, ray, si, walk, lambdas, sampler, Start::Camera)
    }

    /// Continues a path that arrived along `ray` at `si`.
    #[allow(clippy::too_many_arguments)]
    fn walk<const N: usize, O: Contribution>(
        &self,
        scene: &Scene,
        mut ray: Ray,
        mut si: SurfaceHit,
        mut w: Walk<N>,
        lambdas: &Lambdas<N>,
        sampler: &mut Sampler,
        mut start: Start,
    ) -> O {
        let mut l = Sampled::<N>::splat(0.0);
        let mut split = O::default();
        let mut add_emission = start == Start::Camera;
        let mut passes = 0;
        loop {
            let hit = &si.hit;
            // 0. The medium the segment ran in (once: a split walk starts at a
            //    hit already counted): Beer-Lambert where it only absorbs; where
            //    it scatters, a distance drawn by spectral MIS, and a scattering
            //    event before the surface is a vertex of the path.
            if add_emission && let Some(medium) = scene.medium_in(w.media.current()) {
                if medium.scatters() || medium.is_grid() {
                    let u = sampler.get_1d(Dim::medium_distance(w.bounces));
                    let d = medium.sample_distance_along(ray.origin, ray.dir, hit.t, lambdas, u);
                    w.beta *= d.weight;
                    if d.scattered {
                        match self.scatter_in_medium(
                            scene,
                            medium,
                            ray.at(d.t),
                            ray.dir,
                            &mut w,
                            &mut l,
                            lambdas,
                            sampler,
                        ) {
                            Some((next_ray, next)) => {
                                (ray, si) = (next_ray, next);
                                continue;
                            }
                            None => break,
                        }
                    }
                } else {
                    w.beta *= medium.transmittance(hit.t, lambdas);
                }
            }
            // 1. Emission, MIS-weighted against the light sample taken at the previous vertex.
            let mut emitted = None;
            if add_emission && let Some(e) = scene.le(&si, ray.dir, &mut emitted) {
                let weight = if w.prev.delta {
                    1.0
                } else {
                    power_heuristic(w.prev.pdf_bsdf, scene.pdf_li(e.light, w.prev.p, ray.dir, &si))
                };
                l += w.beta * lambdas.sample(e.radiance) * (e.scale * weight);
            }
            add_emission = true;
            // Nested dielectrics: a false intersection goes straight on.
            let at = interface(scene, &mut w.media, &si, ray.dir);
            if let Interface::Pass = at {
                // The previous vertex's light sample reaches through false
                // intersections too (`Scene::transmittance`), along the same
                // straight line: an emitter beyond keeps its MIS weight.
                passes += 1;
                ray = Ray::spawn(hit.p, hit.n, ray.dir);
                match scene.intersect(&ray, f32::INFINITY) {
                    Some(next) if passes <= MAX_PASSES => si = next,
                    Some(_) => break,
                    None => {
                        l += escape(scene, &ray, &w, lambdas);
                        break;
                    }
                }
                continue;
            }
            passes = 0;
            // 2. Depth limit.
            if w.bounces >= self.max_bounces {
                break;
            }
            let mut textured = None;
            let bxdf = scene.bsdf_in(&si, &mut textured);
            if bxdf.is_black() {
                break;
            }
            let sh = Shading::new(hit.p, hit.n, hit.ns, ray.dir);
            // 3. A dispersive surface splits the packet into single wavelengths.
            let mut reflect = None;
            let dispersion = if self.disperse { bxdf.dispersion_within(at.outside()) } else { None };
            if N > 1
                && let Some(dispersion) = dispersion
            {
                if N == N_BINS && lambdas.readout == Readout::Spectral && dispersion.is_smooth() {
                    // `auto`: reflection keeps the full spectrum, refraction collapses.
                    match self.collapse(scene, ray, si, &sh, dispersion, &w, lambdas, sampler, &mut split) {
                        Some(fr) => reflect = Some(fr),
                        None => break,
                    }
                } else if N == N_BINS && lambdas.readout == Readout::Spectral {
                    // `auto` at rough dispersive glass: every lobe's direction
                    // depends on the wavelength, so the whole path collapses here.
                    let importance = bin_importance();
                    let Some(dist) = BinDistribution::new(|b| w.beta[b] * importance[b]) else {
                        break;
                    };
                    let u = sampler.get_1d(Dim::collapse_bins(w.bounces));
                    if O::CONTINUOUS {
                        // Continuous wavelengths, each at the interpolated throughput.
                        for_each_rotated_continuous(&dist, self.collapse_to as usize, u, |l1, weight| {
                            let one = Walk { beta: Sampled([beta_at(&w.beta, &l1)]), ..copy_walk(&w) };
                            let l1 = Lambdas { weight: lambdas.weight * weight, ..l1 };
                            split += self.walk::<1, O>(scene, ray, si, one, &l1, sampler, Start::Split);
                        });
                        break;
                    }
                    for_each_rotated(&dist, self.collapse_to as usize, u, |bin, weight| {
                        let one = Walk { beta: Sampled([w.beta[bin]]), ..copy_walk(&w) };
                        let l1 =
                            Lambdas { pos: [bin as f32], weight: lambdas.weight * weight, readout: Readout::Spectral };
                        split += self.walk::<1, O>(scene, ray, si, one, &l1, sampler, Start::Split);
                    });
                    break;
                } else {
                    for i in 0..N {
                        let one = Walk { beta: Sampled([w.beta[i]]), ..copy_walk(&w) };
                        split += self.walk::<1, O>(scene, ray, si, one, &lambdas.single(i), sampler, Start::Split);
                    }
                    break;
                }
            }
            // 4. Direct light.
            if !bxdf.is_delta() {
                let aimed = !(w.owned && scene.glossy_at(si.object, bxdf));
                l += w.beta * sample_direct(scene, bxdf, &sh, &at, &w.media, lambdas, sampler, true, aimed, w.bounces);
            }
            // 5. The next direction.
            let (reads_u, reads_uc) = bxdf.reads_draws();
            let u = sampler.get_2d_if(reads_u, Dim::bsdf(w.bounces));
            let uc = sampler.get_1d_if(reads_uc, Dim::lobe(w.bounces));
            let sample = match (reflect.take(), std::mem::replace(&mut start, Start::Camera), dispersion) {
                (Some(weight), ..) => Some(mirror(sh.wo, weight)),
                (None, Start::SplitRefraction, Some(d)) => refraction(d, sh.wo, lambdas),
                _ => bxdf.sample_within(sh.wo, u, uc, lambdas, at.outside()),
            };
            let Some(bs) = sample else {
                break;
            };
            let wi = sh.frame.to_world(bs.wi);
            if !sh.consistent(wi, bs.wi) {
                break;
            }
            at.scattered(&mut w.media, ray.dir, hit.n, wi);
            w.beta *= bs.f * (bs.wi.z.abs() / bs.pdf);
            w.eta_scale *= bs.eta * bs.eta;
            let glossy = self.light_caustics && scene.glossy_at(si.object, bxdf);
            if w.bounces == 0 {
                w.owned = self.light_caustics && !bs.is_delta && !bxdf.is_glossy();
            }
            w.bounces += 1;
            w.prev = Prev { p: hit.p, pdf_bsdf: bs.pdf, delta: bs.is_delta, glossy };
            if w.beta.is_black() {
                break;
            }
            // 6. Russian roulette.
            if w.bounces >= RR_DEPTH {
                let q = (w.beta.max_value() * w.eta_scale).min(1.0);
                if sampler.get_1d_if(q < 1.0, Dim::roulette(w.bounces - 1)) >= q {
                    break;
                }
                w.beta /= q;
            }
            ray = Ray::spawn(hit.p, hit.n, wi);
            match scene.intersect(&ray, f32::INFINITY) {
                Some(next) => si = next,
                None => {
                    l += escape(scene, &ray, &w, lambdas);
                    break;
                }
            }
        }
        let mut out = O::from_packet(&scene.sensor, lambdas, &l);
        out += split;
        out
    }
}

impl PathTracer {
    /// `auto` at a dispersive dielectric, with the full spectrum. Reflection
    /// sends every wavelength the same way, so it is chosen first, with a
    /// probability `P_r`, and the path goes on full-spectrum with per-bin
    /// weight `F(λ) / P_r` (returned, as the value of the mirror lobe).
    /// Otherwise the path collapses: `C` bins drawn in proportion to
    /// throughput × [`bin_importance`], each weighted `1 / (C · p(bin))`,
    /// each refracting at its own index as a single-wavelength walk of
    /// throughput `β(λ) (1 − F(λ)) / (1 − P_r)` whose colour is added to
    /// `split`. For colour output each wavelength is then placed
    /// continuously within its bin's tent ([`for_each_rotated_continuous`],
    /// weight `1 / (C · p(λ))`), `β(λ)` interpolated between bins and `F`
    /// and the index taken at λ exactly; `P_r` is then at most
    /// `1 − 2⁻¹⁰`, since wavelengths beyond the last bin may refract where
    /// every bin is totally reflected. Returns `None` after a collapse (or a
    /// dead path).
    ///
    /// Any `P_r` that is below 1 wherever some wavelength is transmitted keeps
    /// this unbiased. Arriving from outside (always, unless the camera or an
    /// emitter sits inside glass) into glass whose index at 589.3 nm is at
    /// least 1, that wavelength is never totally reflected, so `P_r` is its
    /// reflectance and only the drawn bins' reflectances are computed
    /// (evaluating all 36 at every glass hit cost 10% of the instructions of
    /// a prism render); a bin that is totally reflected gets throughput 0.
    /// Otherwise `P_r` is the reflectance averaged over the bins with weights
    /// throughput × importance, which is 1 only when every bin is totally
    /// reflected.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn collapse<const N: usize, O: Contribution>(
        &self,
        scene: &Scene,
        ray: Ray,
        si: SurfaceHit,
        sh: &Shading,
        glass: Dispersion<'_>,
        w: &Walk<N>,
        lambdas: &Lambdas<N>,
        sampler: &mut Sampler,
        split: &mut O,
    ) -> Option<Sampled<N>> {
        let importance = bin_importance();
        let cos = sh.wo.z;
        let (p_reflect, all_fr) = if cos > 0.0 && glass.reference_eta() >= 1.0 {
            (glass.reference_reflectance(cos), None)
        } else {
            let fr = glass.reflectance(sh.wo, lambdas);
            let (mut total, mut reflected) = (0.0f32, 0.0f32);
            for i in 0..N {
                let v = w.beta[i] * importance[i];
                total += v;
                reflected += v * fr[i];
            }
            if total.is_nan() || total <= 0.0 {
                return None;
            }
            ((reflected / total).clamp(0.0, 1.0), Some(fr))
        };
        // Continuous wavelengths beyond 730 nm may refract where every bin is
        // totally reflected: refraction must stay possible.
        let p_reflect = if O::CONTINUOUS { p_reflect.min(MAX_CONTINUOUS_P_REFLECT) } else { p_reflect };
        if sampler.get_1d(Dim::collapse(w.bounces)) < p_reflect {
            let fr = all_fr.unwrap_or_else(|| glass.reflectance(sh.wo, lambdas));
            return Some(fr / p_reflect);
        }
        let p_refract = 1.0 - p_reflect;
        let dist = BinDistribution::new(|b| w.beta[b] * importance[b])?;
        let u = sampler.get_1d(Dim::collapse_bins(w.bounces));
        if O::CONTINUOUS {
            // Each wavelength at its own λ: the interpolated throughput, the
            // reflectance and index at λ exactly.
            for_each_rotated_continuous(&dist, self.collapse_to as usize, u, |l1, weight| {
                let fr = glass.reflectance_at(cos, l1.pos[0]);
                let one = Walk { beta: Sampled([beta_at(&w.beta, &l1) * (1.0 - fr) / p_refract]), ..copy_walk(w) };
                let l1 = Lambdas { weight: lambdas.weight * weight, ..l1 };
                *split += self.walk::<1, O>(scene, ray, si, one, &l1, sampler, Start::SplitRefraction);
            });
            return None;
        }
        for_each_rotated(&dist, self.collapse_to as usize, u, |bin, weight| {
            let fr = match all_fr {
                Some(fr) => fr[bin],
                None => glass.reflectance_at(cos, lambdas.pos[bin]),
            };
            let one = Walk { beta: Sampled([w.beta[bin] * (1.0 - fr) / p_refract]), ..copy_walk(w) };
            let l1 = Lambdas { pos: [bin as f32], weight: lambdas.weight * weight, readout: Readout::Spectral };
            *split += self.walk::<1, O>(scene, ray, si, one, &l1, sampler, Start::SplitRefraction);
        });
        None
    }
}

impl PathTracer {
    /// A scattering event at `p` in `medium` for a path that travelled along
    /// `dir`: next-event estimation with the phase function (MIS against
    /// phase sampling, the power heuristic), then a direction from the phase
    /// function (its weight is 1), Russian roulette, and the next hit. Adds
    /// what it finds to `l`; `None` when the path ends (depth, roulette, or
    /// escape: the environment is added then).
    #[allow(clippy::too_many_arguments)]
    #[inline(never)]
    fn scatter_in_medium<const N: usize>(
        &self,
        scene: &Scene,
        medium: &crate::medium::Medium,
        p: glam::Vec3,
        dir: glam::Vec3,
        w: &mut Walk<N>,
        l: &mut Sampled<N>,
        lambdas: &Lambdas<N>,
        sampler: &mut Sampler,
    ) -> Option<(Ray, SurfaceHit)> {
        if w.bounces >= self.max_bounces || w.beta.is_black() {
            return None;
        }
        let phase = medium.phase();
        let wo = -dir;
        *l += w.beta * super::sample_direct_medium(scene, phase, p, wo, &w.media, lambdas, sampler, w.bounces);
        let (wi, pdf) = phase.sample(wo, sampler.get_2d(Dim::bsdf(w.bounces)));
        w.bounces += 1;
        w.prev = Prev { p, pdf_bsdf: pdf, delta: false, glossy: false };
        if w.bounces >= RR_DEPTH {
            let q = (w.beta.max_value() * w.eta_scale).min(1.0);
            if sampler.get_1d_if(q < 1.0, Dim::roulette(w.bounces - 1)) >= q {
                return None;
            }
            w.beta /= q;
        }
        let ray = Ray::new(p, wi);
        match scene.intersect(&ray, f32::INFINITY) {
            Some(next) => Some((ray, next)),
            None => {
                *l += escape(scene, &ray, w, lambdas);
                None
            }
        }
    }
}

/// The environment's radiance for a walk whose ray escaped the scene,
/// MIS-weighted against the light sample taken at the previous vertex (zero
/// without an environment, or when the path is inside an absorbing medium:
/// an infinite segment there transmits nothing; zero too for a path `caustics`'
/// light side owns, [`Walk::owned`], that escapes through a delta lobe or off a
/// glossy surface).
#[inline]
fn escape<const N: usize>(scene: &Scene, ray: &Ray, w: &Walk<N>, lambdas: &Lambdas<N>) -> Sampled<N> {
    if w.owned && (w.prev.delta || w.prev.glossy) {
        // `caustics`: the light side's path (see `Walk::owned`).
        return Sampled::splat(0.0);
    }
    match scene.escaped(ray.dir) {
        Some((light, le)) if scene.medium_in(w.media.current()).is_none() => {
            let weight =
                if w.prev.delta { 1.0 } else { power_heuristic(w.prev.pdf_bsdf, scene.pdf_escaped(light, ray.dir)) };
            w.beta * lambdas.sample(&le) * weight
        }
        _ => Sampled::splat(0.0),
    }
}

/// How a walk starts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Start {
    /// From the camera: emission seen directly counts.
    Camera,
    /// A single wavelength split off at this very hit (emission already counted).
    Split,
    /// As `Split`, and refraction was already chosen (and weighted) at this hit.
    SplitRefraction,
}

/// The mirror direction of `wo` (local frame) as a delta sample of probability
/// 1 whose weight `f |cos θ| / pdf` is `weight`.
#[inline]
fn mirror<const N: usize>(wo: glam::Vec3, weight: Sampled<N>) -> BsdfSample<N> {
    let wi = glam::Vec3::new(-wo.x, -wo.y, wo.z);
    BsdfSample { wi, f: weight / wi.z.abs().max(f32::MIN_POSITIVE), pdf: 1.0, is_delta: true, eta: 1.0 }
}

/// The forced refraction of a walk split off at a dispersive surface: a
/// packet of one wavelength, refracting at its own index.
#[inline]
fn refraction<const N: usize>(d: Dispersion<'_>, wo: glam::Vec3, lambdas: &Lambdas<N>) -> Option<BsdfSample<N>> {
    let one = Lambdas { pos: [lambdas.pos[0]], weight: lambdas.weight, readout: lambdas.readout };
    let s = d.sample_refraction(wo, &one)?;
    Some(BsdfSample { wi: s.wi, f: Sampled::splat(s.f[0]), pdf: s.pdf, is_delta: s.is_delta, eta: s.eta })
}

/// A full-spectrum throughput (`N` = 36) at the continuous wavelength of
/// `one`: linear between bins, flat beyond the end bins.
#[inline]
fn beta_at<const N: usize>(beta: &Sampled<N>, one: &Lambdas<1>) -> f32 {
    one.sample(&Spectrum::from_fn(|b| beta.0.get(b).copied().unwrap_or(0.0)))[0]
}

/// The packet-independent part of a walk's state, for a split.
#[inline]
fn copy_walk<const N: usize>(w: &Walk<N>) -> Walk<1> {
    Walk {
        beta: Sampled([0.0]),
        eta_scale: w.eta_scale,
        bounces: w.bounces,
        prev: w.prev,
        media: w.media,
        owned: w.owned,
    }
}
