//! BDPT's MIS weights by value: fixed full paths, their vertices built the
//! way the walks and connections build them, and each strategy's weight
//! against the power heuristic of the strategies' path densities computed
//! here from the geometry alone.

use glam::Vec3;
use std::f64::consts::PI;

use super::mis::{Overrides, mis_weight};
use super::vertex::{Kind, Vertex, connectible, pdf_at, pdf_light, to_area};
use crate::color::Spectrum;
use crate::integrator::Shading;
use crate::scene::{Scene, load_scene_str};

/// A diffuse floor (y = 0, object 0), a diffuse back wall (z = −1, object 1),
/// a 1x1 quad light at y = 2 facing down (object 2, light 0: area 1, the
/// only light) and a mirror wall at x = 1.5 (object 3), seen from (0, 1, 3)
/// with a 60° view of a square film.
const ROOM: &str = r#"(
    camera: (eye: (0, 1, 3), look_at: (0, 1, 0), fov_deg: 60),
    render: (width: 16, height: 16, max_bounces: 8),
    materials: { "white": Lambertian(reflectance: Constant(0.5)), "mirror": Mirror(reflectance: Constant(0.9)) },
    objects: [
        (shape: Quad(origin: (-2, 0, -2), edge_u: (0, 0, 4), edge_v: (4, 0, 0)), material: "white"),
        (shape: Quad(origin: (-2, 0, -1), edge_u: (4, 0, 0), edge_v: (0, 3, 0)), material: "white"),
        (shape: Quad(origin: (-0.5, 2, -0.5), edge_u: (1, 0, 0), edge_v: (0, 0, 1)), emission: Constant(5)),
        (shape: Quad(origin: (1.5, 0, -1), edge_u: (0, 0, 3), edge_v: (0, 3, 0)), material: "mirror"),
    ],
)"#;

/// A point of a fixed path: position, unit normal, object.
#[derive(Clone, Copy)]
struct Point {
    p: Vec3,
    n: Vec3,
    object: u32,
}

const FLOOR: u32 = 0;
const WALL: u32 = 1;
const LIGHT: u32 = 2;
const MIRROR: u32 = 3;

fn floor(x: f32, z: f32) -> Point {
    Point { p: Vec3::new(x, 0.0, z), n: Vec3::Y, object: FLOOR }
}
fn wall(x: f32, y: f32) -> Point {
    Point { p: Vec3::new(x, y, -1.0), n: Vec3::Z, object: WALL }
}
fn mirror(y: f32, z: f32) -> Point {
    Point { p: Vec3::new(1.5, y, z), n: Vec3::NEG_X, object: MIRROR }
}
fn light(x: f32, z: f32) -> Point {
    Point { p: Vec3::new(x, 2.0, z), n: Vec3::NEG_Y, object: LIGHT }
}

/// Extends `path` through `points` as `Walk::run` does: each vertex's
/// `pdf_fwd` from the previous direction density, `g_prev`, and the
/// previous vertex's `pdf_rev` once the next direction is known.
fn walk(scene: &Scene, path: &mut Vec<Vertex>, mut pdf_dir: f32, points: &[Point], kind: impl Fn(&Point) -> Kind) {
    for (i, q) in points.iter().enumerate() {
        let prev = *path.last().unwrap();
        let arrival = (q.p - prev.p()).normalize();
        let kind = kind(q);
        let material = if let Kind::Surface(o) = kind { scene.material_at(o, q.p, glam::Vec2::ZERO) } else { 0 };
        let mut v = Vertex {
            kind,
            sh: Shading::new(q.p, q.n, q.n, arrival),
            beta: Spectrum::ONE,
            delta: false,
            glossy: false,
            collapsed: false,
            pdf_fwd: 0.0,
            pdf_rev: 0.0,
            g_prev: 0.0,
            outside: None,
            uv: glam::Vec2::ZERO,
            material,
        };
        v.pdf_fwd = to_area(scene, pdf_dir, &prev, &v);
        v.g_prev = to_area(scene, 1.0, &v, &prev);
        path.push(v);
        if let Some(next) = points.get(i + 1) {
            // The walk samples the direction to `next` here: a delta lobe
            // marks the vertex and leaves both densities 0.
            let wi = v.sh.frame.to_local((next.p - q.p).normalize());
            let n = path.len();
            path[n - 1].delta = scene.bsdf(q.object).is_delta();
            path[n - 2].pdf_rev = pdf_at(scene, &v, wi, v.sh.wo) * v.g_prev;
            pdf_dir = pdf_at(scene, &v, v.sh.wo, wi);
        }
    }
}

