//! The strategies `(s, t)`: joining a camera prefix and a light prefix, with the
//! segment between them (visibility and transmittance).

use glam::{Vec2, Vec3};

use crate::color::Spectrum;
use crate::medium::VolumeStack;
use crate::sampler::{Dim, Sampler};
use crate::scene::{LightChoice, Scene};
use crate::spectral::Lambdas;

use super::mis::{Overrides, mis_weight};
use super::vertex::{
    Contrib, Kind, Vertex, Wavelength, bsdf_at, connectible, consistent_at, cos_at, cos_normal, is_dispersive, outside,
    pdf_at, pdf_light, scatter, shading_correction, to_area,
};
use super::{Bdpt, Sub};

impl Bdpt {
    /// Strategy `(s, t = 1)`: light vertex `y_{s-1}` seen by the eye, or by a
    /// point of a thin lens drawn uniformly ([`Dim::lens_from_light`], pbrt-v4's
    /// `PerspectiveCamera::SampleWi`). Returns the film position and the
    /// MIS-weighted contribution.
    pub(super) fn connect_camera(
        &self,
        scene: &Scene,
        light: Sub<'_>,
        s: usize,
        camera: Sub<'_>,
        sampler: &mut Sampler,
        wl: &mut Wavelength,
    ) -> Option<(Vec2, Contrib)> {
        let cam = &scene.camera;
        let eye =
            if cam.has_lens() { cam.lens_point(sampler.get_2d(Dim::lens_from_light(s as u32 - 1))) } else { cam.eye() };
        let qs = &light.v[s - 1];
        if !connectible(scene, qs) {
            return None;
        }
        let to_eye = eye - qs.p();
        let d2 = to_eye.length_squared();
        if d2.is_nan() || d2 <= 0.0 {
            return None;
        }
        let w = to_eye / d2.sqrt();
        let (film, importance) = cam.importance(eye, -w, d2)?;
        let single = qs.collapsed || is_dispersive(scene, qs);
        // Emission (s = 1) or the adjoint BSDF towards the eye, with the cosine at y.
        let c = match qs.kind {
            Kind::Light(i) => {
                let light = scene.light(i);
                if light.is_delta() {
                    // Point and spot lights are invisible to the camera in every
                    // integrator (path tracing cannot see them either).
                    return None;
                }
                let e = light.emit_factor(qs.sh.n, w) * importance;
                if e.is_nan() || e <= 0.0 {
                    return None;
                }
                if single { Contrib::Single(wl.at(&qs.beta, qs.collapsed) * e) } else { Contrib::Full(qs.beta * e) }
            }
            Kind::Surface(_) => {
                let mut slot = None;
                let bxdf = bsdf_at(scene, qs, &mut slot);
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
            Kind::Medium(_) => {
                // The phase function towards the eye (symmetric: no adjoint correction, no cosine).
                let wi = qs.sh.frame.to_local(w);
                let mut slot = None;
                let sc = scatter(scene, qs, &mut slot)?;
                if single {
                    let one = wl.single();
                    let f = sc.eval(wi, qs.sh.wo, &one.lambdas)[0];
                    Contrib::Single(wl.at(&qs.beta, qs.collapsed) * f * importance)
                } else {
                    Contrib::Full(qs.beta * sc.eval(wi, qs.sh.wo, &Lambdas::full()) * importance)
                }
            }
            Kind::Camera => return None,
        };
        if is_black(&c) {
            return None;
        }
        let transmittance = segment(scene, qs, light.media_towards(scene, s - 1, w).as_ref(), eye, Vec3::ZERO)?;
        let weight = if self.light_only {
            1.0
        } else {
            // The camera vertex of this strategy: the eye, or the lens point drawn here.
            let eye_v = Vertex::at_point(Kind::Camera, eye, cam.forward(), Spectrum::ONE, 1.0);
            let qs_rev = to_area(scene, cam.pdf_dir_from(eye, -w), &eye_v, qs);
            let qsm_rev = match qs.kind {
                Kind::Surface(_) | Kind::Medium(_) if s >= 2 => {
                    pdf_at(scene, qs, qs.sh.frame.to_local(w), qs.sh.wo) * qs.g_prev
                }
                _ => 0.0,
            };
            mis_weight(scene, camera.v, 1, light.v, s, Overrides { pt_rev: 0.0, ptm_rev: 0.0, qs_rev, qsm_rev })
        };
        Some((film, scale(c, weight, transmittance, wl)))
    }

    /// Strategies `(s, t ≥ 2)`: emitter hit (`s = 0`), next-event estimation
    /// (`s = 1`), or a connection of `x_{t-1}` and `y_{s-1}`; MIS-weighted.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn connect(
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
        let ptm = &camera.v[t - 2];
        if let Kind::Light(index) = pt.kind {
            // The camera subpath escaped to the environment (its only light vertex).
            return if s == 0 { self.escaped(scene, camera, t, index, wl) } else { NONE };
        }
        if !matches!(pt.kind, Kind::Surface(_) | Kind::Medium(_)) {
            return NONE;
        }
        let object = match pt.kind {
            Kind::Surface(o) | Kind::Medium(o) => o,
            _ => return NONE,
        };
        match s {
            0 => {
                // The camera subpath ends on an emitter.
                let (Kind::Surface(_), Some(index)) = (pt.kind, scene.emitter(object)) else {
                    return NONE;
                };
                let light = scene.light(index);
                let dir = (pt.p() - ptm.p()).normalize();
                let le = light.le_scale(pt.sh.n, dir);
                if le <= 0.0 {
                    return NONE;
                }
                let c = if pt.collapsed {
                    let one = wl.single();
                    scene.with_radiance(index, dir, pt.uv, |s| {
                        Contrib::Single(pt.beta[one.slot] * one.lambdas.sample(s)[0] * le)
                    })
                } else {
                    scene.with_radiance(index, dir, pt.uv, |s| Contrib::Full(pt.beta * *s * le))
                };
                let (pdf_pos, pdf_dir) = light.pdf_le(pt.p(), pt.sh.n, -dir);
                let pt_rev = scene.light_pmf(index) * pdf_pos;
                let as_light = Vertex { kind: Kind::Light(index), ..*pt };
                let ptm_rev = to_area(scene, pdf_dir, &as_light, ptm);
                let overrides = Overrides { pt_rev, ptm_rev, qs_rev: 0.0, qsm_rev: 0.0 };
                scale(c, mis_weight(scene, camera.v, t, &[], 0, overrides), None, wl)
            }
            1 => {
                // Next-event estimation: a fresh point on a light.
                let (u_light, u) = (
                    sampler.get_1d_if(scene.light_count() > 1, Dim::light_choice(t as u32 - 2)),
                    sampler.get_2d(Dim::light_sample(t as u32 - 2)),
                );
                if !connectible(scene, pt) {
                    return NONE;
                }
                let Some(LightChoice { light: index, pmf, sample: ls, uv }) = scene.sample_li(pt.p(), u_light, u)
                else {
                    return NONE;
                };
                let light = scene.light(index);
                let wi = pt.sh.frame.to_local(ls.wi);
                if !consistent_at(pt, ls.wi, wi) || ls.pdf.is_nan() || ls.pdf <= 0.0 {
                    return NONE;
                }
                let mut slot = None;
                let Some(sc) = scatter(scene, pt, &mut slot) else {
                    return NONE;
                };
                let k = ls.scale * cos_at(pt, wi) / (pmf * ls.pdf);
                let c = if pt.collapsed || is_dispersive(scene, pt) {
                    let one = wl.single();
                    let f = sc.eval(pt.sh.wo, wi, &one.lambdas)[0];
                    let le = scene.with_radiance(index, ls.wi, uv, |s| one.lambdas.sample(s)[0]);
                    Contrib::Single(wl.at(&pt.beta, pt.collapsed) * f * le * k)
                } else {
                    let f = sc.eval(pt.sh.wo, wi, &Lambdas::full());
                    scene.with_radiance(index, ls.wi, uv, |s| Contrib::Full(pt.beta * f * *s * k))
                };
                if is_black(&c) {
                    return NONE;
                }
                let media = camera.media_towards(scene, t - 1, ls.wi);
                let Some(transmittance) = segment(scene, pt, media.as_ref(), ls.point, ls.n) else {
                    return NONE;
                };
                // The sampled light vertex, for the MIS weight (on the environment,
                // a direction: its density is the direction's).
                let (pdf_pos, pdf_dir) = light.pdf_le(ls.point, ls.n, -ls.wi);
                let pdf_y = if light.is_infinite() { pmf * pdf_dir } else { pmf * pdf_pos };
                let y = Vertex::at_point(Kind::Light(index), ls.point, ls.n, Spectrum::ONE, pdf_y);
                let full = Lambdas::full();
                let pt_rev = pdf_light(scene, &y, pt);
                let ptm_rev = sc.pdf(wi, pt.sh.wo, &full) * pt.g_prev;
                let qs_rev = to_area(scene, sc.pdf(pt.sh.wo, wi, &full), pt, &y);
                let overrides = Overrides { pt_rev, ptm_rev, qs_rev, qsm_rev: 0.0 };
                let weight = mis_weight(scene, camera.v, t, std::slice::from_ref(&y), 1, overrides);
                scale(c, weight, transmittance, wl)
            }
            _ => {
                let qs = &light.v[s - 1];
                if !connectible(scene, pt) || !connectible(scene, qs) {
                    return NONE;
                }
                if !matches!(qs.kind, Kind::Surface(_) | Kind::Medium(_)) {
                    return NONE;
                }
                let d = qs.p() - pt.p();
                let d2 = d.length_squared();
                if d2.is_nan() || d2 <= 0.0 {
                    return NONE;
                }
                let w = d / d2.sqrt();
                let (wi_p, wi_q) = (pt.sh.frame.to_local(w), qs.sh.frame.to_local(-w));
                if !consistent_at(pt, w, wi_p) || !consistent_at(qs, -w, wi_q) {
                    return NONE;
                }
                // Veach's shading-normal correction on the light side's surface (1 in a medium).
                let correction =
                    if matches!(qs.kind, Kind::Medium(_)) { 1.0 } else { shading_correction(&qs.sh, -w, wi_q) };
                let k = cos_at(pt, wi_p) * cos_at(qs, wi_q) / d2 * correction;
                let (mut slot_p, mut slot_q) = (None, None);
                let (Some(sp), Some(sq)) = (scatter(scene, pt, &mut slot_p), scatter(scene, qs, &mut slot_q)) else {
                    return NONE;
                };
                let c = if pt.collapsed || qs.collapsed || is_dispersive(scene, pt) || is_dispersive(scene, qs) {
                    let one = wl.single();
                    let fp = sp.eval(pt.sh.wo, wi_p, &one.lambdas)[0];
                    let fq = sq.eval(wi_q, qs.sh.wo, &one.lambdas)[0];
                    Contrib::Single(wl.at(&pt.beta, pt.collapsed) * fp * fq * wl.at(&qs.beta, qs.collapsed) * k)
                } else {
                    let full = Lambdas::full();
                    let (fp, fq) = (sp.eval(pt.sh.wo, wi_p, &full), sq.eval(wi_q, qs.sh.wo, &full));
                    Contrib::Full(pt.beta * fp * fq * qs.beta * k)
                };
                if is_black(&c) {
                    return NONE;
                }
                let media = camera.media_towards(scene, t - 1, w);
                let Some(transmittance) = segment(scene, pt, media.as_ref(), qs.p(), qs.sh.n) else {
                    return NONE;
                };
                // The four densities the connection changes, from the local
                // directions already at hand (`wo` points back along each subpath).
                let full = Lambdas::full();
                let pt_rev = sq.pdf(qs.sh.wo, wi_q, &full) * cos_normal(pt, w) / d2;
                let qs_rev = sp.pdf(pt.sh.wo, wi_p, &full) * cos_normal(qs, w) / d2;
                let ptm_rev = sp.pdf(wi_p, pt.sh.wo, &full) * pt.g_prev;
                let qsm_rev = sq.pdf(wi_q, qs.sh.wo, &full) * qs.g_prev;
                let weight = mis_weight(scene, camera.v, t, light.v, s, Overrides { pt_rev, ptm_rev, qs_rev, qsm_rev });
                scale(c, weight, transmittance, wl)
            }
        }
    }
}

