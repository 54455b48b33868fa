//! `--integrator caustics`: path tracing, with the caustics of the
//! environment and of distant, point and spot lights traced from the
//! lights (issue 35).
//!
//! # A partition of path space
//! Write a path `E X1 X2 … Xk L` (`E` the eye, `X1` the first vertex seen
//! from the camera, `Xk` the last before the light). Call a vertex's
//! scattering *specular* when it went through a delta lobe (smooth glass,
//! mirror, smooth metal, thin sheet, a smooth Plastic's coat) or off a
//! glossy surface (a rough conductor or rough glass of GGX α at most
//! [`crate::bxdf::GLOSSY_ALPHA`], [`crate::bxdf::Bxdf::is_glossy`], decided at
//! each hit: a roughness texture may make some hits glossy and others not),
//! and *diffuse* otherwise; as a last vertex `Xk` a glossy surface counts as
//! specular only on a bounded object ([`Scene::glossy_at`]: a glossy `Plane`
//! has no disk to aim at). The **light side** owns the paths with `k ≥ 2`
//! whose `X1` is diffuse, whose `Xk` is specular and whose light `L` is
//! *aimed*: the environment (map, uniform or sky with its sun), a distant
//! light, a point or a spot light. The **camera side** owns every other
//! path. Each camera sample adds the two estimates:
//!
//! - the camera side is `auto`'s path tracer ([`PathTracer`] with
//!   `light_caustics`): on a path whose first vertex is diffuse, an escape
//!   to the environment through a delta lobe or off a glossy surface adds 0,
//!   and so does a glossy surface's next-event estimate when it picks an
//!   aimed light (MIS's two strategies for that vertex and light both go:
//!   the light side takes the whole). Next-event estimation never goes
//!   through a delta lobe; distant, point and spot lights are never hit by a
//!   camera path (today's `path` simply misses their caustics);
//! - the light side is, with probability [`Caustics::fraction`] per camera
//!   sample (its splats weighted by the inverse: 1/16 where every aimed ray
//!   reaches a surface that may cast caustics, more where fewer do,
//!   [`Aim::reach`]), one light subpath ([`Bdpt::caustic_splats`]): an
//!   aimed light chosen by power among the aimed lights ([`Aim::choose_light`]),
//!   a ray aimed at the bounding spheres of the objects that may cast
//!   caustics ([`Scene::may_cast_caustics`]; [`Aim::aimed_ray`]): for a
//!   parallel bundle its direction as the light draws it and its origin on
//!   one of the disks that cover the spheres, perpendicular to the direction
//!   and upstream of the scene ([`Aim::sample_origin`]); for a point or spot
//!   light its position and a direction uniform in one sphere's cone
//!   ([`Aim::sample_direction`]). If its first surface vertex `y1`'s
//!   scattering is not specular, the subpath ends (that path is the camera
//!   side's); otherwise every later vertex `y_i`, `i ≥ 2`, that is not
//!   glossy is connected to the eye with weight 1 (no MIS) and splatted, as
//!   `lighttrace`'s are. The path `E y_i … y1 y0` then has `X1 = y_i`
//!   (diffuse: a connection evaluates only the non-delta part of its BSDF),
//!   `Xk = y1` (specular) and `k = i ≥ 2`: exactly the light side's paths,
//!   each made once.
//!
//! Both sides are unbiased estimators of their parts of the measurement
//! (their sampling densities are positive wherever the parts are nonzero:
//! every ray of an aimed light that reaches a specular object passes through
//! that object's disk), so their sum is unbiased by linearity, with no MIS
//! weights. A material with a delta and a non-delta lobe (Plastic) splits the
//! same way per lobe: the camera side keeps its non-delta lobe's paths
//! (next-event estimation and the MIS-weighted escape), the light side its
//! delta lobe's. A glossy surface has one lobe, all of it specular.
//!
//! Why glossy surfaces too: on `scenes/environment.ron` (gold of α 0.08) a
//! camera path found the sun's reflection in the gold onto the floor only
//! when a diffuse bounce happened to hit the gold and its light sample then
//! the sun through the narrow lobe: rare samples of about 240, some 130 times a floor
//! pixel's value. Aimed light subpaths land there at every try
//! (docs/performance.md, "Glossy caustics to the light side").
//!
//! # Aiming
//! From a point or spot light the direction's density per solid angle is
//! the mixture `Σ_k P_k [ω meets sphere k] / Ω_k`, `Ω_k` the solid angle of
//! sphere `k`'s cone (4π from inside it; [`Aim::pdf_direction`]); a spot's
//! falloff is the ray's emission factor (0 outside its cone: wasted).
//! For a parallel bundle of direction `ω` the origin's density per area on
//! the plane perpendicular to `ω` is the mixture `Σ_k P_k [x ∈ disk_k] /
//! (π r_k²)` ([`Aim::pdf_origin`]): disks overlap, and a point in several
//! counts every disk that holds it. Targets are picked with probability
//! `P_k ∝ r_k²` (where disks do not overlap the origin is then uniform over
//! their union). A ray through a disk that first meets a non-delta object is
//! wasted; a ray that could reach a delta object and lies in no disk cannot
//! exist (the disk is the sphere's whole shadow).
//!
//! # Wavelengths and sampler dimensions
//! The camera side is `auto`'s (full spectrum, collapsing at dispersive
//! glass by throughput), the light side BDPT's fixed draw `u_λ`, taken from
//! [`Dim::wavelength`]`(1)`, which `auto`'s path tracer never draws; whether
//! a sample traces a light subpath at all is [`Dim::wavelength`]`(2)`'s. The
//! light side's other draws are [`Dim::EMIT_CHOICE`], [`Dim::EMIT_POSITION`],
//! [`Dim::EMIT_DIRECTION`] and the light subpath's own per-bounce block, so
//! the two sides share no number (a pinhole camera; a lens system is
//! refused, as for `bdpt`).
//!
//! # Limits
//! Paths whose first bounce from the light is diffuse stay with the camera
//! side (the caustic seen in a mirror, say, is the camera side's); so do
//! those whose `X1` is glossy (the floor's caustic seen in the gold): a
//! connection to the eye through a narrow lobe would rarely count; area
//! lights and beams are not aimed (their caustics stay as `path` finds
//! them: none for a beam); an object with a
//! delta lobe and no bounds (a mirror plane) leaves no disk to aim at, and
//! then `caustics` is path tracing alone, as it is without a specular
//! surface or an aimed light; a glossy `Plane`'s caustics stay the camera
//! side's and the other targets keep theirs. Scenes with scattering media are refused at load.
//!
//! [`Dim::wavelength`]: crate::sampler::Dim::wavelength
//! [`Dim::EMIT_CHOICE`]: crate::sampler::Dim::EMIT_CHOICE
//! [`Dim::EMIT_POSITION`]: crate::sampler::Dim::EMIT_POSITION
//! [`Dim::EMIT_DIRECTION`]: crate::sampler::Dim::EMIT_DIRECTION

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use crate::film::Splat;
use crate::geometry::{Frame, Ray};
use crate::light::EmissionSample;
use crate::sampler::warp::{concentric_disk, cone_one_minus_cos, uniform_sphere};
use crate::sampler::{Dim, Sampler};
use crate::scene::Scene;
use crate::spectral::Contribution;

