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
//! Both walks carry a [`MediumStack`], as the path tracer's do: the camera
//! subpath starts in [`Scene::camera_media`], a light subpath in the media
//! around its origin ([`Scene::media_at`], probed per subpath, only in scenes
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

use std::cell::RefCell;
use std::sync::LazyLock;

use glam::{Vec2, Vec3};

use crate::bxdf::{Bxdf, Crossing, MediumStack, Outside};
use crate::color::{N_BINS, Sampled, Spectrum};
use crate::film::Splat;
use crate::geometry::{Frame, Ray};
use crate::light::Light;
use crate::sampler::{Dim, Sampler};
use crate::scene::Scene;
use crate::spectral::{BinDistribution, Contribution, Lambdas, Readout, bin_importance, continuous_wavelength};

use super::{Estimator, MAX_PASSES, Shading, absorption};

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

/// What a subpath vertex is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    /// The eye.
    Camera,
    /// A point on light `index`.
    Light(u32),
    /// A surface point of object `index`.
    Surface(u32),
}

/// A subpath vertex.
#[derive(Clone, Copy, Debug)]
struct Vertex {
    kind: Kind,
    /// Position, geometric normal, shading frame and the local direction
    /// back along the subpath (`wo`).
    sh: Shading,
    /// Throughput of the subpath up to and including this vertex's arrival.
    beta: Spectrum,
    /// The scattering sampled here was a delta lobe.
    delta: bool,
    /// The subpath collapsed to one wavelength before reaching this vertex.
    collapsed: bool,
    /// Area density of this vertex as its own walk generated it.
    pdf_fwd: f32,
    /// Area density of this vertex as a walk from the other end would.
    pdf_rev: f32,
    /// The factor that turns a density per solid angle here towards the
    /// previous vertex into an area density there: `|cos| / d²` at the
    /// previous vertex (no cosine at the eye or a point light; 0 at a
    /// subpath's first vertex). Kept so connections need not recompute it.
    g_prev: f32,
    /// At a dielectric's surface, the material of the medium on its outside
    /// (`None`: vacuum, or not a dielectric).
    outside: Option<u32>,
}

impl Vertex {
    fn at_point(kind: Kind, p: Vec3, n: Vec3, beta: Spectrum, pdf_fwd: f32) -> Vertex {
        let frame = Frame::from_z(if n == Vec3::ZERO { Vec3::Z } else { n });
        let sh = Shading { p, n, frame, wo: Vec3::Z, wo_n: 0.0 };
        Vertex { kind, sh, beta, delta: false, collapsed: false, pdf_fwd, pdf_rev: 0.0, g_prev: 0.0, outside: None }
    }

    #[inline]
    fn p(&self) -> Vec3 {
        self.sh.p
    }

    /// True when densities arriving at this vertex carry its cosine (area
    /// measure on a surface): surfaces and area lights, not the eye or a
    /// point, spot, distant or beam light.
    #[inline]
    fn on_surface(&self, scene: &Scene) -> bool {
        match self.kind {
            Kind::Surface(_) => true,
            Kind::Light(i) => !scene.lights[i as usize].is_delta(),
            Kind::Camera => false,
        }
    }
}

/// The one wavelength a sample collapses to, drawn lazily from `u_λ`.
struct Wavelength {
    u: f32,
    /// Continuous wavelengths (colour output); bin centres for spectral output.
    continuous: bool,
    drawn: Option<Single>,
}

/// The collapsed wavelength: the slot of a throughput that holds its value,
/// and the packet of one wavelength (with the weight `1/p`) that evaluates
/// materials at it and reads its value out as colour.
#[derive(Clone, Copy, Debug)]
struct Single {
    slot: usize,
    lambdas: Lambdas<1>,
}

