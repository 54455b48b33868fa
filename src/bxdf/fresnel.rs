//! The Fresnel equations for dielectrics (thesis eq. 2.4) and Snell's law
//! (thesis eq. 2.3).

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
