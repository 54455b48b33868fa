//! Integrators: from a camera ray to the colour of one sample.
//!
//! The light-transport methods share one spectral machinery (`bdpt` and
//! `lighttrace`: see [`Bdpt`]):
//!
//! | `--integrator` | paths traced | wavelengths |
//! |---|---|---|
//! | `whitted` | E S* (D\|G) L: specular chains, direct light at the first diffuse hit | full spectrum, no dispersion |
//! | `path` | all (NEE + BSDF sampling with MIS, Russian roulette) | full spectrum; a dispersive surface refracts every wavelength like 589.3 nm |
//! | `spectral` | as `path` | a packet of `C` wavelengths (`--wavelengths hero\|random`, `--packet-size C`) that splits into single-wavelength paths at the first dispersive surface: bins, or continuous wavelengths where glass disperses (`--wavelengths continuous`: everywhere); or `--wavelengths rgb` |
//! | `caustics` | as `path`, but the caustics of the environment and distant, point and spot lights through specular surfaces come from light subpaths aimed at those surfaces, splatted to the camera (a partition of path space, no MIS; the crate-internal `caustics` module) | as `auto` on the camera side; BDPT's one collapsed wavelength on the light side |
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
//!
//! # Nested dielectrics
//! Every path carries a [`VolumeStack`] (starting as [`Scene::camera_volumes`]):
//! at a dielectric's surface, `interface` decides whether the hit is a
//! false intersection (passed straight through, no bounce counted, no light
//! sample) or a real interface and what lies outside it; a transmission
//! updates the stack (`Interface::scattered`). Segments are attenuated by the
//! medium they run in ([`Scene::medium_in`]); shadow rays and BDPT's
//! connections follow one rule, [`Scene::transmittance`], which passes false
//! intersections where volumes nest. A path may pass at most `MAX_PASSES`
//! (64) false intersections in a row (then it ends).
//!
//! # The scene
//! Integrators see the scene only through its queries (`crate::scene`'s
//! `query` module: intersect, `bsdf`, `le`, `pdf_li`, `sample_li`, `light`,
//! `volume`, `medium_in`, `transmittance`) and call the lights' and lobes'
//! verbs; none matches a light or material variant.

mod bdpt;
mod caustics;
mod choice;
mod path;
mod whitted;

pub use bdpt::Bdpt;
pub(crate) use caustics::Caustics;
pub(crate) use choice::{EstimatorFn, with_estimator};
pub use choice::{describe, needs_bdpt};
pub use path::PathTracer;
pub use whitted::Whitted;

use std::sync::LazyLock;

use glam::{Vec2, Vec3};

use crate::camera::lens_system::D_LINE_NM;

use crate::bxdf::{Bxdf, Outside};
use crate::color::Sampled;
use crate::film::Splat;
use crate::geometry::{Frame, Ray};
use crate::medium::{Crossing, Volume, VolumeStack};
use crate::sampler::warp::power_heuristic;
use crate::sampler::{Dim, Sampler};
use crate::scene::{Scene, SurfaceHit};

pub(crate) use crate::scene::MAX_PASSES;
use crate::spectral::{
    BinDistribution, Contribution, Lambdas, Readout, WavelengthSampling, bin_importance, continuous_wavelength,
    sample_packet, sample_packet_continuous,
};

/// Computes the colour of one camera sample. Implementations are chosen once
/// per render and the render loop is generic over them.
pub(crate) trait Estimator: Sync {
    /// The estimate of one sample through film position `film` (pixel units): its XYZ, or its
    /// per-bin radiance for spectral output. Light subpaths connected to the camera land in
    /// whatever pixel they reach: those contributions go to `splats`.
    fn sample<O: Contribution>(
        &self,
        scene: &Scene,
        film: Vec2,
        sampler: &mut Sampler,
        splats: &mut Vec<Splat<O>>,
    ) -> O;
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
    /// True when the transport follows dispersion (`auto`, `spectral`); `path`
    /// and `whitted` refract every wavelength alike, a dispersive lens too.
    #[inline]
    fn disperses(&self) -> bool {
        matches!(self, Transport::Path(p) if p.disperse)
    }

