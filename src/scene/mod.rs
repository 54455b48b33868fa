//! The scene: objects, materials, lights and camera, ready to render.
//!
//! Data flow: the RON file ([`desc`]) is parsed and checked by [`load_scene`] into a
//! [`Scene`]; the renderer asks it for the closest hit along a ray
//! ([`Scene::intersect`]) and whether a shadow ray is blocked
//! ([`Scene::occluded`]). Bounded objects sit in a BVH over their bounds
//! when there are enough of them to pay for it; unbounded ones (planes) are
//! tested one by one.

pub(crate) mod check;
pub mod desc;
mod load;
pub mod pbrt;
mod position;
mod query;
mod spectra;
pub mod surround;

pub use load::{load_scene, load_scene_str, load_scene_with_warnings};
pub use query::{Clear, Emitted, LightChoice, MAX_PASSES};

use crate::bxdf::Bxdf;
use crate::camera::Camera;
use crate::geometry::{Aabb, Hit, Ray};
use crate::light::Light;
use crate::medium::{Medium, VOLUME_STACK_DEPTH, Volume, VolumeStack};
use crate::settings::Settings;
use crate::shape::Shape;
use crate::shape::{Batch, Bvh};
use crate::texture::MaterialTextures;

/// Below this many bounded objects the scene tests them one by one instead of
/// building a BVH over them. Measured with callgrind (instructions for a 32x32,
/// 4-spp render, one thread): cornell.ron (7 objects) 50.0 M linear vs 57.9 M
/// with a BVH; spheres.ron (15 objects) 117.1 M linear vs 102.2 M with a BVH.
/// The crossover lies between, so 8. Scenes of quads and spheres only, up to
/// [`Batch::MAX_OBJECTS`], are tested in lanes instead and build no BVH at
/// all (spheres.ron: 15% less render time than with its BVH, 11 alternated runs).
pub(crate) const BVH_MIN_OBJECTS: usize = 8;

/// An object: a shape with a material and possibly an emission.
#[derive(Debug)]
pub struct Object {
    /// The shape.
    pub shape: Shape,
    /// Index into [`Scene::materials`].
    pub material: u32,
    /// Index into [`Scene::lights`] when the object emits.
    pub light: Option<u32>,
    /// Where dielectric volumes overlap, the higher priority wins (nested
    /// dielectrics, [`crate::medium::nested`]).
    pub priority: u32,
    /// The medium filling the object's volume (`interior:`, or a dielectric's
    /// `absorption:` as a medium that only absorbs); `None`: clear.
    pub interior: Option<Box<Medium>>,
    /// True for the sphere holding the camera's medium ([`surround`]): it
    /// encloses the scene, so the scene's bounding sphere (for distant and
    /// environment lights) is that sphere itself, not the box around it.
    pub world: bool,
}

/// The closest hit of a ray in the scene.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceHit {
    /// Geometry of the hit.
    pub hit: Hit,
    /// Index of the object hit.
    pub object: u32,
}

