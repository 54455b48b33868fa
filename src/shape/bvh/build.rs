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
//!
//! Passes over the primitives: one for the root's bounds, then per node one to bin and
//! one to partition. A child's box is the union of the bins on its side of the split and
//! its centroid bounds are gathered by the partition, which computes every centroid
//! anyway (both exact: the values a pass over the child would give). The SAH sweep visits
//! only occupied bins, which is most of the saving on small nodes (docs/performance.md,
//! round 7).

// `!(x > 0.0)` is used on purpose: it is also true for NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use super::Node;
use super::hint::advise_huge_pages;
use crate::geometry::Aabb;
use glam::{Vec3A, Vec4};
use rayon::prelude::*;

/// Number of SAH bins per axis (a power of two: see `fill_bins`).
const BINS: usize = 16;
const _: () = assert!(BINS.is_power_of_two());
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
    /// Nodes of at most this many primitives become leaves without a split (at least 1).
    /// The wide tree passes its leaf size: it tests all of a leaf's triangles, so the
    /// splits below that size would only order them inside the leaf.
    pub leaf: usize,
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

    /// [`Aabb::surface_area`] with the same operations in the same order (so the same
    /// bits), in SIMD registers: 0 unless `min <= max` on every axis (an empty or NaN
    /// box).
    #[inline(always)]
    fn surface_area(self) -> f32 {
        if !self.min.cmple(self.max).all() {
            return 0.0;
        }
        let d = self.max - self.min;
        let p = d * Vec3A::new(d.y, d.z, d.x);
        2.0 * (p.x + p.y + p.z)
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
    // The build's two big arrays (28 MB of primitives for the full dragon) are advised
    // before their first touch, so that it maps 2 MiB pages: a quarter fewer page faults
    // for the whole load, 0.33 s instead of 0.35-0.36 s on one thread (docs/performance.md).
    let mut prims: Vec<BuildPrim> = Vec::with_capacity(n);
    advise_huge_pages(prims.spare_capacity_mut());
    if n > limits.threshold {
        (0..n).into_par_iter().map(prim).collect_into_vec(&mut prims);
    } else {
        prims.extend((0..n).map(prim));
    }
    let mut nodes = Vec::with_capacity(prims.len() * 2 / 3 + 1);
    advise_huge_pages(nodes.spare_capacity_mut());
    if !prims.is_empty() {
        let (bounds, centroids) = node_bounds(&prims, limits.threshold);
        build_node(&mut prims, bounds, centroids, 0, 0, &mut nodes, limits);
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

/// Bin of centroid coordinate `c` on one axis: the definition that [`bins_of`] (binning)
/// and [`Side`] (partitioning) compute without it, tested against it.
#[cfg(test)]
fn bin_of(c: f32, lo: f32, scale: f32) -> usize {
    (((c - lo) * scale) as usize).min(BINS - 1)
}

/// `bin_of` on the three axes at once (binning): the same products lane by lane, and
/// the same index for every value, NaN included: `max` with 0 gives 0 for NaN and for
/// negative values as the saturating `as usize` does, `min` the last bin.
#[inline(always)]
fn bins_of(c: Vec3A, lo: Vec3A, scale: Vec3A) -> [usize; 3] {
    let x = ((c - lo) * scale).max(Vec3A::ZERO).min(Vec3A::splat((BINS - 1) as f32));
    x.as_uvec3().to_array().map(|i| i as usize)
}

/// Adds `prims` to `bins`.
fn fill_bins(bins: &mut Bins, prims: &[BuildPrim], lo: Vec3A, scale: Vec3A) {
    for p in prims {
        let i = bins_of(p.centroid(), lo, scale);
        for a in 0..3 {
            // (`i[a] <= BINS - 1` already; the mask lets the compiler drop the bounds check.)
            let bin = &mut bins[a][i[a] & (BINS - 1)];
            bin.count += 1;
            bin.bounds = bin.bounds.union(p.bounds());
        }
    }
}

/// Bounds and centroid bounds of `prims` (in parallel over fixed chunks when large).
fn node_bounds(prims: &[BuildPrim], threshold: usize) -> (Box3A, Box3A) {
    let one = |ps: &[BuildPrim]| {
        ps.iter().fold((Box3A::EMPTY, Box3A::EMPTY), |(b, c), p| (b.union(p.bounds()), c.grow(p.centroid())))
    };
    if prims.len() > threshold {
        let parts: Vec<(Box3A, Box3A)> = prims.par_chunks(BIN_CHUNK).map(one).collect();
        parts.iter().fold((Box3A::EMPTY, Box3A::EMPTY), |(b, c), (pb, pc)| (b.union(*pb), c.union(*pc)))
    } else {
        one(prims)
    }
}

/// Builds the subtree over `prims` (slots `first..first + prims.len()`), whose bounds and
/// centroid bounds are `bounds` and `cb`, appending its nodes depth-first to `nodes`;
/// node offsets are relative to the start of `nodes`.
///
/// A node's bounds come from its parent: the union of the bins on its side of the split
/// (the same set of primitive boxes), and its centroid bounds from the partition, which
/// computes every centroid anyway. Minima and maxima are exact, so these are the values a
/// pass over the child's primitives would give (up to the sign of a zero, which depends
/// on the order), without that pass.
fn build_node(
    prims: &mut [BuildPrim],
    bounds: Box3A,
    cb: Box3A,
    first: u32,
    depth: u32,
    nodes: &mut Vec<Node>,
    limits: Limits,
) {
    let n = prims.len();
    let me = nodes.len();
    nodes.push(Node::new(bounds.aabb(), first, n as u16));
    if n <= limits.leaf {
        return;
    }

    let extent = cb.max - cb.min;
    // Too deep for the traversal stack if SAH keeps peeling: fall back to median splits,
    // which finish in ceil(log2 n) more levels.
    let force_median = depth + ceil_log2(n) + 2 >= limits.max_depth;
    // (axis, last bin on the left, the children's bounds)
    let mut split: Option<(usize, usize, Box3A, Box3A)> = None;
    if !force_median {
        let mut scale = Vec3A::ZERO;
        for a in 0..3 {
            if extent[a] > 0.0 {
                scale[a] = BINS as f32 / extent[a];
            }
        }
        let mut bins = EMPTY_BINS;
        if n > limits.threshold {
            // Fixed chunks, merged in order: the same bins for any thread count.
            let parts: Vec<Bins> = prims
                .par_chunks(BIN_CHUNK)
                .map(|ps| {
                    let mut b = EMPTY_BINS;
                    fill_bins(&mut b, ps, cb.min, scale);
                    b
                })
                .collect();
            for part in &parts {
                for a in 0..3 {
                    for i in 0..BINS {
                        bins[a][i].count += part[a][i].count;
                        bins[a][i].bounds = bins[a][i].bounds.union(part[a][i].bounds);
                    }
                }
            }
        } else {
            fill_bins(&mut bins, prims, cb.min, scale);
        }
        let mut best_cost = f32::INFINITY;
        let mut best = None;
        for a in 0..3 {
            if !(extent[a] > 0.0) {
                continue;
            }
            // Only the occupied bins: between two of them every split position leaves
            // the same primitives on each side, so its cost is the same and the first
            // position (the occupied bin itself) is the one the strict `<` below keeps.
            // The costs are those of a sweep over all bins, bit for bit (an empty bin's
            // box leaves a union unchanged).
            let mut occupied = [0u8; BINS];
            let mut m = 0;
            for (i, bin) in bins[a].iter().enumerate() {
                occupied[m] = i as u8;
                m += (bin.count > 0) as usize;
            }
            let occupied = &occupied[..m];
            // Right-to-left sweep: area * count of the part right of each occupied bin.
            let mut right = [0.0f32; BINS];
            let mut rb = Box3A::EMPTY;
            let mut rc = 0u32;
            for k in (1..m).rev() {
                let bin = &bins[a][occupied[k] as usize];
                rb = rb.union(bin.bounds);
                rc += bin.count;
                right[k - 1] = rb.surface_area() * rc as f32;
            }
            let mut lb = Box3A::EMPTY;
            let mut lc = 0u32;
            for k in 0..m.saturating_sub(1) {
                let bin = &bins[a][occupied[k] as usize];
                lb = lb.union(bin.bounds);
                lc += bin.count;
                let cost = lb.surface_area() * lc as f32 + right[k];
                if cost < best_cost {
                    best_cost = cost;
                    best = Some((a, occupied[k] as usize));
                }
            }
        }
        let area = bounds.surface_area();
        let split_cost = if area > 0.0 { TRAVERSAL_COST + best_cost / area } else { f32::INFINITY };
        if n <= MAX_LEAF && (n as f32) <= split_cost {
            return;
        }
        if best.is_none() && n <= MAX_LEAF {
            return;
        }
        split = best.map(|(a, last)| {
            let side = |bins: &[Bin]| bins.iter().fold(Box3A::EMPTY, |b, bin| b.union(bin.bounds));
            (a, last, side(&bins[a][..=last]), side(&bins[a][last + 1..]))
        });
    } else if n <= MAX_LEAF {
        return;
    }

    let (mid, axis, (lb, lcb), (rb, rcb)) = match split {
        Some((a, last, lb, rb)) => {
            let (mid, lcb, rcb) = partition(prims, a, cb.min[a], BINS as f32 / extent[a], last);
            (mid, a, (lb, lcb), (rb, rcb))
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
            (mid, a, node_bounds(&prims[..mid], limits.threshold), node_bounds(&prims[mid..], limits.threshold))
        }
    };
    let (left, right) = prims.split_at_mut(mid);
    let second = if n > limits.join {
        // The left subtree goes straight into `nodes` (it comes first depth-first), the
        // right one into its own vector, appended after: one copy of half the nodes.
        let ((), rn) = rayon::join(
            || build_node(left, lb, lcb, first, depth + 1, nodes, limits),
            || {
                let mut v = Vec::with_capacity(right.len() * 2 / 3 + 1);
                build_node(right, rb, rcb, first + mid as u32, depth + 1, &mut v, limits);
                v
            },
        );
        let second = nodes.len();
        append(nodes, rn);
        second
    } else {
        build_node(left, lb, lcb, first, depth + 1, nodes, limits);
        let second = nodes.len();
        build_node(right, rb, rcb, first + mid as u32, depth + 1, nodes, limits);
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

/// Which side of a split a centroid falls on: `bin_of(c[axis], lo, scale) <= last`,
/// without the conversion to an integer. For `last < BINS - 1`, `trunc(x) <= last` is
/// `x < last + 1` for every `x >= 0`; `x` below 0 and NaN go to bin 0, on the left, and
/// `!(x >= last + 1)` holds for them too (tested against `bin_of`).
#[derive(Clone, Copy)]
struct Side {
    lo: Vec3A,
    scale: Vec3A,
    bound: Vec3A,
    axis: u32,
}

impl Side {
    fn new(axis: usize, lo: f32, scale: f32, last: usize) -> Side {
        debug_assert!(last < BINS - 1);
        let bound = Vec3A::splat((last + 1) as f32);
        Side { lo: Vec3A::splat(lo), scale: Vec3A::splat(scale), bound, axis: axis as u32 }
    }

    /// True if centroid `c` goes left (every lane is computed, lane `axis` decides).
    #[inline(always)]
    fn left(&self, c: Vec3A) -> bool {
        ((c - self.lo) * self.scale).cmpge(self.bound).bitmask() >> self.axis & 1 == 0
    }
}

/// In-place two-way partition of `prims` by centroid bin on `axis` (bins up to `last`
/// first; deterministic, not stable); returns the number on the left and the centroid
/// bounds of each side.
fn partition(prims: &mut [BuildPrim], axis: usize, lo: f32, scale: f32, last: usize) -> (usize, Box3A, Box3A) {
    let side = Side::new(axis, lo, scale, last);
    let (mut lcb, mut rcb) = (Box3A::EMPTY, Box3A::EMPTY);
    let mut i = 0;
    let mut j = prims.len();
    loop {
        while i < j {
            let c = prims[i].centroid();
            if !side.left(c) {
                break;
            }
            lcb = lcb.grow(c);
            i += 1;
        }
        while i < j {
            let c = prims[j - 1].centroid();
            if side.left(c) {
                break;
            }
            rcb = rcb.grow(c);
            j -= 1;
        }
        if i >= j {
            return (i, lcb, rcb);
        }
        // `prims[i]` belongs right and `prims[j - 1]` left.
        lcb = lcb.grow(prims[j - 1].centroid());
        rcb = rcb.grow(prims[i].centroid());
        prims.swap(i, j - 1);
        i += 1;
        j -= 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::bvh::tests::soup;
    use glam::Vec3;

    /// Every value class the binning can meet: NaN, infinities, negative values, both
    /// zeros, the bin edges and just below them, and past the last bin.
    const VALUES: [f32; 14] = [
        f32::NAN,
        f32::NEG_INFINITY,
        -1.0,
        -0.0,
        0.0,
        1e-40,
        0.999_999_9,
        1.0,
        7.5,
        14.999_999,
        15.0,
        16.0,
        1e30,
        f32::INFINITY,
    ];

    #[test]
    fn bins_of_three_axes_is_bin_of_on_each() {
        for &c in &VALUES {
            for &lo in &[0.0f32, -0.0, 1.0, f32::INFINITY] {
                for &scale in &[0.0f32, 1.0, 3.2, f32::INFINITY] {
                    let v = Vec3A::new(c, -c, c * 0.5);
                    let got = bins_of(v, Vec3A::splat(lo), Vec3A::splat(scale));
                    let want = [0, 1, 2].map(|a| bin_of(v[a], lo, scale));
                    assert_eq!(got, want, "c {v} lo {lo} scale {scale}");
                }
            }
        }
    }

    #[test]
    fn partition_side_is_bin_of_compared_with_last() {
        for &x in &VALUES {
            for &lo in &[0.0f32, -0.0, 1.0, f32::INFINITY] {
                for &scale in &[0.0f32, 1.0, 3.2, f32::INFINITY] {
                    for last in 0..BINS - 1 {
                        for axis in 0..3 {
                            let mut c = Vec3A::splat(f32::NAN);
                            c[axis] = x;
                            let want = bin_of(x, lo, scale) <= last;
                            let got = Side::new(axis, lo, scale, last).left(c);
                            assert_eq!(got, want, "x {x} lo {lo} scale {scale} last {last} axis {axis}");
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn simd_surface_area_is_the_aabbs_bit_for_bit() {
        let soup = soup(500, 11);
        let mut boxes: Vec<Aabb> = soup.iter().map(|t| t.bounds()).collect();
        boxes.push(Aabb::EMPTY);
        boxes.push(Aabb { min: Vec3::new(0.0, f32::NAN, 0.0), max: Vec3::ONE });
        boxes.push(Aabb { min: Vec3::ZERO, max: Vec3::new(1.0, 0.0, 2.0) }); // flat
        boxes.push(Aabb { min: Vec3::ZERO, max: Vec3::new(1.0, -1.0, 2.0) }); // inverted on y
        boxes.push(Aabb { min: Vec3::splat(-1e30), max: Vec3::splat(1e30) }); // area overflows
        for b in boxes {
            let simd = Box3A { min: b.min.into(), max: b.max.into() };
            assert_eq!(simd.surface_area().to_bits(), b.surface_area().to_bits(), "{b:?}");
        }
    }

    /// A node's box comes from its parent's bins, and its centroid bounds from the
    /// parent's partition; checked here against a fold over the node's own primitives.
    #[test]
    fn every_node_box_is_the_tight_box_of_its_primitives() {
        let mut boxes: Vec<Aabb> = soup(6000, 12).iter().map(|t| t.bounds()).collect();
        // Shared coordinates and zeros of both signs, where the order of a fold shows.
        for (i, b) in boxes.iter_mut().enumerate().step_by(7) {
            b.min.x = if i % 2 == 0 { 0.0 } else { -0.0 };
            b.max.y = b.max.y.max(1.0);
        }
        for threshold in [64, usize::MAX] {
            let limits = Limits { threshold, join: threshold, max_depth: 40, leaf: 1 };
            let (nodes, order) = build_tree(boxes.len(), |i| boxes[i], limits);
            // Slot range of node `i`: a leaf's own, an interior node's from its children.
            fn range(nodes: &[Node], i: usize) -> (u32, u32) {
                let n = &nodes[i];
                if n.count > 0 {
                    return (n.offset, n.offset + n.count as u32);
                }
                (range(nodes, i + 1).0, range(nodes, n.offset as usize).1)
            }
            for (i, node) in nodes.iter().enumerate() {
                let (a, b) = range(&nodes, i);
                let tight = order[a as usize..b as usize].iter().fold(Aabb::EMPTY, |u, &k| u.union(&boxes[k as usize]));
                assert_eq!(node.aabb(), tight, "node {i} (slots {a}..{b}), threshold {threshold}");
            }
        }
    }
}
