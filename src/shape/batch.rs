//! The objects of a small scene, four at a time: quads and spheres packed
//! lane-wise into `Vec4`s, so that one pass of SSE arithmetic tests a ray
//! against four of them.
//!
//! A scene with a handful of objects (the Cornell box: five quads, two
//! spheres) has no BVH; before this, a ray ran the scalar test of every
//! object in turn, behind a match on its shape: about 30% of a Cornell-box
//! render. [`Batch`] is used when every bounded object is a quad or a sphere
//! and there are few of them ([`Batch::MAX_OBJECTS`]).
//!
//! # Same answers as the scalar tests
//! Each lane repeats its scalar test's arithmetic ([`super::quad::Quad`]'s
//! plane and coordinate test, [`super::sphere::sphere_roots`] and
//! `first_root`) operation for operation, in the same order (Rust never
//! fuses a multiply and an add by itself, and SSE's `sqrt`, division and
//! `copysign` round exactly as the scalar ones), so every lane's `t` and its
//! hit-or-miss verdict are bit-for-bit the scalar test's. The scalar loop
//! keeps the first object (in scene order) among those at the smallest `t`;
//! [`Batch::closest`] breaks ties the same way, and the caller then runs the
//! winner's own scalar test once for its hit record. Images are identical.
//!
//! Padding lanes never hit: a quad with a zero normal (the scalar test's
//! `denom == 0`), a sphere of radius NaN.

use super::{Quad, Shape, Sphere};
use crate::geometry::Ray;
use glam::{BVec4A, Vec3, Vec4};

/// Four quads, lane-wise: the plane (`n`, `d`), the corner and the
/// coordinate projections `pu`, `pv` (see [`Quad`]).
#[derive(Clone, Debug)]
struct Quads4 {
    n: [Vec4; 3],
    d: Vec4,
    origin: [Vec4; 3],
    pu: [Vec4; 3],
    pv: [Vec4; 3],
}

/// Four spheres, lane-wise.
#[derive(Clone, Debug)]
struct Spheres4 {
    center: [Vec4; 3],
    radius: Vec4,
}

/// A ray's origin and direction, each coordinate in all four lanes.
struct Splat {
    o: [Vec4; 3],
    d: [Vec4; 3],
}

/// Lane-wise `a · b` in [`Vec3::dot`]'s order, `(x x') + (y y') + (z z')`.
#[inline(always)]
fn dot(a: &[Vec4; 3], b: &[Vec4; 3]) -> Vec4 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

impl Quads4 {
    /// Each lane's `t` in `(0, t_max)` where it is hit, and the mask of hits.
    #[inline(always)]
    fn hit(&self, r: &Splat, t_max: Vec4) -> (Vec4, BVec4A) {
        // plane_t
        let denom = dot(&self.n, &r.d);
        let t = (self.d - dot(&self.n, &r.o)) / denom;
        let mut mask = denom.cmpne(Vec4::ZERO) & t.cmpgt(Vec4::ZERO) & t.cmplt(t_max);
        // q = ray.at(t) - origin; its quad coordinates.
        let q = [0, 1, 2].map(|k| (r.o[k] + r.d[k] * t) - self.origin[k]);
        let (a, b) = (dot(&q, &self.pu), dot(&q, &self.pv));
        mask &= a.cmpge(Vec4::ZERO) & a.cmple(Vec4::ONE) & b.cmpge(Vec4::ZERO) & b.cmple(Vec4::ONE);
        (t, mask)
    }
}

impl Spheres4 {
    /// Each lane's first root in `(0, t_max)` where it is hit, and the mask of hits.
    #[inline(always)]
    fn hit(&self, r: &Splat, t_max: Vec4) -> (Vec4, BVec4A) {
        // sphere_roots
        let f = [0, 1, 2].map(|k| r.o[k] - self.center[k]);
        let a = dot(&r.d, &r.d);
        let b = Vec4::splat(2.0) * dot(&r.d, &f);
        let rad = self.radius;
        let cc = dot(&f, &f) - rad * rad;
        let s = b / (Vec4::splat(2.0) * a);
        let l = [0, 1, 2].map(|k| f[k] - r.d[k] * s);
        let ll = dot(&l, &l).sqrt();
        let disc = Vec4::splat(4.0) * a * (rad + ll) * (rad - ll);
        let mut mask = disc.cmpge(Vec4::ZERO);
        let root = disc.sqrt();
        let q = Vec4::splat(-0.5) * (b + root.copysign(b));
        let q_zero = q.cmpeq(Vec4::ZERO);
        let t0 = Vec4::select(q_zero, Vec4::ZERO, q / a);
        let t1 = Vec4::select(q_zero, Vec4::ZERO, cc / q);
        mask &= t0.is_finite_mask() & t1.is_finite_mask();
        let (lo, hi) = (Vec4::select(t0.cmple(t1), t0, t1), Vec4::select(t0.cmple(t1), t1, t0));
        // first_root
        let lo_ok = lo.cmpgt(Vec4::ZERO) & lo.cmplt(t_max);
        let hi_ok = hi.cmpgt(Vec4::ZERO) & hi.cmplt(t_max);
        (Vec4::select(lo_ok, lo, hi), mask & (lo_ok | hi_ok))
    }
}

