//! Quads: parallelograms `origin + a * edge_u + b * edge_v`, `a, b` in [0, 1], with
//! normal `normalize(edge_u x edge_v)` (the same on both sides). Typical area lights.

use super::Placement;
use super::plane::plane_t;
use crate::error::Result;
use crate::geometry::{Aabb, Hit, Ray};
use crate::scene::check::Check;
use crate::scene::desc::V3;
use glam::Vec3;

/// A parallelogram, with the plane and the coordinate projection precomputed
/// (the intersection test is hot: the Cornell box is made of quads).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quad {
    /// One corner.
    pub origin: Vec3,
    /// First edge from `origin`.
    pub edge_u: Vec3,
    /// Second edge from `origin`.
    pub edge_v: Vec3,
    /// Unit normal.
    n: Vec3,
    /// `n · origin`: the plane offset.
    d: f32,
    /// `v × w` and `w × u` with `w = (u × v) / |u × v|²`: a point `q` relative
    /// to the origin has quad coordinates `(q · pu, q · pv)` (the triple
    /// products `w · (q × v)` and `w · (u × q)` with the cross products
    /// taken once, here, instead of per ray).
    pu: Vec3,
    pv: Vec3,
}

impl Quad {
    /// A quad from a corner and its two edges (a degenerate quad, with
    /// parallel or zero edges, is never hit).
    pub fn new(origin: Vec3, edge_u: Vec3, edge_v: Vec3) -> Quad {
        let c = edge_u.cross(edge_v);
        let len2 = c.length_squared();
        let (n, w) = if len2 > 0.0 { (c / len2.sqrt(), c / len2) } else { (Vec3::ZERO, Vec3::ZERO) };
        Quad { origin, edge_u, edge_v, n, d: n.dot(origin), pu: edge_v.cross(w), pv: w.cross(edge_u) }
    }

    /// Unit normal `normalize(edge_u x edge_v)`.
    #[inline]
    pub fn normal(&self) -> Vec3 {
        self.n
    }

    /// `n · origin`, the plane's offset along the normal.
    #[inline]
    pub(crate) fn plane_offset(&self) -> f32 {
        self.d
    }

    /// The vectors whose dot products with `q − origin` are the quad coordinates `(a, b)`.
    #[inline]
    pub(crate) fn projections(&self) -> (Vec3, Vec3) {
        (self.pu, self.pv)
    }

    /// Area `|edge_u x edge_v|`.
    pub fn area(&self) -> f32 {
        self.edge_u.cross(self.edge_v).length()
    }

    /// Ray parameter and the quad coordinates `(a, b)` of the hit.
    #[inline]
    fn hit_coords(&self, ray: &Ray, t_max: f32) -> Option<(f32, f32, f32, Vec3)> {
        let t = plane_t(self.n, self.d, ray, t_max)?;
        let q = ray.at(t) - self.origin;
        let (a, b) = (q.dot(self.pu), q.dot(self.pv));
        ((0.0..=1.0).contains(&a) && (0.0..=1.0).contains(&b)).then_some((t, a, b, self.n))
    }

    /// Closest hit with `0 < t < t_max`; the point is rebuilt from the quad coordinates.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        let (t, a, b, n) = self.hit_coords(ray, t_max)?;
        Some(Hit::flat(t, self.origin + self.edge_u * a + self.edge_v * b, n))
    }

    /// The hit record of a hit at `t` already found ([`super::Batch`]): what
    /// [`Quad::intersect`] returns for it, from the same arithmetic.
    #[inline]
    pub(crate) fn hit_at(&self, ray: &Ray, t: f32) -> Hit {
        let q = ray.at(t) - self.origin;
        let (a, b) = (q.dot(self.pu), q.dot(self.pv));
        Hit::flat(t, self.origin + self.edge_u * a + self.edge_v * b, self.n)
    }

    /// True if the ray hits the quad with `0 < t < t_max`.
    #[inline]
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        self.hit_coords(ray, t_max).is_some()
    }

    /// Bounding box of the four corners.
    pub fn bounds(&self) -> Aabb {
        Aabb::new(self.origin, self.origin + self.edge_u)
            .grow(self.origin + self.edge_v)
            .grow(self.origin + self.edge_u + self.edge_v)
    }
}

