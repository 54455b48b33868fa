//! Surface (u, v) coordinates of a hit: where a texture (issue 35) is looked
//! up. They are computed on demand from the hit, not during traversal, so a
//! scene without textures pays nothing for them: [`Shape::uv`] is called by
//! [`crate::scene::Scene::uv`] only where a material asks.
//!
//! The parameterisation of each shape (scene axes, +y up), every value in
//! [0, 1] unless said otherwise:
//!
//! | shape | u | v |
//! |---|---|---|
//! | `Quad` | `a` in `origin + a·edge_u + b·edge_v` | `b` |
//! | `Sphere`, `Bubble` (both spheres) | longitude `φ / 2π`, `φ` from +x towards +z about the centre | latitude `θ / π`, 0 at the bottom pole (−y), 1 at the top (+y) |
//! | `Disk` | angle `φ / 2π` about the normal, from the tangent of `Frame::from_z(normal)` | radius `r / radius`: 0 at the centre, 1 on the rim |
//! | `Cuboid` | on a face perpendicular to axis `k`: the position along axis `(k + 1) mod 3`, over the box's extent | along axis `(k + 2) mod 3` (x faces: (y, z); y faces: (z, x); z faces: (x, y)) |
//! | `Plane` | distance along the tangent of `Frame::from_z(normal)` from `point`, in scene units (not wrapped) | along the bitangent |
//! | `Mesh` | the per-vertex texture coordinates interpolated, when the mesh has them (inline `Triangles(uvs: ...)`, OBJ `vt`, PLY `s t`, `u v`, `texture_u texture_v` or `texture_s texture_t`); else pbrt's default per triangle, (0, 0), (1, 0), (1, 1) at its three vertices | as u |
//!
//! An `Instance` (a group's mesh placed by an affine map) is parameterised as its
//! mesh, at the hit's point in group space.
//!
//! A mesh hit's barycentric coordinates are recovered from the hit point and
//! the triangle's vertices (the hit record does not carry them).

use std::f32::consts::TAU;

use glam::{Vec2, Vec3};

use super::{Cuboid, Disk, Mesh, Plane, Quad, Shape};
use crate::geometry::{Frame, Hit};

impl Shape {
    /// The (u, v) coordinates of `hit`, a hit on this shape (see the module docs).
    pub fn uv(&self, hit: &Hit) -> Vec2 {
        match self {
            Shape::Sphere(s) => sphere_uv(s.center, hit.p),
            Shape::Bubble(s) => sphere_uv(s.center, hit.p),
            Shape::Plane(s) => plane_uv(s, hit.p),
            Shape::Disk(s) => disk_uv(s, hit.p),
            Shape::Cuboid(s) => cuboid_uv(s, hit.p),
            Shape::Quad(s) => quad_uv(s, hit.p),
            Shape::Mesh(m) => mesh_uv(m, hit.prim, hit.p),
            Shape::Instance(i) => mesh_uv(i.mesh(), hit.prim, i.group_point(hit.p)),
        }
    }
}

/// Longitude and latitude of `p` about `center`.
fn sphere_uv(center: Vec3, p: Vec3) -> Vec2 {
    let d = (p - center).normalize_or_zero();
    let phi = d.z.atan2(d.x);
    let u = if phi < 0.0 { phi / TAU + 1.0 } else { phi / TAU };
    let v = (-d.y).clamp(-1.0, 1.0).acos() / std::f32::consts::PI;
    Vec2::new(u.min(1.0), v)
}

fn plane_uv(s: &Plane, p: Vec3) -> Vec2 {
    let f = Frame::from_z(s.normal);
    let d = p - s.point;
    Vec2::new(d.dot(f.s), d.dot(f.t))
}

fn disk_uv(s: &Disk, p: Vec3) -> Vec2 {
    let f = Frame::from_z(s.normal);
    let d = p - s.center;
    let (x, y) = (d.dot(f.s), d.dot(f.t));
    let phi = y.atan2(x);
    let u = if phi < 0.0 { phi / TAU + 1.0 } else { phi / TAU };
    Vec2::new(u.min(1.0), ((x * x + y * y).sqrt() / s.radius).min(1.0))
}

