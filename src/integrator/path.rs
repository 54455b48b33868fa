//! Path tracing with next-event estimation and multiple importance sampling
//! (power heuristic), Russian roulette, and wavelength packets that split at
//! dispersive surfaces (thesis §2.4.1-2.4.2, pbrt-v4 §13.4).
//!
//! One walk serves the `path` and `spectral` integrators:
//! 1. intersect; at an emitter add `β · L_e`, MIS-weighted against light
//!    sampling unless the previous bounce was delta (or this is the camera ray);
//! 2. stop after `max_bounces` scattering events;
//! 3. at a dispersive surface, when dispersion is on and the packet has more
//!    than one wavelength, continue as `N` single-wavelength walks from this
//!    very hit (each keeps its own throughput, weight and sampler stream
//!    position; their colours add);
//! 4. at a non-delta surface add direct light (one light sample, MIS);
//! 5. sample the BSDF for the next direction and update `β ← β f |cos| / pdf`;
//! 6. after 5 bounces continue with probability `q = min(max_λ β · η², 0.95)`
//!    and divide `β` by `q` (unbiased).

use crate::color::N_BINS;
use crate::color::Xyz;
use crate::geometry::Ray;
use crate::sampler::Sampler;
use crate::sampling::power_heuristic;
use crate::scene::{Scene, SurfaceHit};
use crate::spectral::{Lambdas, REFERENCE_LAMBDA_NM, Readout, Sampled, hero_bin};

use super::{Shading, sample_direct};

/// Bounces after which Russian roulette starts (Mitsuba's `rr_depth`).
pub const RR_DEPTH: u32 = 5;

/// The unidirectional path tracer.
#[derive(Clone, Copy, Debug)]
pub struct PathTracer {
    /// Maximum number of scattering events.
    pub max_bounces: u32,
    /// Whether packets split at dispersive surfaces (the `spectral` and
    /// `auto` integrators); without it every wavelength refracts like 589.3 nm.
    pub disperse: bool,
    /// The hero packet size a full-spectrum path collapses to at its first
    /// dispersive surface (`auto`); packets smaller than the full spectrum
    /// split into all their wavelengths.
    pub collapse_to: u32,
}

/// What the walk remembers about the previous vertex, for MIS at emitters.
#[derive(Clone, Copy, Debug)]
struct Prev {
    p: glam::Vec3,
    pdf_bsdf: f32,
    delta: bool,
}

/// The state of a walk between vertices.
#[derive(Clone, Copy, Debug)]
struct Walk<const N: usize> {
    beta: Sampled<N>,
    /// Product of η² over refractions, to undo their radiance scaling in roulette.
    eta_scale: f32,
    bounces: u32,
    prev: Prev,
}

impl PathTracer {
    /// Radiance arriving along `ray` for the packet `lambdas`, as XYZ.
    pub fn li<const N: usize>(&self, scene: &Scene, ray: Ray, lambdas: &Lambdas<N>, sampler: &mut Sampler) -> Xyz {
        let Some(si) = scene.intersect(&ray, f32::INFINITY) else {
            return Xyz::default();
        };
        let walk = Walk {
            beta: Sampled::splat(1.0),
            eta_scale: 1.0,
            bounces: 0,
            prev: Prev { p: ray.origin, pdf_bsdf: 0.0, delta: true },
        };
        self.walk(scene, ray, si, walk, lambdas, sampler, true)
    }