use super::{Bdpt, Estimator, FullSpectrum, PathTracer};

/// A disk to aim at: the bounding sphere of an object that may cast caustics.
#[derive(Clone, Copy, Debug)]
struct Target {
    center: Vec3,
    radius: f32,
    /// The probability of picking it.
    p: f32,
}

/// Where `caustics`' light side aims: the aimed lights with their choice
/// probabilities, and the targets.
#[derive(Clone, Debug)]
pub(crate) struct Aim {
    targets: Vec<Target>,
    /// Cumulative target probabilities.
    target_cdf: Vec<f32>,
    /// The aimed lights' indices and probabilities (by power).
    lights: Vec<(u32, f32)>,
    /// Cumulative light probabilities.
    light_cdf: Vec<f32>,
    /// The scene's radius: rays start `2R + r_k` upstream of target `k`'s
    /// centre, beyond everything bounded.
    scene_radius: f32,
}

impl Aim {
    /// The aim for `scene`, or `None` when there is nothing to aim (no aimed
    /// light with power, no object that may cast caustics, or an unbounded one).
    pub(crate) fn new(scene: &Scene) -> Option<Aim> {
        let spheres = scene.caustic_targets()?;
        let spheres: Vec<(Vec3, f32)> =
            spheres.into_iter().filter(|(c, r)| c.is_finite() && r.is_finite() && *r > 0.0).collect();
        let lights: Vec<(u32, f32)> = (0..scene.light_count() as u32)
            .filter(|&i| scene.light(i).can_be_aimed())
            .map(|i| (i, scene.light(i).power().max(0.0)))
            .filter(|(_, p)| p.is_finite() && *p > 0.0)
            .collect();
        Aim::from_parts(&spheres, &lights, scene.radius())
    }

