//! Geometry maths: rays (with robust spawning), bounding boxes, shading
//! frames, hit records and floating-point error bounds. The shapes that use
//! them are in [`crate::shape`].

// `!(x > 0.0)` is used on purpose: it is also true for NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod bounds;
mod frame;
mod hit;
mod ray;
mod transform;

pub use bounds::Aabb;
pub use frame::Frame;
pub use hit::Hit;
pub use ray::{Ray, offset_ray_origin};
pub use transform::Transform;

/// Half the f32 machine epsilon (the unit roundoff u = 2^-24).
pub const MACHINE_EPSILON: f32 = f32::EPSILON * 0.5;

/// The classic floating-point error bound gamma(n) = n u / (1 - n u): the relative
/// error accumulated by n successive rounded operations.
#[inline]
pub const fn gamma(n: i32) -> f32 {
    let nu = n as f32 * MACHINE_EPSILON;
    nu / (1.0 - nu)
}
