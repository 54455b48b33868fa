//! Bidirectional path tracing (`--integrator bdpt`) and light tracing
//! (`--integrator lighttrace`), spectral (Veach 1997 ch. 10; pbrt-v4 §13.4
//! describes the same bookkeeping: read, not copied).
//!
//! # Data flow of one camera sample
//! 1. One uniform number `u_λ` is drawn first (see *Wavelengths*).
//! 2. The **camera subpath** `x0 … x_{t-1}`: `x0` is the eye, `x1` the first
//!    hit of the pixel's ray, then BSDF sampling (radiance transport) up to
//!    `max_bounces + 1` surface vertices, Russian roulette after
//!    [`RR_DEPTH`] bounces. Each vertex keeps its throughput `β`, the area
//!    density `pdf_fwd` with which this walk generated it, and `pdf_rev`,
//!    the density with which a walk in the opposite direction would have.
//! 3. The **light subpath** `y0 … y_{s-1}`: a light chosen by power, a ray
//!    from [`Light::sample_le`], then BSDF sampling in importance transport
//!    (the adjoint BSDF: refraction is not scaled by `1/η²`, and shading
//!    normals get Veach's correction `|ωo·ns||ωi·ng| / (|ωo·ng||ωi·ns|)`),
//!    up to `max_bounces` surface vertices.
//! 4. **Every strategy** `(s, t)` with `s + t − 2 ≤ max_bounces` connects the
//!    prefixes: `s = 0` is the camera subpath hitting an emitter; `s = 1` is
//!    next-event estimation (a fresh light sample, as the path tracer's);
//!    `t = 1` connects a light vertex to the eye and is **splatted** to the
//!    pixel it projects to; the others join `y_{s-1}` and `x_{t-1}` with a
//!    shadow ray. Delta vertices (mirror, smooth glass, point and spot
//!    light positions, distant and beam directions) cannot be connection
//!    ends; their strategies get weight 0 and the others share their paths.
//! 5. Each strategy's contribution is weighted by the **power heuristic**
//!    over all strategies that could have made the same path,
//!    `w_s = p_s² / Σ_i p_i²`, computed from the ratios `pdf_rev / pdf_fwd`
//!    along the path (a zero density of a delta vertex counts as 1 in the
//!    ratios and its strategies are skipped, as in Veach's thesis §10.3.5).
//!    `lighttrace` uses only `t = 1`, unweighted.
//!
//! A camera sample's own value is the sum of its `t ≥ 2` strategies; its
//! `t = 1` splats go to the film's fixed-point sums wherever they land
//! (see [`crate::film::Splat`]). Each pass traces one light subpath per
//! pixel, so a splat is divided by the number of pixels: that is the
//! `1/A` in the camera importance `W_e = 1/(A cos⁴θ)`, `A` the whole film's
//! area on the plane at distance 1 (`Camera::pdf_dir`). Since a pass's light
//! subpaths are keyed like its camera samples, `(seed, pixel, pass)`, and
//! integer sums do not depend on order, images stay bit-identical for any
//! thread count, and `--passes`, resume and merge stay exact.
//!
//! # Wavelengths
//! Both subpaths carry the full 36-bin spectrum. Sampling a direction at a
//! dispersive surface needs one wavelength, so there the sample **collapses**
//! to one wavelength λ, drawn once per camera sample by `u_λ`: a bin `b` from
//! the fixed distribution `P_b ∝` visual importance ([`bin_importance`]), then
//! λ within `b`'s interpolation tent ([`continuous_wavelength`], density
//! `p(λ) = Σ_b P_b φ_b(λ)/A_b`; with `--spectral` output λ stays at the bin
//! centre, `p = P_b`, so the bins reproduce the colour exactly). Whichever
//! subpath meets dispersion first, both use the same λ, so their wavelengths
//! agree at every connection. From the collapse on, a subpath's throughput is
//! one value at λ (kept in one slot of its spectrum), and every material,
//! spectrum and index of refraction it meets is evaluated at λ. A connection
//! whose prefixes include a collapse (or whose end vertex is rough dispersive
//! glass) is computed at λ alone: each full-spectrum factor is interpolated
//! there, and the value `c(λ)` adds `c(λ) cmf(λ) / p(λ)` to the pixel (read
//! out through the one-wavelength packet).
//!
//! *Unbiased:* λ is independent of everything before the collapse and
//! `p(λ) > 0` wherever the colour matching functions are, so
//! `E_λ[c(λ) cmf(λ) / p(λ)] = ∫ c cmf dλ`, the colour integral, for every
//! strategy on its own; connections whose prefixes never met dispersion are
//! full-spectrum (read out with the bin weights `W_b`) and need no such weight. The MIS weights
//! use the same densities in every strategy (the reference-wavelength BSDF
//! pdf at rough dispersive vertices), so they sum to 1 over the strategies of
//! each path and any such weights keep the sum unbiased. A throughput-driven
//! draw (as `auto`'s) could not be shared between two independent subpaths;
//! the fixed draw costs colour noise only where dispersion is.
//!
//! # Nested dielectrics
//! Both walks carry a [`VolumeStack`], as the path tracer's do: the camera
//! subpath starts in [`Scene::camera_volumes`], a light subpath in the volumes
//! around its origin ([`Scene::volumes_at`], probed per subpath, only in scenes
//! with a dielectric). A false intersection is no vertex: the walk goes
//! straight on, and the next vertex's densities are those of the whole
//! straight line. Each vertex remembers the medium outside its dielectric
//! (for `eval`/`pdf`/`sample` with the right relative index) and, in scenes
//! with dielectrics, the stack it was reached in. A connection leaves each
//! end in the media on its side of the surface, passes false intersections
//! (a march, only where media nest; elsewhere one occlusion test), and is
//! attenuated by the one medium it runs in (the current medium does not
//! change at a false intersection).
//!
//! Russian roulette ([`RR_DEPTH`]) continues with probability
//! `min(1, β η_scale / β_0)`: a subpath that has lost nothing (a delta chain
//! through clear glass) is never cut, so exact cases stay exact.