    /// The aim at `spheres` (centre, radius) for lights `(index, power)`.
    fn from_parts(spheres: &[(Vec3, f32)], lights: &[(u32, f32)], scene_radius: f32) -> Option<Aim> {
        let area: f32 = spheres.iter().map(|(_, r)| r * r).sum();
        let power: f32 = lights.iter().map(|(_, p)| p).sum();
        if spheres.is_empty() || lights.is_empty() || !(area > 0.0 && power > 0.0) {
            return None;
        }
        let targets: Vec<Target> =
            spheres.iter().map(|&(center, radius)| Target { center, radius, p: radius * radius / area }).collect();
        let cdf = |ps: &mut dyn Iterator<Item = f32>| {
            let mut acc = 0.0;
            let mut c: Vec<f32> = ps
                .map(|p| {
                    acc += p;
                    acc
                })
                .collect();
            // The last entry exactly 1, so every u < 1 finds one.
            if let Some(last) = c.last_mut() {
                *last = 1.0;
            }
            c
        };
        let lights: Vec<(u32, f32)> = lights.iter().map(|&(i, p)| (i, p / power)).collect();
        Some(Aim {
            target_cdf: cdf(&mut targets.iter().map(|t| t.p)),
            light_cdf: cdf(&mut lights.iter().map(|l| l.1)),
            targets,
            lights,
            scene_radius,
        })
    }

    /// The share of aimed rays whose first surface may scatter through a
    /// delta lobe, from [`PILOT_RAYS`] rays drawn as the light side draws
    /// them (a fixed stream: deterministic); 0 when none does.
    pub(crate) fn reach(&self, scene: &Scene) -> f32 {
        // An independent stream: its draws come in order whatever their dimensions.
        let mut sampler = Sampler::new(0x0a1e_d5ee_d000_0035, 0, 0);
        let mut hits = 0u32;
        for _ in 0..PILOT_RAYS {
            let (u_light, u_pos, u_dir) = (
                sampler.get_1d(Dim::EMIT_CHOICE),
                sampler.get_2d(Dim::EMIT_POSITION),
                sampler.get_2d(Dim::EMIT_DIRECTION),
            );
            let Some((index, _)) = self.choose_light(u_light) else { continue };
            let Some(e) = self.aimed_ray(scene, index, u_pos, u_dir) else { continue };
            if let Some(si) = scene.intersect(&Ray::spawn(e.point, e.n, e.dir), f32::INFINITY)
                && scene.may_cast_caustics(si.object)
            {
                hits += 1;
            }
        }
        hits as f32 / PILOT_RAYS as f32
    }

