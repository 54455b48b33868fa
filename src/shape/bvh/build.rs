//! The binned-SAH build shared by [`super::Bvh`] and [`super::WideBvh`]: a binary tree
//! over primitive bounding boxes, flattened depth-first. It lives apart from the
//! traversal code because both trees start from it (the wide tree collapses it).
//!
//! Determinism: the tree depends only on the input boxes, never on the thread count.
//! Subtrees are built in parallel with `rayon::join` (at every level down to
//! [`super::JOIN_THRESHOLD`] primitives) and appended in a fixed order; the
//! bins of large nodes are filled in parallel over fixed chunks and merged in chunk
//! order, and a bin holds only minima, maxima and counts, which are exact whatever the
//! order of the merge.

// `!(x > 0.0)` is used on purpose: it is also true for NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use super::Node;
use crate::geometry::Aabb;
use glam::{Vec3, Vec3A, Vec4};
use rayon::prelude::*;

/// Number of SAH bins per axis.
const BINS: usize = 16;
/// Largest leaf the SAH may choose.
const MAX_LEAF: usize = 8;
/// SAH cost of visiting a node, relative to intersecting one primitive, for the build:
/// a node visit (two box tests, likely a cache miss) costs about two triangle tests
/// (the triangles of a leaf are contiguous, so the next ones are cheap to fetch).
const TRAVERSAL_COST: f32 = 2.0;
/// Primitives per chunk when a large node's bins are filled in parallel.
const BIN_CHUNK: usize = 32 * 1024;

/// Knobs of one build.
#[derive(Clone, Copy, Debug)]
pub(super) struct Limits {
    /// Node sizes above which the bins and bounds are filled in parallel.
    pub threshold: usize,
    /// Node sizes above which the two children are built in parallel (`rayon::join`).
    pub join: usize,
    /// The tree's depth stays below this (levels of nodes, the root is level 0): nodes
    /// that the SAH would take deeper are split at the median instead.
    pub max_depth: u32,
}

/// A box in SIMD registers (glam's `Vec3A`: one SSE register per corner), so that a union
/// is two instructions. Minima and maxima are exact, so the boxes equal [`Aabb`]'s.
#[derive(Clone, Copy, Debug)]
struct Box3A {
    min: Vec3A,
    max: Vec3A,
}

impl Box3A {
    const EMPTY: Box3A = Box3A { min: Vec3A::INFINITY, max: Vec3A::NEG_INFINITY };

    #[inline(always)]
    fn union(self, o: Box3A) -> Box3A {
        Box3A { min: self.min.min(o.min), max: self.max.max(o.max) }
    }

    #[inline(always)]
    fn grow(self, p: Vec3A) -> Box3A {
        Box3A { min: self.min.min(p), max: self.max.max(p) }
    }

    fn aabb(self) -> Aabb {
        Aabb { min: self.min.into(), max: self.max.into() }
    }
}

/// A primitive during the build, in 32 bytes: its box's corners as SSE registers, the
/// index in the input slice kept in the minimum's unused fourth lane as the bits of a
/// float in `[2, 2^33)`: the SIMD arithmetic on boxes computes that lane too, and a
/// denormal there (the index's bits alone) costs a microcode assist per operation.
#[derive(Clone, Copy, Debug)]
struct BuildPrim {
    min: Vec4,
    max: Vec4,
}

const _: () = assert!(std::mem::size_of::<BuildPrim>() == 32);

/// Set in a [`BuildPrim`]'s index lane (bit 30: the float's exponent is at least 128).
const INDEX_BIT: u32 = 1 << 30;

impl BuildPrim {
    fn new(b: Aabb, index: u32) -> BuildPrim {
        debug_assert!(index < INDEX_BIT);
        BuildPrim { min: b.min.extend(f32::from_bits(INDEX_BIT | index)), max: b.max.extend(0.0) }
    }

    #[inline(always)]
    fn bounds(&self) -> Box3A {
        Box3A { min: Vec3A::from_vec4(self.min), max: Vec3A::from_vec4(self.max) }
    }

    #[inline(always)]
    fn index(&self) -> u32 {
        self.min.w.to_bits() & !INDEX_BIT
    }

    /// `(min + max) * 0.5`, as [`Aabb::centroid`].
    #[inline(always)]
    fn centroid(&self) -> Vec3A {
        let b = self.bounds();
        (b.min + b.max) * 0.5
    }
}

