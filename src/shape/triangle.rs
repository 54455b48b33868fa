//! Triangles, with a watertight ray/triangle test (after Woop, Benthin and Wald,
//! "Watertight Ray/Triangle Intersection", JCGT 2013): the ray is turned into the
//! +z axis by a permutation and a shear computed once per ray, and the 2D edge
//! functions are evaluated so that a ray through a shared edge or vertex hits at
//! least one of the triangles sharing it. Exactly-zero edge functions are redone
//! in f64. Degenerate triangles give det = 0 and miss, with no NaN.

use crate::geometry::{Aabb, Hit, Ray};
use glam::Vec3;

/// A single triangle; its geometric normal is `normalize((v1 - v0) x (v2 - v0))`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    /// First vertex.
    pub v0: Vec3,
    /// Second vertex.
    pub v1: Vec3,
    /// Third vertex.
    pub v2: Vec3,
}

/// Per-ray data of the watertight test: the axis permutation and the shear.
#[derive(Clone, Copy, Debug)]
pub struct TriRay {
    pub(super) origin: Vec3,
    pub(super) kx: usize,
    pub(super) ky: usize,
    pub(super) kz: usize,
    pub(super) sx: f32,
    pub(super) sy: f32,
    pub(super) sz: f32,
}

impl TriRay {
    /// Precomputes the permutation (the dominant direction axis becomes z, winding kept)
    /// and the shear that maps the ray direction to +z.
    ///
    /// Written without branches: the axes follow the ray's direction, which for incoherent
    /// rays no predictor learns (the nested `if`s this replaces cost about 1.1
    /// mispredictions a ray in callgrind's model). Ties and NaN pick as the nested form
    /// did: `kz` is x if `|d.x| > |d.y|` and `|d.x| > |d.z|`, else y if `|d.y| > |d.z|`
    /// (and not the x case), else z.
    #[inline]
    pub fn new(ray: &Ray) -> TriRay {
        let a = ray.dir.abs();
        let x_over_y = a.x > a.y;
        let (m, i) = if x_over_y { (a.x, 0) } else { (a.y, 1) };
        // i if m > |d.z| (false for NaN), else 2.
        let kz = 2 - (m > a.z) as usize * (2 - i);
        let d = ray.dir.to_array();
        let dz = d[kz];
        // (kz + 1) % 3 and (kz + 2) % 3, swapped when dz < 0 (the winding is kept).
        let (k1, k2) = ([1, 2, 0][kz], [2, 0, 1][kz]);
        let swap = 0usize.wrapping_sub((dz < 0.0) as usize) & (k1 ^ k2);
        let (kx, ky) = (k1 ^ swap, k2 ^ swap);
        TriRay { origin: ray.origin, kx, ky, kz, sx: d[kx] / dz, sy: d[ky] / dz, sz: 1.0 / dz }
    }

    /// Watertight test against triangle `(p0, p1, p2)`: `Some((t, b0, b1, b2))` for a hit
    /// with `0 < t < t_max`, where `b` are the barycentric weights of the three vertices.
    #[inline(always)]
    pub fn intersect(&self, p0: Vec3, p1: Vec3, p2: Vec3, t_max: f32) -> Option<(f32, f32, f32, f32)> {
        let a = p0 - self.origin;
        let b = p1 - self.origin;
        let c = p2 - self.origin;
        let (kx, ky, kz) = (self.kx, self.ky, self.kz);
        let (az, bz, cz) = (a[kz], b[kz], c[kz]);
        let ax = a[kx] - self.sx * az;
        let ay = a[ky] - self.sy * az;
        let bx = b[kx] - self.sx * bz;
        let by = b[ky] - self.sy * bz;
        let cx = c[kx] - self.sx * cz;
        let cy = c[ky] - self.sy * cz;
        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        if u == 0.0 || v == 0.0 || w == 0.0 {
            let (ax, ay, bx, by, cx, cy) = (ax as f64, ay as f64, bx as f64, by as f64, cx as f64, cy as f64);
            u = (cx * by - cy * bx) as f32;
            v = (ax * cy - ay * cx) as f32;
            w = (bx * ay - by * ax) as f32;
        }
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 {
            return None;
        }
        let tt = (u * az + v * bz + w * cz) * self.sz;
        // t = tt / det must lie in (0, t_max): compare without dividing.
        if det < 0.0 {
            if tt >= 0.0 || tt <= t_max * det {
                return None;
            }
        } else if tt <= 0.0 || tt >= t_max * det {
            return None;
        }
        let inv = 1.0 / det;
        let t = tt * inv;
        if !(t > 0.0 && t < t_max) {
            return None;
        }
        Some((t, u * inv, v * inv, w * inv))
    }
}