    /// A ray leaving aimed light `index`, drawn with `u_pos` and `u_dir`. A
    /// parallel bundle (the environment, a distant light): the direction as
    /// [`crate::light::Light::sample_le`] draws it, the origin by [`Aim::sample_origin`]
    /// (its density in `pdf_pos`). A point or spot light: its position, and a
    /// direction by [`Aim::sample_direction`] (its density in `pdf_dir`; a
    /// spot's falloff in `scale`).
    pub(crate) fn aimed_ray(&self, scene: &Scene, index: u32, u_pos: Vec2, u_dir: Vec2) -> Option<EmissionSample> {
        let light = scene.light(index);
        if light.is_delta_position() {
            // The position (the direction drawn here is the spot's axis, always emitted).
            let e = light.sample_le(Vec2::ZERO, Vec2::ZERO)?;
            let (dir, pdf_dir) = self.sample_direction(e.point, u_dir)?;
            let scale = light.emit_factor(Vec3::ZERO, dir);
            return (scale > 0.0).then_some(EmissionSample { dir, pdf_dir, scale, ..e });
        }
        let e = light.sample_le(u_pos, u_dir)?;
        let (point, pdf_pos) = self.sample_origin(e.dir, u_pos)?;
        Some(EmissionSample { point, pdf_pos, ..e })
    }

    /// A direction from `from` (a point or spot light's position) towards
    /// the targets, drawn with `u`: a target `k` with probability `P_k` (by
    /// `u.x`, then rescaled), then uniform in the cone of directions that
    /// meet its sphere (the whole sphere of directions when `from` lies in
    /// it). Returns it with its density per solid angle, [`Aim::pdf_direction`].
    pub(crate) fn sample_direction(&self, from: Vec3, u: Vec2) -> Option<(Vec3, f32)> {
        let (t, ux) = self.pick(u.x);
        let d = t.center - from;
        let d2 = d.length_squared();
        let r2 = t.radius * t.radius;
        let dir = if d2 <= r2 {
            uniform_sphere(Vec2::new(ux, u.y))
        } else {
            let v = ux * cone_one_minus_cos(r2 / d2);
            let (cos, sin) = (1.0 - v, (v * (2.0 - v)).max(0.0).sqrt());
            let phi = 2.0 * PI * u.y;
            Frame::from_z(d / d2.sqrt()).to_world(Vec3::new(sin * phi.cos(), sin * phi.sin(), cos)).normalize()
        };
        let pdf = self.pdf_direction(from, dir);
        (pdf.is_finite() && pdf > 0.0).then_some((dir, pdf))
    }

    /// The density per solid angle with which [`Aim::sample_direction`]
    /// draws unit `dir` from `from`: `Σ_k P_k [dir meets sphere k] / Ω_k`,
    /// `Ω_k` the solid angle of sphere `k`'s cone (4π from inside it).
    /// "Meets" is tested as the line's distance from the centre, within
    /// r (1 + 5·10⁻⁵) so that drawn directions on a cone's rim, rounded, still
    /// count (a cone's solid angle `2π (1 − cos θ)` stays exact for tiny cones).
    pub(crate) fn pdf_direction(&self, from: Vec3, dir: Vec3) -> f32 {
        self.targets
            .iter()
            .map(|t| {
                let d = t.center - from;
                let (d2, r2) = (d.length_squared(), t.radius * t.radius);
                if d2 <= r2 {
                    return t.p / (4.0 * PI);
                }
                let along = d.dot(dir);
                if along <= 0.0 || (d - dir * along).length_squared() > r2 * (1.0 + 1e-4) {
                    return 0.0;
                }
                t.p / (2.0 * PI * cone_one_minus_cos(r2 / d2))
            })
            .sum()
    }

