//! Spheres, intersected with the numerically stable quadratic and hit points
//! re-projected onto the surface (so spawned rays do not re-hit it).

use super::Placement;
use crate::error::Result;
use crate::geometry::{Aabb, Hit, Ray};
use crate::scene::check::Check;
use crate::scene::desc::V3;
use glam::Vec3;

/// A solid sphere; its normal points outward.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre.
    pub center: Vec3,
    /// Radius (> 0).
    pub radius: f32,
}

/// Both ray parameters where the ray's line meets the sphere (centre `c`, radius `r`),
/// `t0 <= t1`, or None when it misses. Uses the discriminant in the form
/// `4a (r - |l|)(r + |l|)` with `l` the vector from the centre to the closest point on
/// the line, which stays accurate for far or grazing rays, and the stable root pair
/// `q / a`, `c / q`.
#[inline]
pub(crate) fn sphere_roots(c: Vec3, r: f32, ray: &Ray) -> Option<(f32, f32)> {
    let f = ray.origin - c;
    let a = ray.dir.length_squared();
    let b = 2.0 * ray.dir.dot(f);
    let cc = f.length_squared() - r * r;
    let l = f - ray.dir * (b / (2.0 * a));
    let ll2 = l.length_squared();
    // Most rays pass well clear: reject them before the square roots and
    // divisions. The margin (2^-10) is far above the rounding of `ll2` and
    // `r²`, so every ray rejected here is rejected by `disc < 0` below too
    // (`r²` must be normal: a tiny sphere's square underflows).
    let rr = r * r;
    if rr.is_normal() && ll2 > rr * (1.0 + 1.0 / 1024.0) {
        return None;
    }
    let ll = ll2.sqrt();
    let disc = 4.0 * a * (r + ll) * (r - ll);
    if !(disc >= 0.0) {
        return None;
    }
    let root = disc.sqrt();
    let q = -0.5 * (b + root.copysign(b));
    let (t0, t1) = if q == 0.0 {
        // b == 0 and disc == 0: the origin is on the tangent point's normal plane.
        (0.0, 0.0)
    } else {
        (q / a, cc / q)
    };
    if !(t0.is_finite() && t1.is_finite()) {
        return None;
    }
    Some(if t0 <= t1 { (t0, t1) } else { (t1, t0) })
}

/// The smallest root in (0, t_max), if any.
#[inline]
pub(crate) fn first_root(roots: (f32, f32), t_max: f32) -> Option<f32> {
    let (t0, t1) = roots;
    if t0 > 0.0 && t0 < t_max {
        Some(t0)
    } else if t1 > 0.0 && t1 < t_max {
        Some(t1)
    } else {
        None
    }
}

/// The point of the sphere nearest `p` (its re-projection) and the outward unit normal there.
#[inline]
pub(crate) fn reproject(c: Vec3, r: f32, p: Vec3) -> (Vec3, Vec3) {
    let n = (p - c).normalize_or(Vec3::Z);
    (c + n * r, n)
}

impl Sphere {
    /// A sphere of centre `center` and radius `radius`.
    pub fn new(center: Vec3, radius: f32) -> Sphere {
        Sphere { center, radius }
    }

    /// Closest hit with `0 < t < t_max`; the normal points outward.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        let t = first_root(sphere_roots(self.center, self.radius, ray)?, t_max)?;
        let (p, n) = reproject(self.center, self.radius, ray.at(t));
        Some(Hit::flat(t, p, n))
    }

    /// The hit record of a hit at `t` already found ([`super::Batch`]): what
    /// [`Sphere::intersect`] returns for it.
    #[inline]
    pub(crate) fn hit_at(&self, ray: &Ray, t: f32) -> Hit {
        let (p, n) = reproject(self.center, self.radius, ray.at(t));
        Hit::flat(t, p, n)
    }

    /// True if the ray hits the sphere with `0 < t < t_max`.
    #[inline]
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        sphere_roots(self.center, self.radius, ray).and_then(|r| first_root(r, t_max)).is_some()
    }

    /// Bounding box.
    pub fn bounds(&self) -> Aabb {
        let r = Vec3::splat(self.radius.abs());
        Aabb::new(self.center - r, self.center + r)
    }
}

