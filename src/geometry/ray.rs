//! Rays, and the robust spawning of secondary rays from surface points.
//!
//! A hit point computed in floating point lies a little off the true surface,
//! so a ray leaving it could re-hit the surface it leaves ("shadow acne").
//! [`offset_ray_origin`] moves the origin along the normal, to the side the new
//! ray goes, by a bound on that error. The bound is relative to the magnitude of
//! the point's coordinates (as rounding error is), so scenes behave the same at
//! any scale and any distance from the origin.

use glam::Vec3;

/// A ray `origin + t * dir`, with `dir` of unit length.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    /// Origin.
    pub origin: Vec3,
    /// Unit direction.
    pub dir: Vec3,
}

/// Relative error bound assumed for the coordinates of a hit point: 2^-20, i.e. about
/// 8 units in the last place of the largest coordinate. The shapes of this module
/// refine their hit points onto the surface (sphere: re-projection; flat shapes and
/// triangles: projection or barycentric interpolation), which keeps their error to a
/// few ulps of the largest coordinate of the point (or, for triangles, of its vertices).
pub const ORIGIN_REL_ERROR: f32 = 1.0 / 1_048_576.0;

/// Absolute floor added to the offset, for points at (or extremely near) the
/// world origin where the relative bound vanishes. Far below any sensible scene scale.
pub const ORIGIN_ABS_ERROR: f32 = 1e-20;

/// Relative amount by which [`Ray::spawn_to`] stops short of its target.
pub const SHADOW_EPSILON: f32 = 1e-4;

/// Conservative bound on the absolute error of each coordinate of a hit point `p`.
#[inline]
fn point_error(p: Vec3) -> f32 {
    p.abs().max_element() * ORIGIN_REL_ERROR + ORIGIN_ABS_ERROR
}

/// The next representable f32 above `x` (for finite `x`).
#[inline]
fn next_up(x: f32) -> f32 {
    if x.is_nan() || x == f32::INFINITY {
        return x;
    }
    let b = x.to_bits();
    if x == 0.0 {
        return f32::from_bits(1);
    }
    f32::from_bits(if x > 0.0 { b + 1 } else { b - 1 })
}

/// The next representable f32 below `x` (for finite `x`).
#[inline]
fn next_down(x: f32) -> f32 {
    -next_up(-x)
}

/// The origin for a ray leaving surface point `p` (unit geometric normal `n`) in
/// direction `dir`: `p` moved along `±n`, towards the side `dir` points to, by
/// `d = max(|p.x|, |p.y|, |p.z|) * 2^-20 + 1e-20` (see `ORIGIN_REL_ERROR`), each
/// coordinate then rounded one more ulp away from `p`. Since the error bound scales
/// with the coordinates, a scene scaled by 1e-4 or 1e4 or moved far from the origin
/// behaves the same.
#[inline(always)]
pub fn offset_ray_origin(p: Vec3, n: Vec3, dir: Vec3) -> Vec3 {
    let d = point_error(p);
    let mut offset = n * d;
    if dir.dot(n) < 0.0 {
        offset = -offset;
    }
    let mut o = p + offset;
    for i in 0..3 {
        if offset[i] > 0.0 {
            o[i] = next_up(o[i]);
        } else if offset[i] < 0.0 {
            o[i] = next_down(o[i]);
        }
    }
    o
}

impl Ray {
    /// A ray from `origin` along `dir` (which must be unit length).
    #[inline]
    pub fn new(origin: Vec3, dir: Vec3) -> Ray {
        Ray { origin, dir }
    }

    /// The point at parameter `t`.
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.dir * t
    }

    /// A ray leaving surface point `p` (geometric normal `n`) in direction `dir`, with its
    /// origin offset along ±n to the side `dir` points to, robust against self-intersection.
    #[inline(always)]
    pub fn spawn(p: Vec3, n: Vec3, dir: Vec3) -> Ray {
        Ray { origin: offset_ray_origin(p, n, dir), dir }
    }

    /// A shadow ray from surface point `p` (normal `n`) towards point `target`; returns
    /// the ray and the `t_max` to use.
    ///
    /// - A target on a surface (`target_n` non-zero: an area light's point, a BDPT
    ///   vertex) must not hit its own surface: the distance is shortened by
    ///   `SHADOW_EPSILON` relative and by the target's own coordinate error bound.
    /// - A target that is a free point (`target_n` zero: a point or spot light, the
    ///   eye) has no surface to miss, so the ray runs the whole distance: any surface
    ///   before it blocks, however close to it (a point light 1e-6 inside a closed box
    ///   lights nothing outside; shortening by 1e-4 relative let it leak).
    ///
    /// Coincident points give `t_max = 0`.
    #[inline(always)]
    pub fn spawn_to(p: Vec3, n: Vec3, target: Vec3, target_n: Vec3) -> (Ray, f32) {
        let origin = offset_ray_origin(p, n, target - p);
        let d = target - origin;
        let dist = d.length();
        if !(dist > 0.0) || !dist.is_finite() {
            return (Ray { origin, dir: n }, 0.0);
        }
        let t_max =
            if target_n == Vec3::ZERO { dist } else { dist * (1.0 - SHADOW_EPSILON) - 2.0 * point_error(target) };
        (Ray { origin, dir: d / dist }, t_max.max(0.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offset_goes_to_the_side_of_dir_and_scales() {
        let n = Vec3::Y;
        for s in [1e-4f32, 1.0, 1e4] {
            let p = Vec3::new(1.0, 2.0, 3.0) * s;
            let up = offset_ray_origin(p, n, Vec3::new(0.0, 1.0, 0.0));
            let down = offset_ray_origin(p, n, Vec3::new(0.3, -1.0, 0.0).normalize());
            assert!(up.y > p.y && down.y < p.y);
            assert_eq!(up.x, p.x);
            let rel = (up.y - p.y) / s;
            assert!(rel > 1e-6 && rel < 1e-5, "offset relative to scale {rel}");
        }
        let o = offset_ray_origin(Vec3::ZERO, Vec3::Z, Vec3::Z);
        assert!(o.z > 0.0);
    }

    #[test]
    fn spawn_to_stops_short() {
        let (r, t) = Ray::spawn_to(Vec3::ZERO, Vec3::Y, Vec3::new(0.0, 3.0, 4.0), Vec3::Z);
        assert!((r.dir.length() - 1.0).abs() < 1e-6);
        assert!(t < 5.0 && t > 4.99);
        // A free point (a point light) is reached: the ray runs the whole distance.
        let (r, t) = Ray::spawn_to(Vec3::ZERO, Vec3::Y, Vec3::new(0.0, 3.0, 4.0), Vec3::ZERO);
        assert!((r.at(t) - Vec3::new(0.0, 3.0, 4.0)).length() < 1e-6, "{t}");
        let (_, t0) = Ray::spawn_to(Vec3::ONE, Vec3::Y, Vec3::ONE, Vec3::ZERO);
        assert!((0.0..1e-4).contains(&t0));
        assert_eq!(Ray::new(Vec3::ZERO, Vec3::X).at(2.0), Vec3::new(2.0, 0.0, 0.0));
    }
}
