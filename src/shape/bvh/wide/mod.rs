//! The triangle BVH of meshes: 8-wide nodes of one 256-byte, cache-line-aligned block
//! (the eight children's boxes as `[min/max][axis][lane]` arrays of `f32`, then the eight
//! child references), leaves of [`Tri4`] blocks, closest-hit traversal that enters the
//! nearest child first, and any-hit traversal for shadow rays.
//!
//! It is built by collapsing the binary SAH tree of [`super::build`]: a node takes its
//! grandchildren (a leaf child stays as it is), then keeps replacing the child with the
//! largest box that can open by that child's two children, until it has [`W`]; a subtree
//! of at most [`LEAF_TRIANGLES`] triangles becomes one leaf of up to three blocks. The
//! binary build is told to stop there (`leaf` in its limits): a leaf's triangles are all
//! tested, so splitting it further would only order them inside it, and those small nodes
//! were most of the build's nodes. Children stay in slot order and leaves keep the binary
//! tree's slot order, so the triangles' storage order (and `Hit::prim`) is the binary
//! tree's; the tree is as deterministic as that build. The collapse writes the nodes and
//! places the blocks; the blocks' vertices are gathered after, in parallel. Every child a
//! ray is about to visit is prefetched, and the node and block arrays are advised into
//! huge pages (`hint.rs`).
//!
//! Memory (full Stanford dragon): see `docs/performance.md`; nodes and index data stay
//! under 32 bytes per triangle, the vertices live in the blocks.
//!
//! Traversal stack: every node below the root sits at least two binary levels under its
//! parent node, so a binary tree of depth below [`BINARY_DEPTH`] gives at most
//! `BINARY_DEPTH / 2` node levels, and `W - 1` pending siblings per level fit [`STACK`].
//! A tree whose own deepest traversal fits [`SMALL_STACK`] (measured after the build) is
//! traversed with that smaller stack, which is cheaper to zero for every ray.

// Lane loops `for l in 0..W` index several arrays by lane on purpose: that is the form the
// compiler vectorises.
#![allow(clippy::needless_range_loop)]

use super::build::{Limits, build_tree};
use super::hint::{advise_huge_pages, prefetch_blocks, prefetch_line, prefetch_node};
use super::tri4::Tri4;
use super::{JOIN_THRESHOLD, Node, PARALLEL_THRESHOLD, ROBUST};
use crate::geometry::{Aabb, Ray};
use crate::shape::triangle::TriRay;
use glam::Vec3;
use rayon::prelude::*;

/// Children per node. Measured against 4 (128-byte nodes; the same leaves, so the same
/// hits bit for bit) on the full dragon's ray files: incoherent rays 1.12-1.16x in
/// in-process pairs and 1.17x in a 15-round sitting, primary rays 1.01x in both
/// (docs/performance.md, round 8). On a CPU with AVX an 8-lane box test is as many
/// instructions as a 4-lane one, and a ray visits fewer nodes (SAH cost 19.8 against
/// 25.7). Round 2 measured 8-wide nodes as no faster on the SSE2 baseline with leaves of
/// one block.
const W: usize = 8;
/// Depth limit of the binary tree that is collapsed (see the module doc).
const BINARY_DEPTH: u32 = 42;
/// Largest binary subtree that becomes a leaf (three full blocks). Measured on the full
/// dragon's incoherent rays against 4 (one block per leaf, the binary SAH's own cost
/// model): 8 gave +7%, 12 +11% (per-round median of 9 alternated runs), 16 +13%, 24
/// less again; 12 also cuts nodes and index data from 24.7 to 12.8 bytes per triangle
/// and fills 86% of block lanes instead of 76% (docs/performance.md, round 5). A node
/// visit costs more than the SAH's unit here: it is a dependent cache miss, while a
/// leaf's blocks are contiguous and fetched together.
const LEAF_TRIANGLES: u32 = 12;
/// Traversal stack entries: `W - 1` pending children per node level, plus one.
const STACK: usize = (W - 1) * (BINARY_DEPTH as usize / 2) + 1;
/// Traversal stack entries for a tree whose deepest traversal fits them (the full dragon's
/// needs 54; [`WideBvh::stack_need`]): an array of [`STACK`] entries, zeroed for every
/// ray as safe Rust requires, compiled to a call to `memset` of 84 instructions, a third
/// of a primary ray's; 64 entries (512 bytes) are zeroed by 16 inline vector stores.
const SMALL_STACK: usize = 64;
/// Reference flag of a leaf; its bits 28-30 hold the block count minus one and bits
/// 0-27 the first block.
const LEAF: u32 = 1 << 31;
/// Mask of a leaf's first block.
const BLOCK_MASK: u32 = (1 << 28) - 1;
/// An unused child slot.
const EMPTY: u32 = u32::MAX;
/// Most blocks a mesh can have (the rest of a reference's bits).
pub(crate) const MAX_BLOCKS: usize = BLOCK_MASK as usize;