mod connect;
mod mis;
mod vertex;
mod walk;

#[cfg(test)]
mod tests;

use std::cell::RefCell;

use glam::{Vec2, Vec3};

use crate::color::{Sampled, Spectrum};
use crate::film::Splat;
use crate::geometry::Ray;
use crate::medium::VolumeStack;
use crate::sampler::{Dim, Sampler};
use crate::scene::Scene;
use crate::spectral::{Contribution, Lambdas};

use super::caustics::Aim;
use super::{Estimator, camera_ray};
use crate::light::EmissionSample;
use vertex::{Contrib, Kind, Vertex, Wavelength};
use walk::Walk;

/// Russian roulette starts after this many scattering events on either
/// subpath (the path tracer waits for 5, as Mitsuba does). A subpath vertex
/// costs a connection to every vertex of the other subpath, so depth costs
/// BDPT quadratically: on `cornell.ron` (64x64, 6 seeds, callgrind and MSE
/// against an 8192-spp reference) starting at 1 instead of 5 cut the
/// instructions per sample by 42% and raised the error per sample by 9%,
/// 1.6x the efficiency (the path tracer gains 1.24x from the same change).
pub const RR_DEPTH: u32 = 1;

/// Bidirectional path tracing, or light tracing alone.
#[derive(Clone, Copy, Debug)]
pub struct Bdpt {
    /// Maximum number of scattering events on a full path.
    pub max_bounces: u32,
    /// Only the `t = 1` strategies, unweighted (`lighttrace`).
    pub light_only: bool,
}

