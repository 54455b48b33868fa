//! The triangle BVH of meshes: 8-wide nodes of one 128-byte, cache-line-aligned block
//! (the eight children's boxes quantised to 8 bits per plane on a power-of-two grid of
//! the node, then the eight child references), leaves of [`Tri4`] blocks, closest-hit
//! traversal that enters the nearest child first, and any-hit traversal for shadow rays.
//! The quantised boxes contain the true ones, so the box test only becomes more
//! conservative and the triangle test decides every hit as before.
//!
//! It is built by collapsing the binary SAH tree of [`super::build`]: a node takes its
//! grandchildren (or, beside a leaf child, its other child's children), then keeps
//! replacing its largest child (by area) that is not a leaf by that child's two children
//! until it has eight; a subtree of at most four triangles becomes one leaf block. Leaves
//! keep the binary tree's slot order, so the triangles' storage order (and `Hit::prim`)
//! is the binary tree's; the tree is as deterministic as that build.
//!
//! Memory (full Stanford dragon): see `docs/performance.md`; nodes and index data stay
//! under 32 bytes per triangle, the vertices live in the blocks.
//!
//! Traversal stack: every node below the root sits at least two binary levels under its
//! parent node, so a binary tree of depth below [`BINARY_DEPTH`] gives at most
//! `BINARY_DEPTH / 2` node levels, and seven pending siblings per level fit [`STACK`].

// Lane loops `for l in 0..W` index several arrays by lane on purpose: that is the form the
// compiler vectorises.
#![allow(clippy::needless_range_loop)]

use super::build::{Limits, build_tree};
use super::tri4::Tri4;
use super::{Node, PARALLEL_THRESHOLD, ROBUST};
use crate::geometry::{Aabb, Ray};
use crate::shape::triangle::TriRay;
use glam::Vec3;

/// Children per node.
const W: usize = 8;
/// Depth limit of the binary tree that is collapsed (see the module doc).
const BINARY_DEPTH: u32 = 42;
/// Traversal stack entries: `W - 1` pending children per node level, plus one.
const STACK: usize = (W - 1) * (BINARY_DEPTH as usize / 2) + 1;
/// Reference flag of a leaf; its bits 28-30 hold the block count minus one and bits
/// 0-27 the first block.
const LEAF: u32 = 1 << 31;
/// Mask of a leaf's first block.
const BLOCK_MASK: u32 = (1 << 28) - 1;
/// An unused child slot.
const EMPTY: u32 = u32::MAX;
/// Most blocks a mesh can have (the rest of a reference's bits).
pub(crate) const MAX_BLOCKS: usize = BLOCK_MASK as usize;

/// Eight children in two 64-byte cache lines: their boxes quantised to 8 bits per plane on
/// a grid of the node (`origin + q * scale` per axis, `scale` a power of two), as
/// `q[0 = min, 1 = max][axis][lane]`, then their references (a node index, a leaf, or
/// [`EMPTY`]). The grid boxes contain the true boxes (see [`WideNode::set_all`]), so the
/// slab test on them only ever enters more boxes than on the true ones.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
struct WideNode {
    origin: [f32; 3],
    scale: [f32; 3],
    child: [u32; W],
    q: [[[u8; W]; 3]; 2],
}

const _: () = assert!(std::mem::size_of::<WideNode>() == 128 && std::mem::size_of::<Tri4>() == 144);

/// `2^e` for `e` in `[-149, 127]` (subnormal below -126).
fn pow2(e: i32) -> f32 {
    let e = e.clamp(-149, 127);
    if e >= -126 { f32::from_bits(((e + 127) as u32) << 23) } else { f32::from_bits(1 << (e + 149)) }
}

/// The grid plane `q` of an axis, computed exactly as traversal computes it.
#[inline(always)]
fn plane(origin: f32, scale: f32, q: u8) -> f32 {
    origin + f32::from(q) * scale
}

