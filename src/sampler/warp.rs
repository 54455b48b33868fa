//! Warps from uniform numbers to directions and points, with their pdfs, and
//! the multiple importance sampling weight.
//!
//! Conventions: directions in a local frame where the normal is +z; pdfs are
//! per unit solid angle unless the name says `_area`.

use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

/// `(cos x, sin x)` for `|x| <= π/4`, by the minimax polynomials of Cephes'
/// `sinf`/`cosf` kernels (Moshier): within 2 ulp there (tested against `f64`),
/// and inline, where the C library's `sincosf` was a call costing about 3% of
/// a Cornell-box render. The warps only need angles they can reduce exactly
/// to this range.
#[inline(always)]
fn cos_sin_quarter(x: f32) -> (f32, f32) {
    let z = x * x;
    let sin = ((-1.951_529_6e-4 * z + 8.332_161e-3) * z - 1.666_665_5e-1) * z * x + x;
    let cos = ((2.443_315_7e-5 * z - 1.388_731_6e-3) * z + 4.166_664_6e-2) * z * z - 0.5 * z + 1.0;
    (cos, sin)
}

/// `(cos 2πu, sin 2πu)` for `u` in [0, 1]: `4u` is split exactly into the
/// nearest quadrant `k` and a remainder in [-1/2, 1/2], whose angle goes to
/// [`cos_sin_quarter`]; the quadrant swaps and negates.
#[inline(always)]
pub fn cos_sin_2pi(u: f32) -> (f32, f32) {
    let v = 4.0 * u;
    let k = v.round();
    let (c, s) = cos_sin_quarter((v - k) * std::f32::consts::FRAC_PI_2);
    match (k as i32) & 3 {
        0 => (c, s),
        1 => (-s, c),
        2 => (-c, -s),
        _ => (s, -c),
    }
}

/// Maps [0,1)² to the unit disk, area-preserving (Shirley-Chiu concentric map).
#[inline]
pub fn concentric_disk(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    if o.x == 0.0 && o.y == 0.0 {
        return Vec2::ZERO;
    }
    // θ = π/4 · (y/x), or π/2 − π/4 · (x/y): cos and sin of the latter are
    // sin and cos of π/4 · (x/y).
    if o.x.abs() > o.y.abs() {
        let (c, s) = cos_sin_quarter(std::f32::consts::FRAC_PI_4 * (o.y / o.x));
        o.x * Vec2::new(c, s)
    } else {
        let (c, s) = cos_sin_quarter(std::f32::consts::FRAC_PI_4 * (o.x / o.y));
        o.y * Vec2::new(s, c)
    }
}

/// Cosine-weighted direction on the +z hemisphere (Malley's method).
#[inline]
pub fn cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = concentric_disk(u);
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    Vec3::new(d.x, d.y, z)
}

/// The pdf of [`cosine_hemisphere`]: cos θ / π (0 below the horizon).
#[inline]
pub fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    cos_theta.max(0.0) * FRAC_1_PI
}

/// `1 − cos θmax` of the cone a sphere subtends, from `sin² θmax = r² / d²`,
/// as `sin² / (1 + cos)`: exact to rounding at any size, where `1 − sqrt(1 − sin²)`
/// loses every digit once the sphere is smaller than about 1e-3 of its distance.
#[inline]
pub fn cone_one_minus_cos(sin2_max: f32) -> f32 {
    let sin2 = sin2_max.min(1.0);
    sin2 / (1.0 + (1.0 - sin2).max(0.0).sqrt())
}

/// Uniform direction on the unit sphere.
#[inline]
pub fn uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (cos_phi, sin_phi) = cos_sin_2pi(u.y);
    Vec3::new(r * cos_phi, r * sin_phi, z)
}