/// The camera subpath through `path` (the light's point last, as a surface
/// hit on the emitter) and the light subpath back along it.
fn subpaths(scene: &Scene, path: &[Point]) -> (Vec<Vertex>, Vec<Vertex>) {
    let cam = &scene.camera;
    let mut camera = vec![Vertex::at_point(Kind::Camera, cam.eye(), cam.forward(), Spectrum::ONE, 1.0)];
    walk(scene, &mut camera, cam.pdf_dir((path[0].p - cam.eye()).normalize()), path, |q| Kind::Surface(q.object));
    let back: Vec<Point> = path.iter().rev().copied().collect();
    let (y0, rest) = back.split_first().unwrap();
    let l = scene.light(0);
    let (pdf_pos, pdf_dir) = l.pdf_le(y0.p, y0.n, (rest[0].p - y0.p).normalize());
    let mut light = vec![Vertex::at_point(Kind::Light(0), y0.p, y0.n, Spectrum::ONE, scene.light_pmf(0) * pdf_pos)];
    walk(scene, &mut light, pdf_dir, rest, |q| Kind::Surface(q.object));
    (camera, light)
}

/// The MIS weight BDPT gives strategy `(s, t)` for the full path, with the
/// densities the connection overrides computed as `connect.rs` computes them.
fn weight(scene: &Scene, camera: &[Vertex], light: &[Vertex], s: usize, t: usize) -> f32 {
    let cam = &scene.camera;
    let full = crate::spectral::Lambdas::full();
    if t == 1 {
        // connect_camera: y_{s-1} seen by the eye.
        let qs = &light[s - 1];
        let w = (cam.eye() - qs.p()).normalize();
        let qs_rev = to_area(scene, cam.pdf_dir(-w), &camera[0], qs);
        let qsm_rev = if s >= 2 { pdf_at(scene, qs, qs.sh.frame.to_local(w), qs.sh.wo) * qs.g_prev } else { 0.0 };
        return mis_weight(scene, camera, 1, light, s, Overrides { pt_rev: 0.0, ptm_rev: 0.0, qs_rev, qsm_rev });
    }
    let (pt, ptm) = (&camera[t - 1], &camera[t - 2]);
    match s {
        0 => {
            // The camera subpath hits the emitter.
            let index = scene.emitter(LIGHT).unwrap();
            let l = scene.light(index);
            let dir = (pt.p() - ptm.p()).normalize();
            let (pdf_pos, pdf_dir) = l.pdf_le(pt.p(), pt.sh.n, -dir);
            let as_light = Vertex { kind: Kind::Light(index), ..*pt };
            let o = Overrides {
                pt_rev: scene.light_pmf(index) * pdf_pos,
                ptm_rev: to_area(scene, pdf_dir, &as_light, ptm),
                qs_rev: 0.0,
                qsm_rev: 0.0,
            };
            mis_weight(scene, &camera[..t], t, &[], 0, o)
        }
        1 => {
            // Next-event estimation: the light's point sampled afresh.
            let y = light[0];
            let wi_world = (y.p() - pt.p()).normalize();
            let wi = pt.sh.frame.to_local(wi_world);
            let bxdf = scene.bsdf(match pt.kind {
                Kind::Surface(o) => o,
                _ => unreachable!(),
            });
            let out = scene.outside(None);
            let y = Vertex::at_point(Kind::Light(0), y.p(), y.sh.n, Spectrum::ONE, y.pdf_fwd);
            let o = Overrides {
                pt_rev: pdf_light(scene, &y, pt),
                ptm_rev: bxdf.pdf_within(wi, pt.sh.wo, &full, out) * pt.g_prev,
                qs_rev: to_area(scene, bxdf.pdf_within(pt.sh.wo, wi, &full, out), pt, &y),
                qsm_rev: 0.0,
            };
            mis_weight(scene, &camera[..t], t, std::slice::from_ref(&y), 1, o)
        }
        _ => {
            let qs = &light[s - 1];
            let d = qs.p() - pt.p();
            let d2 = d.length_squared();
            let w = d / d2.sqrt();
            let (wi_p, wi_q) = (pt.sh.frame.to_local(w), qs.sh.frame.to_local(-w));
            let o = Overrides {
                pt_rev: pdf_at(scene, qs, qs.sh.wo, wi_q) * w.dot(pt.sh.n).abs() / d2,
                qs_rev: pdf_at(scene, pt, pt.sh.wo, wi_p) * w.dot(qs.sh.n).abs() / d2,
                ptm_rev: pdf_at(scene, pt, wi_p, pt.sh.wo) * pt.g_prev,
                qsm_rev: pdf_at(scene, qs, wi_q, qs.sh.wo) * qs.g_prev,
            };
            mis_weight(scene, &camera[..t], t, &light[..s], s, o)
        }
    }
}