impl WideNode {
    /// A node over `kids` (one to four children: true box and reference). The grid origin
    /// is the union's minimum, the scale the smallest power of two whose 255 steps reach
    /// its maximum; every child's planes are rounded outwards and then checked with the
    /// traversal's own arithmetic, so the grid box contains the true box (if the true box
    /// is finite; non-finite boxes do not occur, meshes reject such vertices).
    fn set_all(kids: &[(Aabb, u32)]) -> WideNode {
        let mut n = WideNode { origin: [0.0; 3], scale: [1.0; 3], child: [EMPTY; W], q: [[[255; W]; 3], [[0; W]; 3]] };
        let all = kids.iter().fold(Aabb::EMPTY, |b, k| b.union(&k.0));
        for a in 0..3 {
            let (lo, hi) = (all.min[a], all.max[a]);
            // Start one below the estimate (it may be a step too coarse), then coarsen
            // until the top plane reaches `hi`; 2^127 * 255 is infinite, so this ends.
            let est = ((hi - lo) / 255.0).log2().ceil();
            let mut e = if est.is_finite() { est as i32 - 1 } else { -149 }.clamp(-149, 127);
            while e < 127 && plane(lo, pow2(e), 255) < hi {
                e += 1;
            }
            let s = pow2(e);
            n.origin[a] = lo;
            n.scale[a] = s;
            for (l, (b, _)) in kids.iter().enumerate() {
                // Saturating casts: NaN gives 0, out of range the nearest end.
                let mut ql = ((b.min[a] - lo) / s).floor().clamp(0.0, 255.0) as u8;
                while ql > 0 && plane(lo, s, ql) > b.min[a] {
                    ql -= 1;
                }
                let mut qh = ((b.max[a] - lo) / s).ceil().clamp(0.0, 255.0) as u8;
                while qh < 255 && plane(lo, s, qh) < b.max[a] {
                    qh += 1;
                }
                n.q[0][a][l] = ql;
                n.q[1][a][l] = qh;
            }
        }
        for (l, k) in kids.iter().enumerate() {
            n.child[l] = k.1;
        }
        n
    }

    /// The grid box of child `lane` (it contains the child's true box).
    fn child_box(&self, lane: usize) -> Aabb {
        let p = |m: usize, a: usize| plane(self.origin[a], self.scale[a], self.q[m][a][lane]);
        Aabb { min: Vec3::new(p(0, 0), p(0, 1), p(0, 2)), max: Vec3::new(p(1, 0), p(1, 1), p(1, 2)) }
    }
}

/// The closest triangle a ray hits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    /// The triangle's slot (its index in storage order, see [`WideBvh::prim_order`]).
    pub slot: u32,
    /// Distance along the ray.
    pub t: f32,
    /// Barycentric weights of the three vertices.
    pub b: [f32; 3],
    /// The triangle's vertices.
    pub v: [Vec3; 3],
}

/// A 4-wide BVH that stores its triangles (see the module doc).
#[derive(Clone, Debug)]
pub struct WideBvh {
    nodes: Vec<WideNode>,
    blocks: Vec<Tri4>,
    /// Slot of each block's lane 0; the other lanes follow.
    block_first: Vec<u32>,
    /// Input index of each slot.
    order: Vec<u32>,
    root: u32,
    bounds: Aabb,
}

/// Per-ray data of the 4-wide slab test.
struct RayBoxW {
    o: [f32; 3],
    inv: [f32; 3],
    neg: [usize; 3],
}

impl RayBoxW {
    #[inline(always)]
    fn new(ray: &Ray) -> RayBoxW {
        // As in the binary tree: 1/±0 = ±inf, NaN slab values are ignored.
        let inv = (Vec3::ONE / ray.dir).to_array();
        RayBoxW { o: ray.origin.to_array(), inv, neg: inv.map(|x| (x < 0.0) as usize) }
    }

