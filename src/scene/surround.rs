//! What surrounds the objects: the medium the camera sits in
//! (`camera: (..., medium: "haze")`) and the check of an object's declared
//! `exterior:`.
//!
//! # The camera's medium
//! rust-v finds the medium a path is in from the volumes around it (the
//! [`VolumeStack`](crate::medium::VolumeStack) of nested volumes), with vacuum
//! at the bottom. A medium around the camera is therefore a volume too: the
//! loader adds one object, an index-matched sphere (`Interface`) whose interior
//! is the named medium, enclosing every bounded object and the eye with a 5%
//! margin (`world_volume`). Everything else follows from what volumes
//! already do, in every integrator: the camera's paths start inside it
//! (`Scene::camera_volumes`), light subpaths from the environment or a distant
//! light enter it from outside, shadow rays sum its optical depth, and an
//! inner volume (a glass, a cloud) of equal or higher `priority` holds its own
//! medium, being entered after it.
//!
//! Why a sphere and not all of space (pbrt-v4's camera medium): an unbounded
//! scattering medium leaves nothing of the environment or of a distant light
//! (every ray scatters or is absorbed before infinity), while pbrt-v4 still
//! lights through it from a distant light, over twice the scene's radius:
//! light tracing and path tracing would disagree. A sphere gives every
//! integrator the same finite haze, and the environment seen through its
//! thickness.
//!
//! # `exterior:`
//! pbrt-v4 and Mitsuba 3 give every surface an inside and an outside medium;
//! rust-v derives the outside from the nesting. An object may still say which
//! medium it expects outside (`exterior: "haze"`): `check_exteriors` finds
//! a point just outside its surface, takes the volumes around that point
//! without the object itself, and refuses the scene, naming the field, when
//! the current one's medium is another (or vacuum). So a declaration can never
//! silently disagree with what is rendered.

use glam::Vec3;

use super::{Object, PROBES, volumes_at};
use crate::bxdf::Bxdf;
use crate::error::Result;
use crate::geometry::{Aabb, Ray};
use crate::medium::Medium;
use crate::scene::check::Check;
use crate::scene::desc::ObjectDesc;
use crate::shape::{Shape, Sphere};

/// The margin of the camera medium's sphere beyond the scene and the eye.
pub const WORLD_MARGIN: f32 = 1.05;

/// The sphere the camera's medium fills: around the bounds of every bounded
/// object and the camera (the eye and, for a thin lens, a cube of the
/// aperture's radius around it), radius `WORLD_MARGIN` times the
/// half-diagonal (at least 1e-3 scene units).
pub fn world_sphere(objects: &[Object], eye: Vec3, aperture: f32) -> (Vec3, f32) {
    let camera = Aabb::new(eye - Vec3::splat(aperture), eye + Vec3::splat(aperture));
    let world = objects.iter().filter_map(|o| o.shape.bounds()).fold(camera, |a, b| a.union(&b));
    let center = world.centroid();
    let radius = (world.diagonal().length() * 0.5 * WORLD_MARGIN).max(1e-3);
    (center, radius)
}

/// The object that holds the camera's medium `medium`: an index-matched
/// sphere (material `interface`, an `Interface`) around the scene and the
/// camera at `eye` with a thin lens of radius `aperture`.
pub(crate) fn world_volume(
    ctx: &Check<'_>,
    objects: &[Object],
    (eye, aperture): (Vec3, f32),
    medium: &Medium,
    interface: u32,
) -> Result<Object> {
    let (center, radius) = world_sphere(objects, eye, aperture);
    if !(center.is_finite() && radius.is_finite()) {
        return Err(ctx.err("camera.medium", "the scene's bounds are not finite: no sphere can hold the medium"));
    }
    let sphere = Shape::Sphere(Sphere::new(center, radius));
    let b = sphere.bounds().expect("a sphere is bounded");
    Ok(Object {
        shape: sphere,
        material: interface,
        light: None,
        priority: 0,
        interior: Some(Box::new(medium.placed(b.min, b.max))),
        world: true,
    })
}

/// Checks every `exterior:` in `descs` (the scene file's objects, the first
/// of `objects`) against the medium the volumes around each object give just
/// outside its surface. `names[i]` is object `i`'s interior medium's name
/// (the camera's medium for the sphere that holds it).
pub(crate) fn check_exteriors(
    ctx: &Check<'_>,
    descs: &[ObjectDesc],
    objects: &[Object],
    materials: &[Bxdf],
    names: &[Option<&str>],
    known: &[&str],
) -> Result<()> {
    for (i, d) in descs.iter().enumerate() {
        let Some(want) = d.exterior.as_deref() else { continue };
        let field = format!("objects[{i}].exterior");
        if !known.contains(&want) {
            return Err(ctx.err(&field, format!("unknown medium \"{want}\"; defined: {}", known.join(", "))));
        }
        let Some(p) = just_outside(objects, i) else {
            return Err(
                ctx.err(&field, "no ray from outside reaches the object's surface: its outside cannot be found")
            );
        };
        let mut around = volumes_at(p, objects, materials);
        around.leave(i as u32);
        let found = around.current();
        let found_name = found.and_then(|v| names[v.object as usize]);
        if found_name != Some(want) {
            let what = match found {
                None => "vacuum".to_string(),
                Some(v) if objects[v.object as usize].world => "the camera's medium".to_string(),
                // Objects past the file's own are the further members of instances.
                Some(v) if v.object as usize >= descs.len() => {
                    "the clear or absorbing inside of a group member placed by an `Instance`".to_string()
                }
                Some(v) => match names[v.object as usize] {
                    Some(n) => format!("\"{n}\", the interior of objects[{}]", v.object),
                    None => format!("the clear or absorbing inside of objects[{}]", v.object),
                },
            };
            return Err(ctx.err(
                &field,
                format!(
                    "\"{want}\", but just outside its surface is {what} (rust-v finds the outside from the volumes around the object: \
                     place it inside an object whose `interior:` is \"{want}\", give the camera `medium: \"{want}\"`, or remove `exterior:`)"
                ),
            ));
        }
    }
    Ok(())
}

/// A point just outside object `i`'s surface (on the side its geometric
/// normal points to): where a ray from outside its bounds first meets it, or
/// for an unbounded object (a plane) where a ray from the scene's centre does.
fn just_outside(objects: &[Object], i: usize) -> Option<Vec3> {
    let shape = &objects[i].shape;
    let rays: Vec<Ray> = match shape.bounds() {
        Some(b) => {
            let (c, r) = (b.centroid(), b.diagonal().length() + 1.0);
            PROBES.iter().map(|d| Vec3::from(*d).normalize()).map(|d| Ray::new(c + d * r, -d)).collect()
        }
        None => {
            let world = objects.iter().filter_map(|o| o.shape.bounds()).reduce(|a, b| a.union(&b));
            let c = world.map_or(Vec3::ZERO, |w| w.centroid());
            PROBES.iter().map(|d| Ray::new(c, Vec3::from(*d).normalize())).collect()
        }
    };
    rays.iter().find_map(|ray| {
        let hit = shape.intersect(ray, f32::INFINITY)?;
        let eps = 1e-4 * (1.0 + hit.p.abs().max_element());
        Some(hit.p + hit.n * eps)
    })
}
