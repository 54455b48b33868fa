//! Extending a subpath by BSDF sampling (radiance transport on the camera
//! side, importance transport on the light side).

use crate::color::Spectrum;
use crate::geometry::Ray;
use crate::integrator::{MAX_PASSES, Shading};
use crate::medium::{Crossing, VolumeStack};
use crate::sampler::{Dim, Sampler};
use crate::scene::Scene;
use crate::spectral::Lambdas;

use super::RR_DEPTH;
use super::vertex::{Kind, Vertex, Wavelength, medium_vertex, outside, shading_correction, to_area};

/// A subpath walk's fixed parameters.
pub(super) struct Walk {
    /// Importance transport (the light subpath) rather than radiance.
    pub(super) importance: bool,
    /// The most vertices the subpath may have, its first included.
    pub(super) max_vertices: usize,
    /// End the subpath at its first surface vertex unless that vertex
    /// scattered through a delta lobe or is glossy on a bounded object
    /// (`Scene::glossy_at`; `caustics`' light side).
    pub(super) delta_first: bool,
}

impl Walk {
    /// Extends `path` along `ray` by BSDF sampling. `pdf_dir` is the density
    /// of `ray`'s direction at the last vertex (per solid angle; for a
    /// `parallel` light, per area of its disk).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn run(
        &self,
        scene: &Scene,
        mut ray: Ray,
        mut beta: Spectrum,
        mut pdf_dir: f32,
        mut parallel: bool,
        sampler: &mut Sampler,
        path: &mut Vec<Vertex>,
        mut stacks: Option<&mut Vec<VolumeStack>>,
        mut media: VolumeStack,
        wl: &mut Wavelength,
    ) {
        let full = Lambdas::full();
        let beta_ref = beta.max_value();
        let mut passes = 0;
        let mut collapsed = false;
        let mut bounces = 0u32;
        // Radiance transport divides by η² at each refraction; roulette looks
        // through that scaling (as the path tracer's does).
        let mut eta_scale = 1.0f32;
        while path.len() < self.max_vertices {
            let Some(si) = scene.intersect(&ray, f32::INFINITY) else {
                // A camera subpath that escapes ends on the environment (outside any medium).
                if let Some((index, _)) = scene.escaped(ray.dir)
                    && !self.importance
                    && scene.medium_in(media.current()).is_none()
                {
                    let far = ray.origin + ray.dir * (4.0 * scene.radius());
                    let mut v = Vertex::at_point(Kind::Light(index), far, -ray.dir, beta, pdf_dir);
                    v.collapsed = collapsed;
                    path.push(v);
                    if let Some(stacks) = stacks.as_deref_mut() {
                        stacks.push(media);
                    }
                }
                break;
            };
            let hit = si.hit;
            let uv = if scene.needs_uv(si.object) { scene.uv(&si) } else { glam::Vec2::ZERO };
            let mut slot = None;
            let material = scene.material_at(si.object, hit.p, uv);
            let bxdf = scene.bsdf_of(material, uv, &mut slot);
            // The medium the segment ran in: Beer-Lambert where it only absorbs;
            // where it scatters (or is a grid), a distance by spectral MIS, and a
            // scattering event before the surface is a medium vertex.
            if let Some(volume) = media.current()
                && let Some(medium) = scene.medium_in(Some(volume))
            {
                if medium.scatters() || medium.is_grid() {
                    let u = sampler.get_1d(Dim::medium_distance(bounces).on_light_path_if(self.importance));
                    let (t, scattered) = if collapsed {
                        let one = wl.single();
                        let d = medium.sample_distance_along(ray.origin, ray.dir, hit.t, &one.lambdas, u);
                        beta[one.slot] *= d.weight[0];
                        (d.t, d.scattered)
                    } else {
                        let d = medium.sample_distance_along(ray.origin, ray.dir, hit.t, &full, u);
                        beta *= d.weight;
                        (d.t, d.scattered)
                    };
                    if scattered {
                        if beta.is_black() {
                            break;
                        }
                        let p = ray.at(t);
                        let prev = path.last().expect("a subpath starts at the eye or a light");
                        let mut v = medium_vertex(volume.object, p, ray.dir, beta, collapsed);
                        // A medium point carries no cosine: a parallel light's disk density as it is.
                        v.pdf_fwd = if parallel { pdf_dir } else { to_area(scene, pdf_dir, prev, &v) };
                        v.g_prev = to_area(scene, 1.0, &v, prev);
                        parallel = false;
                        path.push(v);
                        if let Some(stacks) = stacks.as_deref_mut() {
                            stacks.push(media);
                        }
                        if path.len() >= self.max_vertices {
                            break;
                        }
                        // The phase function's direction: weight 1, symmetric density.
                        let u2 = sampler.get_2d(Dim::bsdf(bounces).on_light_path_if(self.importance));
                        let (wi, pdf) = medium.phase().sample(-ray.dir, u2);
                        let n = path.len();
                        path[n - 2].pdf_rev = pdf * path[n - 1].g_prev;
                        pdf_dir = pdf;
                        bounces += 1;
                        if bounces >= RR_DEPTH {
                            let q = (beta.max_value() * eta_scale / beta_ref).min(1.0);
                            if sampler.get_1d_if(q < 1.0, Dim::roulette(bounces - 1).on_light_path_if(self.importance))
                                >= q
                                || q.is_nan()
                            {
                                break;
                            }
                            beta /= q;
                        }
                        ray = Ray::new(p, wi);
                        passes = 0;
                        continue;
                    }
                } else if collapsed {
                    let one = wl.single();
                    beta[one.slot] *= medium.transmittance(hit.t, &one.lambdas)[0];
                } else {
                    beta *= medium.transmittance(hit.t, &full);
                }
            }
            // Nested dielectrics: a false intersection is no vertex; the walk
            // goes straight on (densities stay those of the whole straight line).
            let arrival = media;
            let mut crossing = None;
            let mut outside_material = None;
            if let Some(m) = scene.volume(si.object) {
                let entering = ray.dir.dot(hit.n) < 0.0;
                match scene.crossing(&media, m, entering) {
                    Crossing::Pass => {
                        media.cross(m, entering);
                        passes += 1;
                        if passes > MAX_PASSES {
                            break;
                        }
                        ray = Ray::spawn(hit.p, hit.n, ray.dir);
                        continue;
                    }
                    Crossing::Interface { outside } => {
                        crossing = Some((m, entering));
                        outside_material = outside;
                    }
                }
            }
            passes = 0;
            let out = outside(scene, outside_material);
            let sh = Shading::new(hit.p, hit.n, hit.ns, ray.dir);
            let prev = path.last().expect("a subpath starts at the eye or a light");
            let mut v = Vertex {
                kind: Kind::Surface(si.object),
                sh,
                beta,
                delta: false,
                glossy: bxdf.is_glossy(),
                collapsed,
                pdf_fwd: 0.0,
                pdf_rev: 0.0,
                g_prev: 0.0,
                outside: outside_material,
                uv,
                material,
            };
            v.pdf_fwd = if parallel { pdf_dir * ray.dir.dot(hit.n).abs() } else { to_area(scene, pdf_dir, prev, &v) };
            v.g_prev = to_area(scene, 1.0, &v, prev);
            parallel = false;
            path.push(v);
            if let Some(stacks) = stacks.as_deref_mut() {
                stacks.push(arrival);
            }
            if path.len() >= self.max_vertices || bxdf.is_black() {
                break;
            }
            let (reads_u, reads_uc) = bxdf.reads_draws();
            let (u, uc) = (
                sampler.get_2d_if(reads_u, Dim::bsdf(bounces).on_light_path_if(self.importance)),
                sampler.get_1d_if(reads_uc, Dim::lobe(bounces).on_light_path_if(self.importance)),
            );
            let sample = if collapsed || bxdf.dispersion_within(out).is_some() {
                let one = wl.single();
                if !collapsed {
                    // The direction depends on the wavelength: the subpath collapses to the
                    // sample's wavelength; its throughput's value there moves to the slot.
                    let v = one.lambdas.sample(&beta)[0];
                    beta = Spectrum::ZERO;
                    beta[one.slot] = v;
                    collapsed = true;
                }
                bxdf.sample_within(sh.wo, u, uc, &one.lambdas, out).map(|s| {
                    let mut f = Spectrum::ZERO;
                    f[one.slot] = s.f[0];
                    crate::bxdf::BsdfSample { wi: s.wi, f, pdf: s.pdf, is_delta: s.is_delta, eta: s.eta }
                })
            } else {
                bxdf.sample_within(sh.wo, u, uc, &full, out)
            };
            let Some(bs) = sample else {
                break;
            };
            let wi = sh.frame.to_world(bs.wi);
            if !sh.consistent(wi, bs.wi) || bs.pdf.is_nan() || bs.pdf <= 0.0 {
                break;
            }
            let mut weight = bs.f * (bs.wi.z.abs() / bs.pdf);
            if self.importance {
                // The adjoint BSDF: no 1/η² radiance scaling; Veach's shading-normal correction.
                weight *= bs.eta * bs.eta * shading_correction(&sh, wi, bs.wi);
            } else {
                eta_scale *= bs.eta * bs.eta;
            }
            beta *= weight;
            if let Some((m, entering)) = crossing
                && wi.dot(hit.n) * ray.dir.dot(hit.n) > 0.0
            {
                media.cross(m, entering);
            }
            let (fwd, rev) = if bs.is_delta { (0.0, 0.0) } else { (bs.pdf, bxdf.pdf_within(bs.wi, sh.wo, &full, out)) };
            let n = path.len();
            path[n - 1].delta = bs.is_delta;
            if self.delta_first && n == 2 && !bs.is_delta && !scene.glossy_at(si.object, bxdf) {
                break;
            }
            path[n - 2].pdf_rev = rev * path[n - 1].g_prev;
            pdf_dir = fwd;
            if beta.is_black() {
                break;
            }
            bounces += 1;
            if bounces >= RR_DEPTH {
                // Continue with probability min(1, relative throughput): a
                // subpath that has lost nothing (a delta chain through clear
                // glass) is never cut, so exact cases stay exact.
                let q = (beta.max_value() * eta_scale / beta_ref).min(1.0);
                if sampler.get_1d_if(q < 1.0, Dim::roulette(bounces - 1).on_light_path_if(self.importance)) >= q
                    || q.is_nan()
                {
                    break;
                }
                beta /= q;
            }
            ray = Ray::spawn(hit.p, hit.n, wi);
        }
    }
}