/// The two subpaths of a sample and, in scenes with dielectrics, the medium
/// stack each vertex was reached in (index for index; empty otherwise).
#[derive(Default)]
struct Paths {
    camera: Vec<Vertex>,
    light: Vec<Vertex>,
    camera_media: Vec<VolumeStack>,
    light_media: Vec<VolumeStack>,
}

/// One subpath and its vertices' medium stacks.
#[derive(Clone, Copy)]
struct Sub<'p> {
    v: &'p [Vertex],
    media: &'p [VolumeStack],
}

impl Sub<'_> {
    /// The media around vertex `i` on the side of world direction `w` (None
    /// in a scene without dielectrics).
    #[inline]
    fn media_towards(&self, scene: &Scene, i: usize, w: Vec3) -> Option<VolumeStack> {
        let mut media = *self.media.get(i)?;
        let v = &self.v[i];
        if let Kind::Surface(o) = v.kind
            && let Some(m) = scene.volume(o)
            && w.dot(v.sh.n) * v.sh.wo_n < 0.0
        {
            // Across the surface from where the subpath arrived.
            media.cross(m, v.sh.wo_n > 0.0);
        }
        Some(media)
    }
}

thread_local! {
    /// The subpaths of the current sample, reused (no allocation per sample).
    static PATHS: RefCell<Paths> = RefCell::new(Paths::default());
}

impl Estimator for Bdpt {
    fn sample<O: Contribution>(
        &self,
        scene: &Scene,
        film: Vec2,
        sampler: &mut Sampler,
        splats: &mut Vec<Splat<O>>,
    ) -> O {
        PATHS.with(|paths| {
            let mut paths = paths.borrow_mut();
            let Paths { camera, light, camera_media, light_media } = &mut *paths;
            camera.clear();
            light.clear();
            camera_media.clear();
            light_media.clear();
            let track = scene.has_volumes();
            let mut wl = Wavelength { u: sampler.get_1d(Dim::wavelength(0)), continuous: O::CONTINUOUS, drawn: None };
            let full = Lambdas::full();
            let (mut l, mut l_single) = (Spectrum::ZERO, 0.0f32);
            if !self.light_only {
                self.camera_subpath(scene, film, sampler, camera, track.then_some(&mut *camera_media), &mut wl);
            } else if scene.has_environment() {
                // Light tracing cannot reach the eye from infinity: the environment
                // seen directly is the pixel ray's, unweighted (the only strategy).
                // Through index-matched boundaries and false intersections, attenuated by
                // the media on the way (the one visibility rule).
                let ray = camera_ray(scene, film, sampler);
                let far = ray.origin + ray.dir * (4.0 * scene.radius() + (ray.origin - scene.camera.eye()).length());
                let volumes = scene.has_volumes().then_some(&scene.camera_volumes);
                if let Some((_, le)) = scene.escaped(ray.dir)
                    && let Some(clear) = scene.transmittance(ray.origin, Vec3::ZERO, volumes, far, -ray.dir)
                {
                    l += match clear.spectrum() {
                        Some(t) => le * t,
                        None => le,
                    };
                }
            }
            self.light_subpath(scene, None, sampler, light, track.then_some(&mut *light_media), &mut wl);
            let max = self.max_bounces as usize;
            let (camera, light) = (Sub { v: camera, media: camera_media }, Sub { v: light, media: light_media });
            let t_range = if self.light_only { 1..=1 } else { 1..=camera.v.len() };
            for t in t_range {
                for s in 0..=light.v.len() {
                    if s + t < 2 || s + t - 2 > max || (t == 1 && s == 0) {
                        continue;
                    }
                    if t == 1 {
                        if let Some((pixel, c)) = self.connect_camera(scene, light, s, camera, sampler, &mut wl) {
                            let value = match c {
                                Contrib::Full(c) => O::from_packet(&scene.sensor, &full, &c),
                                Contrib::Single(v) => {
                                    O::from_packet(&scene.sensor, &wl.single().lambdas, &Sampled([v]))
                                }
                            };
                            splats.push(Splat { x: pixel.x as u32, y: pixel.y as u32, value });
                        }
                    } else if !self.light_only {
                        match self.connect(scene, camera, t, light, s, sampler, &mut wl) {
                            Contrib::Full(c) => l += c,
                            Contrib::Single(v) => l_single += v,
                        }
                    }
                }
            }
            let mut out = O::from_packet(&scene.sensor, &full, &l);
            if let Some(one) = wl.drawn {
                out += O::from_packet(&scene.sensor, &one.lambdas, &Sampled([l_single]));
            }
            out
        })
    }
}

