//! The record of a ray/surface intersection, shared by all shapes.

use glam::Vec3;

/// A ray/surface intersection.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    /// Ray parameter of the hit (distance along the unit direction).
    pub t: f32,
    /// The hit point, refined onto the surface.
    pub p: Vec3,
    /// Unit geometric normal, pointing out of the solid (see the crate conventions).
    pub n: Vec3,
    /// Unit shading normal (interpolated vertex normal for meshes that have them,
    /// in the same hemisphere as `n`), else equal to `n`.
    pub ns: Vec3,
    /// Triangle index for meshes (in the mesh's storage order, see
    /// [`Mesh::triangle`](crate::shape::Mesh::triangle)), 0 for other shapes.
    pub prim: u32,
}

impl Hit {
    /// A hit whose shading normal is its geometric normal (analytic shapes).
    #[inline]
    pub fn flat(t: f32, p: Vec3, n: Vec3) -> Hit {
        Hit { t, p, n, ns: n, prim: 0 }
    }
}
