//! A bounding volume hierarchy over arbitrary primitives, given only their
//! bounding boxes: binned-SAH build (parallel with rayon above a size threshold,
//! deterministic whatever the thread count), flattened depth-first into 32-byte
//! nodes (first child follows its parent, the second child's index is stored,
//! pbrt's linear layout), and ordered stack traversal for closest and any hits.
//!
//! The BVH knows nothing of the primitives themselves: traversal calls back with
//! the slot `k` of each primitive in a visited leaf. [`Bvh::prim_order`] maps slots
//! to indices in the slice the tree was built from. Scenes use it over their shapes.
//!
//! Meshes use [`WideBvh`] instead (`wide.rs`): the same build (`build.rs`), stopped at
//! subtrees of 12 triangles and collapsed into 8-wide nodes whose leaves hold the
//! triangles themselves, four to a block (`tri4.rs`), in that build's slot order.

// `!(x > 0.0)` is used on purpose: it is also true for NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use crate::geometry::{Aabb, Ray, gamma};
use glam::Vec3;

mod build;
mod hint;
mod tri4;
mod wide;

pub(crate) use wide::MAX_BLOCKS;
pub use wide::{TriangleHit, WideBvh};

use build::{Limits, build_tree};

/// Node sizes above which the bins and bounds of a node are filled in parallel.
const PARALLEL_THRESHOLD: usize = 64 * 1024;
/// Node sizes above which the two children are built in parallel (`rayon::join`):
/// small enough that every level of a large tree is parallel, large enough that a task
/// (about a millisecond) dwarfs rayon's overhead.
const JOIN_THRESHOLD: usize = 4096;
/// Traversal stack depth; the build keeps the tree shallower than this.
const STACK: usize = 64;
/// Traversal cost of [`Bvh::sah_cost`], the usual 1 so that reports stay comparable.
const REPORT_TRAVERSAL_COST: f32 = 1.0;

/// A flattened node: 32 bytes. Interior nodes have `count == 0`, their first child at
/// the next index and their second at `offset`; leaves hold slots `offset..offset+count`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub(super) struct Node {
    /// Box planes: min x, y, z then max x, y, z (indexable by the ray's direction signs).
    pub(super) b: [f32; 6],
    /// First slot (leaf) or index of the second child (interior).
    pub(super) offset: u32,
    /// Number of slots of a leaf; 0 for an interior node.
    pub(super) count: u16,
    /// Split axis of an interior node.
    pub(super) axis: u8,
    _pad: u8,
}

impl Node {
    #[inline]
    pub(super) fn new(bounds: Aabb, offset: u32, count: u16) -> Node {
        let (lo, hi) = (bounds.min, bounds.max);
        Node { b: [lo.x, lo.y, lo.z, hi.x, hi.y, hi.z], offset, count, axis: 0, _pad: 0 }
    }

    #[inline]
    pub(super) fn aabb(&self) -> Aabb {
        Aabb { min: Vec3::new(self.b[0], self.b[1], self.b[2]), max: Vec3::new(self.b[3], self.b[4], self.b[5]) }
    }
}

/// A bounding volume hierarchy over primitive bounding boxes.
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    nodes: Vec<Node>,
    order: Vec<u32>,
}

/// Per-ray data for the slab test.
struct RayBox {
    o: Vec3,
    inv: Vec3,
    neg: [bool; 3],
}

/// Factor applied to the far slab distances so that rounding never makes a ray miss a
/// box that it grazes or a primitive lying exactly on a box face (pbrt's 1 + 2 gamma(3)).
pub(super) const ROBUST: f32 = 1.0 + 2.0 * gamma(3);

impl RayBox {
    #[inline(always)]
    fn new(ray: &Ray) -> RayBox {
        // 1/0 = +inf and 1/-0 = -inf: the slab of a zero direction component is then
        // (-inf, inf) or empty, except when the origin lies exactly on a slab plane where
        // 0 * inf = NaN, which the comparisons below ignore (the ray counts as inside).
        let inv = Vec3::ONE / ray.dir;
        RayBox { o: ray.origin, inv, neg: [inv.x < 0.0, inv.y < 0.0, inv.z < 0.0] }
    }