    /// Entry distance into each child's box if the ray hits it with `t` in `[0, t_max]`,
    /// else infinity: the binary tree's slab test, lane by lane.
    #[inline(always)]
    fn entry(&self, n: &WideNode, t_max: f32) -> [f32; W] {
        let mut t0 = [0.0f32; W];
        let mut t1 = [t_max; W];
        for a in 0..3 {
            let near = &n.q[self.neg[a]][a];
            let far = &n.q[1 - self.neg[a]][a];
            let (o, inv) = (self.o[a], self.inv[a]);
            let (org, s) = (n.origin[a], n.scale[a]);
            for l in 0..W {
                let ta = (plane(org, s, near[l]) - o) * inv;
                let tb = (plane(org, s, far[l]) - o) * inv * ROBUST;
                // Written so that a NaN slab value leaves t0/t1 unchanged (maxps/minps).
                t0[l] = if ta > t0[l] { ta } else { t0[l] };
                t1[l] = if tb < t1[l] { tb } else { t1[l] };
            }
        }
        let mut e = [f32::INFINITY; W];
        for l in 0..W {
            e[l] = if t0[l] <= t1[l] { t0[l] } else { f32::INFINITY };
        }
        e
    }
}

impl WideBvh {
    /// Builds over triangles given by their vertices (binned SAH on their boxes, in
    /// parallel above 64k triangles, then collapsed). At most 2^28 - 1 blocks (meshes
    /// check this when they load).
    pub fn build(tris: &[[Vec3; 3]]) -> WideBvh {
        Self::build_with_threshold(tris, PARALLEL_THRESHOLD)
    }

    fn build_with_threshold(tris: &[[Vec3; 3]], threshold: usize) -> WideBvh {
        let limits = Limits { threshold, max_depth: BINARY_DEPTH };
        let (bin, order) = build_tree(tris.len(), |i| Aabb::new(tris[i][0], tris[i][1]).grow(tris[i][2]), limits);
        // Slot range (first, count) of every binary subtree; children follow their parent.
        let mut range = vec![(0u32, 0u32); bin.len()];
        for i in (0..bin.len()).rev() {
            let n = &bin[i];
            range[i] = if n.count > 0 {
                (n.offset, n.count as u32)
            } else {
                (range[i + 1].0, range[i + 1].1 + range[n.offset as usize].1)
            };
        }
        let mut w = WideBvh {
            nodes: Vec::with_capacity(tris.len() / 6 + 1),
            blocks: Vec::with_capacity(tris.len() / 2 + 1),
            block_first: Vec::with_capacity(tris.len() / 2 + 1),
            order: Vec::new(),
            root: EMPTY,
            bounds: bin.first().map_or(Aabb::EMPTY, |n| n.aabb()),
        };
        if !bin.is_empty() {
            let mut c = Collapse { bin: &bin, range: &range, tris, order: &order, out: &mut w };
            w.root = c.subtree(0);
        }
        w.order = order;
        w.nodes.shrink_to_fit();
        w.blocks.shrink_to_fit();
        w.block_first.shrink_to_fit();
        w
    }

    /// Slot order: `prim_order()[slot]` is the triangle's index in the slice given to
    /// [`WideBvh::build`].
    pub fn prim_order(&self) -> &[u32] {
        &self.order
    }

    /// Bounds of everything (empty for an empty tree).
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// Number of 4-wide nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Number of four-triangle blocks.
    pub fn block_count(&self) -> usize {
        self.blocks.len()
    }

    /// Bytes of the nodes and the index data (each block's first slot, the slot order);
    /// the vertices are [`WideBvh::triangle_bytes`].
    pub fn memory_bytes(&self) -> usize {
        self.nodes.len() * size_of::<WideNode>() + (self.block_first.len() + self.order.len()) * 4
    }

    /// Bytes of the triangle blocks (the vertices, unused lanes included).
    pub fn triangle_bytes(&self) -> usize {
        self.blocks.len() * size_of::<Tri4>()
    }