/// Quads and spheres in lanes of four, with the caller's id of each lane.
#[derive(Clone, Debug, Default)]
pub struct Batch {
    quads: Vec<Quads4>,
    quad_ids: Vec<u32>,
    spheres: Vec<Spheres4>,
    sphere_ids: Vec<u32>,
}

impl Batch {
    /// Up to this many objects are tested in lanes instead of through a BVH
    /// (a scene of this size gains nothing from a tree: nine objects, the
    /// glass-spheres box, are three lane tests, 13% faster than its BVH; the
    /// 15 of `scenes/spheres.ron` are five, 15% faster).
    pub const MAX_OBJECTS: usize = 16;

    /// Packs `shapes` (each with its id), or None when one of them is not a quad
    /// or a sphere, or there are more than [`Batch::MAX_OBJECTS`].
    pub fn new<'a>(shapes: impl IntoIterator<Item = (u32, &'a Shape)>) -> Option<Batch> {
        let mut quads: Vec<(u32, Quad)> = Vec::new();
        let mut spheres: Vec<(u32, Sphere)> = Vec::new();
        for (id, shape) in shapes {
            match shape {
                Shape::Quad(q) => quads.push((id, *q)),
                Shape::Sphere(s) => spheres.push((id, *s)),
                _ => return None,
            }
        }
        if quads.len() + spheres.len() > Batch::MAX_OBJECTS {
            return None;
        }
        let lanes = |f: &dyn Fn(usize) -> f32| Vec4::new(f(0), f(1), f(2), f(3));
        let mut batch = Batch::default();
        for chunk in quads.chunks(4) {
            // Padding: a zero quad (zero normal: never hit).
            let pad = Quad::new(Vec3::ZERO, Vec3::ZERO, Vec3::ZERO);
            let q = |i: usize| chunk.get(i).map_or(pad, |c| c.1);
            let v = |get: &dyn Fn(&Quad) -> Vec3| [0, 1, 2].map(|k| lanes(&|i| get(&q(i))[k]));
            batch.quads.push(Quads4 {
                n: v(&|q| q.normal()),
                d: lanes(&|i| q(i).plane_offset()),
                origin: v(&|q| q.origin),
                pu: v(&|q| q.projections().0),
                pv: v(&|q| q.projections().1),
            });
            batch.quad_ids.extend((0..4).map(|i| chunk.get(i).map_or(u32::MAX, |c| c.0)));
        }
        for chunk in spheres.chunks(4) {
            let s = |i: usize| chunk.get(i).map_or(Sphere::new(Vec3::ZERO, f32::NAN), |c| c.1);
            batch.spheres.push(Spheres4 {
                center: [0, 1, 2].map(|k| lanes(&|i| s(i).center[k])),
                radius: lanes(&|i| s(i).radius),
            });
            batch.sphere_ids.extend((0..4).map(|i| chunk.get(i).map_or(u32::MAX, |c| c.0)));
        }
        Some(batch)
    }

    #[inline(always)]
    fn splat(ray: &Ray) -> Splat {
        Splat { o: [0, 1, 2].map(|k| Vec4::splat(ray.origin[k])), d: [0, 1, 2].map(|k| Vec4::splat(ray.dir[k])) }
    }

    /// The id and `t` of the closest object hit with `0 < t < t_max`; among
    /// objects at the same `t`, the smallest id (the scalar loop's first).
    #[inline]
    pub fn closest(&self, ray: &Ray, t_max: f32) -> Option<(u32, f32)> {
        let r = Batch::splat(ray);
        let limit = Vec4::splat(t_max);
        let mut best: Option<(u32, f32)> = None;
        let mut take = |t: Vec4, mask: BVec4A, ids: &[u32]| {
            let mut bits = mask.bitmask();
            while bits != 0 {
                let i = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                let (id, t) = (ids[i], t[i]);
                if best.is_none_or(|(bid, bt)| t < bt || (t == bt && id < bid)) {
                    best = Some((id, t));
                }
            }
        };
        for (q, ids) in self.quads.iter().zip(self.quad_ids.chunks_exact(4)) {
            let (t, mask) = q.hit(&r, limit);
            take(t, mask, ids);
        }
        for (s, ids) in self.spheres.iter().zip(self.sphere_ids.chunks_exact(4)) {
            let (t, mask) = s.hit(&r, limit);
            take(t, mask, ids);
        }
        best
    }

    /// True when some object is hit with `0 < t < t_max`.
    #[inline]
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        let r = Batch::splat(ray);
        let limit = Vec4::splat(t_max);
        self.quads.iter().any(|q| q.hit(&r, limit).1.any()) || self.spheres.iter().any(|s| s.hit(&r, limit).1.any())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::sphere::tests::{random_dir, uniform};
    use rand_pcg::Pcg32;

    /// The scalar loop the batch replaces: first object at the smallest `t`.
    fn scalar(shapes: &[Shape], ray: &Ray, t_max: f32) -> Option<(u32, f32)> {
        let mut best = None;
        let mut t_max = t_max;
        for (i, s) in shapes.iter().enumerate() {
            if let Some(hit) = s.intersect(ray, t_max) {
                t_max = hit.t;
                best = Some((i as u32, hit.t));
            }
        }
        best
    }

    /// Random quads and spheres (some degenerate, some sharing an edge or a
    /// plane, so that ties happen), random rays from inside and outside, random
    /// `t_max`: the batch's id and `t` are exactly the scalar loop's, hit for
    /// hit, `occluded` agrees with it, and the hit record rebuilt from `t` is
    /// the scalar test's. 9 objects span three lane groups and
    /// a padded one.
    #[test]
    fn same_hits_as_the_scalar_tests() {
        let mut rng = Pcg32::new(7, 11);
        let mut hits = 0;
        for scene in 0..200 {
            let mut shapes = Vec::new();
            let n = 1 + scene % 9;
            for k in 0..n {
                let p = Vec3::new(uniform(&mut rng), uniform(&mut rng), uniform(&mut rng)) * 4.0 - 2.0;
                shapes.push(match (k + scene) % 3 {
                    0 => Shape::Sphere(Sphere::new(p, 0.05 + uniform(&mut rng))),
                    1 if k % 4 == 1 => Shape::Quad(Quad::new(p, Vec3::ZERO, Vec3::X)), // degenerate
                    _ => Shape::Quad(Quad::new(p, random_dir(&mut rng) * 2.0, random_dir(&mut rng) * 2.0)),
                });
            }
            // Two quads sharing an edge, and a copy of the first shape (ties in t).
            shapes.push(Shape::Quad(Quad::new(Vec3::new(-1.0, 0.0, -1.0), Vec3::new(2.0, 0.0, 0.0), Vec3::Z * 2.0)));
            shapes.push(Shape::Quad(Quad::new(Vec3::new(-1.0, 0.0, -1.0), Vec3::new(2.0, 0.0, 0.0), Vec3::Y * 2.0)));
            shapes.push(shapes[0].clone());
            let batch = Batch::new(shapes.iter().enumerate().map(|(i, s)| (i as u32, s))).unwrap();
            for _ in 0..500 {
                let o = Vec3::new(uniform(&mut rng), uniform(&mut rng), uniform(&mut rng)) * 6.0 - 3.0;
                let mut ray = Ray::new(o, random_dir(&mut rng));
                if uniform(&mut rng) < 0.1 {
                    // Aimed at the shared edge.
                    ray = Ray::new(o, (Vec3::new(uniform(&mut rng) * 2.0 - 1.0, 0.0, -1.0) - o).normalize());
                }
                let t_max = if uniform(&mut rng) < 0.5 { f32::INFINITY } else { uniform(&mut rng) * 5.0 };
                let want = scalar(&shapes, &ray, t_max);
                let got = batch.closest(&ray, t_max);
                assert_eq!(got.map(|g| (g.0, g.1.to_bits())), want.map(|w| (w.0, w.1.to_bits())), "{ray:?} {t_max}");
                assert_eq!(batch.occluded(&ray, t_max), want.is_some());
                // The hit record built from the batch's `t` is the scalar test's, bit for bit.
                if let Some((i, t)) = got {
                    let full = shapes[i as usize].intersect(&ray, t_max).unwrap();
                    let rebuilt = match &shapes[i as usize] {
                        Shape::Quad(q) => q.hit_at(&ray, t),
                        Shape::Sphere(s) => s.hit_at(&ray, t),
                        _ => unreachable!(),
                    };
                    let bits = |h: &crate::geometry::Hit| {
                        (h.t.to_bits(), h.p.to_array().map(f32::to_bits), h.n.to_array().map(f32::to_bits))
                    };
                    assert_eq!(bits(&full), bits(&rebuilt));
                }
                hits += want.is_some() as u32;
            }
        }
        assert!(hits > 10_000, "the test should hit often (about 17,000 of 100,000): {hits}");
    }

    #[test]
    fn only_quads_and_spheres_and_few() {
        let q = Shape::Quad(Quad::new(Vec3::ZERO, Vec3::X, Vec3::Y));
        let plane = Shape::Plane(crate::shape::Plane::new(Vec3::ZERO, Vec3::Y));
        assert!(Batch::new([(0, &q), (1, &plane)]).is_none());
        let many = vec![q.clone(); Batch::MAX_OBJECTS + 1];
        assert!(Batch::new(many.iter().enumerate().map(|(i, s)| (i as u32, s))).is_none());
        assert!(Batch::new(many[1..].iter().enumerate().map(|(i, s)| (i as u32, s))).is_some());
    }
}
