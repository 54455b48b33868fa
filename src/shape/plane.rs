//! Infinite planes (unbounded, so they live outside the scene BVH).

use super::Placement;
use crate::error::Result;
use crate::geometry::{Hit, Ray};
use crate::scene::check::Check;
use crate::scene::desc::V3;
use glam::Vec3;

/// The infinite plane through `point` with unit normal `normal` (the same normal on both sides).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    /// A point on the plane.
    pub point: Vec3,
    /// Unit normal.
    pub normal: Vec3,
}

/// Ray parameter where the ray meets the plane `dot(n, x) = d`, if in `(0, t_max)`.
/// Rays parallel to the plane (or with a non-finite result) miss.
#[inline]
pub(crate) fn plane_t(n: Vec3, d: f32, ray: &Ray, t_max: f32) -> Option<f32> {
    let denom = n.dot(ray.dir);
    if denom == 0.0 {
        return None;
    }
    let t = (d - n.dot(ray.origin)) / denom;
    (t > 0.0 && t < t_max).then_some(t)
}

/// The point `p` projected onto the plane `dot(n, x) = d` (n unit): removes the
/// error of `o + t d` along the normal.
#[inline]
pub(crate) fn project(n: Vec3, d: f32, p: Vec3) -> Vec3 {
    p - n * (n.dot(p) - d)
}

impl Plane {
    /// The plane through `point` with normal `normal` (normalised here).
    pub fn new(point: Vec3, normal: Vec3) -> Plane {
        Plane { point, normal: normal.normalize() }
    }

    /// Closest hit with `0 < t < t_max`.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        let d = self.normal.dot(self.point);
        let t = plane_t(self.normal, d, ray, t_max)?;
        Some(Hit::flat(t, project(self.normal, d, ray.at(t)), self.normal))
    }

    /// True if the ray hits the plane with `0 < t < t_max`.
    #[inline]
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        plane_t(self.normal, self.normal.dot(self.point), ray, t_max).is_some()
    }
}

impl Plane {
    /// A plane from the scene description at `field` (the normal need not be unit),
    /// placed by `xf` (any scale).
    pub(crate) fn from_desc(
        check: &Check,
        field: &str,
        point: V3,
        normal: V3,
        xf: Option<&Placement>,
    ) -> Result<Plane> {
        let point = check.vec(&format!("{field}.point"), point)?;
        let normal = check.direction(&format!("{field}.normal"), normal)?;
        match xf {
            None => Ok(Plane { point, normal }),
            Some(x) => Ok(Plane { point: x.point(check, point)?, normal: x.normal(check, normal)? }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::sphere::tests::{random_dir, uniform};
    use rand_pcg::Pcg32;

    #[test]
    fn hits_parallel_and_spawn() {
        let pl = Plane::new(Vec3::new(0.0, 1.0, 0.0), Vec3::Y);
        let h = pl.intersect(&Ray::new(Vec3::new(3.0, 5.0, 0.0), -Vec3::Y), f32::INFINITY).unwrap();
        assert!((h.t - 4.0).abs() < 1e-6 && h.n == Vec3::Y && h.p.y == 1.0);
        // From below: same normal.
        let h = pl.intersect(&Ray::new(Vec3::new(3.0, -1.0, 0.0), Vec3::Y), f32::INFINITY).unwrap();
        assert!((h.t - 2.0).abs() < 1e-6 && h.n == Vec3::Y);
        // Parallel: no hit, no NaN, also when lying in the plane.
        assert!(pl.intersect(&Ray::new(Vec3::new(0.0, 5.0, 0.0), Vec3::X), f32::INFINITY).is_none());
        assert!(pl.intersect(&Ray::new(Vec3::new(0.0, 1.0, 0.0), Vec3::Z), f32::INFINITY).is_none());
        assert!(!pl.occluded(&Ray::new(Vec3::new(0.0, 1.0, 0.0), -Vec3::Z), f32::INFINITY));
        // Spawned rays from plane hits do not re-hit it, at several scales and tilts.
        let mut rng = Pcg32::new(5, 1);
        for scale in [1e-4f32, 1.0, 1e4] {
            let pl = Plane::new(Vec3::new(0.3, 1.0, -0.2) * scale, Vec3::new(0.2, 1.0, 0.1));
            for _ in 0..3000 {
                let o = Vec3::new(uniform(&mut rng) - 0.5, 3.0, uniform(&mut rng) - 0.5) * 4.0 * scale;
                let d = (Vec3::new(uniform(&mut rng) - 0.5, -1.0, uniform(&mut rng) - 0.5)).normalize();
                let h = pl.intersect(&Ray::new(o, d), f32::INFINITY).unwrap();
                let dir = random_dir(&mut rng);
                assert!(!pl.occluded(&Ray::spawn(h.p, h.n, dir), f32::INFINITY), "scale {scale}");
            }
        }
    }
}