impl Bdpt {
    /// Strategy `(0, t)` for a camera subpath that escaped to the environment
    /// (light `index`): its radiance, MIS-weighted. The densities a light
    /// subpath would have made the ends with are the environment's direction
    /// density at `x_{t-1}` and its disk's, projected, at `x_{t-2}`. A path
    /// straight from the eye to the environment (`t = 2`) has no other
    /// strategy (no light subpath connects to the eye from infinity): weight 1.
    fn escaped(&self, scene: &Scene, camera: Sub<'_>, t: usize, index: u32, wl: &mut Wavelength) -> Contrib {
        let (pt, ptm) = (&camera.v[t - 1], &camera.v[t - 2]);
        let light = scene.light(index);
        let dir = (pt.p() - ptm.p()).normalize();
        let c = if pt.collapsed {
            let one = wl.single();
            Contrib::Single(pt.beta[one.slot] * light.with_radiance_at(dir, |s| one.lambdas.sample(s)[0]))
        } else {
            Contrib::Full(light.with_radiance_at(dir, |s| pt.beta * *s))
        };
        if t == 2 {
            return c;
        }
        let (_, pdf_dir) = light.pdf_le(pt.p(), pt.sh.n, -dir);
        let pt_rev = scene.light_pmf(index) * pdf_dir;
        let ptm_rev = pdf_light(scene, pt, ptm);
        let overrides = Overrides { pt_rev, ptm_rev, qs_rev: 0.0, qsm_rev: 0.0 };
        scale(c, mis_weight(scene, camera.v, t, &[], 0, overrides), None, wl)
    }
}