impl Bdpt {
    /// `caustics`' light side for one camera sample: one aimed light subpath
    /// (its wavelength draw `u_λ` from [`Dim::wavelength`]`(1)`, which the
    /// camera side never draws), and, when its first surface vertex
    /// scattered through a delta lobe or is glossy on a bounded object, every later vertex `y_i`,
    /// `i ≥ 2`, that is not glossy connected to the eye (`t = 1`, weight 1, as
    /// `lighttrace`'s: `self` is `light_only`) and splatted to `splats`,
    /// scaled by `weight`.
    pub(crate) fn caustic_splats<O: Contribution>(
        &self,
        scene: &Scene,
        aim: &Aim,
        sampler: &mut Sampler,
        splats: &mut Vec<Splat<O>>,
        weight: f32,
    ) {
        debug_assert!(self.light_only, "caustics' light side is unweighted");
        PATHS.with(|paths| {
            let mut paths = paths.borrow_mut();
            let Paths { camera, light, camera_media, light_media } = &mut *paths;
            camera.clear();
            light.clear();
            camera_media.clear();
            light_media.clear();
            let track = scene.has_volumes();
            let mut wl = Wavelength { u: sampler.get_1d(Dim::wavelength(1)), continuous: O::CONTINUOUS, drawn: None };
            self.light_subpath(scene, Some(aim), sampler, light, track.then_some(&mut *light_media), &mut wl);
            if light.len() < 3 || !(light[1].delta || light[1].glossy) {
                return;
            }
            let full = Lambdas::full();
            let max = self.max_bounces as usize;
            let (camera, light) = (Sub { v: camera, media: camera_media }, Sub { v: light, media: light_media });
            for s in 3..=light.v.len().min(max + 1) {
                // A glossy `y_i` seen from the eye is the camera side's (its `X1`).
                if light.v[s - 1].glossy {
                    continue;
                }
                if let Some((pixel, c)) = self.connect_camera(scene, light, s, camera, sampler, &mut wl) {
                    let value = match c {
                        Contrib::Full(c) => O::from_packet(&scene.sensor, &full, &(c * weight)),
                        Contrib::Single(v) => {
                            O::from_packet(&scene.sensor, &wl.single().lambdas, &Sampled([v * weight]))
                        }
                    };
                    splats.push(Splat { x: pixel.x as u32, y: pixel.y as u32, value });
                }
            }
        })
    }

    /// The eye and the walk of the pixel ray.
    fn camera_subpath(
        &self,
        scene: &Scene,
        film: Vec2,
        sampler: &mut Sampler,
        path: &mut Vec<Vertex>,
        mut stacks: Option<&mut Vec<VolumeStack>>,
        wl: &mut Wavelength,
    ) {
        let cam = &scene.camera;
        let ray = camera_ray(scene, film, sampler);
        path.push(Vertex::at_point(Kind::Camera, ray.origin, cam.forward(), Spectrum::ONE, 1.0));
        if let Some(stacks) = stacks.as_deref_mut() {
            stacks.push(scene.camera_volumes);
        }
        let pdf_dir = cam.pdf_dir_from(ray.origin, ray.dir);
        let walk = Walk { importance: false, max_vertices: self.max_bounces as usize + 2, delta_first: false };
        walk.run(scene, ray, Spectrum::ONE, pdf_dir, false, sampler, path, stacks, scene.camera_volumes, wl);
    }