impl Wavelength {
    /// The sample's wavelength (drawn on first use).
    fn single(&mut self) -> Single {
        static DIST: LazyLock<BinDistribution> = LazyLock::new(|| {
            let importance = bin_importance();
            BinDistribution::new(|b| importance[b]).expect("visual importance is positive")
        });
        let (u, continuous) = (self.u, self.continuous);
        *self.drawn.get_or_insert_with(|| {
            if continuous {
                let (lambdas, _) = continuous_wavelength(&DIST, u);
                Single { slot: (lambdas.pos[0].round().max(0.0) as usize).min(N_BINS - 1), lambdas }
            } else {
                let (b, p) = DIST.sample(u);
                Single { slot: b, lambdas: Lambdas { pos: [b as f32], weight: 1.0 / p, readout: Readout::Spectral } }
            }
        })
    }

    /// The value of throughput `v` at the sample's wavelength: the slot that
    /// holds it once its subpath has collapsed, else its interpolation there.
    fn at(&mut self, v: &Spectrum, collapsed: bool) -> f32 {
        let one = self.single();
        if collapsed { v[one.slot] } else { one.lambdas.sample(v)[0] }
    }
}

/// A strategy's contribution: the full spectrum, or one value at the
/// sample's collapsed wavelength.
#[derive(Clone, Copy, Debug)]
enum Contrib {
    Full(Spectrum),
    Single(f32),
}

/// Veach's correction of the adjoint BSDF for shading normals: the factor
/// by which importance transport differs from radiance transport where the
/// shading normal is not the geometric one (1 on flat geometry).
#[inline]
fn shading_correction(sh: &Shading, wi: Vec3, wi_local: Vec3) -> f32 {
    let den = sh.wo_n.abs() * wi_local.z.abs();
    let c = sh.wo.z.abs() * wi.dot(sh.n).abs() / den;
    if c.is_finite() { c } else { 0.0 }
}

/// The two subpaths of a sample and, in scenes with dielectrics, the medium
/// stack each vertex was reached in (index for index; empty otherwise).
#[derive(Default)]
struct Paths {
    camera: Vec<Vertex>,
    light: Vec<Vertex>,
    camera_media: Vec<MediumStack>,
    light_media: Vec<MediumStack>,
}

/// One subpath and its vertices' medium stacks.
#[derive(Clone, Copy)]
struct Sub<'p> {
    v: &'p [Vertex],
    media: &'p [MediumStack],
}