/// Everything needed to render.
#[derive(Debug)]
pub struct Scene {
    /// Objects.
    pub objects: Vec<Object>,
    /// Materials (objects refer to them by index).
    pub materials: Vec<Bxdf>,
    /// Each material's reflectance texture, if it has one (index for index
    /// with `materials`; empty when no material has one).
    textures: Vec<Option<MaterialTextures>>,
    /// Each material's Mix, if it is one (index for index with `materials`,
    /// where a Mix has a stand-in; empty when no material is a Mix).
    mixes: Vec<Option<crate::material::Mix>>,
    /// Lights (area lights refer back to their object).
    pub lights: Vec<Light>,
    /// Probability of choosing each light for next-event estimation (∝ power).
    pub light_pmf: Vec<f32>,
    light_cdf: Vec<f32>,
    /// The camera.
    pub camera: Camera,
    /// The dielectric volumes the camera's eye is inside, where every camera
    /// path starts ([`Scene::camera_volumes`]).
    pub camera_volumes: VolumeStack,
    /// Dielectric volumes nest or overlap ([`Scene::has_nested_volumes`]).
    nested: bool,
    /// Some object is a dielectric ([`Scene::has_volumes`]).
    volumes: bool,
    /// Some object's interior scatters or is a grid (a path samples distances there).
    scattering: bool,
    /// Some object is an index-matched boundary (`Interface`): shadow rays
    /// pass it ([`Scene::transmittance`]).
    interfaces: bool,
    /// Render settings: the file's `render` block with command-line overrides applied.
    pub settings: Settings,
    /// Indices of bounded objects, in the BVH's order when there is one.
    bounded: Vec<u32>,
    /// Indices of unbounded objects (planes).
    unbounded: Vec<u32>,
    bvh: Option<Bvh>,
    /// The bounded objects in lanes of four, for a small scene of quads and
    /// spheres (no BVH then).
    batch: Option<Batch>,
    /// The index of the environment light in `lights`, if the scene has one.
    environment: Option<u32>,
    /// The radius of a sphere around everything bounded and the camera.
    radius: f32,
    /// Whether any object's material is dispersive (computed once: the
    /// `spectral` integrator asks for every camera sample).
    dispersive: bool,
    /// Some area light's emission is a texture: only then do light samples
    /// and emitter hits look for one ([`Scene::le`], [`Scene::sample_li`]).
    emission_textures: bool,
    /// The identity of the scene file and every file it reads (for
    /// checkpoints: resume and merge refuse other inputs).
    pub content_hash: u64,
    /// Every file the scene reads besides itself (meshes, data files), as
    /// resolved paths: no output may overwrite one.
    pub inputs: Vec<std::path::PathBuf>,
    /// The hash of the scene file and of each file it reads, for naming the inputs
    /// that changed when a checkpoint is resumed.
    pub input_hashes: crate::checkpoint::InputHashes,
    /// The camera's sensor: the curves every sample is projected on (`--sensor`; the CIE 1931
    /// CMFs by default, and the film then holds XYZ). A render's film must have the same one.
    pub sensor: std::sync::Arc<crate::color::Sensor>,
}

