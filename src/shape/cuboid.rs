//! Cuboids: axis-aligned boxes as solids (normals point outward). A ray starting
//! inside hits the far face, still with the outward normal.

use super::{Mesh, Placement, Shape};
use crate::error::{Error, Result};
use crate::geometry::{Aabb, Hit, Ray};
use crate::scene::check::Check;
use crate::scene::desc::V3;
use glam::Vec3;

/// A solid axis-aligned box `[min, max]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cuboid {
    /// Lower corner.
    pub min: Vec3,
    /// Upper corner.
    pub max: Vec3,
}

impl Cuboid {
    /// The box spanned by two opposite corners (in any order).
    pub fn new(a: Vec3, b: Vec3) -> Cuboid {
        Cuboid { min: a.min(b), max: a.max(b) }
    }

    /// Entry and exit parameters with the axis of each, or None if the line misses.
    /// Zero direction components give infinite slab parameters; a NaN (origin exactly
    /// on a slab plane, direction parallel to it) is ignored by the comparisons.
    #[inline]
    fn slabs(&self, ray: &Ray) -> Option<(f32, usize, f32, usize)> {
        let mut t_near = f32::NEG_INFINITY;
        let mut t_far = f32::INFINITY;
        let (mut a_near, mut a_far) = (0, 0);
        for axis in 0..3 {
            let inv = 1.0 / ray.dir[axis];
            let mut t0 = (self.min[axis] - ray.origin[axis]) * inv;
            let mut t1 = (self.max[axis] - ray.origin[axis]) * inv;
            if inv < 0.0 {
                std::mem::swap(&mut t0, &mut t1);
            }
            if t0 > t_near {
                t_near = t0;
                a_near = axis;
            }
            if t1 < t_far {
                t_far = t1;
                a_far = axis;
            }
        }
        (t_near <= t_far).then_some((t_near, a_near, t_far, a_far))
    }

    #[inline]
    fn hit_t(&self, ray: &Ray, t_max: f32) -> Option<(f32, usize, bool)> {
        let (t0, a0, t1, a1) = self.slabs(ray)?;
        if t0 > 0.0 && t0 < t_max {
            Some((t0, a0, true))
        } else if t1 > 0.0 && t1 < t_max {
            Some((t1, a1, false))
        } else {
            None
        }
    }

    /// Closest hit with `0 < t < t_max` (the far face when starting inside).
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        let (t, axis, entering) = self.hit_t(ray, t_max)?;
        let d = ray.dir[axis];
        // Entering through the face the ray faces: the one at min if d > 0.
        let at_max = (d > 0.0) != entering;
        let mut p = ray.at(t);
        p[axis] = if at_max { self.max[axis] } else { self.min[axis] };
        // Keep the point inside the face despite rounding in the other coordinates.
        p = p.clamp(self.min, self.max);
        let mut n = Vec3::ZERO;
        n[axis] = if at_max { 1.0 } else { -1.0 };
        Some(Hit::flat(t, p, n))
    }

    /// True if the ray hits the box surface with `0 < t < t_max`.
    #[inline]
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        self.hit_t(ray, t_max).is_some()
    }

    /// Bounding box (the box itself).
    pub fn bounds(&self) -> Aabb {
        Aabb { min: self.min, max: self.max }
    }
}

impl Cuboid {
    /// A cuboid from the scene description at `field`: `min < max` on every axis;
    /// placed by `xf`: scaled and translated it stays an axis-aligned [`Cuboid`], with
    /// any non-zero `rotate_deg` it becomes a closed 12-triangle [`Mesh`] (outward
    /// normals: still a solid for nested dielectrics).
    pub(crate) fn from_desc(check: &Check, field: &str, min: V3, max: V3, xf: Option<&Placement>) -> Result<Shape> {
        let (lo, hi) = (check.vec(&format!("{field}.min"), min)?, check.vec(&format!("{field}.max"), max)?);
        if !lo.cmplt(hi).all() {
            return Err(check.err(field, "expected min < max on every axis"));
        }
        let Some(x) = xf else {
            return Ok(Shape::Cuboid(Cuboid { min: lo, max: hi }));
        };
        if x.t.rotate_deg == Vec3::ZERO {
            // Scales are positive, so the corners keep their order.
            let (lo, hi) = (x.point(check, lo)?, x.point(check, hi)?);
            if !lo.cmplt(hi).all() {
                return Err(check.err(format!("{}.scale", x.field), "the scale makes the box flat in f32"));
            }
            return Ok(Shape::Cuboid(Cuboid { min: lo, max: hi }));
        }
        let mesh = Mesh::cuboid(lo, hi, &x.t).map_err(|e| match e {
            Error::Setting { name, message } => check.err(format!("{}.{name}", x.field), message),
            e => check.err(&x.field, e.to_string()),
        })?;
        Ok(Shape::Mesh(Box::new(mesh)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::sphere::tests::random_dir;
    use rand_pcg::Pcg32;

    #[test]
    fn outside_inside_and_axis_parallel() {
        let c = Cuboid::new(Vec3::new(1.0, 1.0, 1.0), Vec3::new(-1.0, -2.0, -3.0));
        let h = c.intersect(&Ray::new(Vec3::new(0.0, 0.0, -10.0), Vec3::Z), f32::INFINITY).unwrap();
        assert!((h.t - 7.0).abs() < 1e-6 && h.n == -Vec3::Z && h.p.z == -3.0);
        // From inside: the far face, outward normal.
        let h = c.intersect(&Ray::new(Vec3::ZERO, Vec3::Z), f32::INFINITY).unwrap();
        assert!((h.t - 1.0).abs() < 1e-6 && h.n == Vec3::Z);
        let h = c.intersect(&Ray::new(Vec3::ZERO, -Vec3::Y), f32::INFINITY).unwrap();
        assert!((h.t - 2.0).abs() < 1e-6 && h.n == -Vec3::Y);
        // Parallel to a face, outside its slab: miss; with -0 components: no NaN.
        assert!(c.intersect(&Ray::new(Vec3::new(0.0, 5.0, -10.0), Vec3::Z), f32::INFINITY).is_none());
        let h = c.intersect(&Ray::new(Vec3::new(0.5, 0.5, 5.0), Vec3::new(-0.0, -0.0, -1.0)), f32::INFINITY).unwrap();
        assert!((h.t - 4.0).abs() < 1e-6 && h.n == Vec3::Z);
        assert!(!c.occluded(&Ray::new(Vec3::new(0.0, 0.0, -10.0), Vec3::Z), 6.9));
        // Spawned from the surface: outward rays escape; inward rays hit another face.
        let mut rng = Pcg32::new(3, 3);
        for _ in 0..2000 {
            let o = random_dir(&mut rng) * 10.0;
            let h = c.intersect(&Ray::new(o, (-o).normalize()), f32::INFINITY).unwrap();
            let d = random_dir(&mut rng);
            let r = Ray::spawn(h.p, h.n, d);
            match c.intersect(&r, f32::INFINITY) {
                None => assert!(d.dot(h.n) > 0.0),
                Some(h2) => assert!(d.dot(h.n) < 0.0 && h2.n != h.n),
            }
        }
    }
}
