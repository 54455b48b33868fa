//! Instances: a mesh built once in its group's own space (the scene format's
//! `groups:`), placed in the world any number of times by an affine map without
//! copying its triangles or its BVH.
//!
//! A ray is moved into group space without normalising its direction, so the
//! ray parameter `t` of a hit there is the world ray's; the hit point goes back
//! to the world by the placement, normals by the inverse transpose of its linear
//! part (renormalised). As for a mesh placed by a mirroring transform, the front
//! side stays the side the group-space normal points to, so a closed mesh keeps
//! outward normals under a mirror.
//!
//! Robustness: a ray leaving an instance is offset by a bound relative to the
//! world point's magnitude (`crate::geometry::ray`), but the instance rounds at
//! the magnitude of its group-space coordinates and translation. A placement
//! that cancels them (group coordinates near −10⁴ moved by +10⁴ to near the
//! origin) rounds far above that offset, and rays would re-hit the surface they
//! leave; [`MeshInstance::cancels`] finds it and the loader places a copy of the
//! mesh there instead ([`Mesh::placed_copy`]), which rounds once, as a mesh
//! placed by its object's transform does.

use std::sync::Arc;

use glam::{Mat3, Vec3};

use super::Mesh;
use crate::geometry::{Aabb, Hit, Ray};

/// How much larger the magnitude at which an instance rounds,
/// `‖L‖∞·max|p_group|∞ + |T|∞`, may be than its world bounds' largest coordinate
/// before it is placed as a copy ([`MeshInstance::cancels`]). Without cancellation the
/// two agree within `√3` (a rotation spreads a coordinate over three axes), so 2 only
/// catches real cancellation; the spawn offset (2^-20 of the world magnitude, 16 ulps)
/// then still exceeds the instance's rounding (a few ulps of twice that magnitude).
pub const MAX_CANCELLATION: f32 = 2.0;

/// A shared mesh placed by `x -> to_world · x + offset`.
#[derive(Clone, Debug)]
pub struct MeshInstance {
    mesh: Arc<Mesh>,
    to_world: Mat3,
    offset: Vec3,
    /// The inverse of `to_world`.
    to_group: Mat3,
    /// The inverse transpose of `to_world`, for normals.
    normals: Mat3,
    bounds: Aabb,
}

/// The eight corners of a box.
fn corners(b: &Aabb) -> [Vec3; 8] {
    std::array::from_fn(|i| Vec3::select(glam::BVec3::new(i & 1 != 0, i & 2 != 0, i & 4 != 0), b.max, b.min))
}

/// The box around `mesh`'s group-space bounds placed by `x -> m x + t`.
fn world_box(mesh: &Mesh, m: Mat3, t: Vec3) -> Aabb {
    let c = corners(&mesh.bounds()).map(|c| m * c + t);
    c.iter().fold(Aabb::new(c[0], c[0]), |a, p| a.grow(*p))
}

/// The largest coordinate magnitude of a box.
fn magnitude(b: &Aabb) -> f32 {
    b.min.abs().max(b.max.abs()).max_element()
}

/// `‖m‖∞`, the largest row sum of magnitudes.
fn norm_inf(m: Mat3) -> f32 {
    let t = m.transpose();
    [t.x_axis, t.y_axis, t.z_axis].iter().map(|r| r.abs().element_sum()).fold(0.0, f32::max)
}

impl MeshInstance {
    /// `mesh` placed by `x -> m x + t`; `m` must be invertible and finite (the loader
    /// checks it, naming the field).
    pub fn new(mesh: Arc<Mesh>, m: Mat3, t: Vec3) -> MeshInstance {
        let to_group = m.inverse();
        let world = world_box(&mesh, m, t);
        // The corners of `world` are rounded like the points inside; widen it by a bound
        // on that rounding so that no hit lies outside the box a scene's BVH tests.
        let pad = Vec3::splat(MeshInstance::rounding_magnitude(&mesh, m, t) * 1e-6);
        let bounds = Aabb::new(world.min - pad, world.max + pad);
        MeshInstance { mesh, to_world: m, offset: t, to_group, normals: to_group.transpose(), bounds }
    }