    /// Entry and exit distances of the ray in the node's box, clipped to `[0, t_max]`;
    /// the ray hits the box if entry <= exit. The near and far planes of each axis are
    /// picked by index from the direction's signs (`3 * neg + axis` is at most 5, so
    /// the indexing has no bounds check and no branch).
    #[inline(always)]
    fn slab(&self, n: &Node, t_max: f32) -> (f32, f32) {
        let mut t0 = 0.0f32;
        let mut t1 = t_max;
        for a in 0..3 {
            let neg = self.neg[a] as usize;
            let near = n.b[3 * neg + a];
            let far = n.b[3 - 3 * neg + a];
            let ta = (near - self.o[a]) * self.inv[a];
            let tb = (far - self.o[a]) * self.inv[a] * ROBUST;
            // Written so that a NaN slab value leaves t0/t1 unchanged.
            t0 = if ta > t0 { ta } else { t0 };
            t1 = if tb < t1 { tb } else { t1 };
        }
        (t0, t1)
    }

    /// True if the ray enters the node's box with `t < t_max` (and exits at `t >= 0`).
    #[inline(always)]
    fn hits(&self, n: &Node, t_max: f32) -> bool {
        let (t0, t1) = self.slab(n, t_max);
        t0 <= t1
    }

    /// Entry distance into the node's box if the ray hits it before `t_max`, else infinity.
    #[inline(always)]
    fn entry(&self, n: &Node, t_max: f32) -> f32 {
        let (t0, t1) = self.slab(n, t_max);
        if t0 <= t1 { t0 } else { f32::INFINITY }
    }
}

impl Bvh {
    /// Builds over primitive bounding boxes (binned SAH with 16 bins per axis on the
    /// centroid bounds, all three axes tried; leaves of at most 8 primitives when the
    /// SAH prefers them; children built in parallel with `rayon::join` above 4k
    /// primitives, bins filled in parallel above 64k). Deterministic: the same tree
    /// whatever the thread count.
    pub fn build(prim_bounds: &[Aabb]) -> Bvh {
        Self::build_with(prim_bounds, PARALLEL_THRESHOLD, JOIN_THRESHOLD)
    }

    /// With both thresholds equal (tests: small to be parallel everywhere, `usize::MAX`
    /// for a serial build).
    #[cfg(test)]
    fn build_with_threshold(prim_bounds: &[Aabb], threshold: usize) -> Bvh {
        Self::build_with(prim_bounds, threshold, threshold)
    }

    fn build_with(prim_bounds: &[Aabb], threshold: usize, join: usize) -> Bvh {
        let (nodes, order) = build_tree(
            prim_bounds.len(),
            |i| prim_bounds[i],
            Limits { threshold, join, max_depth: STACK as u32, leaf: 1 },
        );
        Bvh { nodes, order }
    }

    /// Primitive order of the leaves: leaf ranges index into this; `prim_order()[k]` is an
    /// index into the original slice. Meshes use it to reorder their triangles so that
    /// leaves are contiguous.
    pub fn prim_order(&self) -> &[u32] {
        &self.order
    }

    /// Bounds of everything (empty for an empty tree).
    pub fn bounds(&self) -> Aabb {
        self.nodes.first().map_or(Aabb::EMPTY, |n| n.aabb())
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Bytes used by the nodes and the primitive order.
    pub fn memory_bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<Node>() + self.order.len() * 4
    }

    /// SAH cost of the tree (traversal cost 1, intersection cost 1 per primitive,
    /// areas normalised by the root's), for reports.
    pub fn sah_cost(&self) -> f32 {
        let Some(root) = self.nodes.first() else {
            return 0.0;
        };
        let area = |n: &Node| n.aabb().surface_area() as f64;
        let root_area = area(root);
        if !(root_area > 0.0) {
            return 0.0;
        }
        let cost: f64 = self
            .nodes
            .iter()
            .map(|n| if n.count == 0 { area(n) * REPORT_TRAVERSAL_COST as f64 } else { area(n) * n.count as f64 })
            .sum();
        (cost / root_area) as f32
    }

