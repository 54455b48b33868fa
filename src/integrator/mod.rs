//! Integrators: from a camera ray to the colour of one sample.
//!
//! Three light-transport methods share one spectral machinery:
//!
//! | `--integrator` | paths traced | wavelengths |
//! |---|---|---|
//! | `whitted` | E S* (D\|G) L: specular chains, direct light at the first diffuse hit | full spectrum, no dispersion |
//! | `path` | all (NEE + BSDF sampling with MIS, Russian roulette) | full spectrum; a dispersive surface refracts every wavelength like 589.3 nm |
//! | `spectral` | as `path` | a packet of `C` wavelengths (`--wavelengths hero\|random`, `--packet-size C`) that splits into single-wavelength paths at the first dispersive surface: bins, or continuous wavelengths where glass disperses (`--wavelengths continuous`: everywhere); or `--wavelengths rgb` |
//! | `auto` (default) | as `path` | the full spectrum until a path refracts at a dispersive surface (a reflection there keeps it); the refraction collapses it to `C` bins drawn in proportion to throughput × visual importance, weighted `1/(C·p)`, each refracting on its own at a continuous wavelength within its bin: no wavelength noise where nothing disperses |
//!
//! Every method is written once, generically over the packet size `N`
//! (the crate-internal `spectral` module), and picked once per render (`Estimator`) so the
//! tile loop is monomorphic.
//!
//! # Depth
//! `max_bounces` counts scattering events (reflections and refractions) on a
//! path, as pbrt-v4's `maxdepth`: 0 shows only emitters seen directly, 1 adds
//! direct lighting. A path of `k` bounces has `k + 1` segments, so Mitsuba's
//! `max_depth = k + 1`. The NEE shadow ray from the `k`-th bounce is allowed.

mod path;
mod whitted;

pub use path::PathTracer;
pub use whitted::Whitted;

use glam::{Vec2, Vec3};

use crate::bxdf::Bxdf;
use crate::color::Sampled;
use crate::geometry::{Frame, Ray};
use crate::sampler::Sampler;
use crate::sampler::warp::power_heuristic;
use crate::scene::Scene;
use crate::settings::{IntegratorKind, Settings, WavelengthsKind};
use crate::spectral::{Contribution, Lambdas, WavelengthSampling, sample_packet, sample_packet_continuous};

/// Computes the colour of one camera sample. Implementations are chosen once
/// per render and the render loop is generic over them.
pub(crate) trait Estimator: Sync {
    /// The estimate of one sample through film position `film` (pixel units): its XYZ, or its
    /// per-bin radiance for spectral output.
    fn sample<O: Contribution>(&self, scene: &Scene, film: Vec2, sampler: &mut Sampler) -> O;
}

/// The light-transport method, with its bounce limit.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Transport {
    /// Whitted-style.
    Whitted(Whitted),
    /// Path tracing.
    Path(PathTracer),
}

impl Transport {
    /// Radiance along `ray` for the packet `lambdas`, as XYZ.
    #[inline]
    pub fn li<const N: usize, O: Contribution>(
        &self,
        scene: &Scene,
        ray: Ray,
        lambdas: &Lambdas<N>,
        sampler: &mut Sampler,
    ) -> O {
        match self {
            Transport::Whitted(w) => w.li(scene, ray, lambdas, sampler),
            Transport::Path(p) => p.li(scene, ray, lambdas, sampler),
        }
    }
}

/// Full spectrum on every path (the `path` and `whitted` integrators).
pub(crate) struct FullSpectrum(pub Transport);

impl Estimator for FullSpectrum {
    #[inline]
    fn sample<O: Contribution>(&self, scene: &Scene, film: Vec2, sampler: &mut Sampler) -> O {
        let ray = scene.camera.ray(film);
        self.0.li(scene, ray, &Lambdas::full(), sampler)
    }
}