/// True when a contribution is zero. (A NaN is not: it reaches the film,
/// which drops and counts it, so a bug cannot hide here.)
#[inline]
pub(super) fn is_black(c: &Contrib) -> bool {
    match c {
        Contrib::Full(s) => s.is_black(),
        Contrib::Single(v) => *v == 0.0,
    }
}

/// A contribution times the MIS weight and a segment's transmittance (if
/// the segment runs inside an absorbing dielectric).
#[inline]
pub(super) fn scale(c: Contrib, weight: f32, transmittance: Option<Spectrum>, wl: &mut Wavelength) -> Contrib {
    match (c, transmittance) {
        (Contrib::Full(s), None) => Contrib::Full(s * weight),
        (Contrib::Full(s), Some(tr)) => Contrib::Full(s * tr * weight),
        (Contrib::Single(v), None) => Contrib::Single(v * weight),
        (Contrib::Single(v), Some(tr)) => Contrib::Single(v * wl.at(&tr, false) * weight),
    }
}

/// The segment of a connection from vertex `v` to point `to` (normal `to_n`,
/// zero for a free point: the eye, a point or spot light), starting in the
/// volumes `volumes` (those around `v` on the segment's side; `None` in a
/// scene without dielectrics): [`Scene::transmittance`] over the full spectrum.
/// `None` when something blocks it; else the transmittance when the segment
/// runs in a medium.
#[inline]
pub(super) fn segment(
    scene: &Scene,
    v: &Vertex,
    volumes: Option<&VolumeStack>,
    to: Vec3,
    to_n: Vec3,
) -> Option<Option<Spectrum>> {
    scene.transmittance(v.p(), v.sh.n, volumes, to, to_n).map(|clear| clear.spectrum())
}