    /// Closest-hit traversal: visits leaves front to back (both children's boxes are
    /// tested and the nearer entered first; the farther is skipped once a hit lies in
    /// front of it), calls `hit(k, t_max)` for each primitive slot `k` in a
    /// visited leaf (`k` indexes [`Bvh::prim_order`], i.e. the reordered position),
    /// which returns `Some((t, payload))` on a hit closer than `t_max`; shrinks `t_max`;
    /// returns the closest payload.
    #[inline]
    pub fn intersect<H>(&self, ray: &Ray, t_max: f32, mut hit: impl FnMut(u32, f32) -> Option<(f32, H)>) -> Option<H> {
        if self.nodes.is_empty() {
            return None;
        }
        let rb = RayBox::new(ray);
        let mut t_max = t_max;
        let mut best = None;
        if !rb.hits(&self.nodes[0], t_max) {
            return None;
        }
        // Children are tested before they are visited; the nearer is visited first and
        // the farther pushed with its entry distance, skipped if a hit is found before it.
        let mut stack = [(0u32, 0.0f32); STACK];
        let mut sp = 0usize;
        let mut idx = 0usize;
        loop {
            let node = &self.nodes[idx];
            if node.count > 0 {
                let start = node.offset;
                for k in start..start + node.count as u32 {
                    if let Some((t, h)) = hit(k, t_max)
                        && t < t_max
                    {
                        t_max = t;
                        best = Some(h);
                    }
                }
            } else {
                let (l, r) = (idx + 1, node.offset as usize);
                let tl = rb.entry(&self.nodes[l], t_max);
                let tr = rb.entry(&self.nodes[r], t_max);
                if tl < f32::INFINITY {
                    if tr < f32::INFINITY {
                        let (near, far, tfar) = if tr < tl { (r, l, tl) } else { (l, r, tr) };
                        stack[sp] = (far as u32, tfar);
                        sp += 1;
                        idx = near;
                    } else {
                        idx = l;
                    }
                    continue;
                } else if tr < f32::INFINITY {
                    idx = r;
                    continue;
                }
            }
            // Pop the next node still in front of the closest hit.
            loop {
                if sp == 0 {
                    return best;
                }
                sp -= 1;
                let (i, t) = stack[sp];
                if t < t_max {
                    idx = i as usize;
                    break;
                }
            }
        }
    }

