//! Whitted-style recursive ray tracing (thesis §2.4: paths E S* (D|G) L).
//!
//! From the camera, follow specular surfaces (mirror, glass: one stochastic
//! Fresnel choice per vertex, so glass costs one ray per path, not one per
//! lobe); at the first non-specular surface add the direct light from one light
//! sample and stop. Emitters are seen directly or through specular chains.
//! Indirect diffuse light and caustics are missing by construction: that is the
//! method's documented shortfall, not a bug. Rough metals and rough glass are
//! not specular: they end the chain like a diffuse surface (direct light
//! only). Nested dielectrics follow the path's medium stack as in `path`
//! (false intersections passed, relative indices, absorption by the medium
//! each segment runs in). Dispersive glass refracts every
//! wavelength like 589.3 nm (no rainbow), as in the `path` integrator: its
//! packets are the full spectrum, which a BxDF samples at that wavelength.

use crate::color::Sampled;
use crate::geometry::Ray;
use crate::sampler::{Dim, Sampler};
use crate::scene::Scene;
use crate::spectral::{Contribution, Lambdas};

use super::{Interface, MAX_PASSES, Shading, interface, sample_direct};

/// The Whitted integrator.
#[derive(Clone, Copy, Debug)]
pub struct Whitted {
    /// Maximum number of specular bounces before the diffuse hit.
    pub max_bounces: u32,
}

impl Whitted {
    /// Radiance arriving along `ray` for the packet `lambdas`, as XYZ.
    pub(crate) fn li<const N: usize, O: Contribution>(
        &self,
        scene: &Scene,
        mut ray: Ray,
        lambdas: &Lambdas<N>,
        sampler: &mut Sampler,
    ) -> O {
        let mut l = Sampled::<N>::splat(0.0);
        let mut beta = Sampled::<N>::splat(1.0);
        let mut bounces = 0;
        let mut media = scene.camera_volumes;
        let mut passes = 0;
        loop {
            let Some(si) = scene.intersect(&ray, f32::INFINITY) else {
                // Seen directly or through specular surfaces: the environment.
                if let Some((_, le)) = scene.escaped(ray.dir)
                    && scene.medium_in(media.current()).is_none()
                {
                    l += beta * lambdas.sample(&le);
                }
                break;
            };
            let hit = &si.hit;
            // Beer-Lambert absorption along the segment, in the medium it ran in.
            if let Some(medium) = scene.medium_in(media.current()) {
                beta *= medium.transmittance(hit.t, lambdas);
            }
            // Emitters seen directly or through specular surfaces only.
            let mut emitted = None;
            if let Some(e) = scene.le(&si, ray.dir, &mut emitted) {
                l += beta * lambdas.sample(e.radiance) * e.scale;
            }
            // Nested dielectrics: a false intersection goes straight on.
            let at = interface(scene, &mut media, &si, ray.dir);
            if let Interface::Pass = at {
                passes += 1;
                if passes > MAX_PASSES {
                    break;
                }
                ray = Ray::spawn(hit.p, hit.n, ray.dir);
                continue;
            }
            passes = 0;
            if bounces >= self.max_bounces {
                break;
            }
            let mut textured = None;
            let bxdf = scene.bsdf_in(&si, &mut textured);
            if bxdf.is_black() {
                break;
            }
            let sh = Shading::new(hit.p, hit.n, hit.ns, ray.dir);
            if !bxdf.is_delta() {
                // The diffuse end of E S* D L: direct light only, then stop.
                l += beta * sample_direct(scene, bxdf, &sh, &at, &media, lambdas, sampler, false, true, bounces);
                break;
            }
            let (reads_u, reads_uc) = bxdf.reads_draws();
            let u = sampler.get_2d_if(reads_u, Dim::bsdf(bounces));
            let uc = sampler.get_1d_if(reads_uc, Dim::lobe(bounces));
            let Some(bs) = bxdf.sample_within(sh.wo, u, uc, lambdas, at.outside()) else {
                break;
            };
            let wi = sh.frame.to_world(bs.wi);
            if !sh.consistent(wi, bs.wi) {
                break;
            }
            at.scattered(&mut media, ray.dir, hit.n, wi);
            beta *= bs.f * (bs.wi.z.abs() / bs.pdf);
            bounces += 1;
            ray = Ray::spawn(hit.p, hit.n, wi);
        }
        O::from_packet(&scene.sensor, lambdas, &l)
    }
}