/// Builds the tree over `n` primitives whose boxes `prim_bounds(i)` gives: the nodes
/// (depth first, root first) and the slot order (slot `k` of a leaf holds primitive
/// `order[k]` of the input).
pub(super) fn build_tree(
    n: usize,
    prim_bounds: impl Fn(usize) -> Aabb + Sync,
    limits: Limits,
) -> (Vec<Node>, Vec<u32>) {
    assert!(n < INDEX_BIT as usize, "{n} primitives: at most 2^30 - 1 are supported");
    let prim = |i: usize| BuildPrim::new(prim_bounds(i), i as u32);
    let mut prims: Vec<BuildPrim> =
        if n > limits.threshold { (0..n).into_par_iter().map(prim).collect() } else { (0..n).map(prim).collect() };
    let mut nodes = Vec::with_capacity(prims.len() * 2 / 3 + 1);
    if !prims.is_empty() {
        build_node(&mut prims, 0, 0, &mut nodes, limits);
    }
    nodes.shrink_to_fit();
    let order = prims.iter().map(|p| p.index()).collect();
    drop(prims);
    (nodes, order)
}

/// Smallest `k` with `2^k >= n`.
fn ceil_log2(n: usize) -> u32 {
    usize::BITS - n.saturating_sub(1).leading_zeros()
}

#[derive(Clone, Copy)]
struct Bin {
    bounds: Box3A,
    count: u32,
}

/// The SAH bins of one node: per axis, the boxes and counts of the primitives whose
/// centroids fall in each of [`BINS`] equal slices of the centroid bounds.
type Bins = [[Bin; BINS]; 3];

const EMPTY_BINS: Bins = [[Bin { bounds: Box3A::EMPTY, count: 0 }; BINS]; 3];

/// Bin of centroid coordinate `c` (same formula for binning and partitioning).
#[inline(always)]
fn bin_of(c: f32, lo: f32, scale: f32) -> usize {
    (((c - lo) * scale) as usize).min(BINS - 1)
}

/// Adds `prims` to `bins`.
fn fill_bins(bins: &mut Bins, prims: &[BuildPrim], lo: Vec3, scale: [f32; 3]) {
    for p in prims {
        let c = p.centroid();
        for a in 0..3 {
            let b = &mut bins[a][bin_of(c[a], lo[a], scale[a])];
            b.count += 1;
            b.bounds = b.bounds.union(p.bounds());
        }
    }
}

/// Bounds and centroid bounds of `prims` (in parallel over fixed chunks when large).
fn node_bounds(prims: &[BuildPrim], threshold: usize) -> (Aabb, Aabb) {
    let one = |ps: &[BuildPrim]| {
        ps.iter().fold((Box3A::EMPTY, Box3A::EMPTY), |(b, c), p| (b.union(p.bounds()), c.grow(p.centroid())))
    };
    let (b, c) = if prims.len() > threshold {
        let parts: Vec<(Box3A, Box3A)> = prims.par_chunks(BIN_CHUNK).map(one).collect();
        parts.iter().fold((Box3A::EMPTY, Box3A::EMPTY), |(b, c), (pb, pc)| (b.union(*pb), c.union(*pc)))
    } else {
        one(prims)
    };
    (b.aabb(), c.aabb())
}