    /// The magnitude at which an instance of `mesh` placed by `x -> m x + t` rounds:
    /// `‖m‖∞·max|p|∞ + |t|∞` over the mesh's group-space bounds.
    fn rounding_magnitude(mesh: &Mesh, m: Mat3, t: Vec3) -> f32 {
        norm_inf(m) * magnitude(&mesh.bounds()) + t.abs().max_element()
    }

    /// True when the placement `x -> m x + t` of `mesh` cancels: it rounds at more than
    /// [`MAX_CANCELLATION`] times the magnitude of where the mesh lands, so that rays
    /// leaving the instance could re-hit it (see the module docs); the loader then places
    /// a copy of the mesh.
    pub fn cancels(mesh: &Mesh, m: Mat3, t: Vec3) -> bool {
        MeshInstance::rounding_magnitude(mesh, m, t) > MAX_CANCELLATION * magnitude(&world_box(mesh, m, t))
    }

    /// The shared mesh, in group space.
    pub fn mesh(&self) -> &Arc<Mesh> {
        &self.mesh
    }

    /// A world point in group space (for texture coordinates).
    #[inline]
    pub fn group_point(&self, p: Vec3) -> Vec3 {
        self.to_group * (p - self.offset)
    }

    /// The ray in group space: the same `t` at the same point (the direction is not
    /// normalised).
    #[inline(always)]
    fn local(&self, ray: &Ray) -> Ray {
        Ray { origin: self.group_point(ray.origin), dir: self.to_group * ray.dir }
    }

