//! Loop subdivision (Loop 1987) of a triangle mesh, for pbrt's `loopsubdiv`
//! shape: each level splits every triangle in four, moving old vertices by
//! the even rule (interior: `(1 − nβ) v + β Σ neighbours`, β = 3/16 for
//! valence 3, else 3/(8n); boundary: `3/4 v + 1/8 (b₀ + b₁)`) and placing new
//! edge vertices by the odd rule (interior: `3/8 (a + b) + 1/8 (c + d)`;
//! boundary: the midpoint). After the last level the vertices are pushed to
//! the limit surface (interior: β' = 1/(n + 3/(8β)); boundary:
//! `3/5 v + 1/5 (b₀ + b₁)`), as pbrt does, and given area-weighted normals.

use std::collections::HashMap;

use glam::DVec3;

/// One undirected edge: its faces' opposite vertices and its new vertex.
struct Edge {
    opposite: Vec<u32>,
    mid: u32,
}

fn key(a: u32, b: u32) -> (u32, u32) {
    if a < b { (a, b) } else { (b, a) }
}

/// Edges with their opposite vertices, each vertex's neighbours and its
/// boundary neighbours (along edges with one face).
#[allow(clippy::type_complexity)]
fn topology(n: usize, tris: &[[u32; 3]]) -> (HashMap<(u32, u32), Edge>, Vec<Vec<u32>>, Vec<Vec<u32>>) {
    let mut edges: HashMap<(u32, u32), Edge> = HashMap::new();
    for t in tris {
        for k in 0..3 {
            let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
            edges.entry(key(a, b)).or_insert(Edge { opposite: Vec::new(), mid: 0 }).opposite.push(c);
        }
    }
    let mut nbr = vec![Vec::new(); n];
    let mut boundary = vec![Vec::new(); n];
    let mut keys: Vec<&(u32, u32)> = edges.keys().collect();
    keys.sort();
    for &(a, b) in keys {
        nbr[a as usize].push(b);
        nbr[b as usize].push(a);
        if edges[&(a, b)].opposite.len() == 1 {
            boundary[a as usize].push(b);
            boundary[b as usize].push(a);
        }
    }
    (edges, nbr, boundary)
}

fn beta(n: usize) -> f64 {
    if n == 3 { 3.0 / 16.0 } else { 3.0 / (8.0 * n as f64) }
}

/// A vertex moved by a rule with weight `w` on itself and `wn` on each neighbour.
fn weighted(p: &[DVec3], v: usize, ns: &[u32], w: f64, wn: f64) -> DVec3 {
    ns.iter().fold(p[v] * w, |s, &j| s + p[j as usize] * wn)
}

