//! Four triangles in one block, coordinates stored lane by lane (`[vertex][axis][lane]`),
//! and the watertight test of [`TriRay`] run on the four lanes at once. Each of the
//! test's quantities is one glam `Vec4` (an SSE register): one coordinate of one vertex
//! of all four triangles is one load, and every operation is one packed instruction.
//! Written as loops over fixed `[f32; 4]` arrays, the same test compiled to scalar loads
//! and shuffles, about 370 instructions a block; this form takes about 330 fewer
//! (docs/performance.md, round 4). The arithmetic is exactly the single-triangle test's,
//! operation by operation (no fused multiply-add), so a lane returns the same `t` bit for
//! bit (tested), and images do not change.
//!
//! A block holds one to four triangles; unused lanes repeat lane 0, so they can only
//! report lane 0's hit again, at the same `t` (closest-hit keeps the first lane on ties).

// The f64 redo of exactly-zero edge functions indexes several arrays by lane.
#![allow(clippy::needless_range_loop)]

use crate::shape::triangle::TriRay;
use glam::{Vec3, Vec4};

/// Four triangles, lane by lane: `p[vertex][axis][lane]` (144 bytes).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(16))]
pub(super) struct Tri4 {
    p: [[[f32; 4]; 3]; 3],
}

impl Tri4 {
    /// A block of one to four triangles; missing lanes repeat the first triangle.
    pub(super) fn new(tris: &[[Vec3; 3]]) -> Tri4 {
        debug_assert!((1..=4).contains(&tris.len()));
        let mut p = [[[0.0f32; 4]; 3]; 3];
        for lane in 0..4 {
            let tri = tris.get(lane).unwrap_or(&tris[0]);
            for (v, vertex) in tri.iter().enumerate() {
                for a in 0..3 {
                    p[v][a][lane] = vertex[a];
                }
            }
        }
        Tri4 { p }
    }

    /// The vertices of the triangle in `lane`.
    #[inline]
    pub(super) fn triangle(&self, lane: usize) -> [Vec3; 3] {
        let p = &self.p;
        [0, 1, 2].map(|v| Vec3::new(p[v][0][lane], p[v][1][lane], p[v][2][lane]))
    }

    /// The watertight test of [`TriRay::intersect`] on the four lanes: each lane's `t` if
    /// that triangle is hit with `0 < t < t_max`, else infinity. Written with `Vec4` (one
    /// SSE register per quantity): each operation is the single test's, in its order, so
    /// every lane rounds exactly as [`TriRay::intersect`] does.
    #[inline(always)]
    pub(super) fn hit_t(&self, r: &TriRay, t_max: f32) -> [f32; 4] {
        self.hit(r, t_max).0
    }