    /// Any-hit traversal; `hit(k, t_max)` returns true if primitive slot `k` blocks the
    /// ray before `t_max`. Stops at the first blocker.
    #[inline]
    pub fn occluded(&self, ray: &Ray, t_max: f32, mut hit: impl FnMut(u32, f32) -> bool) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        let rb = RayBox::new(ray);
        let mut stack = [0u32; STACK];
        let mut sp = 0usize;
        let mut idx = 0usize;
        loop {
            let node = &self.nodes[idx];
            if rb.hits(node, t_max) {
                if node.count > 0 {
                    let start = node.offset;
                    for k in start..start + node.count as u32 {
                        if hit(k, t_max) {
                            return true;
                        }
                    }
                } else {
                    let (first, second) = if rb.neg[node.axis as usize] {
                        (node.offset as usize, idx + 1)
                    } else {
                        (idx + 1, node.offset as usize)
                    };
                    stack[sp] = second as u32;
                    sp += 1;
                    idx = first;
                    continue;
                }
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            idx = stack[sp] as usize;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::Triangle;
    use crate::shape::sphere::tests::{random_dir, uniform};
    use rand_pcg::Pcg32;

    /// `n` random triangles of random sizes in a 10-unit cube.
    pub(super) fn soup(n: usize, seed: u64) -> Vec<Triangle> {
        let mut rng = Pcg32::new(seed, 1);
        let mut v = || Vec3::new(uniform(&mut rng), uniform(&mut rng), uniform(&mut rng));
        (0..n)
            .map(|_| {
                let c = v() * 10.0 - 5.0;
                let s = 0.1 + uniform_len(&mut v);
                Triangle::new(c + (v() - 0.5) * s, c + (v() - 0.5) * s, c + (v() - 0.5) * s)
            })
            .collect()
    }

    fn uniform_len(v: &mut impl FnMut() -> Vec3) -> f32 {
        v().x * 2.0
    }

    #[test]
    fn node_is_32_bytes() {
        assert_eq!(std::mem::size_of::<Node>(), 32);
    }

    #[test]
    fn matches_brute_force_on_triangle_soup() {
        let tris = soup(3000, 1);
        let bvh = Bvh::build(&tris.iter().map(|t| t.bounds()).collect::<Vec<_>>());
        assert!(bvh.sah_cost() > 1.0);
        let mut order = bvh.prim_order().to_vec();
        order.sort();
        assert!(order.iter().enumerate().all(|(i, &k)| i as u32 == k), "prim_order is a permutation");
        let mut rng = Pcg32::new(2, 2);
        let mut hits = 0;
        for i in 0..10_000 {
            let o = Vec3::new(uniform(&mut rng), uniform(&mut rng), uniform(&mut rng)) * 14.0 - 7.0;
            let mut d = random_dir(&mut rng);
            if i % 10 == 0 {
                // Axis-parallel rays, including -0 components.
                d = [Vec3::X, -Vec3::Y, Vec3::new(-0.0, 0.0, 1.0)][i / 10 % 3];
            }
            let ray = Ray::new(o, d);
            let t_max = if i % 7 == 0 { 3.0 } else { f32::INFINITY };
            let brute = tris
                .iter()
                .enumerate()
                .filter_map(|(k, t)| t.intersect(&ray, t_max).map(|h| (h.t, k as u32)))
                .min_by(|a, b| a.0.total_cmp(&b.0));
            let got = bvh.intersect(&ray, t_max, |k, tm| {
                let idx = bvh.prim_order()[k as usize];
                tris[idx as usize].intersect(&ray, tm).map(|h| (h.t, (h.t, idx)))
            });
            match (brute, got) {
                (None, None) => {}
                (Some((tb, kb)), Some((tg, kg))) => {
                    hits += 1;
                    assert!((tb - tg).abs() <= 1e-5 * tb, "ray {i}: t {tb} vs {tg}");
                    assert!(kb == kg || (tb - tg).abs() <= 1e-6 * tb, "ray {i}: triangle {kb} vs {kg}");
                }
                other => panic!("ray {i}: brute force {:?} vs bvh {:?}", other.0, other.1),
            }
            let occ = bvh.occluded(&ray, t_max, |k, tm| tris[bvh.prim_order()[k as usize] as usize].occluded(&ray, tm));
            assert_eq!(occ, brute.is_some(), "ray {i}: occluded");
        }
        assert!(hits > 2000, "test rays should hit often ({hits})");
    }

    #[test]
    fn deterministic_across_thread_counts() {
        let tris = soup(5000, 3);
        let b: Vec<Aabb> = tris.iter().map(|t| t.bounds()).collect();
        let reference = Bvh::build_with_threshold(&b, 64);
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let t = pool.install(|| Bvh::build_with_threshold(&b, 64));
            assert_eq!(t.nodes, reference.nodes, "{threads} threads");
            assert_eq!(t.order, reference.order);
        }
        let serial = Bvh::build_with_threshold(&b, usize::MAX);
        assert_eq!(serial.nodes, reference.nodes);
        assert_eq!(Bvh::build(&b).nodes, reference.nodes);
    }

    #[test]
    fn empty_identical_and_flat_inputs() {
        let empty = Bvh::build(&[]);
        assert_eq!(empty.node_count(), 0);
        assert!(empty.intersect(&Ray::new(Vec3::ZERO, Vec3::X), f32::INFINITY, |_, _| Some((1.0, ()))).is_none());
        // Many identical boxes: median splits, bounded depth, all reachable.
        let same = vec![Aabb::new(Vec3::ZERO, Vec3::ONE); 1000];
        let bvh = Bvh::build(&same);
        let mut seen = 0;
        bvh.occluded(&Ray::new(Vec3::new(0.5, 0.5, -1.0), Vec3::Z), f32::INFINITY, |_, _| {
            seen += 1;
            false
        });
        assert_eq!(seen, 1000);
        // A box flat in z, hit by a ray lying in its plane and by a ray with zero components.
        let flat = [Aabb::new(Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0))];
        let bvh = Bvh::build(&flat);
        let hit = |r: Ray| bvh.occluded(&r, f32::INFINITY, |_, _| true);
        assert!(hit(Ray::new(Vec3::new(-1.0, 0.5, 0.0), Vec3::X)));
        assert!(hit(Ray::new(Vec3::new(0.5, 0.5, 1.0), Vec3::new(0.0, -0.0, -1.0))));
        assert!(!hit(Ray::new(Vec3::new(1.5, 0.5, 1.0), Vec3::new(0.0, -0.0, -1.0))));
    }
}