/// The area density of each strategy `s` (`t = k + 2 − s`) for the path
/// eye, z_1 … z_{k+1} (z_{k+1} on the light), from the geometry alone, in
/// f64: from the camera side, z_1 by the camera's `1 / (A cos³θ)` per solid
/// angle (A the film's area at distance 1) and each later z_i by the cosine
/// lobe `cos/π` at z_{i−1}; from the light side, z_{k+1} uniform on the
/// light (1/area) and z_k by its cosine lobe, each earlier z_i by `cos/π` at
/// z_{i+1}; each density per solid angle times `|cos| / d²` at its vertex.
/// Strategy s takes z_t … z_{k+1} from the light and z_1 … z_{t−1} from the camera.
/// A vertex reached from a mirror at z_`delta` (either way) counts 1: the
/// delta factor and its conversion to area are left out of every
/// strategy's density alike (Veach §10.3.5; pbrt-v4 does the same).
fn independent_densities(eye: Vec3, forward: Vec3, fov_deg: f64, path: &[Point], delta: Option<usize>) -> Vec<f64> {
    let z: Vec<(glam::DVec3, glam::DVec3)> = std::iter::once((eye.as_dvec3(), forward.as_dvec3()))
        .chain(path.iter().map(|q| (q.p.as_dvec3(), q.n.as_dvec3())))
        .collect();
    let m = z.len() - 1; // z_m is on the light
    let unit = |a: usize, b: usize| (z[b].0 - z[a].0).normalize();
    let d2 = |a: usize, b: usize| (z[b].0 - z[a].0).length_squared();
    let cos = |at: usize, to: usize| z[at].1.dot(unit(at, to)).abs();
    let tan = (fov_deg.to_radians() / 2.0).tan();
    let film_area = 4.0 * tan * tan;
    let fwd: Vec<f64> = (0..=m)
        .map(|i| match i {
            0 => f64::NAN,
            1 => {
                let c = unit(0, 1).dot(forward.as_dvec3());
                1.0 / (film_area * c * c * c) * cos(1, 0) / d2(0, 1)
            }
            _ if delta == Some(i - 1) => 1.0,
            _ => cos(i - 1, i) / PI * cos(i, i - 1) / d2(i - 1, i),
        })
        .collect();
    let rev: Vec<f64> = (0..=m)
        .map(|i| {
            if i == 0 {
                f64::NAN
            } else if i == m || delta == Some(i + 1) {
                1.0 // the light's area is 1; a mirror's delta counts 1
            } else {
                cos(i + 1, i) / PI * cos(i, i + 1) / d2(i, i + 1)
            }
        })
        .collect();
    (0..=m)
        .map(|s| {
            let t = m + 1 - s;
            (t..=m).map(|i| rev[i]).product::<f64>() * (1..t).map(|i| fwd[i]).product::<f64>()
        })
        .collect()
}