    /// Continues a path that arrived along `ray` at `si`.
    #[allow(clippy::too_many_arguments)]
    fn walk<const N: usize>(
        &self,
        scene: &Scene,
        mut ray: Ray,
        mut si: SurfaceHit,
        mut w: Walk<N>,
        lambdas: &Lambdas<N>,
        sampler: &mut Sampler,
        mut add_emission: bool,
    ) -> Xyz {
        let mut l = Sampled::<N>::splat(0.0);
        let mut split = Xyz::default();
        loop {
            let object = &scene.objects[si.object as usize];
            let hit = &si.hit;
            // 1. Emission, MIS-weighted against the light sample taken at the previous vertex.
            if add_emission && let Some(index) = object.light {
                let light = &scene.lights[index as usize];
                let scale = light.le_scale(hit.n, ray.dir);
                if scale > 0.0 {
                    let weight = if w.prev.delta {
                        1.0
                    } else {
                        let pdf_light = scene.light_pmf[index as usize] * light.pdf_li(w.prev.p, ray.dir, hit.p);
                        power_heuristic(w.prev.pdf_bsdf, pdf_light)
                    };
                    l += w.beta * lambdas.sample(light.spectrum()) * (scale * weight);
                }
            }
            add_emission = true;
            // 2. Depth limit.
            if w.bounces >= self.max_bounces {
                break;
            }
            let bxdf = &scene.materials[object.material as usize];
            if bxdf.is_black() {
                break;
            }
            // 3. A dispersive surface splits the packet into single wavelengths;
            //    the full spectrum first collapses to a hero packet (`auto`).
            if N > 1 && self.disperse && bxdf.is_dispersive() {
                if N == N_BINS && lambdas.readout == Readout::Spectral {
                    // Each bin joins the packet with probability C/36: weight 36/C.
                    let c = self.collapse_to as usize;
                    let hero = ((sampler.next_1d() * N_BINS as f32) as usize).min(N_BINS - 1);
                    for k in 0..c {
                        let bin = hero_bin(hero, k, c);
                        let one = Walk { beta: Sampled([w.beta[bin]]), ..copy_walk(&w) };
                        let l1 = Lambdas {
                            pos: [bin as f32],
                            weight: lambdas.weight * N_BINS as f32 / c as f32,
                            readout: Readout::Spectral,
                        };
                        split = split + self.walk::<1>(scene, ray, si, one, &l1, sampler, false);
                    }
                } else {
                    for i in 0..N {
                        let one = Walk { beta: Sampled([w.beta[i]]), ..copy_walk(&w) };
                        split = split + self.walk::<1>(scene, ray, si, one, &lambdas.single(i), sampler, false);
                    }
                }
                break;
            }
            let sh = Shading::new(hit.p, hit.n, hit.ns, ray.dir);
            // 4. Direct light.
            if !bxdf.is_delta() {
                l += w.beta * sample_direct(scene, bxdf, &sh, lambdas, sampler, true);
            }
            // 5. The next direction.
            let u = sampler.next_2d();
            let uc = sampler.next_1d();
            let lambda_nm = if N == 1 && self.disperse { lambdas.lambda_nm(0) } else { REFERENCE_LAMBDA_NM };
            let Some(bs) = bxdf.sample(sh.wo, u, uc, lambdas, lambda_nm) else {
                break;
            };
            let wi = sh.frame.to_world(bs.wi);
            if !sh.consistent(wi, bs.wi) {
                break;
            }
            w.beta *= bs.f * (bs.wi.z.abs() / bs.pdf);
            w.eta_scale *= bs.eta * bs.eta;
            w.bounces += 1;
            w.prev = Prev { p: hit.p, pdf_bsdf: bs.pdf, delta: bs.is_delta };
            if w.beta.is_black() {
                break;
            }
            // 6. Russian roulette.
            if w.bounces >= RR_DEPTH {
                let q = (w.beta.max_value() * w.eta_scale).min(0.95);
                if sampler.next_1d() >= q {
                    break;
                }
                w.beta = w.beta / q;
            }
            ray = Ray::spawn(hit.p, hit.n, wi);
            match scene.intersect(&ray, f32::INFINITY) {
                Some(next) => si = next,
                None => break,
            }
        }
        lambdas.to_xyz(&l) + split
    }
}

/// The packet-independent part of a walk's state, for a split.
#[inline]
fn copy_walk<const N: usize>(w: &Walk<N>) -> Walk<1> {
    Walk { beta: Sampled([0.0]), eta_scale: w.eta_scale, bounces: w.bounces, prev: w.prev }
}