    /// Radiance along `ray` for the packet `lambdas`, as XYZ.
    #[inline(always)]
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
    fn sample<O: Contribution>(&self, scene: &Scene, film: Vec2, sampler: &mut Sampler, _: &mut Vec<Splat<O>>) -> O {
        if let Some(system) = scene.camera.lens_system() {
            let u = sampler.get_2d(Dim::LENS);
            if system.is_dispersive() && self.0.disperses() {
                let one = one_wavelength::<O>(sampler.get_1d(Dim::wavelength(0)));
                return through_lens_system(&self.0, scene, film, u, &one, sampler);
            }
            return through_lens_system(&self.0, scene, film, u, &Lambdas::full(), sampler);
        }
        let ray = camera_ray(scene, film, sampler);
        self.0.li(scene, ray, &Lambdas::full(), sampler)
    }
}

/// A packet of `C` sampled wavelengths per camera sample (the `spectral` integrator): bins, or
/// continuous wavelengths for colour output in a scene with dispersive glass (or in any scene
/// when the third field is set, `--wavelengths continuous`); see `crate::spectral`.
pub(crate) struct Packets<const C: usize>(pub Transport, pub WavelengthSampling, pub bool);

impl<const C: usize> Estimator for Packets<C> {
    #[inline]
    fn sample<O: Contribution>(&self, scene: &Scene, film: Vec2, sampler: &mut Sampler, _: &mut Vec<Splat<O>>) -> O {
        if let Some(system) = scene.camera.lens_system() {
            let u_lens = sampler.get_2d(Dim::LENS);
            let u: [f32; C] = std::array::from_fn(|i| sampler.get_1d(Dim::wavelength(i)));
            let dispersive = system.is_dispersive();
            let lambdas = if O::CONTINUOUS && (self.2 || dispersive || scene.has_dispersion()) {
                sample_packet_continuous::<C>(self.1, u)
            } else {
                sample_packet::<C>(self.1, u)
            };
            return through_lens_system_split(&self.0, scene, film, u_lens, &lambdas, dispersive, sampler);
        }
        let ray = camera_ray(scene, film, sampler);
        let u: [f32; C] = std::array::from_fn(|i| sampler.get_1d(Dim::wavelength(i)));
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
    fn sample<O: Contribution>(&self, scene: &Scene, film: Vec2, sampler: &mut Sampler, _: &mut Vec<Splat<O>>) -> O {
        if let Some(system) = scene.camera.lens_system() {
            let u = sampler.get_2d(Dim::LENS);
            let dispersive = system.is_dispersive();
            return through_lens_system_split(&self.0, scene, film, u, &Lambdas::rgb(), dispersive, sampler);
        }
        let ray = camera_ray(scene, film, sampler);
        self.0.li(scene, ray, &Lambdas::rgb(), sampler)
    }
}

/// The estimate through a lens system for film position `film` and
/// exit-pupil sample `u`: one ray for the packet `lambdas`, traced at the d
/// line, or, for a one-wavelength packet through a dispersive lens, at its
/// wavelength; its weight scales the packet's. A blocked ray sees nothing.
fn through_lens_system<const N: usize, O: Contribution>(
    transport: &Transport,
    scene: &Scene,
    film: Vec2,
    u: Vec2,
    lambdas: &Lambdas<N>,
    sampler: &mut Sampler,
) -> O {
    let cam = &scene.camera;
    let dispersive = cam.lens_system().is_some_and(|s| s.is_dispersive());
    let nm = if N == 1 && dispersive && transport.disperses() { lambdas.lambda_nm(0) } else { D_LINE_NM };
    match cam.lens_system_ray(film, u, nm) {
        Some((ray, w)) => transport.li(scene, ray, &Lambdas { weight: lambdas.weight * w, ..*lambdas }, sampler),
        None => O::default(),
    }
}

/// [`through_lens_system`] for a packet: whole when the lens does not
/// disperse, else each wavelength on its own ray (carrying the packet's
/// weight; they share the exit-pupil sample and the per-bounce draws, as the
/// walks of a packet split at dispersive glass do).
fn through_lens_system_split<const N: usize, O: Contribution>(
    transport: &Transport,
    scene: &Scene,
    film: Vec2,
    u: Vec2,
    lambdas: &Lambdas<N>,
    dispersive: bool,
    sampler: &mut Sampler,
) -> O {
    if !dispersive {
        return through_lens_system(transport, scene, film, u, lambdas, sampler);
    }
    let mut out = O::default();
    for i in 0..N {
        out += through_lens_system(transport, scene, film, u, &lambdas.single(i), sampler);
    }
    out
}

/// One wavelength drawn from `u` by visual importance (as BDPT's collapse
/// draws it), with weight `1/p`: continuous for colour output, a bin centre
/// for spectral output.
fn one_wavelength<O: Contribution>(u: f32) -> Lambdas<1> {
    static DIST: LazyLock<BinDistribution> = LazyLock::new(|| {
        let importance = bin_importance();
        BinDistribution::new(|b| importance[b]).expect("visual importance is positive")
    });
    if O::CONTINUOUS {
        continuous_wavelength(&DIST, u).0
    } else {
        let (b, p) = DIST.sample(u);
        Lambdas { pos: [b as f32], weight: 1.0 / p, readout: Readout::Spectral }
    }
}

/// The camera ray through film position `film`: with a thin lens, through
/// the lens point of a [`Dim::LENS`] draw; a pinhole draws nothing.
#[inline(always)]
pub(crate) fn camera_ray(scene: &Scene, film: Vec2, sampler: &mut Sampler) -> Ray {
    let cam = &scene.camera;
    if cam.has_lens() { cam.ray_through(film, sampler.get_2d(Dim::LENS)) } else { cam.ray(film) }
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

/// A path's view of a surface hit among nested dielectrics.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Interface<'a> {
    /// A false intersection: go straight on (the stack is already updated).
    Pass,
    /// Scatter here, with `outside` on a dielectric's outside; `crossing`
    /// is the medium whose surface this is and whether the path enters it.
    Scatter { outside: Outside<'a>, crossing: Option<(Volume, bool)> },
}

impl<'a> Interface<'a> {
    /// The medium outside the dielectric (vacuum for other surfaces).
    #[inline]
    pub fn outside(&self) -> Outside<'a> {
        match self {
            Interface::Scatter { outside, .. } => *outside,
            Interface::Pass => Outside::VACUUM,
        }
    }

    /// After scattering into world direction `wi` at a surface of geometric
    /// normal `n` reached along `dir`: a transmission through a medium's
    /// surface enters or leaves it.
    #[inline]
    pub fn scattered(&self, media: &mut VolumeStack, dir: Vec3, n: Vec3, wi: Vec3) {
        if let Interface::Scatter { crossing: Some((m, entering)), .. } = *self
            && wi.dot(n) * dir.dot(n) > 0.0
        {
            media.cross(m, entering);
        }
    }

    /// The volumes on one side of the surface, for a shadow ray: those the
    /// path is in (`volumes`, before crossing) on `wo`'s side (`same_side`),
    /// else those a transmission would reach.
    #[inline]
    pub fn volumes_towards(&self, volumes: &VolumeStack, same_side: bool) -> VolumeStack {
        let mut side = *volumes;
        if let Interface::Scatter { crossing: Some((v, entering)), .. } = *self
            && !same_side
        {
            side.cross(v, entering);
        }
        side
    }
}

/// What a hit on object `si.object`, reached along `dir`, is for a path in
/// `media`: a false intersection (then `media` is updated) or a surface to
/// scatter at.
#[inline]
pub(crate) fn interface<'a>(scene: &'a Scene, media: &mut VolumeStack, si: &SurfaceHit, dir: Vec3) -> Interface<'a> {
    let Some(m) = scene.volume(si.object) else {
        return Interface::Scatter { outside: Outside::VACUUM, crossing: None };
    };
    let entering = dir.dot(si.hit.n) < 0.0;
    match scene.crossing(media, m, entering) {
        Crossing::Pass => {
            media.cross(m, entering);
            Interface::Pass
        }
        Crossing::Interface { outside } => {
            Interface::Scatter { outside: scene.outside(outside), crossing: Some((m, entering)) }
        }
    }
}