    /// The vertices of the triangle in `slot`; panics if `slot >= prim_order().len()`.
    pub fn triangle(&self, slot: u32) -> [Vec3; 3] {
        let b = self.block_first.partition_point(|&f| f <= slot) - 1;
        self.blocks[b].triangle((slot - self.block_first[b]) as usize)
    }

    /// SAH cost of the tree for reports: visiting a node costs 1, testing a block 1, each
    /// weighted by the area of its box relative to the root's.
    pub fn sah_cost(&self) -> f32 {
        let area = |b: Aabb| b.surface_area() as f64;
        let root_area = area(self.bounds);
        if self.root == EMPTY || !(root_area > 0.0) {
            return 0.0;
        }
        let cost = |r: u32| if r & LEAF == 0 { 1.0 } else { (((r >> 28) & 7) + 1) as f64 };
        let mut total = cost(self.root) * root_area;
        for n in &self.nodes {
            for l in 0..W {
                if n.child[l] != EMPTY {
                    total += cost(n.child[l]) * area(n.child_box(l));
                }
            }
        }
        (total / root_area) as f32
    }

    /// Closest hit with `0 < t < t_max`. Children whose boxes the ray enters are visited
    /// nearest first; pending ones are skipped once a hit lies in front of them. Ties
    /// between triangles at the same `t` go to the first one found.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<TriangleHit> {
        if self.root == EMPTY {
            return None;
        }
        let rb = RayBoxW::new(ray);
        let tr = TriRay::new(ray);
        let mut t_max = t_max;
        let mut best = None;
        let mut stack = [(0u32, 0.0f32); STACK];
        let mut sp = 0usize;
        let mut cur = self.root;
        loop {
            if cur & LEAF == 0 {
                let node = &self.nodes[cur as usize];
                let e = rb.entry(node, t_max);
                // Hit children, then sorted farthest first: the nearest is visited now.
                let mut c = [(0.0f32, 0u32); W];
                let mut n = 0;
                for l in 0..W {
                    if e[l] < f32::INFINITY && node.child[l] != EMPTY {
                        c[n] = (e[l], node.child[l]);
                        n += 1;
                    }
                }
                if n > 0 {
                    for i in 1..n {
                        let x = c[i];
                        let mut j = i;
                        while j > 0 && c[j - 1].0 < x.0 {
                            c[j] = c[j - 1];
                            j -= 1;
                        }
                        c[j] = x;
                    }
                    for &x in &c[..n - 1] {
                        stack[sp] = (x.1, x.0);
                        sp += 1;
                    }
                    cur = c[n - 1].1;
                    continue;
                }
            } else {
                let first = (cur & BLOCK_MASK) as usize;
                for b in first..=first + ((cur >> 28) & 7) as usize {
                    let ts = self.blocks[b].hit_t(&tr, t_max);
                    for (l, &t) in ts.iter().enumerate() {
                        if t < t_max {
                            t_max = t;
                            best = Some((b, l));
                        }
                    }
                }
            }
            // Pop the next child still in front of the closest hit.
            loop {
                if sp == 0 {
                    let (b, l) = best?;
                    let v = self.blocks[b].triangle(l);
                    let (t, b0, b1, b2) = tr.intersect(v[0], v[1], v[2], f32::INFINITY)?;
                    debug_assert_eq!(t, t_max);
                    return Some(TriangleHit { slot: self.block_first[b] + l as u32, t, b: [b0, b1, b2], v });
                }
                sp -= 1;
                let (r, t) = stack[sp];
                if t < t_max {
                    cur = r;
                    break;
                }
            }
        }
    }

    /// True if any triangle blocks the ray with `0 < t < t_max`.
    #[inline]
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        if self.root == EMPTY {
            return false;
        }
        let rb = RayBoxW::new(ray);
        let tr = TriRay::new(ray);
        let mut stack = [0u32; STACK];
        stack[0] = self.root;
        let mut sp = 1usize;
        while sp > 0 {
            sp -= 1;
            let cur = stack[sp];
            if cur & LEAF == 0 {
                let node = &self.nodes[cur as usize];
                let e = rb.entry(node, t_max);
                for l in 0..W {
                    if e[l] < f32::INFINITY && node.child[l] != EMPTY {
                        stack[sp] = node.child[l];
                        sp += 1;
                    }
                }
            } else {
                let first = (cur & BLOCK_MASK) as usize;
                for b in first..=first + ((cur >> 28) & 7) as usize {
                    if self.blocks[b].hit_t(&tr, t_max).iter().any(|&t| t < t_max) {
                        return true;
                    }
                }
            }
        }
        false
    }
}

