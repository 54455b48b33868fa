//! Tests of the 8-wide BVH: traversal against brute force, stack bounds, the collapse.

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
                // The weights kept from the lane test are the scalar test's, bit for bit.
                let (ts, b0, b1, b2) = TriRay::new(&ray).intersect(tri.v0, tri.v1, tri.v2, t_max).unwrap();
                assert_eq!(
                    [ts, b0, b1, b2].map(f32::to_bits),
                    [h.t, h.b[0], h.b[1], h.b[2]].map(f32::to_bits),
                    "ray {i}: t and weights"
                );
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

/// Triangles under reference `r`, checking on the way that every leaf holds at most
/// [`LEAF_TRIANGLES`] of them in as few blocks as that takes, and every node more.
fn covered(w: &WideBvh, r: u32) -> u32 {
    if r & LEAF != 0 {
        let (first, nb) = ((r & BLOCK_MASK) as usize, ((r >> 28) & 7) as usize + 1);
        let end = w.block_first.get(first + nb).copied().unwrap_or(w.order.len() as u32);
        let n = end - w.block_first[first];
        assert!(n <= LEAF_TRIANGLES && nb == n.div_ceil(4) as usize, "leaf of {n} triangles in {nb} blocks");
        return n;
    }
    let kids = w.nodes[r as usize].child;
    let n = kids.iter().filter(|&&c| c != EMPTY).map(|&c| covered(w, c)).sum();
    assert!(n > LEAF_TRIANGLES, "a node over {n} triangles should have been a leaf");
    // The collapse fills a node to W children while any child can open, so a node
    // with an unused slot has only leaves below it.
    if kids.contains(&EMPTY) {
        assert!(kids.iter().all(|&c| c == EMPTY || c & LEAF != 0), "node {r} has room but a node child");
    }
    n
}

#[test]
fn leaves_hold_at_most_leaf_triangles_and_nodes_more() {
    for n in [1, 12, 13, 3000] {
        let w = WideBvh::build(&verts(&soup(n, 4)));
        assert_eq!(covered(&w, w.root), n as u32);
        // Fuller blocks than one leaf per four-triangle subtree gave (76% on the dragon).
        if n == 3000 {
            assert!(n as f64 / (4 * w.block_count()) as f64 > 0.8, "{} blocks", w.block_count());
        }
    }
}

#[test]
fn matches_brute_force_on_triangle_soup() {
    let tris = soup(3000, 1);
    let w = WideBvh::build(&verts(&tris));
    assert!(w.sah_cost() > 1.0 && w.node_count() > 50);
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
fn same_tree_as_the_whole_binary_tree_and_deterministic() {
    let tris = soup(5000, 3);
    let v = verts(&tris);
    let reference = WideBvh::build_with_threshold(&v, 64);
    // Built from the whole binary tree (no subtree left unsplit), the collapse keeps
    // the binary tree's slot order...
    let whole = WideBvh::build_with(v.len(), |i| v[i], 64, 64, 1);
    let binary = super::super::Bvh::build(&tris.iter().map(|t| t.bounds()).collect::<Vec<_>>());
    assert_eq!(whole.order, binary.prim_order(), "storage order unchanged by the collapse");
    // ...and the tree that stops splitting at the leaf size has the same nodes and
    // leaves, holding the same triangles, only in another order inside each leaf.
    assert_eq!(
        (&reference.nodes, &reference.block_first, reference.root),
        (&whole.nodes, &whole.block_first, whole.root)
    );
    let mut leaves = 0;
    for r in
        reference.nodes.iter().flat_map(|n| n.child).chain([reference.root]).filter(|&r| r != EMPTY && r & LEAF != 0)
    {
        let (first, nb) = ((r & BLOCK_MASK) as usize, ((r >> 28) & 7) as usize + 1);
        let a = reference.block_first[first] as usize;
        let b = reference.block_first.get(first + nb).map_or(reference.order.len(), |&x| x as usize);
        let sorted = |o: &[u32]| {
            let mut o = o.to_vec();
            o.sort();
            o
        };
        assert_eq!(sorted(&reference.order[a..b]), sorted(&whole.order[a..b]), "leaf at slots {a}..{b}");
        leaves += 1;
    }
    assert!(leaves > 400 && reference.order != whole.order, "{leaves} leaves");
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
    assert_eq!((&serial.nodes, &serial.blocks, serial.root), (&reference.nodes, &reference.blocks, reference.root));
    // The default thresholds and the indexed input (vertices shared between
    // triangles, as a mesh gives them) build the same tree too.
    let positions: Vec<Vec3> = v.iter().flatten().copied().collect();
    let indexed: Vec<[u32; 3]> = (0..v.len() as u32).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
    for t in [WideBvh::build(&v), WideBvh::build_indexed(&positions, &indexed)] {
        assert_eq!((t.nodes, t.blocks, t.order), (serial.nodes.clone(), serial.blocks.clone(), serial.order.clone()));
    }
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
        tris[i] = if i % 2 == 0 { Triangle::new(p, p, p) } else { Triangle::new(p, p + Vec3::X, p + Vec3::X * 2.0) };
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
    // A NaN ray's traversal visits the whole tree and fills its stack as far as the
    // tree allows: these trees need 56 entries (the small stack) and 78 (the large).
    let deep = |n: i32, g: f32| -> Vec<[Vec3; 3]> {
        (0..n)
            .map(|i| {
                let s = g.powi(i);
                [Vec3::new(s, 0.0, 0.0), Vec3::new(s, s, 0.0), Vec3::new(s, 0.0, s)]
            })
            .collect()
    };
    let same = vec![[Vec3::ZERO, Vec3::X, Vec3::Y]; 1000];
    let probes = [
        (Ray::new(Vec3::new(-1.0, 0.1, 0.1), Vec3::X), 2.0, true),
        (Ray::new(Vec3::new(-1.0, 0.1, 0.1), Vec3::X), 2.0, false),
        (Ray::new(Vec3::new(0.2, 0.2, -1.0), Vec3::Z), 1.0, true),
    ];
    for (tris, (probe, t, shallow)) in [deep(1000, 1.02), deep(3000, 1.02), same].into_iter().zip(probes) {
        let w = WideBvh::build(&tris);
        let lv = levels(&w, w.root);
        assert!(lv >= 3 && (W - 1) * lv < STACK, "{lv} levels");
        let need = w.stack_need(w.root);
        assert!(w.shallow == shallow && need < STACK && (need > 40 || tris[0] == tris[1]), "needs {need}");
        for r in &nan {
            assert!(w.intersect(r, f32::INFINITY).is_none() && !w.occluded(r, f32::INFINITY));
        }
        assert_eq!(w.intersect(&probe, f32::INFINITY).map(|h| h.t), Some(t));
        assert!(w.occluded(&probe, f32::INFINITY));
    }
}
