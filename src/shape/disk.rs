//! Disks: flat circles, one-sided normal given by the user (the same on both sides).

use super::Placement;
use super::plane::{plane_t, project};
use crate::error::Result;
use crate::geometry::{Aabb, Hit, Ray};
use crate::scene::check::Check;
use crate::scene::desc::V3;
use glam::Vec3;

/// A disk of radius `radius` around `center` in the plane with unit normal `normal`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Disk {
    /// Centre.
    pub center: Vec3,
    /// Unit normal.
    pub normal: Vec3,
    /// Radius.
    pub radius: f32,
}

impl Disk {
    /// A disk (the normal is normalised here).
    pub fn new(center: Vec3, normal: Vec3, radius: f32) -> Disk {
        Disk { center, normal: normal.normalize(), radius }
    }

    #[inline]
    fn hit_point(&self, ray: &Ray, t_max: f32) -> Option<(f32, Vec3)> {
        let d = self.normal.dot(self.center);
        let t = plane_t(self.normal, d, ray, t_max)?;
        let p = project(self.normal, d, ray.at(t));
        ((p - self.center).length_squared() <= self.radius * self.radius).then_some((t, p))
    }

    /// Closest hit with `0 < t < t_max`.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        let (t, p) = self.hit_point(ray, t_max)?;
        Some(Hit::flat(t, p, self.normal))
    }

    /// True if the ray hits the disk with `0 < t < t_max`.
    #[inline]
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        self.hit_point(ray, t_max).is_some()
    }

    /// Bounding box: per axis, the disk extends `radius * sqrt(1 - n_axis^2)`.
    pub fn bounds(&self) -> Aabb {
        let n = self.normal;
        let e = (Vec3::ONE - n * n).max(Vec3::ZERO).powf(0.5) * self.radius.abs();
        Aabb::new(self.center - e, self.center + e)
    }
}

impl Disk {
    /// A disk from the scene description at `field` (the normal need not be unit),
    /// placed by `xf` (uniform scale only: a disk scaled otherwise would be an ellipse).
    pub(crate) fn from_desc(
        check: &Check,
        field: &str,
        center: V3,
        normal: V3,
        radius: f32,
        xf: Option<&Placement>,
    ) -> Result<Disk> {
        let center = check.vec(&format!("{field}.center"), center)?;
        let normal = check.direction(&format!("{field}.normal"), normal)?;
        let radius = check.positive(&format!("{field}.radius"), radius)?;
        match xf {
            None => Ok(Disk { center, normal, radius }),
            Some(x) => {
                let s = x.uniform_scale(check, "disk")?;
                Ok(Disk {
                    center: x.point(check, center)?,
                    normal: x.normal(check, normal)?,
                    radius: x.length(check, radius, s)?,
                })
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inside_and_just_outside_the_radius() {
        let d = Disk::new(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z, 2.0);
        let h = d.intersect(&Ray::new(Vec3::new(1.99, 0.0, 0.0), Vec3::Z), f32::INFINITY).unwrap();
        assert!((h.t - 5.0).abs() < 1e-6 && h.n == -Vec3::Z);
        assert!(d.intersect(&Ray::new(Vec3::new(2.01, 0.0, 0.0), Vec3::Z), f32::INFINITY).is_none());
        assert!(d.intersect(&Ray::new(Vec3::new(1.5, 1.5, 0.0), Vec3::Z), f32::INFINITY).is_none());
        assert!(d.occluded(&Ray::new(Vec3::new(0.0, 1.9, 0.0), Vec3::Z), 6.0));
        assert!(!d.occluded(&Ray::new(Vec3::new(0.0, 1.9, 0.0), Vec3::Z), 4.0));
        let b = d.bounds();
        assert_eq!(b.min, Vec3::new(-2.0, -2.0, 5.0));
        assert_eq!(b.max, Vec3::new(2.0, 2.0, 5.0));
    }
}