/// [`W`] children: boxes as `b[0 = min, 1 = max][axis][lane]`, then their references
/// (a node index, a leaf, or [`EMPTY`] with an empty box).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
struct WideNode {
    b: [[[f32; W]; 3]; 2],
    child: [u32; W],
}

const _: () = assert!(std::mem::size_of::<WideNode>() == 256 && std::mem::size_of::<Tri4>() == 144);

impl WideNode {
    const EMPTY: WideNode = WideNode { b: [[[f32::INFINITY; W]; 3], [[f32::NEG_INFINITY; W]; 3]], child: [EMPTY; W] };

    fn set(&mut self, lane: usize, bounds: Aabb, child: u32) {
        for a in 0..3 {
            self.b[0][a][lane] = bounds.min[a];
            self.b[1][a][lane] = bounds.max[a];
        }
        self.child[lane] = child;
    }

    fn child_box(&self, lane: usize) -> Aabb {
        let b = &self.b;
        Aabb {
            min: Vec3::new(b[0][0][lane], b[0][1][lane], b[0][2][lane]),
            max: Vec3::new(b[1][0][lane], b[1][1][lane], b[1][2][lane]),
        }
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

/// An 8-wide BVH that stores its triangles (see the module doc).
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
    /// True if every traversal fits [`SMALL_STACK`] entries.
    shallow: bool,
}

/// Per-ray data of the wide slab test.
struct RayBox {
    o: [f32; 3],
    inv: [f32; 3],
    neg: [usize; 3],
}

impl RayBox {
    #[inline(always)]
    fn new(ray: &Ray) -> RayBox {
        // As in the binary tree: 1/±0 = ±inf, NaN slab values are ignored.
        let inv = (Vec3::ONE / ray.dir).to_array();
        RayBox { o: ray.origin.to_array(), inv, neg: inv.map(|x| (x < 0.0) as usize) }
    }