fn cuboid_uv(s: &Cuboid, p: Vec3) -> Vec2 {
    let ext = s.max - s.min;
    let local = (p - s.min) / ext;
    // The face: the axis along which the point lies closest to a side.
    let dist = local.min(Vec3::ONE - local).abs();
    let k = if dist.x <= dist.y && dist.x <= dist.z {
        0
    } else if dist.y <= dist.z {
        1
    } else {
        2
    };
    Vec2::new(local[(k + 1) % 3], local[(k + 2) % 3]).clamp(Vec2::ZERO, Vec2::ONE)
}

fn quad_uv(s: &Quad, p: Vec3) -> Vec2 {
    let (eu, ev, d) = (s.edge_u, s.edge_v, p - s.origin);
    let (uu, uv, vv) = (eu.dot(eu), eu.dot(ev), ev.dot(ev));
    let (du, dv) = (d.dot(eu), d.dot(ev));
    let det = uu * vv - uv * uv;
    Vec2::new((du * vv - dv * uv) / det, (dv * uu - du * uv) / det).clamp(Vec2::ZERO, Vec2::ONE)
}

/// Barycentric coordinates `(b0, b1, b2)` of `p` in triangle `v`.
fn barycentric(v: [Vec3; 3], p: Vec3) -> Vec3 {
    let (e1, e2, d) = (v[1] - v[0], v[2] - v[0], p - v[0]);
    let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let (dp1, dp2) = (d.dot(e1), d.dot(e2));
    let det = d11 * d22 - d12 * d12;
    let b1 = ((dp1 * d22 - dp2 * d12) / det).clamp(0.0, 1.0);
    let b2 = ((dp2 * d11 - dp1 * d12) / det).clamp(0.0, 1.0 - b1);
    Vec3::new(1.0 - b1 - b2, b1, b2)
}

