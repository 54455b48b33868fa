//! Shapes: the closed set of surfaces a scene object can have, one file per
//! shape, and the BVH that meshes and scenes build over them.
//!
//! [`Shape`] dispatches with `match` (no trait objects, no allocation on the
//! per-ray path). Every shape answers the same two questions, closest hit and
//! any hit, with robust floating-point arithmetic (the maths is in
//! [`crate::geometry`]), so that rays spawned from a hit never re-hit the
//! surface they leave, at any scene scale. A new shape is a new file here,
//! a variant of [`Shape`] and a variant of the scene format's `ShapeDesc`.

// `!(x > 0.0)` is used on purpose: it is also true for NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod batch;
mod bubble;
mod bvh;
mod cuboid;
mod disk;
mod inline;
mod instance;
mod mesh;
mod plane;
mod quad;
mod sphere;
mod triangle;
mod uv;

pub use crate::geometry::Transform;
pub use batch::Batch;
pub use bubble::Bubble;
pub use bvh::{Bvh, TriangleHit, WideBvh};
pub use cuboid::Cuboid;
pub use disk::Disk;
pub use instance::{MAX_CANCELLATION, MeshInstance};
pub use mesh::Mesh;
pub(crate) use mesh::MeshAhead;
pub use plane::Plane;
pub use quad::Quad;
pub use sphere::Sphere;
pub use triangle::Triangle;

use crate::error::Result;
use crate::geometry::{Aabb, Hit, Ray};
use crate::scene::check::{Check, MAX_MAGNITUDE};
use crate::scene::desc::ShapeDesc;
use glam::Vec3;

/// Any shape of the renderer.
#[derive(Clone, Debug)]
pub enum Shape {
    /// A solid sphere.
    Sphere(Sphere),
    /// A spherical shell.
    Bubble(Bubble),
    /// An infinite plane (unbounded).
    Plane(Plane),
    /// A flat disk.
    Disk(Disk),
    /// A solid axis-aligned box.
    Cuboid(Cuboid),
    /// A parallelogram.
    Quad(Quad),
    /// A triangle mesh with its own BVH.
    Mesh(Box<Mesh>),
    /// A group's mesh shared by every instance of the group, placed by an affine map.
    Instance(Box<MeshInstance>),
}

impl Shape {
    /// Closest hit with `0 < t < t_max`.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        match self {
            Shape::Sphere(s) => s.intersect(ray, t_max),
            Shape::Bubble(s) => s.intersect(ray, t_max),
            Shape::Plane(s) => s.intersect(ray, t_max),
            Shape::Disk(s) => s.intersect(ray, t_max),
            Shape::Cuboid(s) => s.intersect(ray, t_max),
            Shape::Quad(s) => s.intersect(ray, t_max),
            Shape::Mesh(s) => s.intersect(ray, t_max),
            Shape::Instance(s) => s.intersect(ray, t_max),
        }
    }

    /// True if anything blocks the ray with `0 < t < t_max`.
    #[inline]
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        match self {
            Shape::Sphere(s) => s.occluded(ray, t_max),
            Shape::Bubble(s) => s.occluded(ray, t_max),
            Shape::Plane(s) => s.occluded(ray, t_max),
            Shape::Disk(s) => s.occluded(ray, t_max),
            Shape::Cuboid(s) => s.occluded(ray, t_max),
            Shape::Quad(s) => s.occluded(ray, t_max),
            Shape::Mesh(s) => s.occluded(ray, t_max),
            Shape::Instance(s) => s.occluded(ray, t_max),
        }
    }

    /// Bounding box; None for unbounded shapes (planes).
    pub fn bounds(&self) -> Option<Aabb> {
        match self {
            Shape::Sphere(s) => Some(s.bounds()),
            Shape::Bubble(s) => Some(s.bounds()),
            Shape::Plane(_) => None,
            Shape::Disk(s) => Some(s.bounds()),
            Shape::Cuboid(s) => Some(s.bounds()),
            Shape::Quad(s) => Some(s.bounds()),
            Shape::Mesh(s) => Some(s.bounds()),
            Shape::Instance(s) => Some(s.bounds()),
        }
    }
}

/// How an object places a mesh after the mesh's own transform: its `transform:` as
/// scale, rotation and translation, or a general affine `matrix:` (a linear part and
/// a translation; checked finite and non-singular by the loader).
#[derive(Clone, Copy, Debug)]
pub(crate) enum Then {
    /// Scale, rotate, translate.
    Srt(Transform),
    /// `x -> m x + t`.
    Affine(glam::Mat3, Vec3),
}

/// An object's `transform:` ([`crate::scene::desc::TransformDesc`]), checked, with its
/// field path (`objects[i].transform`) for errors.
#[derive(Clone, Debug)]
pub(crate) struct Placement {
    /// The field path of the `transform:` block.
    pub(crate) field: String,
    /// The placement as scale, rotation and translation (the identity with a `matrix`).
    pub(crate) t: Transform,
    /// A general affine `matrix:` (linear part, translation), checked invertible.
    pub(crate) matrix: Option<(glam::Mat3, Vec3)>,
}

impl Placement {
    /// The placement for a mesh: the general matrix when given, else the transform.
    pub(crate) fn then(&self) -> Then {
        match self.matrix {
            Some((m, t)) => Then::Affine(m, t),
            None => Then::Srt(self.t),
        }
    }

    /// The placement as a linear part and a translation.
    pub(crate) fn affine(&self) -> (glam::Mat3, Vec3) {
        self.matrix.unwrap_or((self.t.linear(), self.t.translate))
    }