    /// Closest hit with `0 < t < t_max`, in world space; `prim` is the mesh's triangle.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        let h = self.mesh.intersect(&self.local(ray), t_max)?;
        let p = self.to_world * h.p + self.offset;
        let n = (self.normals * h.n).normalize();
        let ns = if h.ns == h.n {
            n
        } else {
            match (self.normals * h.ns).try_normalize() {
                Some(s) if s.dot(n) < 0.0 => -s,
                Some(s) => s,
                None => n,
            }
        };
        Some(Hit { t: h.t, p, n, ns, prim: h.prim })
    }

    /// True if any triangle blocks the ray with `0 < t < t_max`.
    #[inline]
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        self.mesh.occluded(&self.local(ray), t_max)
    }

    /// The world bounding box.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::sphere::tests::{random_dir, uniform};
    use rand_pcg::Pcg32;
    use std::path::Path;

    fn bunny() -> Mesh {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("meshes/bunny.obj");
        Mesh::load(&path, &crate::geometry::Transform::default()).unwrap()
    }

    /// Placements: a rotation with a non-uniform scale and a shear, and a mirror.
    fn placements() -> [(Mat3, Vec3); 2] {
        let shear = Mat3::from_cols(Vec3::new(2.0, 0.3, 0.0), Vec3::new(0.2, 1.5, -0.4), Vec3::new(0.0, 0.5, 0.8));
        let mirror = Mat3::from_diagonal(Vec3::new(-1.5, 1.5, 1.5)) * Mat3::from_rotation_y(0.7);
        [(shear, Vec3::new(0.3, -1.0, 2.0)), (mirror, Vec3::new(-2.0, 0.5, 0.1))]
    }

    /// An instance hits where a copy of the mesh placed by the same map does (the copy's
    /// vertices rounded once, so within 1e-4 relative in `t`), with the copy's normals;
    /// both agree on occlusion. 4000 random rays through the bounds per placement.
    #[test]
    fn an_instance_hits_like_a_placed_copy() {
        let mesh = Arc::new(bunny());
        for (k, (m, t)) in placements().into_iter().enumerate() {
            assert!(!MeshInstance::cancels(&mesh, m, t));
            let inst = MeshInstance::new(mesh.clone(), m, t);
            let copy = mesh.placed_copy(m, t).unwrap();
            let b = copy.bounds();
            assert!(inst.bounds().min.cmple(b.min).all() && inst.bounds().max.cmpge(b.max).all());
            let mut rng = Pcg32::new(k as u64, 3);
            let (mut hits, mut agree) = (0, 0);
            for i in 0..4000 {
                let o = b.min + b.diagonal() * Vec3::new(uniform(&mut rng), uniform(&mut rng), uniform(&mut rng)) * 1.4
                    - b.diagonal() * 0.2;
                let ray = Ray::new(o, random_dir(&mut rng));
                let (a, c) = (inst.intersect(&ray, f32::INFINITY), copy.intersect(&ray, f32::INFINITY));
                match (a, c) {
                    (None, None) => {}
                    (Some(a), Some(c)) => {
                        hits += 1;
                        assert!((a.t - c.t).abs() <= 1e-4 * c.t.max(1e-3), "ray {i}: t {} vs {}", a.t, c.t);
                        assert!((a.p - ray.at(a.t)).length() < 1e-4 * (1.0 + a.p.length()), "ray {i}: p off the ray");
                        assert!((a.n.length() - 1.0).abs() < 1e-5 && a.ns.dot(a.n) >= 0.0);
                        // The same triangle (not at a shared edge) has the same normal.
                        if a.n.dot(c.n) > 0.999 {
                            agree += 1;
                        }
                    }
                    // A ray grazing an edge may hit one and miss the other.
                    (a, c) => assert!(
                        a.or(c).is_some_and(|h| h.t > 0.0),
                        "ray {i}: one hit, one miss: {:?} vs {:?}",
                        a.map(|h| h.t),
                        c.map(|h| h.t)
                    ),
                }
                assert_eq!(inst.occluded(&ray, f32::INFINITY), inst.intersect(&ray, f32::INFINITY).is_some());
            }
            assert!(hits > 400 && agree as f64 > 0.99 * hits as f64, "placement {k}: {agree} of {hits}");
        }
    }

    /// A closed cube keeps outward normals under a mirroring placement: every ray from
    /// outside towards the centre meets a face whose normal points back at the ray.
    #[test]
    fn a_mirrored_instance_keeps_outward_normals() {
        let cube = Mesh::cuboid(Vec3::splat(-1.0), Vec3::splat(1.0), &Default::default()).unwrap();
        let mirror = Mat3::from_diagonal(Vec3::new(-1.0, 2.0, 1.0));
        let inst = MeshInstance::new(Arc::new(cube), mirror, Vec3::new(5.0, 0.0, 0.0));
        let mut rng = Pcg32::new(9, 1);
        for _ in 0..500 {
            let d = random_dir(&mut rng);
            let c = Vec3::new(5.0, 0.0, 0.0);
            let h = inst.intersect(&Ray::new(c - d * 10.0, d), f32::INFINITY).unwrap();
            assert!(h.n.dot(d) < 0.0 && h.n.dot(h.p - c) > 0.0, "inward normal {} at {}", h.n, h.p);
        }
    }

    /// Group coordinates near −10⁴ moved back to the origin cancel; the same mesh at the
    /// group origin moved to 10⁴, rotated or mirrored does not.
    #[test]
    fn cancelling_placements_are_found() {
        let far = Mesh::cuboid(Vec3::splat(-10_001.0), Vec3::splat(-9_999.0), &Default::default()).unwrap();
        assert!(MeshInstance::cancels(&far, Mat3::IDENTITY, Vec3::splat(10_000.0)));
        assert!(!MeshInstance::cancels(&far, Mat3::IDENTITY, Vec3::ZERO));
        let near = Mesh::cuboid(Vec3::splat(-1.0), Vec3::splat(1.0), &Default::default()).unwrap();
        for m in
            [Mat3::from_rotation_y(0.7) * Mat3::from_rotation_x(0.6), Mat3::from_diagonal(Vec3::new(-3.0, 1.0, 1.0))]
        {
            assert!(!MeshInstance::cancels(&near, m, Vec3::splat(10_000.0)));
            assert!(!MeshInstance::cancels(&near, m, Vec3::ZERO));
        }
    }
}