impl Sphere {
    /// A sphere from the scene description at `field` (`objects[i].shape`), placed by
    /// `xf` (uniform scale only).
    pub(crate) fn from_desc(
        check: &Check,
        field: &str,
        center: V3,
        radius: f32,
        xf: Option<&Placement>,
    ) -> Result<Sphere> {
        let center = check.vec(&format!("{field}.center"), center)?;
        let radius = check.positive(&format!("{field}.radius"), radius)?;
        match xf {
            None => Ok(Sphere::new(center, radius)),
            Some(x) => {
                let s = x.uniform_scale(check, "sphere")?;
                Ok(Sphere::new(x.point(check, center)?, x.length(check, radius, s)?))
            }
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use rand::Rng;
    use rand_pcg::Pcg32;

    /// Uniform f32 in [0, 1) from a PCG stream.
    pub(crate) fn uniform(rng: &mut Pcg32) -> f32 {
        (rng.next_u32() >> 8) as f32 * (1.0 / 16_777_216.0)
    }

    /// Uniform direction on the unit sphere.
    pub(crate) fn random_dir(rng: &mut Pcg32) -> Vec3 {
        let z = 1.0 - 2.0 * uniform(rng);
        let phi = std::f32::consts::TAU * uniform(rng);
        let s = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(s * phi.cos(), s * phi.sin(), z)
    }

    #[test]
    fn axis_ray_hits_at_d_minus_r() {
        let s = Sphere::new(Vec3::new(0.0, 0.0, 10.0), 2.0);
        let h = s.intersect(&Ray::new(Vec3::ZERO, Vec3::Z), f32::INFINITY).unwrap();
        assert!((h.t - 8.0).abs() < 1e-5);
        assert!((h.n - -Vec3::Z).length() < 1e-6);
        assert_eq!(h.ns, h.n);
        // From the centre: hits the far side with the outward normal.
        let h = s.intersect(&Ray::new(s.center, Vec3::X), f32::INFINITY).unwrap();
        assert!((h.t - 2.0).abs() < 1e-6 && (h.n - Vec3::X).length() < 1e-6);
        // t_max cuts it off; behind the ray misses.
        assert!(s.intersect(&Ray::new(Vec3::ZERO, Vec3::Z), 7.9).is_none());
        assert!(s.intersect(&Ray::new(Vec3::ZERO, -Vec3::Z), f32::INFINITY).is_none());
        assert!(!s.occluded(&Ray::new(Vec3::ZERO, -Vec3::Z), f32::INFINITY));
        assert!(s.occluded(&Ray::new(Vec3::ZERO, Vec3::Z), 9.0));
        assert_eq!(s.bounds(), Aabb::new(Vec3::new(-2.0, -2.0, 8.0), Vec3::new(2.0, 2.0, 12.0)));
    }

    #[test]
    fn grazing_tangent_and_near_miss() {
        let s = Sphere::new(Vec3::ZERO, 1.0);
        let h = s.intersect(&Ray::new(Vec3::new(-5.0, 1.0, 0.0), Vec3::X), f32::INFINITY);
        if let Some(h) = h {
            assert!((h.t - 5.0).abs() < 1e-2 && h.n.is_finite() && (h.n - Vec3::Y).length() < 1e-2);
        }
        assert!(s.intersect(&Ray::new(Vec3::new(-5.0, 1.0001, 0.0), Vec3::X), f32::INFINITY).is_none());
        let h = s.intersect(&Ray::new(Vec3::new(-5.0, 0.9999, 0.0), Vec3::X), f32::INFINITY).unwrap();
        assert!(h.n.is_finite() && (h.p.length() - 1.0).abs() < 1e-6);
    }

    /// Spawns many rays from random hit points on a sphere, leaving outward and inward;
    /// none may re-hit the surface at (near) its start.
    pub(crate) fn no_self_hits(s: &Sphere, seed: u64) {
        let mut rng = Pcg32::new(seed, 7);
        let mut bad = 0;
        for _ in 0..10_000 {
            let p0 = s.center + random_dir(&mut rng) * s.radius;
            // Find the point by a real intersection, from outside towards p0.
            let o = s.center + (p0 - s.center) * 3.0;
            let d = (p0 - o).normalize();
            let Some(h) = s.intersect(&Ray::new(o, d), f32::INFINITY) else {
                continue;
            };
            let mut dir = random_dir(&mut rng);
            let outward = dir.dot(h.n) > 0.0;
            let r = Ray::spawn(h.p, h.n, dir);
            match s.intersect(&r, f32::INFINITY) {
                None => assert!(outward, "inward ray must hit the far side"),
                Some(h2) => {
                    // Outward rays escape a convex shape; inward rays hit the far side, far away.
                    if outward || h2.t < 1e-3 * s.radius * dir.dot(-h.n).abs().max(1e-3) {
                        bad += 1;
                    }
                }
            }
            dir = -dir;
            let r = Ray::spawn(h.p, h.n, dir);
            if dir.dot(h.n) > 0.0 && s.occluded(&r, f32::INFINITY) {
                bad += 1;
            }
        }
        assert_eq!(bad, 0, "self-intersections for {s:?}");
    }

    #[test]
    fn spawned_rays_do_not_rehit_at_any_scale() {
        no_self_hits(&Sphere::new(Vec3::ZERO, 1.0), 1);
        no_self_hits(&Sphere::new(Vec3::new(1e-4, 2e-4, -1e-4), 1e-4), 2);
        no_self_hits(&Sphere::new(Vec3::new(1e4, -2e4, 3e4), 1e4), 3);
        no_self_hits(&Sphere::new(Vec3::new(1e4, 0.0, 0.0), 1.0), 4);
    }
}