    /// The scale factor of a shape that takes only a uniform scale (`what`: "sphere").
    pub(crate) fn uniform_scale(&self, check: &Check, what: &str) -> Result<f32> {
        let s = self.t.scale;
        if s.x == s.y && s.y == s.z {
            Ok(s.x)
        } else {
            Err(check.err(format!("{}.scale", self.field), format!("a {what} takes only a uniform scale, found {s}")))
        }
    }

    /// A point moved by the placement, checked to stay within ±`MAX_MAGNITUDE`.
    pub(crate) fn point(&self, check: &Check, p: Vec3) -> Result<Vec3> {
        self.checked(check, self.t.point(p))
    }

    /// A vector (an edge) mapped by the placement's linear part, checked to stay in range.
    pub(crate) fn vector(&self, check: &Check, v: Vec3) -> Result<Vec3> {
        self.checked(check, self.t.linear() * v)
    }

    /// A unit normal mapped by the inverse transpose of the linear part and renormalised.
    pub(crate) fn normal(&self, check: &Check, n: Vec3) -> Result<Vec3> {
        (self.t.linear().inverse().transpose() * n).try_normalize().ok_or_else(|| {
            check.err(format!("{}.scale", self.field), "the transform makes the shape's normal degenerate in f32")
        })
    }

    /// A length scaled by a uniform factor, checked to stay a positive size.
    pub(crate) fn length(&self, check: &Check, len: f32, s: f32) -> Result<f32> {
        check.positive(&format!("{}.scale", self.field), len * s).map_err(|_| {
            check.err(
                format!("{}.scale", self.field),
                format!("the scale {s} makes a size of {len} leave (0, {MAX_MAGNITUDE:e}]"),
            )
        })
    }

    fn checked(&self, check: &Check, v: Vec3) -> Result<Vec3> {
        check.vec(&self.field, v.into()).map_err(|_| {
            check.err(
                &self.field,
                format!(
                    "the transform moves the shape out of range: {v}, expected coordinates up to ±{MAX_MAGNITUDE:e}"
                ),
            )
        })
    }
}

impl Shape {
    /// The shape of a scene description at `field` (`objects[i].shape`), placed by the
    /// object's transform `xf` when it has one; each shape is built and checked by its
    /// own type's `from_desc`.
    pub(crate) fn from_desc(check: &Check, field: &str, d: &ShapeDesc, xf: Option<&Placement>) -> Result<Shape> {
        if let Some(x) = xf
            && x.matrix.is_some()
            && !matches!(d, ShapeDesc::Mesh { .. } | ShapeDesc::Triangles { .. } | ShapeDesc::Instance { .. })
        {
            return Err(check.err(
                format!("{}.matrix", x.field),
                "a general `matrix:` places only an Instance, a Mesh or Triangles; expected `scale`, `rotate_deg` and `translate` for this shape",
            ));
        }
        Ok(match d {
            ShapeDesc::Sphere { center, radius } => {
                Shape::Sphere(Sphere::from_desc(check, field, *center, *radius, xf)?)
            }
            ShapeDesc::Bubble { center, outer_radius, inner_radius } => {
                Shape::Bubble(Bubble::from_desc(check, field, *center, *outer_radius, *inner_radius, xf)?)
            }
            ShapeDesc::Plane { point, normal } => Shape::Plane(Plane::from_desc(check, field, *point, *normal, xf)?),
            ShapeDesc::Disk { center, normal, radius } => {
                Shape::Disk(Disk::from_desc(check, field, *center, *normal, *radius, xf)?)
            }
            ShapeDesc::Cuboid { min, max } => Cuboid::from_desc(check, field, *min, *max, xf)?,
            ShapeDesc::Quad { origin, edge_u, edge_v } => {
                Shape::Quad(Quad::from_desc(check, field, *origin, *edge_u, *edge_v, xf)?)
            }
            ShapeDesc::Triangles { positions, indices, normals, uvs } => Shape::Mesh(Box::new(Mesh::from_inline_desc(
                check,
                field,
                positions,
                indices,
                normals.as_deref(),
                uvs.as_deref(),
                xf,
            )?)),
            ShapeDesc::Mesh { path, scale, rotate_deg, translate } => {
                Shape::Mesh(Box::new(Mesh::from_desc(check, field, path, scale, rotate_deg, translate, xf)?))
            }
            ShapeDesc::Instance { .. } => {
                return Err(check.err(field, "an Instance places a group's objects: expected it in `objects`"));
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dispatch_agrees_with_shapes() {
        let shapes = [
            Shape::Sphere(Sphere::new(Vec3::new(0.0, 0.0, 5.0), 1.0)),
            Shape::Bubble(Bubble::new(Vec3::new(0.0, 0.0, 5.0), 1.0, 0.5)),
            Shape::Plane(Plane::new(Vec3::new(0.0, 0.0, 4.0), Vec3::Z)),
            Shape::Disk(Disk::new(Vec3::new(0.0, 0.0, 4.0), Vec3::Z, 1.0)),
            Shape::Cuboid(Cuboid::new(Vec3::new(-1.0, -1.0, 4.0), Vec3::new(1.0, 1.0, 6.0))),
            Shape::Quad(Quad::new(Vec3::new(-1.0, -1.0, 4.0), Vec3::X * 2.0, Vec3::Y * 2.0)),
        ];
        let r = Ray::new(Vec3::ZERO, Vec3::Z);
        for s in &shapes {
            let h = s.intersect(&r, f32::INFINITY).unwrap();
            assert!((h.t - 4.0).abs() < 1e-5 && (h.n.z.abs() - 1.0).abs() < 1e-6);
            assert!(s.occluded(&r, 4.5) && !s.occluded(&r, 3.5));
        }
        assert!(shapes[2].bounds().is_none() && shapes[0].bounds().is_some());
    }
}