impl Scene {
    /// Builds the acceleration structure and light tables. `objects` and
    /// `lights` must already be consistent (the loader ensures it).
    pub fn new(
        objects: Vec<Object>,
        materials: Vec<Bxdf>,
        textures: Vec<Option<MaterialTextures>>,
        mut lights: Vec<Light>,
        camera: Camera,
        settings: Settings,
        content_hash: u64,
    ) -> Scene {
        let mut bounded = Vec::new();
        let mut bounds = Vec::new();
        let mut unbounded = Vec::new();
        for (i, o) in objects.iter().enumerate() {
            match o.shape.bounds() {
                Some(b) => {
                    bounded.push(i as u32);
                    bounds.push(b);
                }
                None => unbounded.push(i as u32),
            }
        }
        // A sphere around everything bounded and the camera, for distant lights:
        // around the box of all but the camera medium's sphere, which is centred
        // on that box and counts by its own radius.
        let world = bounds
            .iter()
            .zip(&bounded)
            .filter(|(_, i)| !objects[**i as usize].world)
            .fold(Aabb::new(camera.eye(), camera.eye()), |a, (b, _)| a.union(b));
        let mut radius = (world.diagonal().length() * 0.5).max(1.0);
        for o in objects.iter().filter(|o| o.world) {
            if let Shape::Sphere(s) = &o.shape {
                radius = radius.max(s.center.distance(world.centroid()) + s.radius);
            }
        }
        for l in &mut lights {
            l.set_scene_bounds(world.centroid(), radius);
        }
        let camera_volumes = volumes_at(camera.eye(), &objects, &materials);
        let nested = nested_volumes(&camera_volumes, &objects, &materials);
        let volumes = objects.iter().any(|o| materials[o.material as usize].bounds_volume());
        // A dielectric's absorption is its volume's medium (one that only absorbs).
        let mut objects = objects;
        for o in &mut objects {
            if o.interior.is_none()
                && let Some(a) = materials[o.material as usize].absorption()
            {
                o.interior = Some(Box::new(Medium::absorbing(*a)));
            }
        }
        let scattering = objects.iter().any(|o| o.interior.as_ref().is_some_and(|m| m.scatters() || m.is_grid()));
        let interfaces = objects.iter().any(|o| materials[o.material as usize].is_interface());
        let batch = Batch::new(bounded.iter().map(|&i| (i, &objects[i as usize].shape)));
        let bvh = (batch.is_none() && bounded.len() >= BVH_MIN_OBJECTS).then(|| {
            let bvh = Bvh::build(&bounds);
            bounded = bvh.prim_order().iter().map(|&k| bounded[k as usize]).collect();
            bvh
        });
        let power: Vec<f32> = lights.iter().map(|l| l.power().max(0.0)).collect();
        let total: f32 = power.iter().sum();
        let light_pmf: Vec<f32> = if total > 0.0 {
            power.iter().map(|p| p / total).collect()
        } else {
            vec![1.0 / lights.len().max(1) as f32; lights.len()]
        };
        let mut acc = 0.0;
        let light_cdf = light_pmf
            .iter()
            .map(|p| {
                acc += p;
                acc
            })
            .collect();
        let dispersive = objects.iter().any(|o| materials.get(o.material as usize).is_some_and(Bxdf::is_dispersive));
        let emission_textures = lights.iter().any(|l| l.emission_texture().is_some());
        let environment = lights.iter().position(Light::is_infinite).map(|i| i as u32);
        let textures = if textures.iter().any(Option::is_some) { textures } else { Vec::new() };
        Scene {
            textures,
            mixes: Vec::new(),
            environment,
            radius,
            dispersive,
            emission_textures,
            objects,
            materials,
            lights,
            light_pmf,
            light_cdf,
            camera,
            camera_volumes,
            nested,
            volumes,
            scattering,
            interfaces,
            settings,
            bounded,
            unbounded,
            bvh,
            batch,
            content_hash,
            inputs: Vec::new(),
            input_hashes: Default::default(),
            sensor: crate::color::Sensor::cie1931().clone(),
        }
    }

    /// The radius of a sphere around everything bounded and the camera (at least 1).
    #[inline]
    pub fn radius(&self) -> f32 {
        self.radius
    }