    /// A target chosen with `u` by the probabilities `P_k`, and `u` rescaled
    /// to `[0, 1)` within its stretch.
    fn pick(&self, u: f32) -> (&Target, f32) {
        let k = self.target_cdf.partition_point(|&c| c <= u).min(self.targets.len() - 1);
        let lo = if k == 0 { 0.0 } else { self.target_cdf[k - 1] };
        let t = &self.targets[k];
        (t, ((u - lo) / t.p).clamp(0.0, 1.0 - f32::EPSILON))
    }

    /// How many lights are aimed.
    pub(crate) fn light_count(&self) -> usize {
        self.lights.len()
    }

    /// How many targets there are.
    pub(crate) fn target_count(&self) -> usize {
        self.targets.len()
    }

    /// An aimed light chosen with `u`, by power: its index and probability.
    pub(crate) fn choose_light(&self, u: f32) -> Option<(u32, f32)> {
        let k = self.light_cdf.partition_point(|&c| c <= u).min(self.lights.len().checked_sub(1)?);
        Some(self.lights[k])
    }

    /// The origin of a ray travelling along unit `dir`, drawn with `u`: a
    /// target `k` with probability `P_k` (by `u.x`, then rescaled), a point
    /// uniform on its disk perpendicular to `dir`, moved upstream beyond the
    /// scene. Returns the point and its density per area on that plane,
    /// [`Aim::pdf_origin`].
    pub(crate) fn sample_origin(&self, dir: Vec3, u: Vec2) -> Option<(Vec3, f32)> {
        let (t, ux) = self.pick(u.x);
        let q = concentric_disk(Vec2::new(ux, u.y)) * t.radius;
        let upstream = 2.0 * self.scene_radius + t.radius;
        let point = t.center + Frame::from_z(dir).to_world(Vec3::new(q.x, q.y, 0.0)) - dir * upstream;
        let pdf = self.pdf_origin(point, dir);
        (pdf.is_finite() && pdf > 0.0).then_some((point, pdf))
    }

    /// The density per area, on the plane perpendicular to `dir`, with which
    /// [`Aim::sample_origin`] draws a ray through `point`: the mixture
    /// `Σ_k P_k [point ∈ disk_k] / (π r_k²)`.
    pub(crate) fn pdf_origin(&self, point: Vec3, dir: Vec3) -> f32 {
        self.targets
            .iter()
            .filter(|t| {
                let d = point - t.center;
                let perp = d - dir * d.dot(dir);
                perp.length_squared() <= t.radius * t.radius
            })
            .map(|t| t.p / (PI * t.radius * t.radius))
            .sum()
    }
}

/// The share of camera samples that also trace a light subpath when every
/// aimed ray reaches a surface that may cast caustics (their splats are weighted by the
/// inverse of the share: unbiased); [`Aim::reach`] raises it where fewer do. On
/// `scenes/environment.ron` at 192x128 (32 spp, one thread, against a
/// 4096-spp reference) MSE × time relative to `path`'s was 1.19 with a
/// light subpath per sample (q = 1), 0.63 at 1/4, 0.54 at 1/8, 0.50 at
/// 1/16, 0.45 at 1/32, 0.46 at 1/64: the light subpaths cost as much as the
/// camera paths, and one per 16 camera samples already takes the caustic's
/// error far below the rest of the image's (85% of the aimed rays reach the
/// glass there, so [`Caustics::new`] traces a light subpath for 7.4%). With
/// the gold's glossy caustics aimed at too (8 renders of 16 spp each), 1/8
/// and 1/4 gave 3% and 4% less error than 1/16 for 23% and 48% more time.
const LIGHT_FRACTION: f32 = 1.0 / 16.0;

/// How many aimed rays [`Aim::reach`] traces.
const PILOT_RAYS: u32 = 1024;

