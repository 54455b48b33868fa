//! Axis-aligned bounding boxes, used by shapes to report their extent and by the BVH.

use glam::Vec3;

/// An axis-aligned box `[min, max]`; empty when any `min` component exceeds `max`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Lower corner.
    pub min: Vec3,
    /// Upper corner.
    pub max: Vec3,
}

impl Aabb {
    /// The empty box (identity of [`Aabb::union`]).
    pub const EMPTY: Aabb = Aabb { min: Vec3::splat(f32::INFINITY), max: Vec3::splat(f32::NEG_INFINITY) };

    /// The smallest box holding the two points `a` and `b` (in any order).
    #[inline]
    pub fn new(a: Vec3, b: Vec3) -> Aabb {
        Aabb { min: a.min(b), max: a.max(b) }
    }

    /// The smallest box holding both boxes.
    #[inline]
    pub fn union(&self, o: &Aabb) -> Aabb {
        Aabb { min: self.min.min(o.min), max: self.max.max(o.max) }
    }

    /// The smallest box holding this box and the point `p`.
    #[inline]
    pub fn grow(&self, p: Vec3) -> Aabb {
        Aabb { min: self.min.min(p), max: self.max.max(p) }
    }

    /// The centre of the box.
    #[inline]
    pub fn centroid(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    /// `max - min` (negative components for the empty box).
    #[inline]
    pub fn diagonal(&self) -> Vec3 {
        self.max - self.min
    }

    /// Surface area; 0 for an empty box.
    #[inline]
    pub fn surface_area(&self) -> f32 {
        if self.is_empty() {
            return 0.0;
        }
        let d = self.diagonal();
        2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
    }

    /// True when the box holds no point (a flat box, min == max on an axis, is not empty).
    #[inline]
    pub fn is_empty(&self) -> bool {
        !(self.min.x <= self.max.x && self.min.y <= self.max.y && self.min.z <= self.max.z)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn union_grow_area() {
        let a = Aabb::new(Vec3::new(1.0, 2.0, 3.0), Vec3::ZERO);
        assert_eq!(a.min, Vec3::ZERO);
        assert_eq!(a.max, Vec3::new(1.0, 2.0, 3.0));
        assert_eq!(a.surface_area(), 2.0 * (2.0 + 6.0 + 3.0));
        assert_eq!(a.centroid(), Vec3::new(0.5, 1.0, 1.5));
        assert!(Aabb::EMPTY.is_empty() && !a.is_empty());
        assert_eq!(Aabb::EMPTY.union(&a), a);
        assert_eq!(Aabb::EMPTY.surface_area(), 0.0);
        let g = a.grow(Vec3::new(-1.0, 0.0, 4.0));
        assert_eq!(g.min, Vec3::new(-1.0, 0.0, 0.0));
        assert_eq!(g.max, Vec3::new(1.0, 2.0, 4.0));
        assert!(!Aabb::new(Vec3::ONE, Vec3::ONE).is_empty());
    }
}