    /// Entry distance into each child's box if the ray hits it with `t` in `[0, t_max]`,
    /// else infinity: the binary tree's slab test, lane by lane.
    #[inline(always)]
    fn entry(&self, n: &WideNode, t_max: f32) -> [f32; W] {
        let mut t0 = [0.0f32; W];
        let mut t1 = [t_max; W];
        for a in 0..3 {
            let near = &n.b[self.neg[a]][a];
            let far = &n.b[1 - self.neg[a]][a];
            let (o, inv) = (self.o[a], self.inv[a]);
            for l in 0..W {
                let ta = (near[l] - o) * inv;
                let tb = (far[l] - o) * inv * ROBUST;
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
    /// Builds over triangles given by their vertices (binned SAH on their boxes, subtrees
    /// in parallel above 4k triangles, then collapsed). At most 2^28 - 1 blocks (meshes
    /// check this when they load).
    pub fn build(tris: &[[Vec3; 3]]) -> Self {
        Self::build_with(tris.len(), |i| tris[i], PARALLEL_THRESHOLD, JOIN_THRESHOLD, LEAF_TRIANGLES)
    }

    /// [`WideBvh::build`] over indexed triangles (`tris[i]` holds three indices into
    /// `positions`, all in range), without an array of their vertices.
    pub fn build_indexed(positions: &[Vec3], tris: &[[u32; 3]]) -> Self {
        Self::build_with(
            tris.len(),
            |i| tris[i].map(|v| positions[v as usize]),
            PARALLEL_THRESHOLD,
            JOIN_THRESHOLD,
            LEAF_TRIANGLES,
        )
    }

    /// With both thresholds equal (tests: small to be parallel everywhere, `usize::MAX`
    /// for a serial build).
    #[cfg(test)]
    fn build_with_threshold(tris: &[[Vec3; 3]], threshold: usize) -> Self {
        Self::build_with(tris.len(), |i| tris[i], threshold, threshold, LEAF_TRIANGLES)
    }

    /// `leaf`: binary subtrees of at most this many triangles are not split (the wide
    /// tree's leaf size; 1 in a test builds the whole binary tree, as before).
    fn build_with(n: usize, tri: impl Fn(usize) -> [Vec3; 3] + Sync, threshold: usize, join: usize, leaf: u32) -> Self {
        let limits = Limits { threshold, join, max_depth: BINARY_DEPTH, leaf: leaf as usize };
        let (bin, order) = build_tree(
            n,
            |i| {
                let t = tri(i);
                Aabb::new(t[0], t[1]).grow(t[2])
            },
            limits,
        );
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
            nodes: Vec::with_capacity(n / 6 + 1),
            blocks: Vec::new(),
            block_first: Vec::with_capacity(n / 2 + 1),
            order: Vec::new(),
            root: EMPTY,
            shallow: true,
            bounds: bin.first().map_or(Aabb::EMPTY, |n| n.aabb()),
        };
        // The arrays are advised before they are written, so that their first touch
        // maps huge pages directly; the advice after (`MADV_COLLAPSE`) then finds little
        // left to merge. Merging 4 KiB pages already written took 15-45 ms of a 0.35 s
        // build of the full dragon.
        advise_huge_pages(w.nodes.spare_capacity_mut());
        if !bin.is_empty() {
            let mut c = Collapse { bin: &bin, range: &range, out: &mut w };
            w.root = c.subtree(0);
            w.shallow = w.stack_need(w.root) < SMALL_STACK;
        }
        drop((bin, range));
        // The blocks, filled in parallel in their final order (the collapse above only
        // placed them): gathering the vertices was about half of the collapse's time.
        // Blocks follow each other in slot order, so a block's triangles run up to the
        // next block's first slot.
        let nb = w.block_first.len();
        let mut blocks = Vec::with_capacity(nb);
        advise_huge_pages(blocks.spare_capacity_mut());
        let fill = |b: usize| {
            let first = w.block_first[b] as usize;
            let end = w.block_first.get(b + 1).map_or(n, |&x| x as usize);
            let mut v = [[Vec3::ZERO; 3]; 4];
            for (lane, &k) in v.iter_mut().zip(&order[first..end]) {
                *lane = tri(k as usize);
            }
            Tri4::new(&v[..end - first])
        };
        if n > threshold {
            (0..nb).into_par_iter().with_min_len(1024).map(fill).collect_into_vec(&mut blocks);
        } else {
            blocks.extend((0..nb).map(fill));
        }
        w.blocks = blocks;
        w.order = order;
        w.nodes.shrink_to_fit();
        w.block_first.shrink_to_fit();
        advise_huge_pages(&w.nodes);
        advise_huge_pages(&w.blocks);
        w
    }

    /// Requests the cache lines of child reference `r` (a node, or all of a leaf's blocks).
    #[inline(always)]
    fn prefetch(&self, r: u32) {
        if r & LEAF == 0 {
            prefetch_node(self.nodes.as_ptr().wrapping_add(r as usize));
        } else {
            let n = ((r >> 28) & 7) as usize + 1;
            prefetch_blocks(self.blocks.as_ptr().wrapping_add((r & BLOCK_MASK) as usize), n);
        }
    }

    /// Most entries a traversal from `r` can leave on its stack: a visit to a node pushes
    /// at most all but one of its children, and those wait while one path below it is
    /// followed, so this is the largest sum of `children - 1` over the nodes of a path
    /// (the any-hit traversal pushes the last child too: one more).
    fn stack_need(&self, r: u32) -> usize {
        if r & LEAF != 0 {
            return 0;
        }
        let kids = self.nodes[r as usize].child.into_iter().filter(|&c| c != EMPTY);
        kids.clone().count() - 1 + kids.map(|c| self.stack_need(c)).max().unwrap_or(0)
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

    /// Number of wide nodes.
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
        if self.shallow { self.closest::<SMALL_STACK>(ray, t_max) } else { self.closest::<STACK>(ray, t_max) }
    }

    /// [`WideBvh::intersect`] with a stack of `S` entries (at least [`WideBvh::stack_need`]).
    #[inline(always)]
    fn closest<const S: usize>(&self, ray: &Ray, t_max: f32) -> Option<TriangleHit> {
        if self.root == EMPTY {
            return None;
        }
        let rb = RayBox::new(ray);
        let tr = TriRay::new(ray);
        let mut t_max = t_max;
        let mut best = None;
        let mut stack = [(0u32, 0.0f32); S];
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
                    // Every child to be visited is requested now: the pending ones
                    // arrive while the nearest is visited, and all lines of each come
                    // at once (see `hint`). Prefetching only the pending ones measured
                    // 4.08 against 4.40 Mrays/s on incoherent rays.
                    for &(_, r) in &c[..n] {
                        self.prefetch(r);
                    }
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
                    let (ts, uvw) = self.blocks[b].hit(&tr, t_max);
                    for (l, &t) in ts.iter().enumerate() {
                        if t < t_max {
                            t_max = t;
                            best = Some((b, l, uvw));
                            // Read when the traversal ends; a miss there waited on its own.
                            prefetch_line(self.block_first.as_ptr().wrapping_add(b));
                        }
                    }
                }
            }
            // Pop the next child still in front of the closest hit.
            loop {
                if sp == 0 {
                    // The winning lane's weights, divided as `TriRay::intersect` divides
                    // them (the same operations, so the same bits: tested).
                    let (b, l, uvw) = best?;
                    let [u, v, w] = uvw.map(|x| x[l]);
                    let inv = 1.0 / (u + v + w);
                    let slot = self.block_first[b] + l as u32;
                    let v3 = self.blocks[b].triangle(l);
                    return Some(TriangleHit { slot, t: t_max, b: [u * inv, v * inv, w * inv], v: v3 });
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
        if self.shallow { self.any_hit::<SMALL_STACK>(ray, t_max) } else { self.any_hit::<STACK>(ray, t_max) }
    }

    /// [`WideBvh::occluded`] with a stack of `S` entries (more than [`WideBvh::stack_need`]).
    #[inline(always)]
    fn any_hit<const S: usize>(&self, ray: &Ray, t_max: f32) -> bool {
        if self.root == EMPTY {
            return false;
        }
        let rb = RayBox::new(ray);
        let tr = TriRay::new(ray);
        let mut stack = [0u32; S];
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
                        self.prefetch(node.child[l]);
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

/// State of the collapse of a binary tree into [`WideBvh`] nodes: it writes the nodes and
/// places the blocks (their first slots); the blocks' vertices are gathered after.
struct Collapse<'a> {
    bin: &'a [Node],
    range: &'a [(u32, u32)],
    out: &'a mut WideBvh,
}

impl Collapse<'_> {
    /// True if binary node `i` becomes a wide node (not a leaf).
    fn opens(&self, i: usize) -> bool {
        self.bin[i].count == 0 && self.range[i].1 > LEAF_TRIANGLES
    }

    /// The reference of binary subtree `i`, appending its nodes and blocks depth first.
    fn subtree(&mut self, i: usize) -> u32 {
        let (first, count) = self.range[i];
        if !self.opens(i) {
            let start = self.out.block_first.len();
            self.out.block_first.extend((first..first + count).step_by(4));
            let nb = (self.out.block_first.len() - start) as u32;
            debug_assert!((1..=8).contains(&nb) && start < MAX_BLOCKS);
            return LEAF | (nb - 1) << 28 | start as u32;
        }
        // Children in slot order: two, then grandchildren (see the module doc).
        let kids2 = |j: usize| [j + 1, self.bin[j].offset as usize];
        let [l, r] = kids2(i);
        // Up to W children, in a fixed array (no allocation per node).
        let mut kids = [0usize; W];
        let mut m = 0;
        for c in [l, r] {
            if self.opens(c) {
                kids[m..m + 2].copy_from_slice(&kids2(c));
                m += 2;
            } else {
                kids[m] = c;
                m += 1;
            }
        }
        // Then the largest child that opens is replaced by its two, until there are W.
        while m < W {
            let area = |j: usize| self.bin[j].aabb().surface_area();
            let pick = (0..m).filter(|&k| self.opens(kids[k])).max_by(|&a, &b| area(kids[a]).total_cmp(&area(kids[b])));
            let Some(k) = pick else { break };
            let [a, b] = kids2(kids[k]);
            kids.copy_within(k + 1..m, k + 2);
            kids[k..k + 2].copy_from_slice(&[a, b]);
            m += 1;
        }
        let kids = &kids[..m];
        let me = self.out.nodes.len();
        self.out.nodes.push(WideNode::EMPTY);
        for (lane, &k) in kids.iter().enumerate() {
            let r = self.subtree(k);
            self.out.nodes[me].set(lane, self.bin[k].aabb(), r);
        }
        me as u32
    }
}

#[cfg(test)]
mod tests;
