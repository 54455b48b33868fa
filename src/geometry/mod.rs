//! Geometry: rays, bounding boxes, hit records and the closed set of shapes the
//! renderer can intersect (analytic primitives and triangle meshes).
//!
//! Every shape answers the same two questions, closest hit and any hit, with
//! robust floating-point arithmetic so that rays spawned from a hit never
//! re-hit the surface they leave, at any scene scale.

// `!(x > 0.0)` is used on purpose: it is also true for NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod bounds;
pub mod bubble;
pub mod cuboid;
pub mod disk;
pub mod frame;
pub mod hit;
pub mod mesh;
pub mod plane;
mod ply;
pub mod quad;
pub mod ray;
pub mod shape;
pub mod sphere;
pub mod triangle;

pub use bounds::Aabb;
pub use bubble::Bubble;
pub use cuboid::Cuboid;
pub use disk::Disk;
pub use frame::Frame;
pub use hit::Hit;
pub use mesh::{Mesh, Transform};
pub use plane::Plane;
pub use quad::Quad;
pub use ray::{Ray, offset_ray_origin};
pub use shape::Shape;
pub use sphere::Sphere;
pub use triangle::Triangle;

/// Half the f32 machine epsilon (the unit roundoff u = 2^-24).
pub const MACHINE_EPSILON: f32 = f32::EPSILON * 0.5;

/// The classic floating-point error bound gamma(n) = n u / (1 - n u): the relative
/// error accumulated by n successive rounded operations.
#[inline]
pub const fn gamma(n: i32) -> f32 {
    let nu = n as f32 * MACHINE_EPSILON;
    nu / (1.0 - nu)
}
