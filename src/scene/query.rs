//! The door between the integrators and the scene: every question a
//! light-transport method asks of what a scene contains. No integrator reads
//! the scene's objects, materials or lights directly, and none names a light
//! or material variant; each asks here, and the rooms that answer (shapes,
//! [`crate::bxdf`] lobes, [`crate::light`], [`crate::medium`]) stay closed
//! enums with their verbs in their own files.
//!
//! | question | query |
//! |---|---|
//! | the closest surface along a ray | [`Scene::intersect`] (a [`SurfaceHit`]: point, normals, primitive, object) |
//! | the surface coordinates of a hit, for a texture lookup | [`Scene::uv`] (on demand: nothing computes them during traversal) |
//! | the BSDF at a surface | [`Scene::bsdf_in`] (a `Mix` resolved and textures evaluated at the hit); [`Scene::bsdf`] for what neither changes |
//! | which material a hit has (a `Mix` chooses per hit) | [`Scene::material_at`] |
//! | emission leaving a surface hit | [`Scene::le`] (a textured emitter's radiance at the hit's (u, v)), and its light-sampling density for MIS, [`Scene::pdf_li`] |
//! | a point on a light towards a shading point | [`Scene::sample_li`] (its radiance: [`crate::light::Light::with_radiance`] with the choice's `uv`) |
//! | a ray leaving a light (BDPT, light tracing) | [`Scene::light`] then [`crate::light::Light::sample_le`] |
//! | the volume a dielectric's surface bounds, and the medium inside | [`Scene::volume`], [`Scene::medium_in`] |
//! | whether a segment between two points is clear, and its attenuation | [`Scene::transmittance`]: the one visibility rule |
//!
//! | the radiance a ray that escapes the scene sees | [`Scene::escaped`], and its light-sampling density for MIS, [`Scene::pdf_escaped`] |
//!
//! A ray that escapes meets the environment (`crate::light::EnvironmentLight`)
//! when the scene has one, else nothing: every integrator's escape branch
//! asks [`Scene::escaped`].

use glam::{Vec2, Vec3};

use super::{Scene, SurfaceHit};
use crate::bxdf::{Bxdf, Outside};
use crate::color::{Sampled, Spectrum};
use crate::geometry::Ray;
use crate::light::{Light, LightSample};
use crate::material::mix;
use crate::medium::{Crossing, Medium, Volume, VolumeStack};
use crate::spectral::Lambdas;
use crate::texture::{MaterialTextures, Texture};

/// The most false intersections a path or a segment passes in a row before it
/// ends (a guard against degenerate geometry; real scenes need a handful).
pub const MAX_PASSES: u32 = 64;

/// Emission leaving a surface hit towards the ray's origin.
#[derive(Clone, Copy, Debug)]
pub struct Emitted<'a> {
    /// The light the surface belongs to.
    pub light: u32,
    /// Its emitted radiance.
    pub radiance: &'a Spectrum,
    /// The factor of `radiance` leaving towards the ray (1, or 0 from the back
    /// of a one-sided emitter: then [`Scene::le`] answers `None`).
    pub scale: f32,
}

/// A point on a light chosen for next-event estimation.
#[derive(Clone, Copy, Debug)]
pub struct LightChoice {
    /// Which light.
    pub light: u32,
    /// The probability of having chosen it.
    pub pmf: f32,
    /// The direction, point and density on it.
    pub sample: LightSample,
    /// The point's surface coordinates on a textured emitter (else zero): the
    /// `uv` of [`Light::with_radiance`].
    pub uv: Vec2,
}

impl Scene {
    /// The (u, v) coordinates of a hit on its object's surface (each shape's
    /// parameterisation is in `shape/uv.rs`).
    #[inline]
    pub fn uv(&self, si: &SurfaceHit) -> glam::Vec2 {
        self.objects[si.object as usize].shape.uv(&si.hit)
    }

    /// The BSDF of object `object`'s material, untextured: for what does not
    /// depend on a texture (whether it is delta, black, dispersive; its
    /// dielectric index); the lobe at a hit is [`Scene::bsdf_in`]. For a
    /// `Mix`, the stand-in that answers for its object's volume (its
    /// Dielectric, or black: [`crate::material::mix`]); what a hit on it is,
    /// only [`Scene::material_at`] says.
    #[inline]
    pub fn bsdf(&self, object: u32) -> &Bxdf {
        &self.materials[self.objects[object as usize].material as usize]
    }