fn mesh_uv(m: &Mesh, prim: u32, p: Vec3) -> Vec2 {
    let b = barycentric(m.triangle(prim), p);
    Vec2::from(m.uv(prim, b.y, b.z))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Ray;
    use crate::shape::Sphere;

    /// The hit of a ray from `from` towards `to` on `shape`.
    fn hit(shape: &Shape, from: Vec3, to: Vec3) -> Hit {
        let ray = Ray::new(from, (to - from).normalize());
        shape.intersect(&ray, f32::INFINITY).expect("the ray hits the shape")
    }

    fn close(a: Vec2, b: Vec2) -> bool {
        (a - b).abs().max_element() < 1e-4
    }

    #[test]
    fn quad_uv_is_the_point_s_edge_coordinates() {
        let q = Shape::Quad(Quad::new(Vec3::new(1.0, 0.0, 0.0), Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.5, 0.0, 3.0)));
        for (a, b) in [(0.25f32, 0.5f32), (0.9, 0.1), (0.5, 0.99)] {
            let target = Vec3::new(1.0, 0.0, 0.0) + a * Vec3::new(2.0, 0.0, 0.0) + b * Vec3::new(0.5, 0.0, 3.0);
            let h = hit(&q, target + Vec3::new(0.3, 2.0, -0.2), target);
            assert!(close(q.uv(&h), Vec2::new(a, b)), "({a}, {b}) -> {}", q.uv(&h));
        }
    }

    #[test]
    fn sphere_uv_runs_from_the_bottom_pole_and_from_plus_x_towards_plus_z() {
        let c = Vec3::new(0.5, -1.0, 2.0);
        let s = Shape::Sphere(Sphere::new(c, 2.0));
        let cases = [
            (Vec3::X, Vec2::new(0.0, 0.5)),
            (Vec3::Z, Vec2::new(0.25, 0.5)),
            (-Vec3::X, Vec2::new(0.5, 0.5)),
            (-Vec3::Z, Vec2::new(0.75, 0.5)),
            (Vec3::new(1.0, 1.0, 0.0).normalize(), Vec2::new(0.0, 0.75)),
        ];
        for (dir, want) in cases {
            let h = hit(&s, c + dir * 5.0, c);
            let got = s.uv(&h);
            // u = 0 and u = 1 are the same seam.
            let seam = (got.x - 1.0).abs() < 1e-4 && want.x == 0.0;
            assert!(close(got, want) || (seam && (got.y - want.y).abs() < 1e-4), "{dir}: {got} want {want}");
        }
        let top = s.uv(&hit(&s, c + Vec3::Y * 5.0, c));
        let bottom = s.uv(&hit(&s, c - Vec3::Y * 5.0, c));
        assert!((top.y - 1.0).abs() < 1e-3 && bottom.y.abs() < 1e-3, "{top} {bottom}");
    }

    #[test]
    fn disk_uv_is_angle_and_radius() {
        let d = Disk { center: Vec3::new(0.0, 1.0, 0.0), normal: Vec3::Y, radius: 2.0 };
        let f = Frame::from_z(Vec3::Y);
        let s = Shape::Disk(d);
        for (r, phi) in [(0.5f32, 0.3f32), (1.5, 2.0), (1.0, 4.0)] {
            let target = Vec3::new(0.0, 1.0, 0.0) + r * (phi.cos() * f.s + phi.sin() * f.t);
            let got = s.uv(&hit(&s, target + Vec3::new(0.1, 3.0, 0.2), target));
            assert!(close(got, Vec2::new(phi / TAU, r / 2.0)), "{got}");
        }
    }

    #[test]
    fn cuboid_uv_spans_each_face() {
        let b = Shape::Cuboid(Cuboid { min: Vec3::new(-1.0, 0.0, -2.0), max: Vec3::new(1.0, 4.0, 2.0) });
        // Top face (y): u along z, v along x.
        let got = b.uv(&hit(&b, Vec3::new(0.5, 9.0, -1.0), Vec3::new(0.5, 4.0, -1.0)));
        assert!(close(got, Vec2::new(0.25, 0.75)), "{got}");
        // Front face (+z): u along x, v along y.
        let got = b.uv(&hit(&b, Vec3::new(-0.5, 3.0, 9.0), Vec3::new(-0.5, 3.0, 2.0)));
        assert!(close(got, Vec2::new(0.25, 0.75)), "{got}");
        // Side face (-x): u along y, v along z.
        let got = b.uv(&hit(&b, Vec3::new(-9.0, 1.0, 1.0), Vec3::new(-1.0, 1.0, 1.0)));
        assert!(close(got, Vec2::new(0.25, 0.75)), "{got}");
    }

    #[test]
    fn plane_uv_is_in_scene_units() {
        let p = Shape::Plane(Plane { point: Vec3::ZERO, normal: Vec3::Y });
        let f = Frame::from_z(Vec3::Y);
        let target = 3.0 * f.s - 2.5 * f.t;
        let got = p.uv(&hit(&p, target + Vec3::Y, target));
        assert!(close(got, Vec2::new(3.0, -2.5)), "{got}");
    }

    #[test]
    fn barycentric_recovers_the_weights() {
        let v = [Vec3::new(0.0, 0.0, 0.0), Vec3::new(2.0, 0.0, 1.0), Vec3::new(0.0, 3.0, 0.5)];
        let w = Vec3::new(0.2, 0.5, 0.3);
        let p = w.x * v[0] + w.y * v[1] + w.z * v[2];
        assert!((barycentric(v, p) - w).abs().max_element() < 1e-5);
        // The corners get pbrt's default (0, 0), (1, 0), (1, 1).
        let uv = |p| {
            let b = barycentric(v, p);
            Vec2::new(b.y + b.z, b.z)
        };
        assert!(close(uv(v[0]), Vec2::ZERO) && close(uv(v[1]), Vec2::X) && close(uv(v[2]), Vec2::ONE));
    }
}