/// One next-event estimate at a non-delta surface: a light chosen by power, a
/// point on it sampled by solid angle or area, a shadow ray through
/// [`Scene::transmittance`] (from the volumes the path is in, `volumes`, on the
/// side the light is), and the MIS weight against BSDF sampling (power
/// heuristic) when `mis` is set. Without `aimed`, a light `caustics` aims
/// (`crate::light::Light::can_be_aimed`) adds nothing: at a glossy surface whose
/// caustics its light side traces. Its numbers are the draws of depth `depth`.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(crate) fn sample_direct<const N: usize>(
    scene: &Scene,
    bxdf: &Bxdf,
    sh: &Shading,
    at: &Interface<'_>,
    volumes: &VolumeStack,
    lambdas: &Lambdas<N>,
    sampler: &mut Sampler,
    mis: bool,
    aimed: bool,
    depth: u32,
) -> Sampled<N> {
    let zero = Sampled::splat(0.0);
    let u_light = sampler.get_1d_if(scene.light_count() > 1, Dim::light_choice(depth));
    let u = sampler.get_2d(Dim::light_sample(depth));
    let Some(choice) = scene.sample_li(sh.p, u_light, u) else {
        return zero;
    };
    if !aimed && scene.light(choice.light).can_be_aimed() {
        return zero;
    }
    let ls = choice.sample;
    let wi_local = sh.frame.to_local(ls.wi);
    if !sh.consistent(ls.wi, wi_local) {
        return zero;
    }
    let outside = at.outside();
    let mut f = bxdf.eval_within(sh.wo, wi_local, lambdas, outside);
    if f.is_black() {
        return zero;
    }
    let side = scene.has_volumes().then(|| at.volumes_towards(volumes, ls.wi.dot(sh.n) * sh.wo_n > 0.0));
    let Some(clear) = scene.transmittance(sh.p, sh.n, side.as_ref(), ls.point, ls.n) else {
        return zero;
    };
    clear.attenuate(&mut f, lambdas);
    let pdf_light = choice.pmf * ls.pdf;
    let weight = if ls.is_delta || !mis {
        1.0
    } else {
        power_heuristic(pdf_light, bxdf.pdf_within(sh.wo, wi_local, lambdas, outside))
    };
    let le = scene.with_radiance(choice.light, ls.wi, choice.uv, |s| lambdas.sample(s));
    f * le * (ls.scale * wi_local.z.abs() * weight / pdf_light)
}

