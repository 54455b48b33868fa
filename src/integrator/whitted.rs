//! Whitted-style recursive ray tracing (thesis §2.4: paths E S* (D|G) L).
//!
//! From the camera, follow specular surfaces (mirror, glass: one stochastic
//! Fresnel choice per vertex, so glass costs one ray per path, not one per
//! lobe); at the first non-specular surface add the direct light from one light
//! sample and stop. Emitters are seen directly or through specular chains.
//! Indirect diffuse light and caustics are missing by construction: that is the
//! method's documented shortfall, not a bug. Rough metals and rough glass are
//! not specular: they end the chain like a diffuse surface (direct light
//! only). Absorbing glass attenuates the chain's segments inside it. Dispersive glass refracts every
//! wavelength like 589.3 nm (no rainbow), as in the `path` integrator: its
//! packets are the full spectrum, which a BxDF samples at that wavelength.

use crate::color::Sampled;
use crate::geometry::Ray;
use crate::sampler::Sampler;
use crate::scene::Scene;
use crate::spectral::{Contribution, Lambdas};

use super::{Shading, sample_direct};

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
        while let Some(si) = scene.intersect(&ray, f32::INFINITY) {
            let object = &scene.objects[si.object as usize];
            let hit = &si.hit;
            // Beer-Lambert absorption along a segment inside an absorbing dielectric.
            if let Some(sigma) = scene.materials[object.material as usize].absorption()
                && ray.dir.dot(hit.n) > 0.0
            {
                beta *= (lambdas.sample(sigma) * -hit.t).exp();
            }
            // Emitters seen directly or through specular surfaces only.
            if let Some(index) = object.light {
                let light = &scene.lights[index as usize];
                l += beta * lambdas.sample(light.spectrum()) * light.le_scale(hit.n, ray.dir);
            }
            if bounces >= self.max_bounces {
                break;
            }
            let bxdf = &scene.materials[object.material as usize];
            if bxdf.is_black() {
                break;
            }
            let sh = Shading::new(hit.p, hit.n, hit.ns, ray.dir);
            if !bxdf.is_delta() {
                // The diffuse end of E S* D L: direct light only, then stop.
                l += beta * sample_direct(scene, bxdf, &sh, lambdas, sampler, false);
                break;
            }
            let u = sampler.next_2d();
            let uc = sampler.next_1d();
            let Some(bs) = bxdf.sample(sh.wo, u, uc, lambdas) else {
                break;
            };
            let wi = sh.frame.to_world(bs.wi);
            if !sh.consistent(wi, bs.wi) {
                break;
            }
            beta *= bs.f * (bs.wi.z.abs() / bs.pdf);
            bounces += 1;
            ray = Ray::spawn(hit.p, hit.n, wi);
        }
        O::from_packet(lambdas, &l)
    }
}