/// Builds the subtree over `prims` (slots `first..first + prims.len()`), appending its
/// nodes depth-first to `nodes`; node offsets are relative to the start of `nodes`.
fn build_node(prims: &mut [BuildPrim], first: u32, depth: u32, nodes: &mut Vec<Node>, limits: Limits) {
    let n = prims.len();
    let (bounds, cb) = node_bounds(prims, limits.threshold);
    let me = nodes.len();
    nodes.push(Node::new(bounds, first, n as u16));
    if n == 1 {
        return;
    }

    let extent = cb.diagonal();
    // Too deep for the traversal stack if SAH keeps peeling: fall back to median splits,
    // which finish in ceil(log2 n) more levels.
    let force_median = depth + ceil_log2(n) + 2 >= limits.max_depth;
    let mut split: Option<(usize, usize)> = None; // (axis, last bin on the left)
    if !force_median {
        let mut scale = [0.0f32; 3];
        for a in 0..3 {
            if extent[a] > 0.0 {
                scale[a] = BINS as f32 / extent[a];
            }
        }
        let bins = if n > limits.threshold {
            // Fixed chunks, merged in order: the same bins for any thread count.
            let parts: Vec<Bins> = prims
                .par_chunks(BIN_CHUNK)
                .map(|ps| {
                    let mut b = EMPTY_BINS;
                    fill_bins(&mut b, ps, cb.min, scale);
                    b
                })
                .collect();
            let mut bins = EMPTY_BINS;
            for part in &parts {
                for a in 0..3 {
                    for i in 0..BINS {
                        bins[a][i].count += part[a][i].count;
                        bins[a][i].bounds = bins[a][i].bounds.union(part[a][i].bounds);
                    }
                }
            }
            bins
        } else {
            let mut bins = EMPTY_BINS;
            fill_bins(&mut bins, prims, cb.min, scale);
            bins
        };
        let mut best_cost = f32::INFINITY;
        for a in 0..3 {
            if !(extent[a] > 0.0) {
                continue;
            }
            // Right-to-left sweep: area * count of the right part for each split.
            let mut right = [0.0f32; BINS];
            let mut rb = Box3A::EMPTY;
            let mut rc = 0u32;
            for i in (1..BINS).rev() {
                rb = rb.union(bins[a][i].bounds);
                rc += bins[a][i].count;
                right[i - 1] = rb.aabb().surface_area() * rc as f32;
            }
            let mut lb = Box3A::EMPTY;
            let mut lc = 0u32;
            for i in 0..BINS - 1 {
                lb = lb.union(bins[a][i].bounds);
                lc += bins[a][i].count;
                if lc == 0 || lc as usize == n {
                    continue;
                }
                let cost = lb.aabb().surface_area() * lc as f32 + right[i];
                if cost < best_cost {
                    best_cost = cost;
                    split = Some((a, i));
                }
            }
        }
        let area = bounds.surface_area();
        let split_cost = if area > 0.0 { TRAVERSAL_COST + best_cost / area } else { f32::INFINITY };
        if n <= MAX_LEAF && (n as f32) <= split_cost {
            return;
        }
        if split.is_none() && n <= MAX_LEAF {
            return;
        }
    } else if n <= MAX_LEAF {
        return;
    }

    let (mid, axis) = match split {
        Some((a, last)) => {
            let (lo, scale) = (cb.min[a], BINS as f32 / extent[a]);
            (partition(prims, |p| bin_of(p.centroid()[a], lo, scale) <= last), a)
        }
        None => {
            // Median split on the widest centroid axis, ties broken by index.
            let a = if extent.x >= extent.y && extent.x >= extent.z {
                0
            } else if extent.y >= extent.z {
                1
            } else {
                2
            };
            let mid = n / 2;
            prims.select_nth_unstable_by(mid, |p, q| {
                p.centroid()[a].total_cmp(&q.centroid()[a]).then(p.index().cmp(&q.index()))
            });
            (mid, a)
        }
    };
    let (left, right) = prims.split_at_mut(mid);
    let second = if n > limits.join {
        // The left subtree goes straight into `nodes` (it comes first depth-first), the
        // right one into its own vector, appended after: one copy of half the nodes.
        let ((), rn) = rayon::join(
            || build_node(left, first, depth + 1, nodes, limits),
            || {
                let mut v = Vec::with_capacity(right.len() * 2 / 3 + 1);
                build_node(right, first + mid as u32, depth + 1, &mut v, limits);
                v
            },
        );
        let second = nodes.len();
        append(nodes, rn);
        second
    } else {
        build_node(left, first, depth + 1, nodes, limits);
        let second = nodes.len();
        build_node(right, first + mid as u32, depth + 1, nodes, limits);
        second
    };
    let node = &mut nodes[me];
    node.offset = second as u32;
    node.count = 0;
    node.axis = axis as u8;
}

/// Appends a subtree built in its own vector, shifting its interior links.
fn append(nodes: &mut Vec<Node>, sub: Vec<Node>) {
    let base = nodes.len() as u32;
    nodes.extend(sub.into_iter().map(|mut n| {
        if n.count == 0 {
            n.offset += base;
        }
        n
    }));
}

/// Stable-in-outcome, in-place two-way partition; returns the number of elements for
/// which `left` holds (they come first).
fn partition(prims: &mut [BuildPrim], left: impl Fn(&BuildPrim) -> bool) -> usize {
    let mut i = 0;
    let mut j = prims.len();
    loop {
        while i < j && left(&prims[i]) {
            i += 1;
        }
        while i < j && !left(&prims[j - 1]) {
            j -= 1;
        }
        if i >= j {
            return i;
        }
        prims.swap(i, j - 1);
        i += 1;
        j -= 1;
    }
}