/// State of the collapse of a binary tree into [`WideBvh`] nodes.
struct Collapse<'a> {
    bin: &'a [Node],
    range: &'a [(u32, u32)],
    tris: &'a [[Vec3; 3]],
    order: &'a [u32],
    out: &'a mut WideBvh,
}

impl Collapse<'_> {
    /// True if binary node `i` becomes a 4-wide node (not a leaf).
    fn opens(&self, i: usize) -> bool {
        self.bin[i].count == 0 && self.range[i].1 > 4
    }

    /// The reference of binary subtree `i`, appending its nodes and blocks depth first.
    fn subtree(&mut self, i: usize) -> u32 {
        let (first, count) = self.range[i];
        if !self.opens(i) {
            let start = self.out.blocks.len();
            for j in (first..first + count).step_by(4) {
                let n = (first + count - j).min(4) as usize;
                let mut lanes = [[Vec3::ZERO; 3]; 4];
                for (k, lane) in lanes[..n].iter_mut().enumerate() {
                    *lane = self.tris[self.order[j as usize + k] as usize];
                }
                self.out.blocks.push(Tri4::new(&lanes[..n]));
                self.out.block_first.push(j);
            }
            let nb = (self.out.blocks.len() - start) as u32;
            debug_assert!((1..=8).contains(&nb) && start < MAX_BLOCKS);
            return LEAF | (nb - 1) << 28 | start as u32;
        }
        // Children in slot order: two, then grandchildren, then the children of the
        // largest opening child until there are `W` (see the module doc).
        let kids2 = |j: usize| [j + 1, self.bin[j].offset as usize];
        let mut kids = [0usize; W];
        let mut n = 0;
        for c in kids2(i) {
            let add = if self.opens(c) { &kids2(c)[..] } else { &[c][..] };
            kids[n..n + add.len()].copy_from_slice(add);
            n += add.len();
        }
        let area = |j: usize| self.bin[j].aabb().surface_area();
        while n < W {
            let pick = (0..n).filter(|&k| self.opens(kids[k])).max_by(|&a, &b| area(kids[a]).total_cmp(&area(kids[b])));
            let Some(k) = pick else { break };
            let [a, b] = kids2(kids[k]);
            kids.copy_within(k + 1..n, k + 2);
            kids[k] = a;
            kids[k + 1] = b;
            n += 1;
        }
        let kids = &kids[..n];
        let me = self.out.nodes.len();
        self.out.nodes.push(WideNode::set_all(&[]));
        let mut lanes = [(Aabb::EMPTY, EMPTY); W];
        for (lane, &k) in kids.iter().enumerate() {
            lanes[lane] = (self.bin[k].aabb(), self.subtree(k));
        }
        self.out.nodes[me] = WideNode::set_all(&lanes[..kids.len()]);
        me as u32
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::Triangle;
    use crate::shape::bvh::tests::soup;
    use crate::shape::sphere::tests::{random_dir, uniform};
    use rand_pcg::Pcg32;

    fn verts(tris: &[Triangle]) -> Vec<[Vec3; 3]> {
        tris.iter().map(|t| [t.v0, t.v1, t.v2]).collect()
    }

    /// Node levels of the tree (0 for a tree that is one leaf).
    fn levels(w: &WideBvh, r: u32) -> usize {
        if r & LEAF != 0 {
            return 0;
        }
        1 + w.nodes[r as usize].child.iter().filter(|&&c| c != EMPTY).map(|&c| levels(w, c)).max().unwrap_or(0)
    }

    /// Brute force over `tris` with the single-triangle test: (t, index) of the closest hit.
    fn brute(tris: &[Triangle], ray: &Ray, t_max: f32) -> Option<(f32, u32)> {
        tris.iter()
            .enumerate()
            .filter_map(|(k, t)| t.intersect(ray, t_max).map(|h| (h.t, k as u32)))
            .min_by(|a, b| a.0.total_cmp(&b.0))
    }

    /// Closest and any hits of `w` against brute force on `n` rays through `tris`'s
    /// region (scaled by `scale`); returns the number of hits.
    fn check_against_brute_force(tris: &[Triangle], w: &WideBvh, scale: f32, n: usize, seed: u64) -> usize {
        let mut rng = Pcg32::new(seed, 2);
        let mut hits = 0;
        for i in 0..n {
            let o = (Vec3::new(uniform(&mut rng), uniform(&mut rng), uniform(&mut rng)) * 14.0 - 7.0) * scale;
            let mut d = random_dir(&mut rng);
            if i % 10 == 0 {
                // Axis-parallel rays, including -0 components.
                d = [Vec3::X, -Vec3::Y, Vec3::new(-0.0, 0.0, 1.0)][i / 10 % 3];
            }
            let ray = Ray::new(o, d);
            let t_max = if i % 7 == 0 { 3.0 * scale } else { f32::INFINITY };
            let want = brute(tris, &ray, t_max);
            let got = w.intersect(&ray, t_max);
            match (want, got) {
                (None, None) => {}
                (Some((t, k)), Some(h)) => {
                    hits += 1;
                    // The same arithmetic: the same t, bit for bit.
                    assert_eq!(t.to_bits(), h.t.to_bits(), "ray {i}");
                    let k_got = w.prim_order()[h.slot as usize];
                    assert!(k == k_got || brute(&tris[k_got as usize..=k_got as usize], &ray, t_max).unwrap().0 == t);
                    let tri = &tris[k_got as usize];
                    assert_eq!(h.v, [tri.v0, tri.v1, tri.v2]);
                    assert_eq!(w.triangle(h.slot), h.v);
                    let p = h.v[0] * h.b[0] + h.v[1] * h.b[1] + h.v[2] * h.b[2];
                    assert!(
                        (p - ray.at(h.t)).length() <= 1e-4 * scale * (1.0 + h.t / scale),
                        "ray {i}: {p} vs {}",
                        ray.at(h.t)
                    );
                }
                other => panic!("ray {i}: brute force {:?} vs wide bvh {:?}", other.0, other.1),
            }
            assert_eq!(w.occluded(&ray, t_max), want.is_some(), "ray {i}: occluded");
        }
        hits
    }

    /// The slab test on a true box, as the uncompressed nodes did it (the binary tree's
    /// test): entry distance or infinity.
    fn entry_exact(rb: &RayBoxW, b: &Aabb, t_max: f32) -> f32 {
        let (mut t0, mut t1) = (0.0f32, t_max);
        for a in 0..3 {
            let (near, far) = if rb.neg[a] == 1 { (b.max[a], b.min[a]) } else { (b.min[a], b.max[a]) };
            let ta = (near - rb.o[a]) * rb.inv[a];
            let tb = (far - rb.o[a]) * rb.inv[a] * ROBUST;
            t0 = if ta > t0 { ta } else { t0 };
            t1 = if tb < t1 { tb } else { t1 };
        }
        if t0 <= t1 { t0 } else { f32::INFINITY }
    }

    #[test]
    fn quantised_boxes_contain_the_true_boxes_and_lose_no_ray() {
        let mut rng = Pcg32::new(77, 1);
        let mut entered = 0;
        for case in 0..4000 {
            let scale = [1e-40f32, 1e-12, 1.0, 1e9, 1e30][case % 5];
            // Far from the origin, the grid's planes round to the coordinates' ulp.
            let offset = if case % 3 == 0 { Vec3::splat(1e6 * scale) } else { Vec3::ZERO };
            let p = |rng: &mut Pcg32| (Vec3::new(uniform(rng), uniform(rng), uniform(rng)) * 2.0 - 1.0) * scale;
            let n = 1 + case % 4;
            let kids: Vec<(Aabb, u32)> = (0..n)
                .map(|k| {
                    let mut b = Aabb::new(offset + p(&mut rng), offset + p(&mut rng));
                    match (case / 4 + k) % 7 {
                        0 => b.max = b.min,        // a point
                        1 => b.max.y = b.min.y,    // flat
                        _ => {}
                    }
                    (b, k as u32)
                })
                .collect();
            let node = WideNode::set_all(&kids);
            for (l, (b, _)) in kids.iter().enumerate() {
                let g = node.child_box(l);
                assert!(g.min.cmple(b.min).all() && g.max.cmpge(b.max).all(), "case {case} lane {l}: {g:?} {b:?}");
                if offset == Vec3::ZERO && scale >= 1e-12 {
                    // Tight: within two grid steps of the true planes, steps at most twice
                    // the union's extent / 255.
                    let all = kids.iter().fold(Aabb::EMPTY, |u, k| u.union(&k.0));
                    for a in 0..3 {
                        let s = node.scale[a];
                        assert!(s <= 2.0 * (all.max[a] - all.min[a]) / 255.0 * 1.001 || s <= f32::MIN_POSITIVE);
                        assert!(b.min[a] - g.min[a] <= 2.0 * s && g.max[a] - b.max[a] <= 2.0 * s, "case {case}");
                    }
                }
            }
            for i in 0..20 {
                let o = offset + p(&mut rng) * 2.0;
                let mut d = random_dir(&mut rng);
                if i % 5 == 0 {
                    d = [Vec3::X, -Vec3::Y, Vec3::new(0.0, -0.0, 1.0)][i / 5 % 3];
                } else if i % 2 == 1 {
                    // Aimed at a child's centre: most of these enter.
                    d = (kids[i % n].0.centroid() - o).normalize_or(Vec3::Z);
                }
                let rb = RayBoxW::new(&Ray::new(o, d));
                let t_max = if i % 2 == 0 { f32::INFINITY } else { uniform(&mut rng) * 3.0 * scale };
                let e = rb.entry(&node, t_max);
                for (l, (b, _)) in kids.iter().enumerate() {
                    let want = entry_exact(&rb, b, t_max);
                    if want < f32::INFINITY {
                        entered += 1;
                        assert!(e[l] <= want, "case {case} ray {i} lane {l}: {} > {want}", e[l]);
                    }
                }
            }
        }
        assert!(entered > 10_000, "{entered}");
    }

    #[test]
    fn matches_brute_force_on_triangle_soup() {
        let tris = soup(3000, 1);
        let w = WideBvh::build(&verts(&tris));
        assert!(w.sah_cost() > 1.0 && w.node_count() > 100);
        let mut order = w.prim_order().to_vec();
        order.sort();
        assert!(order.iter().enumerate().all(|(i, &k)| i as u32 == k), "prim_order is a permutation");
        let hits = check_against_brute_force(&tris, &w, 1.0, 10_000, 2);
        assert!(hits > 2000, "test rays should hit often ({hits})");
    }

    #[test]
    fn huge_and_tiny_coordinates() {
        for scale in [1e-12f32, 1e9] {
            let tris: Vec<Triangle> =
                soup(500, 5).iter().map(|t| Triangle::new(t.v0 * scale, t.v1 * scale, t.v2 * scale)).collect();
            let w = WideBvh::build(&verts(&tris));
            let hits = check_against_brute_force(&tris, &w, scale, 2000, 6);
            assert!(hits > 200, "scale {scale}: {hits} hits");
        }
    }

    #[test]
    fn same_slot_order_as_the_binary_tree_and_deterministic() {
        let tris = soup(5000, 3);
        let v = verts(&tris);
        let reference = WideBvh::build_with_threshold(&v, 64);
        let binary = super::super::Bvh::build(&tris.iter().map(|t| t.bounds()).collect::<Vec<_>>());
        assert_eq!(reference.order, binary.prim_order(), "storage order unchanged by the collapse");
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let t = pool.install(|| WideBvh::build_with_threshold(&v, 64));
            assert_eq!(
                (&t.nodes, &t.blocks, &t.block_first, &t.order),
                (&reference.nodes, &reference.blocks, &reference.block_first, &reference.order),
                "{threads} threads"
            );
        }
        let serial = WideBvh::build_with_threshold(&v, usize::MAX);
        assert_eq!((serial.nodes, serial.blocks, serial.root), (reference.nodes, reference.blocks, reference.root));
    }

    #[test]
    fn empty_degenerate_deep_and_nan() {
        let empty = WideBvh::build(&[]);
        let r = Ray::new(Vec3::ZERO, Vec3::X);
        assert!(empty.intersect(&r, f32::INFINITY).is_none() && !empty.occluded(&r, f32::INFINITY));
        assert_eq!((empty.sah_cost(), empty.memory_bytes()), (0.0, 0));
        // One triangle: the root is a leaf.
        let one = WideBvh::build(&[[Vec3::ZERO, Vec3::X, Vec3::Y]]);
        let down = Ray::new(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z);
        assert_eq!(one.intersect(&down, f32::INFINITY).map(|h| h.t), Some(1.0));
        assert!(one.occluded(&down, 1.5) && !one.occluded(&down, 0.5));
        // Degenerate triangles (a point, a segment) among valid ones never hit.
        let mut tris = soup(200, 9);
        for i in (0..200).step_by(3) {
            let p = tris[i].v0;
            tris[i] =
                if i % 2 == 0 { Triangle::new(p, p, p) } else { Triangle::new(p, p + Vec3::X, p + Vec3::X * 2.0) };
        }
        let w = WideBvh::build(&verts(&tris));
        check_against_brute_force(&tris, &w, 1.0, 2000, 10);
        // Deep trees: boxes that grow geometrically make the SAH peel a few triangles per
        // level; 1000 identical triangles force median splits.
        // A NaN ray enters every box, so it pushes every child: the stack must hold.
        let nan = [
            Ray { origin: Vec3::new(f32::NAN, 0.0, 0.0), dir: Vec3::Z },
            Ray { origin: Vec3::ZERO, dir: Vec3::new(0.0, f32::NAN, 1.0) },
        ];
        let deep: Vec<[Vec3; 3]> = (0..3000)
            .map(|i| {
                let s = 1.02f32.powi(i);
                [Vec3::new(s, 0.0, 0.0), Vec3::new(s, s, 0.0), Vec3::new(s, 0.0, s)]
            })
            .collect();
        let same = vec![[Vec3::ZERO, Vec3::X, Vec3::Y]; 1000];
        let probes =
            [(Ray::new(Vec3::new(-1.0, 0.1, 0.1), Vec3::X), 2.0), (Ray::new(Vec3::new(0.2, 0.2, -1.0), Vec3::Z), 1.0)];
        for (tris, (probe, t)) in [deep, same].into_iter().zip(probes) {
            let w = WideBvh::build(&tris);
            let lv = levels(&w, w.root);
            assert!(lv >= 3 && (W - 1) * lv < STACK, "{lv} levels");
            for r in &nan {
                assert!(w.intersect(r, f32::INFINITY).is_none() && !w.occluded(r, f32::INFINITY));
            }
            assert_eq!(w.intersect(&probe, f32::INFINITY).map(|h| h.t), Some(t));
        }
    }
}