    /// A light subpath: a light by power and a ray leaving it ([`crate::light::Light::sample_le`]);
    /// or, for `caustics`' light side (`aim`), an aimed light by
    /// [`Aim::choose_light`] and its ray by [`Aim::aimed_ray`], the walk then
    /// ending at its first surface vertex unless that scattered through a delta
    /// lobe. Both draw the same dimensions in the same order.
    fn light_subpath(
        &self,
        scene: &Scene,
        aim: Option<&Aim>,
        sampler: &mut Sampler,
        path: &mut Vec<Vertex>,
        stacks: Option<&mut Vec<VolumeStack>>,
        wl: &mut Wavelength,
    ) {
        let lights = aim.map_or(scene.light_count(), Aim::light_count);
        let u_light = sampler.get_1d_if(lights > 1, Dim::EMIT_CHOICE);
        let (u_pos, u_dir) = (sampler.get_2d(Dim::EMIT_POSITION), sampler.get_2d(Dim::EMIT_DIRECTION));
        let ray = match aim {
            None => scene.choose_light(u_light).and_then(|(index, pmf)| {
                let index = index as u32;
                scene.light(index).sample_le(u_pos, u_dir).map(|e| (index, pmf, e))
            }),
            Some(aim) => aim
                .choose_light(u_light)
                .and_then(|(index, pmf)| aim.aimed_ray(scene, index, u_pos, u_dir).map(|e| (index, pmf, e))),
        };
        if let Some((index, pmf, e)) = ray {
            self.walk_from_light(scene, index, pmf, e, aim.is_some(), sampler, path, stacks, wl);
        }
    }

    /// The light vertex of ray `e` leaving light `index` (chosen with
    /// probability `pmf`) and the subpath's walk from it.
    #[allow(clippy::too_many_arguments)]
    fn walk_from_light(
        &self,
        scene: &Scene,
        index: u32,
        pmf: f32,
        e: EmissionSample,
        delta_first: bool,
        sampler: &mut Sampler,
        path: &mut Vec<Vertex>,
        mut stacks: Option<&mut Vec<VolumeStack>>,
        wl: &mut Wavelength,
    ) {
        let light = scene.light(index);
        let pdf_origin = pmf * e.pdf_pos;
        if !(pdf_origin > 0.0 && e.pdf_dir > 0.0) {
            return;
        }
        let infinite = light.is_infinite();
        let beta0 = scene.with_radiance(index, -e.dir, e.uv, |s| *s / pdf_origin);
        // The environment's first vertex is a direction: its density is the
        // direction's (per solid angle), as a camera subpath escaping along it sees it.
        let pdf_y0 = if infinite { pmf * e.pdf_dir } else { pdf_origin };
        path.push(Vertex::at_point(Kind::Light(index), e.point, e.n, beta0, pdf_y0));
        let media = scene.volumes_at(e.point);
        if let Some(stacks) = stacks.as_deref_mut() {
            stacks.push(media);
        }
        let cos = if light.is_delta() || infinite { 1.0 } else { e.dir.dot(e.n).abs() };
        let beta = beta0 * (e.scale * cos / e.pdf_dir);
        // A parallel light's (or the environment's) next vertex has the density of the
        // ray's origin on the light's disk, projected (no 1/d²): passed as its "pdf".
        let (pdf, parallel) =
            if light.is_delta_direction() || infinite { (e.pdf_pos, true) } else { (e.pdf_dir, false) };
        let ray = Ray::spawn(e.point, e.n, e.dir);
        let walk = Walk { importance: true, max_vertices: self.max_bounces as usize + 1, delta_first };
        walk.run(scene, ray, beta, pdf, parallel, sampler, path, stacks, media, wl);
    }
}