impl Quad {
    /// A quad from the scene description at `field`: the edges must span a
    /// parallelogram; placed by `xf` (any scale: the image of a parallelogram is one).
    pub(crate) fn from_desc(
        check: &Check,
        field: &str,
        origin: V3,
        edge_u: V3,
        edge_v: V3,
        xf: Option<&Placement>,
    ) -> Result<Quad> {
        let (u, v) = (check.vec(&format!("{field}.edge_u"), edge_u)?, check.vec(&format!("{field}.edge_v"), edge_v)?);
        if u.cross(v).length_squared() <= f32::MIN_POSITIVE {
            return Err(check.err(field, "edge_u and edge_v must be non-zero and not parallel"));
        }
        let origin = check.vec(&format!("{field}.origin"), origin)?;
        let Some(x) = xf else {
            return Ok(Quad::new(origin, u, v));
        };
        let (u, v) = (x.vector(check, u)?, x.vector(check, v)?);
        if !(u.cross(v).length_squared() > f32::MIN_POSITIVE) {
            return Err(check.err(format!("{}.scale", x.field), "the transform makes the quad degenerate in f32"));
        }
        Ok(Quad::new(x.point(check, origin)?, u, v))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::sphere::tests::{random_dir, uniform};
    use rand_pcg::Pcg32;

    #[test]
    fn corners_in_and_out() {
        let q = Quad::new(Vec3::ZERO, Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0));
        assert_eq!(q.normal(), Vec3::Z);
        let down = -Vec3::Z;
        let h = q.intersect(&Ray::new(Vec3::new(1.0, 0.5, 3.0), down), f32::INFINITY).unwrap();
        assert!((h.t - 3.0).abs() < 1e-6 && h.n == Vec3::Z && h.p == Vec3::new(1.0, 0.5, 0.0));
        assert!(q.occluded(&Ray::new(Vec3::new(1.999, 0.999, 3.0), down), f32::INFINITY));
        assert!(q.occluded(&Ray::new(Vec3::new(0.001, 0.001, 3.0), down), f32::INFINITY));
        assert!(!q.occluded(&Ray::new(Vec3::new(2.001, 0.999, 3.0), down), f32::INFINITY));
        assert!(!q.occluded(&Ray::new(Vec3::new(1.0, -0.001, 3.0), down), f32::INFINITY));
        // Skewed parallelogram: the point (0.2, 0.5) is outside, (1.2, 0.5) inside.
        let s = Quad::new(Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0));
        assert!(!s.occluded(&Ray::new(Vec3::new(0.2, 0.5, 1.0), down), f32::INFINITY));
        assert!(s.occluded(&Ray::new(Vec3::new(1.2, 0.5, 1.0), down), f32::INFINITY));
        let b = s.bounds();
        assert_eq!((b.min, b.max), (Vec3::ZERO, Vec3::new(2.0, 1.0, 0.0)));
    }

    #[test]
    fn spawned_rays_do_not_rehit_at_any_scale() {
        let mut rng = Pcg32::new(11, 3);
        for (scale, offset) in
            [(1e-4f32, Vec3::ZERO), (1.0, Vec3::ZERO), (1e4, Vec3::ZERO), (1.0, Vec3::new(1e4, 0.0, 0.0))]
        {
            let q = Quad::new(
                offset + Vec3::new(-0.5, 0.2, -0.5) * scale,
                Vec3::new(1.0, 0.3, 0.0) * scale,
                Vec3::new(0.1, -0.2, 1.0) * scale,
            );
            let mut bad = 0;
            for _ in 0..10_000 {
                let target = q.origin + q.edge_u * uniform(&mut rng) + q.edge_v * uniform(&mut rng);
                let o = target + random_dir(&mut rng) * 2.0 * scale;
                let Some(h) = q.intersect(&Ray::new(o, (target - o).normalize()), f32::INFINITY) else {
                    continue;
                };
                if q.occluded(&Ray::spawn(h.p, h.n, random_dir(&mut rng)), f32::INFINITY) {
                    bad += 1;
                }
            }
            assert_eq!(bad, 0, "scale {scale} offset {offset}");
        }
    }
}
