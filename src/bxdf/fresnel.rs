//! The Fresnel equations for dielectrics (thesis eq. 2.4) and conductors
//! (complex index), and Snell's law (thesis eq. 2.3).

use glam::Vec3;

/// Unpolarised Fresnel reflectance of a dielectric interface, thesis eq. 2.4.
/// `cos_i` is the cosine of the incident direction with the normal (negative
/// when arriving from inside); `eta` is the relative index `η_inside / η_outside`.
/// Returns 1 beyond the critical angle (total internal reflection).
#[inline]
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    let (mut cos_i, mut eta) = (cos_i.clamp(-1.0, 1.0), eta);
    if cos_i < 0.0 {
        eta = 1.0 / eta;
        cos_i = -cos_i;
    }
    let sin2_i = 1.0 - cos_i * cos_i;
    let sin2_t = sin2_i / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    // With η_i = 1 and η_t = eta after the swap above.
    let r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (r_parl * r_parl + r_perp * r_perp)
}

/// Unpolarised Fresnel reflectance of a conductor of complex index
/// `eta + i k` seen from vacuum, at incidence cosine `cos_i` (its sign is
/// ignored: a conductor reflects on both sides). The closed form with real
/// arithmetic (a² + b² = |η̃² − sin²θ|, a = Re √(η̃² − sin²θ); e.g. Lazányi and
/// Szirmay-Kalos 2005), `R_p` written without the tangent so that grazing
/// incidence gives exactly 1:
/// `R_s = (a² + b² − 2a cos θ + cos²θ) / (a² + b² + 2a cos θ + cos²θ)`,
/// `R_p = R_s (cos²θ (a² + b²) − 2a sin²θ cos θ + sin⁴θ) / (cos²θ (a² + b²) + 2a sin²θ cos θ + sin⁴θ)`.
/// With `k = 0` it is the dielectric's reflectance for `eta ≥ 1`.
#[inline]
pub fn fresnel_conductor(cos_i: f32, eta: f32, k: f32) -> f32 {
    // f64 inside: (n² − k²)² overflows f32 for indices above ~1e9.
    let (eta, k) = (eta as f64, k as f64);
    let c = (cos_i.abs() as f64).min(1.0);
    let c2 = c * c;
    let s2 = 1.0 - c2;
    let t = eta * eta - k * k - s2;
    let a2b2 = (t * t + 4.0 * eta * eta * k * k).sqrt();
    let a = (0.5 * (a2b2 + t)).max(0.0).sqrt();
    let rs_num = a2b2 - 2.0 * a * c + c2;
    let rs_den = a2b2 + 2.0 * a * c + c2;
    if rs_den.is_nan() || rs_den <= 0.0 {
        return 1.0;
    }
    let rs = rs_num / rs_den;
    let p_num = c2 * a2b2 - 2.0 * a * s2 * c + s2 * s2;
    let p_den = c2 * a2b2 + 2.0 * a * s2 * c + s2 * s2;
    let rp = if p_den > 0.0 { rs * p_num / p_den } else { rs };
    let r = 0.5 * (rs + rp);
    if r.is_finite() { r.clamp(0.0, 1.0) as f32 } else { 1.0 }
}