impl Triangle {
    /// A triangle from its three vertices (counter-clockwise is the front).
    pub fn new(v0: Vec3, v1: Vec3, v2: Vec3) -> Triangle {
        Triangle { v0, v1, v2 }
    }

    /// Unit geometric normal (zero for a degenerate triangle).
    #[inline]
    pub fn normal(&self) -> Vec3 {
        (self.v1 - self.v0).cross(self.v2 - self.v0).normalize_or_zero()
    }

    /// Area.
    pub fn area(&self) -> f32 {
        0.5 * (self.v1 - self.v0).cross(self.v2 - self.v0).length()
    }

    /// Closest hit with `0 < t < t_max`; the point is the barycentric combination of the vertices.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        let (t, b0, b1, b2) = TriRay::new(ray).intersect(self.v0, self.v1, self.v2, t_max)?;
        let p = self.v0 * b0 + self.v1 * b1 + self.v2 * b2;
        Some(Hit::flat(t, p, self.normal()))
    }

    /// True if the ray hits the triangle with `0 < t < t_max`.
    #[inline]
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        TriRay::new(ray).intersect(self.v0, self.v1, self.v2, t_max).is_some()
    }

    /// Bounding box.
    pub fn bounds(&self) -> Aabb {
        Aabb::new(self.v0, self.v1).grow(self.v2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::sphere::tests::{random_dir, uniform};
    use rand_pcg::Pcg32;

    /// The branch-free axis choice of `TriRay::new` against the nested `if`s of Woop et
    /// al.'s paper (which it replaced), on ties, zeros, signed zeros, infinities and NaN.
    #[test]
    fn permutation_matches_the_nested_form() {
        fn nested(d: Vec3) -> (usize, usize, usize) {
            let a = d.abs();
            let kz = if a.x > a.y {
                if a.x > a.z { 0 } else { 2 }
            } else if a.y > a.z {
                1
            } else {
                2
            };
            let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
            if d[kz] < 0.0 {
                std::mem::swap(&mut kx, &mut ky);
            }
            (kx, ky, kz)
        }
        let vals = [0.0, -0.0, 0.5, -0.5, 1.0, -1.0, 2.0, f32::INFINITY, f32::NEG_INFINITY, f32::NAN];
        let mut seen = std::collections::HashSet::new();
        for &x in &vals {
            for &y in &vals {
                for &z in &vals {
                    let d = Vec3::new(x, y, z);
                    let r = TriRay::new(&Ray { origin: Vec3::ZERO, dir: d });
                    let want = nested(d);
                    assert_eq!((r.kx, r.ky, r.kz), want, "direction {d}");
                    seen.insert(want);
                    let da = d.to_array();
                    let dz = da[want.2];
                    assert_eq!(
                        [r.sx, r.sy, r.sz].map(f32::to_bits),
                        [da[want.0] / dz, da[want.1] / dz, 1.0 / dz].map(f32::to_bits),
                        "direction {d}"
                    );
                }
            }
        }
        // Every axis as z, with both windings.
        assert_eq!(seen.len(), 6, "{seen:?}");
    }

    #[test]
    fn closed_form_hit_and_normal() {
        let tri = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y);
        assert_eq!(tri.normal(), Vec3::Z);
        let h = tri.intersect(&Ray::new(Vec3::new(0.25, 0.25, 2.0), -Vec3::Z), f32::INFINITY).unwrap();
        assert!((h.t - 2.0).abs() < 1e-6 && h.n == Vec3::Z);
        assert!((h.p - Vec3::new(0.25, 0.25, 0.0)).length() < 1e-7);
        // From behind: same normal.
        assert!(tri.intersect(&Ray::new(Vec3::new(0.25, 0.25, -2.0), Vec3::Z), f32::INFINITY).is_some());
        assert!(tri.intersect(&Ray::new(Vec3::new(0.6, 0.6, 2.0), -Vec3::Z), f32::INFINITY).is_none());
        assert!(!tri.occluded(&Ray::new(Vec3::new(0.25, 0.25, 2.0), -Vec3::Z), 1.5));
        // Parallel ray in the plane and a degenerate triangle: no hit, no NaN.
        assert!(tri.intersect(&Ray::new(Vec3::new(-1.0, 0.25, 0.0), Vec3::X), f32::INFINITY).is_none());
        let deg = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::X * 2.0);
        assert!(deg.intersect(&Ray::new(Vec3::new(0.5, 0.0, 1.0), -Vec3::Z), f32::INFINITY).is_none());
    }

    #[test]
    fn shared_edges_are_watertight() {
        // A planar fan of triangles around a centre vertex (in a tilted plane); rays aimed
        // at the shared edges and the centre vertex must hit at least one of them.
        let mut rng = Pcg32::new(21, 5);
        let c = Vec3::new(0.1, 0.2, 0.3);
        let ring: Vec<Vec3> = (0..7)
            .map(|i| {
                let a = i as f32 / 7.0 * std::f32::consts::TAU;
                c + Vec3::new(a.cos(), a.sin(), 0.3 * a.cos() - 0.2 * a.sin())
            })
            .collect();
        let tris: Vec<Triangle> = (0..7).map(|i| Triangle::new(c, ring[i], ring[(i + 1) % 7])).collect();
        for _ in 0..20_000 {
            let i = (uniform(&mut rng) * 7.0) as usize % 7;
            let s = uniform(&mut rng);
            let target = if uniform(&mut rng) < 0.1 { c } else { c + (ring[i] - c) * s };
            let mut o = target + random_dir(&mut rng) * 3.0;
            if (o - target).z.abs() < 0.1 {
                o.z += 1.0;
            }
            let r = Ray::new(o, (target - o).normalize());
            assert!(tris.iter().any(|t| t.occluded(&r, f32::INFINITY)), "leak at {target:?} from {o:?}");
        }
    }

    #[test]
    fn spawned_rays_do_not_rehit() {
        let mut rng = Pcg32::new(9, 9);
        for scale in [1e-4f32, 1.0, 1e4] {
            let tri = Triangle::new(
                Vec3::new(-1.0, 0.0, -1.0) * scale,
                Vec3::new(1.0, 0.3, -1.0) * scale,
                Vec3::new(0.0, -0.2, 1.0) * scale,
            );
            for _ in 0..5000 {
                let (a, b) = (uniform(&mut rng), uniform(&mut rng));
                let (a, b) = if a + b > 1.0 { (1.0 - a, 1.0 - b) } else { (a, b) };
                let target = tri.v0 + (tri.v1 - tri.v0) * a + (tri.v2 - tri.v0) * b;
                let o = target + random_dir(&mut rng) * scale;
                let Some(h) = tri.intersect(&Ray::new(o, (target - o).normalize()), f32::INFINITY) else {
                    continue;
                };
                assert!(!tri.occluded(&Ray::spawn(h.p, h.n, random_dir(&mut rng)), f32::INFINITY));
            }
        }
    }
}