    /// The BSDF at surface hit `si`: its material's, with a textured
    /// reflectance evaluated at the hit's (u, v) and built in `slot`, which the
    /// caller keeps for the hit (a scene without textures pays one branch; a
    /// `Cow`, whose every use matches on it, cost 1.1% more instructions in a
    /// Cornell-box render). A `Mix` is resolved first ([`Scene::material_at`]);
    /// a scene without one pays one more branch.
    #[inline(always)]
    pub fn bsdf_in<'a>(&'a self, si: &SurfaceHit, slot: &'a mut Option<Bxdf>) -> &'a Bxdf {
        if !self.mixes.is_empty() {
            let uv = if self.needs_uv(si.object) { self.uv(si) } else { Vec2::ZERO };
            return self.mixed(si.object, si.hit.p, uv, slot);
        }
        match self.texture(si.object) {
            Some(t) => slot.insert(self.textured(si.object, t, self.uv(si))),
            None => self.bsdf(si.object),
        }
    }

    /// Object `object`'s lobe with textures `t` evaluated at `uv` (out of line).
    #[inline(never)]
    fn textured(&self, object: u32, t: &MaterialTextures, uv: Vec2) -> Bxdf {
        t.apply(self.bsdf(object), uv)
    }

    /// The BSDF of material `m` (a hit's, from [`Scene::material_at`]) at
    /// surface coordinates `uv` (as [`Scene::bsdf_in`], for a path vertex
    /// that resolved its material and kept its (u, v)).
    #[inline(always)]
    pub fn bsdf_of<'a>(&'a self, m: u32, uv: Vec2, slot: &'a mut Option<Bxdf>) -> &'a Bxdf {
        match self.material_texture(m) {
            Some(t) => slot.insert(self.textured_material(m, t, uv)),
            None => &self.materials[m as usize],
        }
    }

    /// Material `m`'s lobe with textures `t` evaluated at `uv` (out of line).
    #[inline(never)]
    fn textured_material(&self, m: u32, t: &MaterialTextures, uv: Vec2) -> Bxdf {
        t.apply(&self.materials[m as usize], uv)
    }

    /// The textures of material `m`, if it has any.
    #[inline]
    fn material_texture(&self, m: u32) -> Option<&MaterialTextures> {
        if self.textures.is_empty() {
            return None;
        }
        self.textures[m as usize].as_ref()
    }

    /// The material a hit on object `object` at point `p`, surface
    /// coordinates `uv`, has: the object's, or where that is a `Mix`, the
    /// material its per-hit choice leads to ([`crate::material::mix`]: a
    /// function of the hit alone, so every strategy at one vertex sees the same).
    #[inline]
    pub fn material_at(&self, object: u32, p: Vec3, uv: Vec2) -> u32 {
        let m = self.objects[object as usize].material;
        if self.mixes.is_empty() { m } else { mix::choose(&self.mixes, m, object, p, uv) }
    }

    /// The BSDF at a hit on object `object` in a scene with a `Mix` (out of
    /// line): the chosen material's, its textures evaluated at `uv`.
    #[inline(never)]
    fn mixed<'a>(&'a self, object: u32, p: Vec3, uv: Vec2, slot: &'a mut Option<Bxdf>) -> &'a Bxdf {
        self.bsdf_of(self.material_at(object, p, uv), uv, slot)
    }

    /// The materials a hit with material `*m` may have: `m` itself, or a
    /// Mix's leaves (for scene-level questions, which look through a Mix).
    #[inline]
    pub fn leaves<'a>(&'a self, m: &'a u32) -> &'a [u32] {
        match self.mixes.get(*m as usize) {
            Some(Some(mix)) => &mix.leaves,
            _ => std::slice::from_ref(m),
        }
    }

    /// The textures of object `object`'s material (reflectance, roughness,
    /// film thickness), if it has any.
    #[inline]
    pub fn texture(&self, object: u32) -> Option<&MaterialTextures> {
        if self.textures.is_empty() {
            return None;
        }
        self.textures[self.objects[object as usize].material as usize].as_ref()
    }