    /// The closest hit along `ray` before `t_max`.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<SurfaceHit> {
        let mut best: Option<SurfaceHit> = None;
        let mut t_max = t_max;
        for &i in &self.unbounded {
            if let Some(hit) = self.objects[i as usize].shape.intersect(ray, t_max) {
                t_max = hit.t;
                best = Some(SurfaceHit { hit, object: i });
            }
        }
        match &self.bvh {
            Some(bvh) => {
                let found = bvh.intersect(ray, t_max, |k, t| {
                    let object = self.bounded[k as usize];
                    self.objects[object as usize].shape.intersect(ray, t).map(|hit| (hit.t, SurfaceHit { hit, object }))
                });
                found.or(best)
            }
            None if let Some(batch) = &self.batch => {
                let Some((object, t)) = batch.closest(ray, t_max) else {
                    return best;
                };
                // The winner's hit record, from its `t` (as its own test builds it).
                let hit = match &self.objects[object as usize].shape {
                    Shape::Quad(q) => q.hit_at(ray, t),
                    Shape::Sphere(s) => s.hit_at(ray, t),
                    _ => unreachable!("a batch holds only quads and spheres"),
                };
                Some(SurfaceHit { hit, object })
            }
            None => {
                for &i in &self.bounded {
                    if let Some(hit) = self.objects[i as usize].shape.intersect(ray, t_max) {
                        t_max = hit.t;
                        best = Some(SurfaceHit { hit, object: i });
                    }
                }
                best
            }
        }
    }

    /// True when something blocks `ray` before `t_max`.
    #[inline]
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        if self.unbounded.iter().any(|&i| self.objects[i as usize].shape.occluded(ray, t_max)) {
            return true;
        }
        match &self.bvh {
            Some(bvh) => {
                bvh.occluded(ray, t_max, |k, t| self.objects[self.bounded[k as usize] as usize].shape.occluded(ray, t))
            }
            None if let Some(batch) = &self.batch => batch.occluded(ray, t_max),
            None => self.bounded.iter().any(|&i| self.objects[i as usize].shape.occluded(ray, t_max)),
        }
    }

    /// Chooses a light for next-event estimation with probability ∝ power;
    /// returns its index and probability.
    #[inline]
    pub fn choose_light(&self, u: f32) -> Option<(usize, f32)> {
        if self.lights.is_empty() {
            return None;
        }
        let i = self.light_cdf.partition_point(|&c| c <= u).min(self.lights.len() - 1);
        Some((i, self.light_pmf[i]))
    }

    /// The volume inside object `object` when its material is a dielectric.
    #[inline]
    pub fn volume(&self, object: u32) -> Option<Volume> {
        let o = &self.objects[object as usize];
        if !self.materials[o.material as usize].bounds_volume() {
            return None;
        }
        Some(Volume { object, priority: o.priority, material: o.material })
    }

    /// True when dielectric volumes may nest or overlap, so that a path needs
    /// the volume stack: the camera starts inside a dielectric, or two
    /// dielectric objects' bounds overlap (an unbounded one overlaps all).
    /// Only then does [`Scene::transmittance`] march through false
    /// intersections (elsewhere one occlusion test suffices).
    #[inline]
    pub fn has_nested_volumes(&self) -> bool {
        self.nested
    }

    /// True when some object is a dielectric (a volume a path can be inside).
    #[inline]
    pub fn has_volumes(&self) -> bool {
        self.volumes
    }

    /// The dielectric volumes around point `p` (as [`Scene::camera_volumes`] is
    /// for the eye): where a light subpath starts.
    pub fn volumes_at(&self, p: glam::Vec3) -> VolumeStack {
        if self.volumes { volumes_at(p, &self.objects, &self.materials) } else { VolumeStack::VACUUM }
    }

    /// True when any material's direction depends on wavelength.
    #[inline]
    pub fn has_dispersion(&self) -> bool {
        self.dispersive
    }

    /// The number of objects.
    pub fn object_count(&self) -> usize {
        self.objects.len()
    }
}

/// Directions that probe whether a point is inside a closed object: the six
/// axes, turned off them so that no probe runs along a face of a box.
const PROBES: [[f32; 3]; 6] = [
    [0.8, 0.35, 0.48],
    [-0.8, -0.35, -0.48],
    [0.3, 0.9, -0.31],
    [-0.3, -0.9, 0.31],
    [-0.42, 0.27, 0.87],
    [0.42, -0.27, -0.87],
];