/// The `caustics` estimator: the camera side's path tracing plus the light
/// side's splats (see the module doc).
pub(crate) struct Caustics {
    /// `auto`'s path tracer with `light_caustics` set.
    pub camera: FullSpectrum,
    /// Light tracing (`light_only`), for its aimed subpath and connections.
    pub light: Bdpt,
    /// The aimed lights and the targets.
    pub aim: Aim,
    /// The probability that a camera sample traces a light subpath:
    /// [`LIGHT_FRACTION`] divided by [`Aim::reach`], at most 1 (1 when no
    /// pilot ray reached a surface that may cast caustics), so that about one camera sample
    /// in 16 has a light subpath that reaches one.
    pub fraction: f32,
}

/// True when every delta light of `scene` is one that `caustics` aims (no
/// beam): then `auto` may pick `caustics` for its caustics.
pub(crate) fn aims_every_delta_light(scene: &Scene) -> bool {
    (0..scene.light_count() as u32).all(|i| {
        let light = scene.light(i);
        !light.is_delta() || light.can_be_aimed()
    })
}

impl Caustics {
    /// The estimator for `scene` with bounce limit `max_bounces`; `None` when
    /// there is nothing to aim ([`Aim::new`]).
    pub(crate) fn new(scene: &Scene, max_bounces: u32, collapse_to: u32) -> Option<Caustics> {
        let aim = Aim::new(scene)?;
        let reach = aim.reach(scene);
        let fraction = if reach > 0.0 { (LIGHT_FRACTION / reach).min(1.0) } else { 1.0 };
        let path = PathTracer { max_bounces, disperse: true, collapse_to, light_caustics: true };
        Some(Caustics {
            camera: FullSpectrum(super::Transport::Path(path)),
            light: Bdpt { max_bounces, light_only: true },
            aim,
            fraction,
        })
    }
}

