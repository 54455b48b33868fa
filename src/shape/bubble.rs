//! Bubbles: a thin spherical shell (the solid) between an outer sphere and a
//! concentric inner sphere (the cavity). The outer surface's normal points away
//! from the centre, the inner surface's normal towards it (out of the shell, into the cavity).

use super::Placement;
use super::sphere::{first_root, reproject, sphere_roots};
use crate::error::Result;
use crate::geometry::{Aabb, Hit, Ray};
use crate::scene::check::Check;
use crate::scene::desc::V3;
use glam::Vec3;

/// A spherical shell of radii `inner_radius < outer_radius` around `center`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bubble {
    /// Common centre of both spheres.
    pub center: Vec3,
    /// Radius of the outer surface.
    pub outer_radius: f32,
    /// Radius of the inner surface (the cavity), `0 < inner_radius < outer_radius`.
    pub inner_radius: f32,
}

impl Bubble {
    /// A bubble around `center` with the given outer and inner radii.
    pub fn new(center: Vec3, outer_radius: f32, inner_radius: f32) -> Bubble {
        Bubble { center, outer_radius, inner_radius }
    }

    /// Closest hit with `0 < t < t_max` on either surface.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        let mut t_max = t_max;
        if let Some(t) = sphere_roots(self.center, self.outer_radius, ray).and_then(|r| first_root(r, t_max)) {
            let (p, n) = reproject(self.center, self.outer_radius, ray.at(t));
            best = Some(Hit::flat(t, p, n));
            t_max = t;
        }
        if let Some(t) = sphere_roots(self.center, self.inner_radius, ray).and_then(|r| first_root(r, t_max)) {
            let (p, n) = reproject(self.center, self.inner_radius, ray.at(t));
            best = Some(Hit::flat(t, p, -n));
        }
        best
    }

    /// True if the ray hits either surface with `0 < t < t_max`.
    #[inline]
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        sphere_roots(self.center, self.outer_radius, ray).and_then(|r| first_root(r, t_max)).is_some()
            || sphere_roots(self.center, self.inner_radius, ray).and_then(|r| first_root(r, t_max)).is_some()
    }

    /// Bounding box (of the outer sphere).
    pub fn bounds(&self) -> Aabb {
        let r = Vec3::splat(self.outer_radius.abs());
        Aabb::new(self.center - r, self.center + r)
    }
}

impl Bubble {
    /// A bubble from the scene description at `field`: the inner radius must be the
    /// smaller; placed by `xf` (uniform scale only).
    pub(crate) fn from_desc(
        check: &Check,
        field: &str,
        center: V3,
        outer_radius: f32,
        inner_radius: f32,
        xf: Option<&Placement>,
    ) -> Result<Bubble> {
        let f = |name: &str| format!("{field}.{name}");
        let outer = check.positive(&f("outer_radius"), outer_radius)?;
        let inner = check.positive(&f("inner_radius"), inner_radius)?;
        if inner >= outer {
            return Err(
                check.err(f("inner_radius"), format!("expected less than outer_radius ({outer}), found {inner}"))
            );
        }
        let center = check.vec(&f("center"), center)?;
        match xf {
            None => Ok(Bubble { center, outer_radius: outer, inner_radius: inner }),
            Some(x) => {
                let s = x.uniform_scale(check, "bubble")?;
                let (outer, inner) = (x.length(check, outer, s)?, x.length(check, inner, s)?);
                if inner >= outer {
                    return Err(check.err(format!("{}.scale", x.field), "the scale makes the radii equal in f32"));
                }
                Ok(Bubble { center: x.point(check, center)?, outer_radius: outer, inner_radius: inner })
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outer_then_inner_with_normals() {
        let b = Bubble::new(Vec3::ZERO, 2.0, 1.5);
        let r = Ray::new(Vec3::new(0.0, 0.0, -10.0), Vec3::Z);
        let h = b.intersect(&r, f32::INFINITY).unwrap();
        assert!((h.t - 8.0).abs() < 1e-5 && (h.n - -Vec3::Z).length() < 1e-6);
        // Inside the shell (between the spheres), heading to the centre: the inner
        // surface, whose normal points into the cavity, i.e. along the ray.
        let r = Ray::new(Vec3::new(0.0, 0.0, -1.75), Vec3::Z);
        let h = b.intersect(&r, f32::INFINITY).unwrap();
        assert!((h.t - 0.25).abs() < 1e-5, "t = {}", h.t);
        assert!((h.p - Vec3::new(0.0, 0.0, -1.5)).length() < 1e-6);
        assert!((h.n - Vec3::Z).length() < 1e-6, "inner normal points towards the centre");
        // Inside the shell, heading outward: the outer surface, outward normal.
        let r = Ray::new(Vec3::new(0.0, 0.0, -1.75), -Vec3::Z);
        let h = b.intersect(&r, f32::INFINITY).unwrap();
        assert!((h.t - 0.25).abs() < 1e-5 && (h.n - -Vec3::Z).length() < 1e-6);
        // From the cavity: the inner surface from inside, normal towards the centre.
        let h = b.intersect(&Ray::new(Vec3::ZERO, Vec3::X), f32::INFINITY).unwrap();
        assert!((h.t - 1.5).abs() < 1e-6 && (h.n - -Vec3::X).length() < 1e-6);
        assert!(b.occluded(&Ray::new(Vec3::ZERO, Vec3::X), 1.6));
        assert!(!b.occluded(&Ray::new(Vec3::ZERO, Vec3::X), 1.4));
    }
}