/// A packet of `C` sampled wavelengths per camera sample (the `spectral` integrator): bins, or
/// continuous wavelengths for colour output in a scene with dispersive glass (or in any scene
/// when the third field is set, `--wavelengths continuous`); see `crate::spectral`.
pub(crate) struct Packets<const C: usize>(pub Transport, pub WavelengthSampling, pub bool);

impl<const C: usize> Estimator for Packets<C> {
    #[inline]
    fn sample<O: Contribution>(&self, scene: &Scene, film: Vec2, sampler: &mut Sampler) -> O {
        let ray = scene.camera.ray(film);
        let u: [f32; C] = std::array::from_fn(|_| sampler.next_1d());
        let lambdas = if O::CONTINUOUS && (self.2 || scene.has_dispersion()) {
            sample_packet_continuous::<C>(self.1, u)
        } else {
            sample_packet::<C>(self.1, u)
        };
        self.0.li(scene, ray, &lambdas, sampler)
    }
}

/// The three fixed wavelengths of the RGB mode.
pub(crate) struct RgbWavelengths(pub Transport);

impl Estimator for RgbWavelengths {
    #[inline]
    fn sample<O: Contribution>(&self, scene: &Scene, film: Vec2, sampler: &mut Sampler) -> O {
        let ray = scene.camera.ray(film);
        self.0.li(scene, ray, &Lambdas::rgb(), sampler)
    }
}

/// Calls `f` with the estimator the settings ask for: the one place where the
/// integrator is chosen, outside the tile loop.
pub(crate) fn with_estimator<R>(settings: &Settings, f: impl EstimatorFn<R>) -> R {
    let whitted = Transport::Whitted(Whitted { max_bounces: settings.max_bounces });
    let path = |disperse| {
        Transport::Path(PathTracer { max_bounces: settings.max_bounces, disperse, collapse_to: settings.packet_size })
    };
    match settings.integrator {
        IntegratorKind::Auto => f.call(&FullSpectrum(path(true))),
        IntegratorKind::Whitted => f.call(&FullSpectrum(whitted)),
        IntegratorKind::Path => f.call(&FullSpectrum(path(false))),
        IntegratorKind::Spectral => {
            let (how, always) = match settings.wavelengths {
                WavelengthsKind::Rgb => return f.call(&RgbWavelengths(path(true))),
                WavelengthsKind::Hero => (WavelengthSampling::Hero, false),
                WavelengthsKind::Random => (WavelengthSampling::Random, false),
                WavelengthsKind::Continuous => (WavelengthSampling::Hero, true),
            };
            match settings.packet_size {
                1 => f.call(&Packets::<1>(path(true), how, always)),
                2 => f.call(&Packets::<2>(path(true), how, always)),
                8 => f.call(&Packets::<8>(path(true), how, always)),
                _ => f.call(&Packets::<4>(path(true), how, always)),
            }
        }
    }
}

/// One line saying which light-transport model the settings pick for this
/// scene and why (printed once by `rust-v render`).
pub fn describe(scene: &Scene) -> String {
    let s = &scene.settings;
    let dispersive = scene.has_dispersion();
    match s.integrator {
        IntegratorKind::Auto if dispersive => format!(
            "auto: dispersive material present: full-spectrum path tracing; a path that refracts at dispersive glass continues as {} single continuous wavelengths (bin centres with --spectral) drawn by throughput and visual importance",
            s.packet_size
        ),
        IntegratorKind::Auto => "auto: no dispersive material: full-spectrum path tracing (all 36 bins on every path, no wavelength sampling)".into(),
        IntegratorKind::Path if dispersive => "path: full spectrum; dispersive glass refracts every wavelength like 589.3 nm (no rainbow)".into(),
        IntegratorKind::Path => "path: full-spectrum path tracing".into(),
        IntegratorKind::Whitted => "whitted: specular chains and direct light at the first diffuse hit (no indirect light, no caustics)".into(),
        IntegratorKind::Spectral => match s.wavelengths {
            WavelengthsKind::Rgb => "spectral, rgb: three wavelengths (435.8, 546.1, 700 nm) read out as RGB".into(),
            WavelengthsKind::Continuous => format!(
                "spectral, continuous: hero packets of {} wavelengths anywhere in 360-830 nm, every spectrum interpolated at each",
                s.packet_size
            ),
            w if dispersive => format!(
                "spectral, {w:?} packets of {} continuous wavelengths (dispersive glass; bin centres with --spectral), split at dispersive surfaces",
                s.packet_size
            )
            .to_lowercase(),
            w => format!("spectral, {w:?} packets of {} wavelengths, split at dispersive surfaces", s.packet_size).to_lowercase(),
        },
    }
}