impl Estimator for Caustics {
    fn sample<O: Contribution>(
        &self,
        scene: &Scene,
        film: Vec2,
        sampler: &mut Sampler,
        splats: &mut Vec<Splat<O>>,
    ) -> O {
        let camera = self.camera.sample(scene, film, sampler, splats);
        if sampler.get_1d(Dim::wavelength(2)) < self.fraction {
            self.light.caustic_splats(scene, &self.aim, sampler, splats, 1.0 / self.fraction);
        }
        camera
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::Sampler;

    /// Three overlapping disks and one apart, seen along several directions:
    /// `E[1/pdf_origin]` over drawn points is the area of the disks' union
    /// on the plane (a Monte Carlo estimate of the area; the union's area is
    /// computed independently on a fine grid over the plane), and every
    /// drawn point has a positive density and lies upstream of the scene.
    #[test]
    fn the_mixture_density_integrates_to_the_union_of_the_disks() {
        let spheres = [
            (Vec3::new(0.0, 0.0, 0.0), 1.0),
            (Vec3::new(0.8, 0.3, 0.1), 0.6),
            (Vec3::new(0.2, -0.5, 0.4), 0.3),
            (Vec3::new(4.0, 1.0, -2.0), 0.5),
        ];
        let scene_radius = 6.0;
        let aim = Aim::from_parts(&spheres, &[(0, 1.0)], scene_radius).unwrap();
        let dirs =
            [Vec3::new(0.0, -1.0, 0.0), Vec3::new(1.0, -2.0, 0.5).normalize(), Vec3::new(-0.3, 0.1, 1.0).normalize()];
        let mut s = Sampler::new(3, 1, 4);
        for dir in dirs {
            // The union's area on a grid of the plane perpendicular to `dir`.
            let frame = Frame::from_z(dir);
            let discs: Vec<(Vec2, f32)> = spheres
                .iter()
                .map(|&(c, r)| {
                    let l = frame.to_local(c);
                    (Vec2::new(l.x, l.y), r)
                })
                .collect();
            let (n, lo, hi) = (2000, -6.0f64, 6.0f64);
            let cell = (hi - lo) / n as f64;
            let mut inside = 0u64;
            for i in 0..n {
                for j in 0..n {
                    let p = Vec2::new((lo + (i as f64 + 0.5) * cell) as f32, (lo + (j as f64 + 0.5) * cell) as f32);
                    if discs.iter().any(|(c, r)| (p - *c).length_squared() <= r * r) {
                        inside += 1;
                    }
                }
            }
            let union = inside as f64 * cell * cell;
            let m = 200_000;
            let (mut sum, mut sum2) = (0.0f64, 0.0f64);
            for _ in 0..m {
                let (p, pdf) = aim.sample_origin(dir, s.next_2d()).expect("a point on a disk");
                assert!(pdf > 0.0 && pdf == aim.pdf_origin(p, dir));
                // Upstream of everything within the scene's radius of any target's centre.
                for (c, _) in spheres {
                    assert!((p - c).dot(dir) < -scene_radius, "{p} not upstream along {dir}");
                }
                let x = 1.0 / pdf as f64;
                sum += x;
                sum2 += x * x;
            }
            let mean = sum / m as f64;
            let se = ((sum2 / m as f64 - mean * mean).max(0.0) / m as f64).sqrt();
            eprintln!("union {union:.4}, E[1/pdf] {mean:.4} ± {se:.4} along {dir}");
            assert!((mean - union).abs() < 5.0 * se + 2e-3 * union, "{mean} ± {se} vs {union}");
        }
    }

    /// The direction mixture from a point: `E[1/pdf_direction]` over drawn
    /// directions is the solid angle of the union of the spheres' cones,
    /// measured independently by counting uniform directions whose rays meet
    /// a sphere (f64, 400k: s.e. under 0.5%); a sphere far and small enough
    /// that `cos θ_max` rounds to 1 in f32 still gets its exact solid angle;
    /// from inside a sphere every direction has density ≥ P_k/4π.
    #[test]
    fn the_direction_mixture_integrates_to_the_union_of_the_cones() {
        let spheres =
            [(Vec3::new(0.0, -2.0, 0.0), 1.0), (Vec3::new(0.6, -2.5, 0.3), 0.8), (Vec3::new(-3.0, 0.0, 1.0), 0.3)];
        let aim = Aim::from_parts(&spheres, &[(0, 1.0)], 10.0).unwrap();
        let from = Vec3::new(0.1, 0.5, 0.0);
        let mut s = Sampler::new(5, 0, 0);
        let n = 400_000;
        let mut hits = 0u64;
        for _ in 0..n {
            let w = uniform_sphere(s.next_2d()).as_dvec3();
            let meets = spheres.iter().any(|&(c, r)| {
                let d = (c - from).as_dvec3();
                let along = d.dot(w);
                along > 0.0 && (d - w * along).length_squared() <= (r as f64) * (r as f64)
            });
            hits += meets as u64;
        }
        let union = 4.0 * std::f64::consts::PI * hits as f64 / n as f64;
        let (mut sum, mut sum2) = (0.0f64, 0.0f64);
        for _ in 0..n {
            let (dir, pdf) = aim.sample_direction(from, s.next_2d()).expect("a direction");
            assert!((dir.length() - 1.0).abs() < 1e-5 && pdf == aim.pdf_direction(from, dir));
            let x = 1.0 / pdf as f64;
            sum += x;
            sum2 += x * x;
        }
        let mean = sum / n as f64;
        let se = ((sum2 / n as f64 - mean * mean).max(0.0) / n as f64).sqrt();
        let se_union =
            4.0 * std::f64::consts::PI * ((hits as f64 / n as f64) * (1.0 - hits as f64 / n as f64) / n as f64).sqrt();
        eprintln!("union of cones {union:.4} ± {se_union:.4}, E[1/pdf] {mean:.4} ± {se:.4}");
        assert!((mean - union).abs() < 5.0 * (se * se + se_union * se_union).sqrt(), "{mean} vs {union}");
        // A tiny far sphere: the solid angle 2π(1 − cos θ) ≈ π (r/d)².
        let tiny = Aim::from_parts(&[(Vec3::new(0.0, 0.0, -1000.0), 0.01)], &[(0, 1.0)], 2000.0).unwrap();
        let (dir, pdf) = tiny.sample_direction(Vec3::ZERO, Vec2::new(0.3, 0.7)).unwrap();
        let want = 1.0 / (std::f64::consts::PI * 1e-10);
        assert!(((pdf as f64) / want - 1.0).abs() < 1e-3 && dir.z < 0.0, "{pdf} vs {want}");
        // From inside the first sphere: every direction counts it.
        let inside = Vec3::new(0.0, -2.0, 0.2);
        for _ in 0..1000 {
            let (dir, pdf) = aim.sample_direction(inside, s.next_2d()).unwrap();
            assert!(pdf >= aim.targets[0].p / (4.0 * PI) && pdf == aim.pdf_direction(inside, dir));
        }
    }

    /// The pilot's share of aimed rays that reach a delta surface: a
    /// distant light straight down on a glass sphere whose disk a diffuse
    /// quad half covers (x < 0, above the sphere) gives ½ (1024 rays: s.e.
    /// 0.016, so within 0.06); the rate is then 1/16 ÷ ½ = 1/8; uncovered,
    /// every ray reaches the glass and the rate is 1/16.
    #[test]
    fn the_pilot_measures_the_share_of_aimed_rays_that_reach_the_glass() {
        let scene = |blocker: &str| {
            let text = format!(
                r#"(camera: (eye: (0, 1, 5), look_at: (0, 0, 0), fov_deg: 30),
                materials: {{ "glass": Dielectric(ior: Constant(1.5)), "grey": Lambertian(reflectance: Constant(0.5)) }},
                objects: [ (shape: Sphere(center: (0, 0, 0), radius: 0.5), material: "glass"), {blocker} ],
                lights: [ Distant(direction: (0, -1, 0), irradiance: Constant(1)) ])"#
            );
            crate::scene::load_scene_str(&text, std::path::Path::new("t.ron"), &Default::default()).unwrap()
        };
        let half =
            scene(r#"(shape: Quad(origin: (-2, 1, -2), edge_u: (2, 0, 0), edge_v: (0, 0, 4)), material: "grey")"#);
        let c = Caustics::new(&half, 8, 4).unwrap();
        let reach = c.aim.reach(&half);
        assert!((reach - 0.5).abs() < 0.06, "half covered: {reach}");
        assert!((c.fraction - LIGHT_FRACTION / reach).abs() < 1e-6);
        let open =
            scene(r#"(shape: Quad(origin: (-2, -3, -2), edge_u: (4, 0, 0), edge_v: (0, 0, 4)), material: "grey")"#);
        let c = Caustics::new(&open, 8, 4).unwrap();
        assert_eq!((c.aim.reach(&open), c.fraction), (1.0, LIGHT_FRACTION));
    }

    /// Lights are chosen by power among the aimed ones, with the probability
    /// returned; targets by area.
    #[test]
    fn lights_by_power_targets_by_area() {
        let aim = Aim::from_parts(&[(Vec3::ZERO, 1.0), (Vec3::X * 3.0, 2.0)], &[(2, 1.0), (5, 3.0)], 5.0).unwrap();
        assert_eq!(aim.choose_light(0.1), Some((2, 0.25)));
        assert_eq!(aim.choose_light(0.3), Some((5, 0.75)));
        assert_eq!(aim.choose_light(1.0 - f32::EPSILON), Some((5, 0.75)));
        assert!((aim.targets[0].p - 0.2).abs() < 1e-6 && (aim.targets[1].p - 0.8).abs() < 1e-6);
        assert!(Aim::from_parts(&[], &[(0, 1.0)], 1.0).is_none());
        assert!(Aim::from_parts(&[(Vec3::ZERO, 1.0)], &[], 1.0).is_none());
    }
}