/// The dielectric volumes a point is inside, the outermost first, as a
/// camera path starts there. For each dielectric object, six rays from `p`
/// find the object's nearest surface: `p` is inside when more of the probes
/// that hit leave the object (along its outward normal) than enter it, which
/// works for solids and half-spaces (planes) and outvotes a hole or a grazing
/// edge. Among the objects found, the one whose surface is farthest is the
/// outermost, entered first (so equal priorities nest by geometry: a camera
/// in water inside glass is in the water).
/// No allocation (BDPT asks at every light subpath's origin); beyond
/// [`VOLUME_STACK_DEPTH`] volumes the innermost are dropped, as a path's stack
/// drops them.
fn volumes_at(p: glam::Vec3, objects: &[Object], materials: &[Bxdf]) -> VolumeStack {
    let mut found = [(0.0f32, Volume::default()); VOLUME_STACK_DEPTH];
    let mut count = 0;
    for (i, o) in objects.iter().enumerate() {
        if !materials[o.material as usize].bounds_volume() {
            continue;
        }
        let (mut leave, mut enter, mut nearest) = (0, 0, f32::INFINITY);
        for d in PROBES {
            let ray = Ray::new(p, glam::Vec3::from(d).normalize());
            if let Some(hit) = o.shape.intersect(&ray, f32::INFINITY) {
                if ray.dir.dot(hit.n) > 0.0 {
                    leave += 1;
                    nearest = nearest.min(hit.t);
                } else {
                    enter += 1;
                }
            }
        }
        if leave > enter {
            let m = (nearest, Volume { object: i as u32, priority: o.priority, material: o.material });
            // Keep the VOLUME_STACK_DEPTH farthest surfaces, sorted farthest first.
            let at = found[..count].partition_point(|f| f.0.total_cmp(&nearest).is_ge());
            if at < VOLUME_STACK_DEPTH {
                found.copy_within(at..(count.min(VOLUME_STACK_DEPTH - 1)), at + 1);
                found[at] = m;
                count = (count + 1).min(VOLUME_STACK_DEPTH);
            }
        }
    }
    let mut stack = VolumeStack::VACUUM;
    for &(_, m) in &found[..count] {
        stack.enter(m);
    }
    stack
}

/// Whether volumes nest ([`Scene::has_nested_volumes`]).
fn nested_volumes(camera_volumes: &VolumeStack, objects: &[Object], materials: &[Bxdf]) -> bool {
    if !camera_volumes.is_empty() {
        return true;
    }
    let glass: Vec<Option<Aabb>> =
        objects.iter().filter(|o| materials[o.material as usize].bounds_volume()).map(|o| o.shape.bounds()).collect();
    glass.iter().enumerate().any(|(i, a)| {
        glass[i + 1..].iter().any(|b| match (a, b) {
            (Some(a), Some(b)) => a.min.cmple(b.max).all() && b.min.cmple(a.max).all(),
            _ => true,
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::settings::SettingsPatch;

    fn camera_media(eye: &str, objects: &str) -> Vec<u32> {
        let text = format!(
            r#"(camera: (eye: {eye}, look_at: (0.1, 0.2, -3), fov_deg: 30),
            materials: {{ "glass": Dielectric(ior: Constant(1.5)), "white": Lambertian(reflectance: Constant(0.5)) }},
            objects: [ {objects} ])"#
        );
        let scene = load_scene_str(&text, std::path::Path::new("t.ron"), &SettingsPatch::default()).unwrap();
        scene.camera_volumes.entries().iter().map(|m| m.object).collect()
    }

    /// The camera's starting media: inside a solid (outermost first, by
    /// distance), below a glass half-space, not in a bubble's cavity, not in
    /// a diffuse object, not outside.
    #[test]
    fn the_camera_starts_in_the_media_around_its_eye() {
        let nested = r#"(shape: Sphere(center: (0, 0, 0), radius: 0.5), material: "glass"),
            (shape: Cuboid(min: (-2, -2, -2), max: (2, 2, 2)), material: "glass"),
            (shape: Sphere(center: (0, 0, 0), radius: 1), material: "white")"#;
        assert_eq!(camera_media("(0, 0, 0)", nested), [1, 0]);
        assert_eq!(camera_media("(0, 1.5, 0)", nested), [1]);
        assert_eq!(camera_media("(0, 3, 0)", nested), Vec::<u32>::new());
        let plane = r#"(shape: Plane(point: (0, 1, 0), normal: (0, 1, 0)), material: "glass")"#;
        assert_eq!(camera_media("(0, 0, 0)", plane), [0]);
        assert_eq!(camera_media("(0, 2, 0)", plane), Vec::<u32>::new());
        let bubble = r#"(shape: Bubble(center: (0, 0, 0), outer_radius: 1, inner_radius: 0.9), material: "glass")"#;
        assert_eq!(camera_media("(0, 0, 0)", bubble), Vec::<u32>::new());
        assert_eq!(camera_media("(0, 0.95, 0)", bubble), [0]);
    }
}