/// For diffuse paths of 1, 2 and 3 surface vertices between the eye and an
/// area light (2 to 4 segments), and two paths with a mirror vertex, every
/// strategy that can make the path (`s = 0 … k + 1`, `t = k + 2 − s`, but
/// not a connection at the mirror): BDPT's weights sum to 1 within 1e-5,
/// and each equals `p_s² / Σ_j p_j²` of the independent densities within
/// 1e-4 relative (f32 products of a few ratios).
#[test]
fn mis_weights_are_the_power_heuristic_of_the_path_densities() {
    let scene = load_scene_str(ROOM, std::path::Path::new("room.ron"), &Default::default()).unwrap();
    assert_eq!(scene.emitter(LIGHT), Some(0));
    let paths: [(&[Point], Option<usize>); 5] = [
        (&[floor(0.3, 0.2), light(0.1, -0.2)], None),
        (&[floor(0.3, 0.2), wall(-0.4, 0.9), light(0.2, 0.1)], None),
        (&[wall(0.2, 1.2), floor(-0.3, 0.4), wall(0.5, 0.6), light(-0.1, 0.2)], None),
        // Through the mirror (z_2): only (s, t) = (0, 4) and (3, 1) can make it.
        (&[floor(0.3, 0.2), mirror(1.0, 0.3), light(0.2, 0.1)], Some(2)),
        // Mirror at z_2 between two diffuse vertices: (0, 5), (1, 4), (4, 1).
        (&[floor(0.3, 0.2), mirror(1.0, 0.3), wall(0.5, 0.6), light(-0.1, 0.2)], Some(2)),
    ];
    for (path, delta) in paths {
        let k = path.len() - 1;
        let (camera, light) = subpaths(&scene, path);
        let p = independent_densities(Vec3::new(0.0, 1.0, 3.0), Vec3::NEG_Z, 60.0, path, delta);
        // A strategy whose connection ends at the delta vertex cannot make the
        // path (BDPT's connections check `connectible` and skip it).
        let valid = |s: usize| {
            let t = k + 2 - s;
            delta != Some(t - 1) && delta != Some(t)
        };
        let sum_p2: f64 = (0..=k + 1).filter(|&s| valid(s)).map(|s| p[s] * p[s]).sum();
        let mut total = 0.0f64;
        for s in 0..=k + 1 {
            let t = k + 2 - s;
            if !valid(s) {
                let end = if s == 0 {
                    &camera[t - 1]
                } else if t == 1 {
                    &light[s - 1]
                } else if delta == Some(t - 1) {
                    &camera[t - 1]
                } else {
                    &light[s - 1]
                };
                assert!(!connectible(&scene, end), "k {k}, ({s}, {t}): a connection at the mirror");
                continue;
            }
            let got = weight(&scene, &camera, &light, s, t) as f64;
            let want = p[s] * p[s] / sum_p2;
            eprintln!("{k} surface vertices, (s, t) = ({s}, {t}): weight {got:.6}, power heuristic {want:.6}");
            assert!((got - want).abs() <= 1e-4 * want.max(1e-3), "k {k}, ({s}, {t}): {got} vs {want}");
            total += got;
        }
        assert!((total - 1.0).abs() < 1e-5, "k {k}: the weights sum to {total}");
    }
}