    /// The medium outside a dielectric surface whose outside volume has
    /// material `material` (`None`: vacuum), as the lobes take it.
    #[inline]
    pub fn outside(&self, material: Option<u32>) -> Outside<'_> {
        match material.and_then(|m| self.materials[m as usize].as_dielectric()) {
            Some(d) => Outside::medium(d),
            None => Outside::VACUUM,
        }
    }

    /// The medium filling object `object`'s inside, if any.
    #[inline]
    pub fn interior(&self, object: u32) -> Option<&Medium> {
        self.objects[object as usize].interior.as_deref()
    }

    /// The medium filling `volume` (`None`: vacuum, or a clear volume).
    #[inline]
    pub fn medium_in(&self, volume: Option<Volume>) -> Option<&Medium> {
        self.objects[volume?.object as usize].interior.as_deref()
    }

    /// The light of object `object`, when it emits.
    #[inline]
    pub fn emitter(&self, object: u32) -> Option<u32> {
        self.objects[object as usize].light
    }

    /// Light `index`.
    #[inline]
    pub fn light(&self, index: u32) -> &Light {
        &self.lights[index as usize]
    }

    /// How many lights the scene has (area lights included).
    #[inline]
    pub fn light_count(&self) -> usize {
        self.lights.len()
    }

    /// The probability with which next-event estimation chooses light `index`.
    #[inline]
    pub fn light_pmf(&self, index: u32) -> f32 {
        self.light_pmf[index as usize]
    }

    /// True when some light is a delta light (point, spot, distant, beam):
    /// no ray can hit it.
    pub fn has_delta_light(&self) -> bool {
        self.lights.iter().any(Light::is_delta)
    }

    /// True when some object's material scatters only into delta directions
    /// (smooth glass, mirror, smooth metal, thin sheet). An index-matched
    /// boundary (`Interface`) does not count: paths pass it without a vertex
    /// ([`Scene::crossing`]), so light sampling reaches a delta light through it.
    pub fn has_delta_surface(&self) -> bool {
        self.objects.iter().any(|o| {
            self.leaves(&o.material).iter().any(|&m| {
                let m = &self.materials[m as usize];
                m.is_delta() && !m.is_interface()
            })
        })
    }

    /// The bounding spheres `(centre, radius)` of the objects that may cast
    /// caustics ([`Scene::may_cast_caustics`]): where `--integrator caustics`
    /// aims its light subpaths. Instances and meshes by their world bounds.
    /// `None` when such an object is unbounded (no sphere holds it).
    pub fn caustic_targets(&self) -> Option<Vec<(Vec3, f32)>> {
        let mut targets = Vec::new();
        for (i, o) in self.objects.iter().enumerate() {
            if self.may_cast_caustics(i as u32) {
                // A sphere is its own bounding sphere (its box's is √3 times as wide).
                if let crate::shape::Shape::Sphere(s) = &o.shape {
                    targets.push((s.center, s.radius));
                } else {
                    let b = o.shape.bounds()?;
                    targets.push((b.centroid(), b.diagonal().length() * 0.5));
                }
            }
        }
        Some(targets)
    }

    /// True when a hit on object `object` may scatter through a delta lobe
    /// ([`Bxdf::has_delta_lobe`] of any material it may have; an index-matched
    /// `Interface` does not count, as in [`Scene::has_delta_surface`]) or a
    /// glossy one ([`Bxdf::may_be_glossy`], on a bounded object: see
    /// [`Scene::glossy_at`]): the surfaces whose caustics `--integrator
    /// caustics` traces from the lights.
    pub fn may_cast_caustics(&self, object: u32) -> bool {
        let bounded = self.objects[object as usize].shape.bounds().is_some();
        self.leaves(&self.objects[object as usize].material).iter().any(|&m| {
            let textured_roughness =
                self.textures.get(m as usize).is_some_and(|t| t.as_ref().is_some_and(|t| t.roughness.is_some()));
            let m = &self.materials[m as usize];
            (m.has_delta_lobe() && !m.is_interface()) || (bounded && m.may_be_glossy(textured_roughness))
        })
    }

    /// True when lobe `bxdf` at a hit on object `object` is glossy and may
    /// be aimed at, as the last vertex `Xk` of a path in `--integrator
    /// caustics`' partition: [`Bxdf::is_glossy`] on a bounded object (the
    /// test [`Scene::may_cast_caustics`] makes, so every such object is a
    /// target). A glossy `Plane` is not (no bounding sphere to aim at): its caustics
    /// stay the camera side's, and the other targets keep theirs. As a path's
    /// first vertex `X1` any glossy surface counts (the light side never
    /// connects the eye to one).
    #[inline]
    pub fn glossy_at(&self, object: u32, bxdf: &Bxdf) -> bool {
        bxdf.is_glossy() && self.objects[object as usize].shape.bounds().is_some()
    }

    /// The emission leaving surface hit `si` back along `dir` (the direction
    /// the ray travelled), or `None` where nothing leaves that side. A
    /// textured emitter's radiance at the hit's (u, v) is built in `slot`,
    /// which the caller keeps for the hit (as [`Scene::bsdf_in`]'s). Always
    /// inlined: out of line, its call cost the Cornell box 0.9% more
    /// instructions (callgrind).
    #[inline(always)]
    pub fn le<'a>(&'a self, si: &SurfaceHit, dir: Vec3, slot: &'a mut Option<Spectrum>) -> Option<Emitted<'a>> {
        let index = self.emitter(si.object)?;
        let light = &self.lights[index as usize];
        let scale = light.le_scale(si.hit.n, dir);
        (scale > 0.0).then_some(())?;
        let radiance = if self.emission_textures
            && let Some(t) = light.emission_texture()
        {
            slot.insert(self.textured_emission(&t.texture, si))
        } else {
            light.spectrum()
        };
        Some(Emitted { light: index, radiance, scale })
    }

    /// Texture `t` of an emitter at the (u, v) of hit `si` (out of line).
    #[inline(never)]
    fn textured_emission(&self, t: &Texture, si: &SurfaceHit) -> Spectrum {
        t.eval(self.uv(si))
    }

    /// True when something at a hit on object `object` depends on the hit's
    /// (u, v): a textured material ([`Scene::texture`]), a `Mix` (whose amount
    /// or materials may be textured) or a textured emission.
    #[inline]
    pub fn needs_uv(&self, object: u32) -> bool {
        self.texture(object).is_some()
            || self.mixes.get(self.objects[object as usize].material as usize).is_some_and(Option::is_some)
            || (self.emission_textures
                && self.emitter(object).is_some_and(|l| self.lights[l as usize].emission_texture().is_some()))
    }

    /// The environment's light index and its radiance from direction `dir`,
    /// for a ray that escaped the scene along `dir`; `None` without an environment.
    #[inline]
    pub fn escaped(&self, dir: Vec3) -> Option<(u32, Spectrum)> {
        let index = self.environment?;
        match &self.lights[index as usize] {
            Light::Environment(env) => Some((index, env.radiance(dir))),
            _ => None,
        }
    }

    /// The density per unit solid angle with which [`Scene::sample_li`] would
    /// have chosen the environment in direction `dir` (light choice included).
    #[inline]
    pub fn pdf_escaped(&self, light: u32, dir: Vec3) -> f32 {
        match &self.lights[light as usize] {
            Light::Environment(env) => self.light_pmf[light as usize] * env.pdf_li(dir),
            _ => 0.0,
        }
    }

    /// What crossing volume `v`'s surface (`entering` it or not) is for a path
    /// in `stack`: as [`VolumeStack::crossing`] says, except that an
    /// index-matched boundary (`Interface`) is always passed straight
    /// through: no vertex, only a change of medium (so the light sample taken
    /// before it, which [`Scene::transmittance`] takes through it, keeps its
    /// MIS weight).
    #[inline]
    pub fn crossing(&self, stack: &VolumeStack, v: Volume, entering: bool) -> Crossing {
        match stack.crossing(v, entering) {
            Crossing::Interface { .. } if self.interfaces && self.bsdf(v.object).is_interface() => Crossing::Pass,
            c => c,
        }
    }

    /// True when some object's interior scatters (a scattering medium).
    #[inline]
    pub fn has_scattering(&self) -> bool {
        self.scattering
    }

    /// True when the environment is the sky with its sun (a near-delta light).
    pub fn has_sun(&self) -> bool {
        self.environment.is_some_and(|i| matches!(&self.lights[i as usize], Light::Environment(e) if e.has_sun()))
    }

    /// True when the scene has an environment.
    #[inline]
    pub fn has_environment(&self) -> bool {
        self.environment.is_some()
    }

    /// The density per unit solid angle with which [`Scene::sample_li`] from
    /// `from` would have produced direction `dir`, which reaches light
    /// `light` at surface hit `si` (the light's choice included).
    #[inline]
    pub fn pdf_li(&self, light: u32, from: Vec3, dir: Vec3, si: &SurfaceHit) -> f32 {
        self.light_pmf[light as usize] * self.lights[light as usize].pdf_li(from, dir, si.hit.p, si.hit.n)
    }

    /// Next-event estimation from point `p`: a light chosen by power with
    /// `u_light`, then a point on it with `u`.
    #[inline(always)]
    pub fn sample_li(&self, p: Vec3, u_light: f32, u: glam::Vec2) -> Option<LightChoice> {
        let (index, pmf) = self.choose_light(u_light)?;
        let (sample, uv) = if self.emission_textures {
            self.sample_li_uv(index, p, u)?
        } else {
            (self.lights[index].sample_li(p, u)?, Vec2::ZERO)
        };
        Some(LightChoice { light: index as u32, pmf, sample, uv })
    }

    /// Light `index`'s [`Light::sample_li_uv`] (out of line: only a scene with
    /// emission textures asks for the uv).
    #[inline(never)]
    fn sample_li_uv(&self, index: usize, p: Vec3, u: Vec2) -> Option<(LightSample, Vec2)> {
        self.lights[index].sample_li_uv(p, u)
    }

    /// `f` of the radiance arriving from light `light` along `wi` from its
    /// point of surface coordinates `uv` ([`Light::with_radiance`]; a scene
    /// without emission textures does not look for a texture). `f` is called
    /// once (its code inlined once), on a spectrum computed here only for
    /// the environment and a texture: with `f` inlined at three places, the
    /// path tracer's walk grew past what LLVM inlines into it (callgrind:
    /// +1.9% instructions on the Cornell box).
    #[inline(always)]
    pub fn with_radiance<R>(&self, light: u32, wi: Vec3, uv: Vec2, f: impl FnOnce(&Spectrum) -> R) -> R {
        let light = &self.lights[light as usize];
        let mut slot = None;
        let s = if self.emission_textures {
            textured_radiance(light, wi, uv, &mut slot)
        } else {
            match light {
                Light::Environment(l) => slot.insert(l.radiance(wi)),
                _ => light.spectrum(),
            }
        };
        f(s)
    }

    /// The one visibility rule, for shadow rays and connections of every
    /// integrator: whether the segment from surface point `p` (geometric
    /// normal `n`) to `to` is clear, and if so what fills it ([`Clear`],
    /// whose [`Clear::attenuate`] applies its transmittance). `to_n` is the
    /// normal of the surface `to` lies on, or zero when `to` is a free point
    /// (a point or spot light, the eye): then every surface up to `to` blocks,
    /// however close (see [`Ray::spawn_to`]). `volumes` are the volumes around
    /// `p` on the segment's side (`None` in a scene without dielectrics).
    ///
    /// Where dielectric volumes nest, the segment passes false
    /// intersections (surfaces the stack says are not interfaces here, at
    /// most [`MAX_PASSES`]); any other surface blocks it. The current volume
    /// does not change at a false intersection, so the medium `p`'s side is
    /// filled with attenuates the whole length, once (Beer-Lambert,
    /// [`Medium::transmittance`]). `None` when blocked.
    ///
    /// The answer is two words, not a spectrum: the common case (vacuum, a
    /// scene without nested volumes) costs one occlusion ray and nothing
    /// else, and the callers multiply by a transmittance only where a medium
    /// is (returning a 36-bin spectrum cost the Cornell box 3% more
    /// instructions).
    #[inline(always)]
    pub fn transmittance(
        &self,
        p: Vec3,
        n: Vec3,
        volumes: Option<&VolumeStack>,
        to: Vec3,
        to_n: Vec3,
    ) -> Option<Clear<'_>> {
        let (ray, t_max) = Ray::spawn_to(p, n, to, to_n);
        match volumes {
            Some(stack) if self.interfaces => {
                return self.through_interfaces(ray, t_max, *stack, to, to_n).map(|tau| {
                    if tau.is_black() { Clear::In { medium: None, length: 0.0 } } else { Clear::Through(tau) }
                });
            }
            Some(stack) if self.nested => {
                if !self.clear_through_volumes(ray, t_max, *stack, to, to_n) {
                    return None;
                }
            }
            _ => {
                if self.occluded(&ray, t_max) {
                    return None;
                }
            }
        }
        let medium = volumes.and_then(|v| self.medium_in(v.current()));
        if let Some(m) = medium
            && m.is_grid()
        {
            return Some(Clear::Through(m.optical_depth(p, to, segment_seed(p, to))));
        }
        Some(Clear::In { medium, length: if medium.is_some() { (to - p).length() } else { 0.0 } })
    }

    /// [`Scene::transmittance`] in a scene with index-matched boundaries
    /// (`Interface` objects): the segment passes false intersections and
    /// `Interface` surfaces (whose crossing changes the medium: the current
    /// one fills each piece), stops at any other surface; the answer is the
    /// optical depth `Σ σt d` of the pieces per bin.
    #[inline(never)]
    fn through_interfaces(
        &self,
        mut ray: Ray,
        mut t_max: f32,
        mut stack: VolumeStack,
        to: Vec3,
        to_n: Vec3,
    ) -> Option<Spectrum> {
        let mut tau = Spectrum::ZERO;
        let mut from = ray.origin;
        let mut passes = 0;
        while let Some(si) = self.intersect(&ray, t_max) {
            let entering = ray.dir.dot(si.hit.n) < 0.0;
            let v = self.volume(si.object)?;
            let crossing = stack.crossing(v, entering);
            let interface = self.bsdf(si.object).is_interface();
            if passes >= MAX_PASSES || !(crossing == Crossing::Pass || interface) {
                return None;
            }
            if let Some(m) = self.medium_in(stack.current()) {
                tau += m.optical_depth(from, si.hit.p, segment_seed(from, si.hit.p));
            }
            from = si.hit.p;
            stack.cross(v, entering);
            passes += 1;
            (ray, t_max) = Ray::spawn_to(si.hit.p, si.hit.n, to, to_n);
        }
        if let Some(m) = self.medium_in(stack.current()) {
            tau += m.optical_depth(from, to, segment_seed(from, to));
        }
        Some(tau)
    }

    /// [`Scene::transmittance`]'s walk through nested volumes: passes false
    /// intersections, stops at the first real one.
    #[inline(never)]
    fn clear_through_volumes(
        &self,
        mut ray: Ray,
        mut t_max: f32,
        mut stack: VolumeStack,
        to: Vec3,
        to_n: Vec3,
    ) -> bool {
        let mut passes = 0;
        while let Some(si) = self.intersect(&ray, t_max) {
            let entering = ray.dir.dot(si.hit.n) < 0.0;
            match self.volume(si.object) {
                Some(v) if passes < MAX_PASSES && stack.crossing(v, entering) == Crossing::Pass => {
                    stack.cross(v, entering);
                    passes += 1;
                    (ray, t_max) = Ray::spawn_to(si.hit.p, si.hit.n, to, to_n);
                }
                _ => return false,
            }
        }
        true
    }
}