/// The power heuristic with β = 2 (Veach 1997): weight of strategy `f` against `g`,
/// each given as (number of samples × pdf).
#[inline]
pub fn power_heuristic(f: f32, g: f32) -> f32 {
    let (f2, g2) = (f * f, g * g);
    let sum = f2 + g2;
    if sum.is_normal() && sum.is_finite() {
        return f2 / sum;
    }
    // Squares that overflow or underflow f32 (densities beyond about 1.8e19 or
    // below 1e-19: rare, a point seen at a grazing angle, a tiny light): the
    // ratio of the squares of `f / m` and `g / m`, `m` the larger density, in
    // f64. An infinite density is a delta strategy and takes the whole weight.
    if f.is_infinite() {
        return 1.0;
    }
    let m = f.max(g) as f64;
    if m.is_nan() || m <= 0.0 || m.is_infinite() {
        return 0.0;
    }
    let (a, b) = (f as f64 / m, g as f64 / m);
    (a * a / (a * a + b * b)) as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::Sampler;

    /// E[cos θ] under the cosine and uniform-sphere warps matches its closed
    /// form; the tolerances cover 40k samples (std. error < 3e-3).
    #[test]
    fn warps_land_where_their_pdfs_say() {
        let mut s = Sampler::new(1, 2, 3);
        let n = 40_000;
        let (mut mean_z_cos, mut mean_z_sph) = (0.0f64, 0.0f64);
        for _ in 0..n {
            let d = cosine_hemisphere(s.next_2d());
            assert!((d.length() - 1.0).abs() < 1e-4 && d.z >= 0.0);
            mean_z_cos += d.z as f64;
            s.next_2d();
            mean_z_sph += uniform_sphere(s.next_2d()).z as f64;
        }
        // E[cos θ] for the cosine pdf is 2/3; for the sphere 0.
        assert!((mean_z_cos / n as f64 - 2.0 / 3.0).abs() < 5e-3);
        assert!((mean_z_sph / n as f64).abs() < 1e-2);
    }

    /// The inline sine and cosine against `f64`: within 2 ulp of 1 (absolute
    /// 2.4e-7) over the whole range, on a fine grid and at the quadrant ends.
    #[test]
    fn cos_sin_match_f64() {
        let tol = 2.0 * f32::EPSILON;
        let grid = (0..=200_000).map(|i| i as f32 / 200_000.0);
        for u in grid.chain([0.125, 0.375, 0.625, 0.875, 1.0 - f32::EPSILON / 2.0]) {
            let (c, s) = cos_sin_2pi(u);
            let a = std::f64::consts::TAU * u as f64;
            assert!((c as f64 - a.cos()).abs() < tol as f64 && (s as f64 - a.sin()).abs() < tol as f64, "{u}: {c} {s}");
        }
        for i in -1000..=1000 {
            let x = std::f32::consts::FRAC_PI_4 * i as f32 / 1000.0;
            let (c, s) = cos_sin_quarter(x);
            assert!(
                (c as f64 - (x as f64).cos()).abs() < tol as f64 && (s as f64 - (x as f64).sin()).abs() < tol as f64
            );
        }
    }

    #[test]
    fn power_heuristic_weights_sum_to_one() {
        for (a, b) in [(1.0, 2.0), (0.3, 0.0), (5.0, 5.0)] {
            assert!((power_heuristic(a, b) + power_heuristic(b, a) - 1.0).abs() < 1e-6);
        }
        assert_eq!(power_heuristic(f32::INFINITY, 1.0), 1.0);
    }

    /// The power heuristic by value: f²/(f² + g²) (evaluated here in f64) for
    /// densities over 30 orders of magnitude, equal, unequal, zero on either
    /// side, and infinite (a delta strategy: it takes the whole weight, the
    /// other none). Within 1e-6 absolute (f32), and each pair's two weights sum
    /// to 1 within 1e-6 unless both are 0.
    #[test]
    fn power_heuristic_is_the_ratio_of_squares() {
        let finite = [0.0f32, 1e-15, 1e-6, 0.01, 0.3, 1.0, 2.0, 3.0, 4.0, 7.5, 1e3, 1e6, 1e15];
        for &a in &finite {
            for &b in &finite {
                let (a2, b2) = ((a as f64).powi(2), (b as f64).powi(2));
                let want = if a2 + b2 == 0.0 { 0.0 } else { a2 / (a2 + b2) };
                let got = power_heuristic(a, b) as f64;
                assert!((got - want).abs() < 1e-6, "w({a}, {b}) = {got}, want {want}");
                if a > 0.0 || b > 0.0 {
                    let sum = got + power_heuristic(b, a) as f64;
                    assert!((sum - 1.0).abs() < 1e-6, "w({a}, {b}) + w({b}, {a}) = {sum}");
                }
            }
            if a < f32::INFINITY {
                assert_eq!(power_heuristic(f32::INFINITY, a), 1.0, "a delta strategy against {a}");
                assert_eq!(power_heuristic(a, f32::INFINITY), 0.0, "{a} against a delta strategy");
            }
        }
        // Exact values: 1/(1 + 4), 9/25, 16/25, ½.
        assert_eq!(power_heuristic(1.0, 2.0), 0.2);
        assert!((power_heuristic(3.0, 4.0) - 0.36).abs() < 1e-7 && (power_heuristic(4.0, 3.0) - 0.64).abs() < 1e-7);
        assert_eq!(power_heuristic(5.0, 5.0), 0.5);
    }

    /// Densities whose squares leave f32's range: above about 1.8e19 (f²
    /// overflows) or below about 1e-23 (f² underflows to 0), the weights no
    /// longer summed to 1: w(1e20, 1e20) = 1 for both orders (want ½ each),
    /// w(1e20, 1e19) = 1 (want 0.990), w(1e-25, 1e-25) = 0 for both orders
    /// (want ½), before `power_heuristic` fell back to scaling by the larger
    /// density where the squares leave f32's range.
    #[test]
    fn power_heuristic_survives_extreme_densities() {
        for (a, b) in [(1e20f32, 1e20f32), (1e20, 1e19), (1e30, 1.0), (1e-25, 1e-25), (1e-25, 1e-26), (1e-30, 1e-31)] {
            let (a2, b2) = ((a as f64).powi(2), (b as f64).powi(2));
            let want = a2 / (a2 + b2);
            let got = power_heuristic(a, b) as f64;
            assert!((got - want).abs() < 1e-6, "w({a}, {b}) = {got}, want {want}");
            let sum = got + power_heuristic(b, a) as f64;
            assert!((sum - 1.0).abs() < 1e-6, "w({a}, {b}) + w({b}, {a}) = {sum}");
        }
    }
}