/// Refracts `wi` (pointing away from the surface, on either side) through a
/// surface with normal `n` and relative index `eta = η_inside / η_outside`
/// (`n` points outside). Returns the refracted direction and the relative
/// index actually crossed (`η_t / η_i`), or `None` on total internal reflection.
#[inline]
pub fn refract(wi: Vec3, n: Vec3, eta: f32) -> Option<(Vec3, f32)> {
    let mut cos_i = n.dot(wi);
    let (mut eta, mut n) = (eta, n);
    if cos_i < 0.0 {
        eta = 1.0 / eta;
        cos_i = -cos_i;
        n = -n;
    }
    let sin2_i = (1.0 - cos_i * cos_i).max(0.0);
    let sin2_t = sin2_i / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let wt = (-wi / eta + n * (cos_i / eta - cos_t)).normalize();
    Some((wt, eta))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_incidence_is_the_closed_form() {
        for eta in [1.33f32, 1.5, 2.417] {
            let want = ((eta - 1.0) / (eta + 1.0)).powi(2);
            assert!((fresnel_dielectric(1.0, eta) - want).abs() < 1e-6);
            assert!((fresnel_dielectric(-1.0, eta) - want).abs() < 1e-6, "from inside too");
        }
    }

    #[test]
    fn total_internal_reflection_beyond_the_critical_angle() {
        let eta = 1.5f32;
        let critical = (1.0 / eta).asin();
        let just_below = (critical - 1e-3).cos();
        let just_above = (critical + 1e-3).cos();
        assert!(fresnel_dielectric(-just_below, eta) < 1.0);
        assert_eq!(fresnel_dielectric(-just_above, eta), 1.0);
        let w = Vec3::new((critical + 1e-3).sin(), 0.0, -(critical + 1e-3).cos());
        assert!(refract(w, Vec3::Z, eta).is_none());
        // At grazing incidence from outside everything reflects.
        assert!((fresnel_dielectric(0.0, eta) - 1.0).abs() < 1e-6);
    }

    // The complex Fresnel equations below are independent of
    // `fresnel_conductor`'s real closed form; their complex arithmetic is the
    // thin film's.
    use crate::bxdf::thin_film::C;

    /// The textbook amplitude coefficients with complex numbers:
    /// cos θt = √(1 − sin²θ / η̃²), r_s = (cos θ − η̃ cos θt) / (cos θ + η̃ cos θt),
    /// r_p = (η̃ cos θ − cos θt) / (η̃ cos θ + cos θt), R = (|r_s|² + |r_p|²) / 2.
    fn complex_fresnel(cos: f64, n: f64, k: f64) -> f64 {
        let eta = C(n, k);
        let ci = C(cos, 0.0);
        let sin2 = C(1.0 - cos * cos, 0.0);
        let ct = C(1.0, 0.0).sub(sin2.div(eta.mul(eta))).sqrt();
        let rs = ci.sub(eta.mul(ct)).div(ci.add(eta.mul(ct)));
        let rp = eta.mul(ci).sub(ct).div(eta.mul(ci).add(ct));
        0.5 * (rs.norm2() + rp.norm2())
    }

    /// The conductor's closed form equals the complex-number Fresnel equations
    /// at 200 angles from normal to grazing for every named metal at every
    /// bin and for extreme (n, k); at normal incidence it is
    /// ((n−1)² + k²) / ((n+1)² + k²); at grazing exactly 1; with k = 0 it is
    /// the dielectric's.
    #[test]
    fn conductor_matches_complex_fresnel() {
        let mut cases: Vec<(f32, f32)> = vec![(0.05, 0.1), (0.2, 8.0), (3.0, 0.01), (1.0, 1.0), (5.0, 10.0)];
        for (_, n, k) in crate::bxdf::NAMED_METALS {
            cases.extend(n.iter().zip(k.iter()).map(|(&a, &b)| (a, b)));
        }
        for (n, k) in cases {
            let normal = ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k);
            assert!((fresnel_conductor(1.0, n, k) - normal).abs() < 1e-5, "n {n} k {k}");
            for i in 0..200 {
                let cos = 1.0 - (i as f64 / 199.0).powi(2);
                let want = complex_fresnel(cos, n as f64, k as f64);
                let got = fresnel_conductor(cos as f32, n, k) as f64;
                assert!((got - want).abs() < 2e-5, "n {n} k {k} cos {cos}: {got} vs {want}");
            }
            assert_eq!(fresnel_conductor(0.0, n, k), 1.0);
        }
        for eta in [1.0f32, 1.33, 1.5, 2.4] {
            for cos in [1.0f32, 0.6, 0.1] {
                assert!((fresnel_conductor(cos, eta, 0.0) - fresnel_dielectric(cos, eta)).abs() < 1e-5);
            }
        }
    }

    /// Snell's law: η_i sin θ_i = η_t sin θ_t, and the refracted ray lies on the far side.
    #[test]
    fn snell_holds() {
        for (theta, eta) in [(30f32, 1.5f32), (60.0, 1.33), (10.0, 2.4)] {
            let t = theta.to_radians();
            let wi = Vec3::new(t.sin(), 0.0, t.cos());
            let (wt, etap) = refract(wi, Vec3::Z, eta).unwrap();
            assert!(wt.z < 0.0 && wt.x < 0.0);
            let sin_t = (wt.x * wt.x + wt.y * wt.y).sqrt();
            assert!((t.sin() - eta * sin_t).abs() < 1e-5);
            assert_eq!(etap, eta);
            // And back out again: reversibility.
            let (back, etab) = refract(wt, Vec3::Z, eta).unwrap();
            assert!((back - wi).length() < 1e-5, "{back:?} vs {wi:?}");
            assert!((etab - 1.0 / eta).abs() < 1e-6);
        }
    }
}