/// [`Light::with_radiance`]'s spectrum, out of line (a scene with emission textures).
#[inline(never)]
fn textured_radiance<'a>(light: &'a Light, wi: Vec3, uv: Vec2, slot: &'a mut Option<Spectrum>) -> &'a Spectrum {
    match light {
        Light::Environment(l) => slot.insert(l.radiance(wi)),
        _ => light.radiance_in(uv, slot),
    }
}

/// The seed of a segment's ratio tracking: a hash of its end points (a
/// path's vertices are random, so these are too; the render stays
/// deterministic for any thread count).
#[inline]
fn segment_seed(a: Vec3, b: Vec3) -> u64 {
    let mut h = crate::io::Fnv1a::default();
    for v in [a.x, a.y, a.z, b.x, b.y, b.z] {
        h.write(&v.to_bits().to_le_bytes());
    }
    h.finish()
}

/// A clear segment (see [`Scene::transmittance`]).
#[derive(Clone, Copy, Debug)]
pub enum Clear<'a> {
    /// One medium fills the whole segment (`None`: vacuum or a clear volume),
    /// over its length (0 when `medium` is `None`: not computed). The common
    /// case: two words.
    In {
        /// What fills the segment.
        medium: Option<&'a Medium>,
        /// Its length.
        length: f32,
    },
    /// The segment crossed index-matched boundaries: its optical depth
    /// `Σ σt d` per bin over the media it ran in.
    Through(Spectrum),
}

impl Clear<'_> {
    /// Multiplies `f` by the segment's transmittance at `lambdas` (nothing in vacuum).
    #[inline(always)]
    pub fn attenuate<const N: usize>(self, f: &mut Sampled<N>, lambdas: &Lambdas<N>) {
        match self {
            Clear::In { medium: Some(m), length } => *f *= m.transmittance(length, lambdas),
            Clear::In { medium: None, .. } => {}
            Clear::Through(tau) => *f *= (lambdas.sample(&tau) * -1.0).exp(),
        }
    }

    /// The transmittance at every bin, `None` where it is 1 (vacuum).
    #[inline]
    pub fn spectrum(self) -> Option<Spectrum> {
        match self {
            Clear::In { medium, length } => medium.map(|m| m.transmittance(length, &Lambdas::full())),
            Clear::Through(tau) => Some((tau * -1.0).exp()),
        }
    }
}