/// The mesh subdivided `levels` times and pushed to the limit surface, with normals.
pub(crate) fn subdivide(
    mut p: Vec<DVec3>,
    mut tris: Vec<[u32; 3]>,
    levels: u32,
) -> (Vec<DVec3>, Vec<[u32; 3]>, Vec<DVec3>) {
    for _ in 0..levels {
        let (mut edges, nbr, boundary) = topology(p.len(), &tris);
        let mut next: Vec<DVec3> = (0..p.len())
            .map(|v| {
                if !boundary[v].is_empty() {
                    if boundary[v].len() == 2 { weighted(&p, v, &boundary[v], 0.75, 0.125) } else { p[v] }
                } else if nbr[v].is_empty() {
                    p[v]
                } else {
                    let n = nbr[v].len();
                    let b = beta(n);
                    weighted(&p, v, &nbr[v], 1.0 - n as f64 * b, b)
                }
            })
            .collect();
        let mut keys: Vec<(u32, u32)> = edges.keys().copied().collect();
        keys.sort();
        for k in keys {
            let e = edges.get_mut(&k).expect("the key was listed");
            let (a, b) = (p[k.0 as usize], p[k.1 as usize]);
            let pos = if e.opposite.len() == 2 {
                (a + b) * 0.375 + (p[e.opposite[0] as usize] + p[e.opposite[1] as usize]) * 0.125
            } else {
                (a + b) * 0.5
            };
            e.mid = next.len() as u32;
            next.push(pos);
        }
        let mid = |a: u32, b: u32| edges[&key(a, b)].mid;
        tris = tris
            .iter()
            .flat_map(|&[a, b, c]| {
                let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
                [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
            })
            .collect();
        p = next;
    }
    // The limit surface.
    let (_, nbr, boundary) = topology(p.len(), &tris);
    let limit: Vec<DVec3> = (0..p.len())
        .map(|v| {
            if !boundary[v].is_empty() {
                if boundary[v].len() == 2 { weighted(&p, v, &boundary[v], 0.6, 0.2) } else { p[v] }
            } else if nbr[v].is_empty() {
                p[v]
            } else {
                let n = nbr[v].len();
                let bl = 1.0 / (n as f64 + 3.0 / (8.0 * beta(n)));
                weighted(&p, v, &nbr[v], 1.0 - n as f64 * bl, bl)
            }
        })
        .collect();
    let mut normals = vec![DVec3::ZERO; limit.len()];
    for t in &tris {
        let [a, b, c] = t.map(|i| limit[i as usize]);
        let n = (b - a).cross(c - a);
        for &i in t {
            normals[i as usize] += n;
        }
    }
    (limit, tris, normals)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A regular octahedron.
    fn octahedron() -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let p = vec![DVec3::X, -DVec3::X, DVec3::Y, -DVec3::Y, DVec3::Z, -DVec3::Z];
        let t = vec![[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]];
        (p, t)
    }

    #[test]
    fn counts_grow_by_four_and_a_closed_mesh_stays_closed() {
        let (p, t) = octahedron();
        let (p2, t2, n2) = subdivide(p, t, 2);
        assert_eq!(t2.len(), 8 * 16);
        // Euler: V − E + F = 2 with E = 3F/2 for a closed triangle mesh.
        assert_eq!(p2.len() as i64 - (3 * t2.len() / 2) as i64 + t2.len() as i64, 2);
        let (_, _, b) = topology(p2.len(), &t2);
        assert!(b.iter().all(Vec::is_empty), "no boundary");
        assert_eq!(n2.len(), p2.len());
    }

    #[test]
    fn limit_points_of_the_octahedron_by_hand() {
        // The limit rule at level 0 on a valence-4 vertex of the unit octahedron, by hand:
        // β(4) = 3/32, β' = 1/(4 + 3/(8·3/32)) = 1/8, and its neighbours (±y, ±z) sum to
        // zero, so the limit point is (1 − 4/8)·(1, 0, 0) = (0.5, 0, 0).
        let (p, t) = octahedron();
        let (lim, _, normals) = subdivide(p, t, 0);
        assert!((lim[0] - DVec3::new(0.5, 0.0, 0.0)).length() < 1e-12, "{:?}", lim[0]);
        assert!(normals[0].normalize().dot(DVec3::X) > 0.999, "outward normal {:?}", normals[0]);
        // Loop's limit point of a vertex does not change under subdivision (the vertex
        // keeps its index: old vertices come first at every level).
        let (lim, _, _) = subdivide(octahedron().0, octahedron().1, 3);
        assert!((lim[0] - DVec3::new(0.5, 0.0, 0.0)).length() < 1e-12, "{:?}", lim[0]);
        // The limit surface lies inside the control octahedron: |x| + |y| + |z| ≤ 1.
        assert!(lim.iter().all(|v| v.x.abs() + v.y.abs() + v.z.abs() <= 1.0));
    }

    #[test]
    fn a_flat_patch_stays_flat_with_boundary_rules() {
        // Two triangles in z = 0: every rule is an affine combination, so z stays 0.
        let p = vec![DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y];
        let (lim, t, _) = subdivide(p, vec![[0, 1, 2], [0, 2, 3]], 2);
        assert_eq!(t.len(), 32);
        assert!(lim.iter().all(|v| v.z == 0.0));
        // A corner (two boundary neighbours): 3/4 v + 1/8 (b0 + b1) stays inside the square.
        assert!(lim.iter().all(|v| (-1e-12..=1.0 + 1e-12).contains(&v.x) && (-1e-12..=1.0 + 1e-12).contains(&v.y)));
    }
}