/// A function generic over the estimator type (a closure cannot be generic).
pub(crate) trait EstimatorFn<R> {
    /// Runs with estimator `e`.
    fn call<E: Estimator>(self, e: &E) -> R;
}

/// The shading context at a surface hit: the local frame and the geometric
/// normal used to keep directions on their proper side.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Shading {
    pub p: Vec3,
    pub n: Vec3,
    pub frame: Frame,
    pub wo: Vec3,
    /// `wo · n` in world space (the geometric side the path arrived on).
    pub wo_n: f32,
}

impl Shading {
    /// The shading context for a ray arriving along `dir` at point `p` with
    /// geometric normal `n` and shading normal `ns`.
    #[inline]
    pub fn new(p: Vec3, n: Vec3, ns: Vec3, dir: Vec3) -> Self {
        let frame = Frame::from_z(ns);
        Shading { p, n, frame, wo: frame.to_local(-dir), wo_n: -dir.dot(n) }
    }

    /// True when world direction `wi` (local `wi_local`) leaves on the side of
    /// the geometric surface that the shading frame claims: a reflection must
    /// stay on `wo`'s side of the real surface and a transmission must cross
    /// it. Rejecting the others prevents light leaks through shading normals.
    #[inline]
    pub fn consistent(&self, wi: Vec3, wi_local: Vec3) -> bool {
        let geometric_same_side = wi.dot(self.n) * self.wo_n > 0.0;
        let shading_same_side = wi_local.z * self.wo.z > 0.0;
        geometric_same_side == shading_same_side
    }
}

/// One next-event estimate at a non-delta surface: a light chosen by power, a
/// point on it sampled by solid angle or area, a shadow ray, and the MIS
/// weight against BSDF sampling (power heuristic) when `mis` is set.
#[inline]
pub(crate) fn sample_direct<const N: usize>(
    scene: &Scene,
    bxdf: &Bxdf,
    sh: &Shading,
    lambdas: &Lambdas<N>,
    sampler: &mut Sampler,
    mis: bool,
) -> Sampled<N> {
    let zero = Sampled::splat(0.0);
    let u_light = sampler.next_1d();
    let u = sampler.next_2d();
    let Some((index, pmf)) = scene.choose_light(u_light) else {
        return zero;
    };
    let light = &scene.lights[index];
    let Some(ls) = light.sample_li(sh.p, u) else {
        return zero;
    };
    let wi_local = sh.frame.to_local(ls.wi);
    if !sh.consistent(ls.wi, wi_local) {
        return zero;
    }
    let f = bxdf.eval(sh.wo, wi_local, lambdas);
    if f.is_black() {
        return zero;
    }
    let (shadow, t_max) = Ray::spawn_to(sh.p, sh.n, ls.point);
    if scene.occluded(&shadow, t_max) {
        return zero;
    }
    let pdf_light = pmf * ls.pdf;
    let weight = if ls.is_delta || !mis { 1.0 } else { power_heuristic(pdf_light, bxdf.pdf(sh.wo, wi_local, lambdas)) };
    f * lambdas.sample(light.spectrum()) * (ls.scale * wi_local.z.abs() * weight / pdf_light)
}