impl Sub<'_> {
    /// The media around vertex `i` on the side of world direction `w` (None
    /// in a scene without dielectrics).
    #[inline]
    fn media_towards(&self, scene: &Scene, i: usize, w: Vec3) -> Option<MediumStack> {
        let mut media = *self.media.get(i)?;
        let v = &self.v[i];
        if let Kind::Surface(o) = v.kind
            && let Some(m) = scene.medium(o)
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
            let track = scene.has_media();
            let mut wl = Wavelength { u: sampler.get_1d(Dim::wavelength(0)), continuous: O::CONTINUOUS, drawn: None };
            let full = Lambdas::full();
            let (mut l, mut l_single) = (Spectrum::ZERO, 0.0f32);
            if !self.light_only {
                self.camera_subpath(scene, film, sampler, camera, track.then_some(&mut *camera_media), &mut wl);
            }
            self.light_subpath(scene, sampler, light, track.then_some(&mut *light_media), &mut wl);
            let max = self.max_bounces as usize;
            let (camera, light) = (Sub { v: camera, media: camera_media }, Sub { v: light, media: light_media });
            let t_range = if self.light_only { 1..=1 } else { 1..=camera.v.len() };
            for t in t_range {
                for s in 0..=light.v.len() {
                    if s + t < 2 || s + t - 2 > max || (t == 1 && s == 0) {
                        continue;
                    }
                    if t == 1 {
                        if let Some((pixel, c)) = self.connect_camera(scene, light, s, camera, &mut wl) {
                            let value = match c {
                                Contrib::Full(c) => O::from_packet(&full, &c),
                                Contrib::Single(v) => O::from_packet(&wl.single().lambdas, &Sampled([v])),
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
            let mut out = O::from_packet(&full, &l);
            if let Some(one) = wl.drawn {
                out += O::from_packet(&one.lambdas, &Sampled([l_single]));
            }
            out
        })
    }
}

impl Bdpt {
    /// The eye and the walk of the pixel ray.
    fn camera_subpath(
        &self,
        scene: &Scene,
        film: Vec2,
        sampler: &mut Sampler,
        path: &mut Vec<Vertex>,
        mut stacks: Option<&mut Vec<MediumStack>>,
        wl: &mut Wavelength,
    ) {
        let cam = &scene.camera;
        let ray = cam.ray(film);
        path.push(Vertex::at_point(Kind::Camera, ray.origin, cam.forward(), Spectrum::ONE, 1.0));
        if let Some(stacks) = stacks.as_deref_mut() {
            stacks.push(scene.camera_media);
        }
        let pdf_dir = cam.pdf_dir(ray.dir);
        let walk = Walk { importance: false, max_vertices: self.max_bounces as usize + 2 };
        walk.run(scene, ray, Spectrum::ONE, pdf_dir, false, sampler, path, stacks, scene.camera_media, wl);
    }

    /// A light by power, a ray leaving it, and its walk.
    fn light_subpath(
        &self,
        scene: &Scene,
        sampler: &mut Sampler,
        path: &mut Vec<Vertex>,
        mut stacks: Option<&mut Vec<MediumStack>>,
        wl: &mut Wavelength,
    ) {
        let u_light = sampler.get_1d_if(scene.lights.len() > 1, Dim::EMIT_CHOICE);
        let (u_pos, u_dir) = (sampler.get_2d(Dim::EMIT_POSITION), sampler.get_2d(Dim::EMIT_DIRECTION));
        let Some((index, pmf)) = scene.choose_light(u_light) else {
            return;
        };
        let light = &scene.lights[index];
        let Some(e) = light.sample_le(u_pos, u_dir) else {
            return;
        };
        let pdf_origin = pmf * e.pdf_pos;
        if !(pdf_origin > 0.0 && e.pdf_dir > 0.0) {
            return;
        }
        let beta0 = *light.spectrum() / pdf_origin;
        path.push(Vertex::at_point(Kind::Light(index as u32), e.point, e.n, beta0, pdf_origin));
        let media = scene.media_at(e.point);
        if let Some(stacks) = stacks.as_deref_mut() {
            stacks.push(media);
        }
        let cos = if light.is_delta() { 1.0 } else { e.dir.dot(e.n).abs() };
        let beta = beta0 * (e.scale * cos / e.pdf_dir);
        // A parallel light's next vertex has the density of the ray's origin
        // on the light's disk, projected (no 1/d²): passed as its "pdf".
        let (pdf, parallel) = if light.is_delta_direction() { (e.pdf_pos, true) } else { (e.pdf_dir, false) };
        let ray = Ray::spawn(e.point, e.n, e.dir);
        let walk = Walk { importance: true, max_vertices: self.max_bounces as usize + 1 };
        walk.run(scene, ray, beta, pdf, parallel, sampler, path, stacks, media, wl);
    }

    /// Strategy `(s, t = 1)`: light vertex `y_{s-1}` seen by the eye. Returns
    /// the film position and the MIS-weighted contribution.
    fn connect_camera(
        &self,
        scene: &Scene,
        light: Sub<'_>,
        s: usize,
        camera: Sub<'_>,
        wl: &mut Wavelength,
    ) -> Option<(Vec2, Contrib)> {
        let qs = &light.v[s - 1];
        if !connectible(scene, qs) {
            return None;
        }
        let cam = &scene.camera;
        let eye = cam.eye();
        let to_eye = eye - qs.p();
        let d2 = to_eye.length_squared();
        if d2.is_nan() || d2 <= 0.0 {
            return None;
        }
        let w = to_eye / d2.sqrt();
        let film = cam.project(-w)?;
        let cos_cam = (-w).dot(cam.forward());
        let importance = 1.0 / (d2 * cam.plane_area() * cos_cam * cos_cam * cos_cam);
        let single = qs.collapsed || is_dispersive(scene, qs);
        // Emission (s = 1) or the adjoint BSDF towards the eye, with the cosine at y.
        let c = match qs.kind {
            Kind::Light(i) => {
                let light = &scene.lights[i as usize];
                if light.is_delta() {
                    // Point and spot lights are invisible to the camera in every
                    // integrator (path tracing cannot see them either).
                    return None;
                }
                let e = emit_factor(light, qs.sh.n, w) * importance;
                if e.is_nan() || e <= 0.0 {
                    return None;
                }
                if single { Contrib::Single(wl.at(&qs.beta, qs.collapsed) * e) } else { Contrib::Full(qs.beta * e) }
            }
            Kind::Surface(o) => {
                let bxdf = material(scene, o);
                let wi = qs.sh.frame.to_local(w);
                if !qs.sh.consistent(w, wi) {
                    return None;
                }
                let k = wi.z.abs() * shading_correction(&qs.sh, w, wi) * importance;
                let out = outside(scene, qs.outside);
                if single {
                    let one = wl.single();
                    let f = bxdf.eval_within(wi, qs.sh.wo, &one.lambdas, out)[0];
                    Contrib::Single(wl.at(&qs.beta, qs.collapsed) * f * k)
                } else {
                    Contrib::Full(qs.beta * bxdf.eval_within(wi, qs.sh.wo, &Lambdas::full(), out) * k)
                }
            }
            Kind::Camera => return None,
        };
        if is_black(&c) {
            return None;
        }
        let transmittance = segment(scene, qs, light.media_towards(scene, s - 1, w).as_ref(), eye)?;
        let weight = if self.light_only {
            1.0
        } else {
            let eye_v = &camera.v[0];
            let qs_rev = to_area(scene, cam.pdf_dir(-w), eye_v, qs);
            let qsm_rev = match qs.kind {
                Kind::Surface(_) if s >= 2 => pdf_at(scene, qs, qs.sh.frame.to_local(w), qs.sh.wo) * qs.g_prev,
                _ => 0.0,
            };
            mis_weight(scene, camera.v, 1, light.v, s, Overrides { pt_rev: 0.0, ptm_rev: 0.0, qs_rev, qsm_rev })
        };
        Some((film, scale(c, weight, transmittance, wl)))
    }

    /// Strategies `(s, t ≥ 2)`: emitter hit (`s = 0`), next-event estimation
    /// (`s = 1`), or a connection of `x_{t-1}` and `y_{s-1}`; MIS-weighted.
    #[allow(clippy::too_many_arguments)]
    fn connect(
        &self,
        scene: &Scene,
        camera: Sub<'_>,
        t: usize,
        light: Sub<'_>,
        s: usize,
        sampler: &mut Sampler,
        wl: &mut Wavelength,
    ) -> Contrib {
        const NONE: Contrib = Contrib::Full(Spectrum::ZERO);
        let pt = &camera.v[t - 1];
        let Kind::Surface(object) = pt.kind else {
            return NONE;
        };
        let ptm = &camera.v[t - 2];
        match s {
            0 => {
                // The camera subpath ends on an emitter.
                let Some(index) = scene.objects[object as usize].light else {
                    return NONE;
                };
                let light = &scene.lights[index as usize];
                let dir = (pt.p() - ptm.p()).normalize();
                let le = light.le_scale(pt.sh.n, dir);
                if le <= 0.0 {
                    return NONE;
                }
                let c = if pt.collapsed {
                    let one = wl.single();
                    Contrib::Single(pt.beta[one.slot] * one.lambdas.sample(light.spectrum())[0] * le)
                } else {
                    Contrib::Full(pt.beta * *light.spectrum() * le)
                };
                let (pdf_pos, pdf_dir) = light.pdf_le(pt.sh.n, -dir);
                let pt_rev = scene.light_pmf[index as usize] * pdf_pos;
                let as_light = Vertex { kind: Kind::Light(index), ..*pt };
                let ptm_rev = to_area(scene, pdf_dir, &as_light, ptm);
                let overrides = Overrides { pt_rev, ptm_rev, qs_rev: 0.0, qsm_rev: 0.0 };
                scale(c, mis_weight(scene, camera.v, t, &[], 0, overrides), None, wl)
            }
            1 => {
                // Next-event estimation: a fresh point on a light.
                let (u_light, u) = (
                    sampler.get_1d_if(scene.lights.len() > 1, Dim::light_choice(t as u32 - 2)),
                    sampler.get_2d(Dim::light_sample(t as u32 - 2)),
                );
                if !connectible(scene, pt) {
                    return NONE;
                }
                let Some((index, pmf)) = scene.choose_light(u_light) else {
                    return NONE;
                };
                let light = &scene.lights[index];
                let Some(ls) = light.sample_li(pt.p(), u) else {
                    return NONE;
                };
                let wi = pt.sh.frame.to_local(ls.wi);
                if !pt.sh.consistent(ls.wi, wi) || ls.pdf.is_nan() || ls.pdf <= 0.0 {
                    return NONE;
                }
                let bxdf = material(scene, object);
                let out = outside(scene, pt.outside);
                let k = ls.scale * wi.z.abs() / (pmf * ls.pdf);
                let c = if pt.collapsed || is_dispersive(scene, pt) {
                    let one = wl.single();
                    let f = bxdf.eval_within(pt.sh.wo, wi, &one.lambdas, out)[0];
                    Contrib::Single(wl.at(&pt.beta, pt.collapsed) * f * one.lambdas.sample(light.spectrum())[0] * k)
                } else {
                    Contrib::Full(
                        pt.beta * bxdf.eval_within(pt.sh.wo, wi, &Lambdas::full(), out) * *light.spectrum() * k,
                    )
                };
                if is_black(&c) {
                    return NONE;
                }
                let media = camera.media_towards(scene, t - 1, ls.wi);
                let Some(transmittance) = segment(scene, pt, media.as_ref(), ls.point) else {
                    return NONE;
                };
                // The sampled light vertex, for the MIS weight.
                let (pdf_pos, _) = light.pdf_le(ls.n, -ls.wi);
                let y = Vertex::at_point(Kind::Light(index as u32), ls.point, ls.n, Spectrum::ONE, pmf * pdf_pos);
                let pt_rev = pdf_light(scene, &y, pt);
                let ptm_rev = bxdf.pdf_within(wi, pt.sh.wo, &Lambdas::full(), out) * pt.g_prev;
                let qs_rev = to_area(scene, bxdf.pdf_within(pt.sh.wo, wi, &Lambdas::full(), out), pt, &y);
                let overrides = Overrides { pt_rev, ptm_rev, qs_rev, qsm_rev: 0.0 };
                let weight = mis_weight(scene, camera.v, t, std::slice::from_ref(&y), 1, overrides);
                scale(c, weight, transmittance, wl)
            }
            _ => {
                let qs = &light.v[s - 1];
                if !connectible(scene, pt) || !connectible(scene, qs) {
                    return NONE;
                }
                let Kind::Surface(q_object) = qs.kind else {
                    return NONE;
                };
                let d = qs.p() - pt.p();
                let d2 = d.length_squared();
                if d2.is_nan() || d2 <= 0.0 {
                    return NONE;
                }
                let w = d / d2.sqrt();
                let (wi_p, wi_q) = (pt.sh.frame.to_local(w), qs.sh.frame.to_local(-w));
                if !pt.sh.consistent(w, wi_p) || !qs.sh.consistent(-w, wi_q) {
                    return NONE;
                }
                let (bp, bq) = (material(scene, object), material(scene, q_object));
                let (op, oq) = (outside(scene, pt.outside), outside(scene, qs.outside));
                let k = wi_p.z.abs() * wi_q.z.abs() / d2 * shading_correction(&qs.sh, -w, wi_q);
                let c = if pt.collapsed || qs.collapsed || is_dispersive(scene, pt) || is_dispersive(scene, qs) {
                    let one = wl.single();
                    let fp = bp.eval_within(pt.sh.wo, wi_p, &one.lambdas, op)[0];
                    let fq = bq.eval_within(wi_q, qs.sh.wo, &one.lambdas, oq)[0];
                    Contrib::Single(wl.at(&pt.beta, pt.collapsed) * fp * fq * wl.at(&qs.beta, qs.collapsed) * k)
                } else {
                    let full = Lambdas::full();
                    let (fp, fq) =
                        (bp.eval_within(pt.sh.wo, wi_p, &full, op), bq.eval_within(wi_q, qs.sh.wo, &full, oq));
                    Contrib::Full(pt.beta * fp * fq * qs.beta * k)
                };
                if is_black(&c) {
                    return NONE;
                }
                let media = camera.media_towards(scene, t - 1, w);
                let Some(transmittance) = segment(scene, pt, media.as_ref(), qs.p()) else {
                    return NONE;
                };
                // The four densities the connection changes, from the local
                // directions already at hand (`wo` points back along each subpath).
                let full = Lambdas::full();
                let pt_rev = bq.pdf_within(qs.sh.wo, wi_q, &full, oq) * w.dot(pt.sh.n).abs() / d2;
                let qs_rev = bp.pdf_within(pt.sh.wo, wi_p, &full, op) * w.dot(qs.sh.n).abs() / d2;
                let ptm_rev = bp.pdf_within(wi_p, pt.sh.wo, &full, op) * pt.g_prev;
                let qsm_rev = bq.pdf_within(wi_q, qs.sh.wo, &full, oq) * qs.g_prev;
                let weight = mis_weight(scene, camera.v, t, light.v, s, Overrides { pt_rev, ptm_rev, qs_rev, qsm_rev });
                scale(c, weight, transmittance, wl)
            }
        }
    }
}

/// True when a contribution is zero. (A NaN is not: it reaches the film,
/// which drops and counts it, so a bug cannot hide here.)
#[inline]
fn is_black(c: &Contrib) -> bool {
    match c {
        Contrib::Full(s) => s.is_black(),
        Contrib::Single(v) => *v == 0.0,
    }
}

/// A contribution times the MIS weight and a segment's transmittance (if
/// the segment runs inside an absorbing dielectric).
#[inline]
fn scale(c: Contrib, weight: f32, transmittance: Option<Spectrum>, wl: &mut Wavelength) -> Contrib {
    match (c, transmittance) {
        (Contrib::Full(s), None) => Contrib::Full(s * weight),
        (Contrib::Full(s), Some(tr)) => Contrib::Full(s * tr * weight),
        (Contrib::Single(v), None) => Contrib::Single(v * weight),
        (Contrib::Single(v), Some(tr)) => Contrib::Single(v * wl.at(&tr, false) * weight),
    }
}

/// A subpath walk's fixed parameters.
struct Walk {
    /// Importance transport (the light subpath) rather than radiance.
    importance: bool,
    /// The most vertices the subpath may have, its first included.
    max_vertices: usize,
}

impl Walk {
    /// Extends `path` along `ray` by BSDF sampling. `pdf_dir` is the density
    /// of `ray`'s direction at the last vertex (per solid angle; for a
    /// `parallel` light, per area of its disk).
    #[allow(clippy::too_many_arguments)]
    fn run(
        &self,
        scene: &Scene,
        mut ray: Ray,
        mut beta: Spectrum,
        mut pdf_dir: f32,
        mut parallel: bool,
        sampler: &mut Sampler,
        path: &mut Vec<Vertex>,
        mut stacks: Option<&mut Vec<MediumStack>>,
        mut media: MediumStack,
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
                break;
            };
            let hit = si.hit;
            let bxdf = material(scene, si.object);
            // Beer-Lambert along the segment, in the medium it ran in.
            if let Some(sigma) = absorption(scene, media.current()) {
                if collapsed {
                    let one = wl.single();
                    beta[one.slot] *= (-one.lambdas.sample(sigma)[0] * hit.t).exp();
                } else {
                    beta *= (*sigma * -hit.t).exp();
                }
            }
            // Nested dielectrics: a false intersection is no vertex; the walk
            // goes straight on (densities stay those of the whole straight line).
            let arrival = media;
            let mut crossing = None;
            let mut outside_material = None;
            if let Some(m) = scene.medium(si.object) {
                let entering = ray.dir.dot(hit.n) < 0.0;
                match media.crossing(m, entering) {
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
                collapsed,
                pdf_fwd: 0.0,
                pdf_rev: 0.0,
                g_prev: 0.0,
                outside: outside_material,
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

/// The material of object `o`.
#[inline]
fn material(scene: &Scene, o: u32) -> &Bxdf {
    &scene.materials[scene.objects[o as usize].material as usize]
}

/// True when a connection can end at `v`: a surface whose material has a
/// non-delta part (a plastic whose walk sampled its mirror coat still has
/// its diffuse base), or a light. Not the sampled lobe's `delta` flag,
/// which only says how the walk continued.
#[inline]
fn connectible(scene: &Scene, v: &Vertex) -> bool {
    match v.kind {
        Kind::Surface(o) => !material(scene, o).is_delta(),
        Kind::Light(_) | Kind::Camera => true,
    }
}

/// True when vertex `v` lies on a dispersive surface (its glass or the
/// medium outside it disperses).
#[inline]
fn is_dispersive(scene: &Scene, v: &Vertex) -> bool {
    matches!(v.kind, Kind::Surface(o) if material(scene, o).dispersion_within(outside(scene, v.outside)).is_some())
}

/// The emitted quantity from light point (normal `n`) towards `w`, as a
/// factor of the light's spectrum, times the cosine at an area light.
#[inline]
fn emit_factor(light: &Light, n: Vec3, w: Vec3) -> f32 {
    match light {
        Light::Point(_) => 1.0,
        Light::Spot(l) => l.falloff(w),
        Light::Distant(_) | Light::Beam(_) => 0.0,
        Light::Sphere(_) | Light::Disk(_) | Light::Area(_) => light.le_scale(n, -w) * w.dot(n).abs(),
    }
}

/// The medium outside a dielectric vertex, from its material index.
#[inline]
fn outside(scene: &Scene, material: Option<u32>) -> Outside<'_> {
    match material.and_then(|m| scene.materials[m as usize].as_dielectric()) {
        Some(d) => Outside::medium(d),
        None => Outside::VACUUM,
    }
}

/// The segment of a connection from vertex `v` to point `to`, starting in
/// `media` (the media around `v` on the segment's side; `None` in a scene
/// without dielectrics). `None` when something blocks it; else the
/// segment's transmittance when it runs in an absorbing medium.
///
/// Among nested dielectrics a segment passes false intersections (surfaces
/// the medium stack says are not interfaces here, at most [`MAX_PASSES`]);
/// the medium it runs in does not change at them, so one Beer-Lambert factor
/// of the current medium over the whole length is exact.
fn segment(scene: &Scene, v: &Vertex, media: Option<&MediumStack>, to: Vec3) -> Option<Option<Spectrum>> {
    let (mut ray, mut t_max) = Ray::spawn_to(v.p(), v.sh.n, to);
    match media {
        Some(stack) if scene.has_nested_media() => {
            let mut stack = *stack;
            let mut passes = 0;
            while let Some(si) = scene.intersect(&ray, t_max) {
                let entering = ray.dir.dot(si.hit.n) < 0.0;
                match scene.medium(si.object) {
                    Some(m) if passes < MAX_PASSES && stack.crossing(m, entering) == Crossing::Pass => {
                        stack.cross(m, entering);
                        passes += 1;
                        (ray, t_max) = Ray::spawn_to(si.hit.p, si.hit.n, to);
                    }
                    _ => return None,
                }
            }
        }
        _ => {
            if scene.occluded(&ray, t_max) {
                return None;
            }
        }
    }
    Some(absorption(scene, media.and_then(|m| m.current())).map(|sigma| (*sigma * -(to - v.p()).length()).exp()))
}

/// Converts a density per solid angle at `from` towards `to` into a density
/// per unit area at `to`.
#[inline]
fn to_area(scene: &Scene, pdf_dir: f32, from: &Vertex, to: &Vertex) -> f32 {
    let d = to.p() - from.p();
    let d2 = d.length_squared();
    if d2.is_nan() || d2 <= 0.0 {
        return 0.0;
    }
    let mut pdf = pdf_dir / d2;
    if to.on_surface(scene) {
        pdf *= (d.dot(to.sh.n) / d2.sqrt()).abs();
    }
    pdf
}

/// The BSDF density at surface vertex `v` for local directions `wo`, `wi`
/// (0 for delta lobes).
#[inline]
fn pdf_at(scene: &Scene, v: &Vertex, wo: Vec3, wi: Vec3) -> f32 {
    match v.kind {
        Kind::Surface(o) => material(scene, o).pdf_within(wo, wi, &Lambdas::full(), outside(scene, v.outside)),
        _ => 0.0,
    }
}

/// The area density at `next` of the ray `sample_le` would start from light
/// vertex `y` towards it.
#[inline]
fn pdf_light(scene: &Scene, y: &Vertex, next: &Vertex) -> f32 {
    let Kind::Light(i) = y.kind else {
        return 0.0;
    };
    let light = &scene.lights[i as usize];
    let w = (next.p() - y.p()).normalize_or_zero();
    let (pdf_pos, pdf_dir) = light.pdf_le(y.sh.n, w);
    if light.is_delta_direction() {
        // Parallel rays: the disk's density projected onto `next`.
        let cos = if next.on_surface(scene) { w.dot(next.sh.n).abs() } else { 1.0 };
        return pdf_pos * cos;
    }
    to_area(scene, pdf_dir, y, next)
}

/// The densities a strategy changes at the connection: `pt_rev` at
/// `x_{t-1}`, `ptm_rev` at `x_{t-2}`, `qs_rev` at `y_{s-1}`, `qsm_rev` at
/// `y_{s-2}`.
#[derive(Clone, Copy, Debug)]
struct Overrides {
    pt_rev: f32,
    ptm_rev: f32,
    qs_rev: f32,
    qsm_rev: f32,
}

/// The power-heuristic weight of strategy `(s, t)` for the path made of
/// `camera[..t]` and `light[..s]`: `1 / (1 + Σ_i (p_i / p_s)²)` over the
/// other strategies, each ratio a product of `pdf_rev / pdf_fwd` along the
/// path (zero densities, of delta vertices, count as 1; strategies that
/// would need a connection at a delta vertex are skipped).
fn mis_weight(scene: &Scene, camera: &[Vertex], t: usize, light: &[Vertex], s: usize, o: Overrides) -> f32 {
    let remap = |p: f32| if p > 0.0 { p } else { 1.0 };
    let mut sum = 0.0f32;
    // Camera side: x_{t-1} … x_1 generated from the light instead.
    let cam_rev = |i: usize| {
        if i + 1 == t {
            o.pt_rev
        } else if i + 2 == t {
            o.ptm_rev
        } else {
            camera[i].pdf_rev
        }
    };
    let cam_delta = |i: usize| i + 1 != t && camera[i].delta;
    let mut ri = 1.0f32;
    for i in (1..t).rev() {
        ri *= remap(cam_rev(i)) / remap(camera[i].pdf_fwd);
        if !cam_delta(i) && !cam_delta(i - 1) {
            sum += ri * ri;
        }
    }
    // Light side: y_{s-1} … y_0 generated from the camera instead.
    let light_rev = |i: usize| {
        if i + 1 == s {
            o.qs_rev
        } else if i + 2 == s {
            o.qsm_rev
        } else {
            light[i].pdf_rev
        }
    };
    let light_delta = |i: usize| i + 1 != s && light[i].delta;
    let delta_light = match light.first().map(|v| v.kind) {
        Some(Kind::Light(i)) => scene.lights[i as usize].is_delta(),
        _ => false,
    };
    let mut ri = 1.0f32;
    for i in (0..s).rev() {
        ri *= remap(light_rev(i)) / remap(light[i].pdf_fwd);
        let delta_before = if i > 0 { light_delta(i - 1) } else { delta_light };
        if !light_delta(i) && !delta_before {
            sum += ri * ri;
        }
    }
    1.0 / (1.0 + sum)
}