/// One next-event estimate at a scattering event at `p` in a medium (the
/// path arrived travelling along `−wo`): a light chosen by power, a point on
/// it, a shadow ray through [`Scene::transmittance`] from the volumes `volumes`
/// (the medium's transmittance on the way), the phase function's value, and
/// the MIS weight against phase sampling (power heuristic). Its numbers are
/// the next-event draws of depth `depth`, as a surface vertex's.
#[allow(clippy::too_many_arguments)]
#[inline(never)]
pub(crate) fn sample_direct_medium<const N: usize>(
    scene: &Scene,
    phase: &crate::medium::HenyeyGreenstein,
    p: Vec3,
    wo: Vec3,
    volumes: &VolumeStack,
    lambdas: &Lambdas<N>,
    sampler: &mut Sampler,
    depth: u32,
) -> Sampled<N> {
    let zero = Sampled::splat(0.0);
    let u_light = sampler.get_1d_if(scene.light_count() > 1, Dim::light_choice(depth));
    let u = sampler.get_2d(Dim::light_sample(depth));
    let Some(choice) = scene.sample_li(p, u_light, u) else {
        return zero;
    };
    let ls = choice.sample;
    let f = phase.eval(wo, ls.wi);
    if f.is_nan() || f <= 0.0 {
        return zero;
    }
    let Some(clear) = scene.transmittance(p, Vec3::ZERO, Some(volumes), ls.point, ls.n) else {
        return zero;
    };
    let mut t = Sampled::splat(f);
    clear.attenuate(&mut t, lambdas);
    let pdf_light = choice.pmf * ls.pdf;
    let weight = if ls.is_delta { 1.0 } else { power_heuristic(pdf_light, f) };
    let le = scene.with_radiance(choice.light, ls.wi, choice.uv, |s| lambdas.sample(s));
    t * le * (ls.scale * weight / pdf_light)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::settings::SettingsPatch;

    /// Water (1.33) in glass (1.5): the interface the medium stack finds
    /// refracts by Snell's law with both absolute indices, n_glass sin θ_g =
    /// n_water sin θ_w, on the way in and out of the water; and beyond the
    /// critical angle glass → water (sin θ_g > 1.33/1.5) it reflects totally,
    /// where a vacuum outside would have refracted.
    #[test]
    fn water_in_glass_refracts_with_the_relative_index() {
        let text = r#"(camera: (eye: (0, 0, 5), look_at: (0, 0, 0), fov_deg: 30),
            materials: { "glass": Dielectric(ior: Constant(1.5)), "water": Dielectric(ior: Constant(1.33)) },
            objects: [ (shape: Sphere(center: (0, 0, 0), radius: 1), material: "glass"),
                       (shape: Sphere(center: (0, 0, 0), radius: 0.5), material: "water") ])"#;
        let scene =
            crate::scene::load_scene_str(text, std::path::Path::new("t.ron"), &SettingsPatch::default()).unwrap();
        let lambdas = Lambdas::full();
        let sin_between = |a: Vec3, n: Vec3| a.normalize().cross(n).length();
        // A ray inside the glass, hitting the water at incidence sine `sin_g`.
        let refract = |media: &mut VolumeStack, ray: Ray| {
            let si = scene.intersect(&ray, f32::INFINITY).unwrap();
            let at = interface(&scene, media, &si, ray.dir);
            assert!(matches!(at, Interface::Scatter { .. }));
            let sh = Shading::new(si.hit.p, si.hit.n, si.hit.ns, ray.dir);
            let bxdf = scene.bsdf(si.object);
            let bs = bxdf.sample_within(sh.wo, Vec2::ZERO, 1.0 - 1e-7, &lambdas, at.outside()).unwrap();
            let wi = sh.frame.to_world(bs.wi);
            at.scattered(media, ray.dir, si.hit.n, wi);
            (si, wi)
        };
        let glass = scene.volume(0).unwrap();
        let water = scene.volume(1).unwrap();
        let mut media = VolumeStack::VACUUM;
        media.enter(glass);
        let (si, wi) = refract(&mut media, Ray::new(Vec3::new(-0.8, 0.3, 0.0), Vec3::X));
        let (sin_g, sin_w) = (sin_between(Vec3::X, si.hit.n), sin_between(wi, si.hit.n));
        assert!((sin_g - 0.6).abs() < 1e-5 && wi.dot(si.hit.n) < 0.0, "into the water");
        assert!((1.5 * sin_g - 1.33 * sin_w).abs() < 1e-5, "Snell into water: {sin_g} {sin_w}");
        assert_eq!(media.current(), Some(water));
        // On through the water and out into the glass again.
        let (si2, wi2) = refract(&mut media, Ray::spawn(si.hit.p, si.hit.n, wi));
        let (sin_w2, sin_g2) = (sin_between(wi, si2.hit.n), sin_between(wi2, si2.hit.n));
        assert!(wi2.dot(si2.hit.n) > 0.0, "out of the water");
        assert!((1.33 * sin_w2 - 1.5 * sin_g2).abs() < 1e-5, "Snell out of water: {sin_w2} {sin_g2}");
        assert_eq!(media.current(), Some(glass));
        // Beyond glass → water's critical angle: total internal reflection.
        let ray = Ray::new(Vec3::new(-0.8, 0.48, 0.0), Vec3::X);
        let (si, wi) = refract(&mut media, ray);
        assert!(sin_between(Vec3::X, si.hit.n) > 1.33 / 1.5);
        assert!(wi.dot(si.hit.n) > 0.0, "reflected back into the glass");
        assert_eq!(media.current(), Some(glass), "reflected: still in the glass");
        // With vacuum outside, the same hit would have refracted.
        let mut vacuum = VolumeStack::VACUUM;
        let (si, wi) = refract(&mut vacuum, ray);
        assert!(wi.dot(si.hit.n) < 0.0 && vacuum.current() == Some(water));
    }
}