    /// [`Tri4::hit_t`], and each lane's edge functions `[u, v, w]` (the barycentric
    /// weights before they are divided by their sum `u + v + w`), exactly as
    /// [`TriRay::intersect`] computes them: the closest hit's weights need no second test.
    #[inline(always)]
    pub(super) fn hit(&self, r: &TriRay, t_max: f32) -> ([f32; 4], [Vec4; 3]) {
        let (kx, ky, kz) = (r.kx, r.ky, r.kz);
        let o = r.origin.to_array();
        let (ox, oy, oz) = (Vec4::splat(o[kx]), Vec4::splat(o[ky]), Vec4::splat(o[kz]));
        let (sx, sy) = (Vec4::splat(r.sx), Vec4::splat(r.sy));
        let [p0, p1, p2] = &self.p;
        let az = Vec4::from_array(p0[kz]) - oz;
        let bz = Vec4::from_array(p1[kz]) - oz;
        let cz = Vec4::from_array(p2[kz]) - oz;
        let ax = (Vec4::from_array(p0[kx]) - ox) - sx * az;
        let ay = (Vec4::from_array(p0[ky]) - oy) - sy * az;
        let bx = (Vec4::from_array(p1[kx]) - ox) - sx * bz;
        let by = (Vec4::from_array(p1[ky]) - oy) - sy * bz;
        let cx = (Vec4::from_array(p2[kx]) - ox) - sx * cz;
        let cy = (Vec4::from_array(p2[ky]) - oy) - sy * cz;
        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        // Exactly-zero edge functions are redone in f64 (rare: a ray through an edge).
        let zero = u.cmpeq(Vec4::ZERO) | v.cmpeq(Vec4::ZERO) | w.cmpeq(Vec4::ZERO);
        if zero.any() {
            let (mut ua, mut va, mut wa) = (u.to_array(), v.to_array(), w.to_array());
            let e = [ax, ay, bx, by, cx, cy].map(|x| x.to_array());
            for l in 0..4 {
                if ua[l] == 0.0 || va[l] == 0.0 || wa[l] == 0.0 {
                    let [ax, ay, bx, by, cx, cy] = e.map(|x| x[l] as f64);
                    ua[l] = (cx * by - cy * bx) as f32;
                    va[l] = (ax * cy - ay * cx) as f32;
                    wa[l] = (bx * ay - by * ax) as f32;
                }
            }
            (u, v, w) = (Vec4::from_array(ua), Vec4::from_array(va), Vec4::from_array(wa));
        }
        let z = Vec4::ZERO;
        let outside = (u.cmplt(z) | v.cmplt(z) | w.cmplt(z)) & (u.cmpgt(z) | v.cmpgt(z) | w.cmpgt(z));
        let det = u + v + w;
        let tt = (u * az + v * bz + w * cz) * Vec4::splat(r.sz);
        let lim = Vec4::splat(t_max) * det;
        // The same rejections as the single test; a NaN fails every comparison there and
        // here alike.
        let range_neg = !(tt.cmpge(z) | tt.cmple(lim));
        let range_pos = !(tt.cmple(z) | tt.cmpge(lim));
        let neg = det.cmplt(z);
        let range = (neg & range_neg) | (!neg & range_pos);
        let t = tt * (Vec4::ONE / det);
        let hit = !outside & det.cmpne(z) & range & t.cmpgt(z) & t.cmplt(Vec4::splat(t_max));
        (Vec4::select(hit, t, Vec4::INFINITY).to_array(), [u, v, w])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Ray;
    use crate::shape::sphere::tests::uniform;
    use rand_pcg::Pcg32;

    #[test]
    fn lanes_agree_bit_for_bit_with_the_single_test() {
        let mut rng = Pcg32::new(44, 3);
        let mut v = || Vec3::new(uniform(&mut rng), uniform(&mut rng), uniform(&mut rng)) * 2.0 - 1.0;
        let mut hits = 0;
        for i in 0..20_000 {
            let mut tris: Vec<[Vec3; 3]> = (0..4).map(|_| [v(), v(), v()]).collect();
            // Shared edges and vertices, a degenerate triangle and a huge one.
            tris[1][0] = tris[0][1];
            tris[1][1] = tris[0][2];
            if i % 5 == 0 {
                tris[2] = [tris[2][0], tris[2][0] * 2.0, tris[2][0] * 3.0];
            }
            if i % 7 == 0 {
                tris[3] = tris[3].map(|p| p * 1e30);
            }
            let n = 1 + i % 4;
            let block = Tri4::new(&tris[..n]);
            let o = v() * 3.0;
            let target = if i % 3 == 0 { (tris[0][1] + tris[0][2]) * 0.5 } else { v() * 0.5 };
            let mut d = (target - o).normalize();
            if i % 11 == 0 {
                d = [Vec3::X, -Vec3::Z, Vec3::new(0.0, -0.0, 1.0)][i % 3];
            }
            let ray = Ray::new(o, d);
            let tr = TriRay::new(&ray);
            let t_max = if i % 2 == 0 { f32::INFINITY } else { uniform(&mut Pcg32::new(i as u64, 0)) * 4.0 };
            let got = block.hit_t(&tr, t_max);
            for l in 0..4 {
                let tri = tris[if l < n { l } else { 0 }];
                let want = tr.intersect(tri[0], tri[1], tri[2], t_max).map_or(f32::INFINITY, |h| h.0);
                assert_eq!(got[l].to_bits(), want.to_bits(), "case {i} lane {l}");
                hits += (want < f32::INFINITY) as u32;
                assert_eq!(block.triangle(l), tri);
            }
        }
        assert!(hits > 5000, "{hits}");
        // NaN rays miss in every lane, without panicking.
        let block = Tri4::new(&[[Vec3::ZERO, Vec3::X, Vec3::Y]]);
        let nan = Ray { origin: Vec3::new(0.2, 0.2, f32::NAN), dir: Vec3::new(0.0, 0.0, -1.0) };
        assert_eq!(block.hit_t(&TriRay::new(&nan), f32::INFINITY), [f32::INFINITY; 4]);
        let nan = Ray { origin: Vec3::new(0.2, 0.2, 1.0), dir: Vec3::new(f32::NAN, 0.0, -1.0) };
        assert_eq!(block.hit_t(&TriRay::new(&nan), f32::INFINITY), [f32::INFINITY; 4]);
    }
}
