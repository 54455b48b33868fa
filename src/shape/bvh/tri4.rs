//! Four triangles in one block, coordinates stored lane by lane (`[vertex][axis][lane]`),
//! and the watertight test of [`TriRay`] run on the four lanes at once. The lanes are
//! fixed arrays of four `f32` that the compiler turns into SSE instructions; the
//! arithmetic is exactly the single-triangle test's, operation by operation, so a lane
//! returns the same `t` bit for bit (tested), and images do not change.
//!
//! A block holds one to four triangles; unused lanes repeat lane 0, so they can only
//! report lane 0's hit again, at the same `t` (closest-hit keeps the first lane on ties).

// `!(x > 0.0)` is used on purpose: it is also true for NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
// Lane loops `for l in 0..4` index several arrays by lane on purpose: that is the form the
// compiler vectorises.
#![allow(clippy::needless_range_loop)]

use crate::shape::triangle::TriRay;
use glam::Vec3;

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
    /// that triangle is hit with `0 < t < t_max`, else infinity.
    #[inline(always)]
    pub(super) fn hit_t(&self, r: &TriRay, t_max: f32) -> [f32; 4] {
        let (kx, ky, kz) = (r.kx, r.ky, r.kz);
        let (ox, oy, oz) = (r.origin[kx], r.origin[ky], r.origin[kz]);
        let [p0, p1, p2] = &self.p;
        let mut e = [[0.0f32; 4]; 6]; // ax, ay, bx, by, cx, cy
        let (mut az, mut bz, mut cz) = ([0.0f32; 4], [0.0f32; 4], [0.0f32; 4]);
        let (mut u, mut v, mut w) = ([0.0f32; 4], [0.0f32; 4], [0.0f32; 4]);
        for l in 0..4 {
            az[l] = p0[kz][l] - oz;
            bz[l] = p1[kz][l] - oz;
            cz[l] = p2[kz][l] - oz;
            let ax = (p0[kx][l] - ox) - r.sx * az[l];
            let ay = (p0[ky][l] - oy) - r.sy * az[l];
            let bx = (p1[kx][l] - ox) - r.sx * bz[l];
            let by = (p1[ky][l] - oy) - r.sy * bz[l];
            let cx = (p2[kx][l] - ox) - r.sx * cz[l];
            let cy = (p2[ky][l] - oy) - r.sy * cz[l];
            u[l] = cx * by - cy * bx;
            v[l] = ax * cy - ay * cx;
            w[l] = bx * ay - by * ax;
            e[0][l] = ax;
            e[1][l] = ay;
            e[2][l] = bx;
            e[3][l] = by;
            e[4][l] = cx;
            e[5][l] = cy;
        }
        // Exactly-zero edge functions are redone in f64 (rare: a ray through an edge).
        let mut zero = false;
        for l in 0..4 {
            zero |= (u[l] == 0.0) | (v[l] == 0.0) | (w[l] == 0.0);
        }
        if zero {
            for l in 0..4 {
                if u[l] == 0.0 || v[l] == 0.0 || w[l] == 0.0 {
                    let [ax, ay, bx, by, cx, cy] = e.map(|x| x[l] as f64);
                    u[l] = (cx * by - cy * bx) as f32;
                    v[l] = (ax * cy - ay * cx) as f32;
                    w[l] = (bx * ay - by * ax) as f32;
                }
            }
        }
        let mut out = [f32::INFINITY; 4];
        for l in 0..4 {
            let (u, v, w) = (u[l], v[l], w[l]);
            let outside = (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0);
            let det = u + v + w;
            let tt = (u * az[l] + v * bz[l] + w * cz[l]) * r.sz;
            let lim = t_max * det;
            // The same rejections as the single test, in the same order of operations.
            let range = if det < 0.0 { !(tt >= 0.0 || tt <= lim) } else { !(tt <= 0.0 || tt >= lim) };
            let t = tt * (1.0 / det);
            let hit = !outside & (det != 0.0) & range & (t > 0.0) & (t < t_max);
            out[l] = if hit { t } else { f32::INFINITY };
        }
        out
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
