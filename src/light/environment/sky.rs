//! The `Sky` environment: the Hosek-Wilkie sky (`crate::light::sky`), its
//! sun as a cone, and a Lambertian ground below the horizon.

use std::f32::consts::{FRAC_PI_2, PI};

use glam::{Mat3, Vec2, Vec3};

use super::map::{from_uv, to_uv};
use super::{EnvironmentLight, Source};
use crate::color::Spectrum;
use crate::light::sky::SkyModel;
use crate::sampler::piecewise::Piecewise2D;

/// The sky, its sun, and the ground below the horizon (see [`EnvironmentLight::sky`]).
#[derive(Clone, Debug)]
pub(super) struct SkyEnv {
    pub(super) model: SkyModel,
    /// Unit direction towards the sun's centre.
    pub(super) sun: Vec3,
    /// `1 − cos R` of the sun's angular radius `R` (as `2 sin²(R/2)`: exact in f32).
    pub(super) sun_one_minus_cos: f32,
    /// The radiance of the ground below the horizon.
    pub(super) ground: Spectrum,
    /// A factor on everything.
    pub(super) scale: f32,
    /// The sampling density of the sky and ground (the sun excluded), over the
    /// equirectangular grid, and the probability of sampling the sun's cone instead.
    pub(super) table: Piecewise2D,
    pub(super) p_sun: f32,
}

/// The sky table's size (over the whole sphere; the sky is smooth away from the
/// sun, which is sampled on its own).
pub(super) const SKY_TABLE: (usize, usize) = (128, 64);

impl EnvironmentLight {
    /// The Hosek-Wilkie sky (`crate::light::sky`) for a sun at `elevation`
    /// and `azimuth` (radians; azimuth 0 towards −z, π/2 towards +x, as the
    /// map's u), with the sun's disk, and below the horizon a Lambertian
    /// ground of reflectance `ground_albedo` lit by the sky and sun, `a E / π`
    /// (`E` the sky's and sun's irradiance on a horizontal plane, computed at
    /// load). Everything times `scale`. Errors name the model's parameter.
    pub fn sky(
        turbidity: f32,
        ground_albedo: f32,
        elevation: f32,
        azimuth: f32,
        scale: f32,
    ) -> Result<EnvironmentLight, String> {
        let model = SkyModel::new(turbidity, ground_albedo, elevation)?;
        let (se, ce) = elevation.sin_cos();
        let (sa, ca) = azimuth.sin_cos();
        let sun = Vec3::new(ce * sa, se, -ce * ca).normalize();
        let half = SkyModel::SUN_ANGULAR_RADIUS * 0.5;
        let sun_one_minus_cos = 2.0 * half.sin() * half.sin();
        let (w, h) = SKY_TABLE;
        // The sky (sun excluded) at texel centres: the irradiance on the ground
        // and the table's weights.
        let mut e_sky = Spectrum::ZERO;
        let mut sky_means = vec![0.0f32; w * h];
        for j in 0..h / 2 {
            let (t0, t1) = (PI * j as f32 / h as f32, PI * (j + 1) as f32 / h as f32);
            let solid = (2.0 * PI / w as f32) * (t0.cos() - t1.cos());
            for i in 0..w {
                let (d, _) = from_uv(Vec2::new((i as f32 + 0.5) / w as f32, (j as f32 + 0.5) / h as f32));
                let l = model.radiance(zenith_angle(d), angle_between(d, sun));
                e_sky += l * (solid * d.y.max(0.0));
                sky_means[j * w + i] = l.average();
            }
        }
        let e_sun = model.sun_irradiance() * se.max(0.0);
        let ground = (e_sky + e_sun) * (ground_albedo / PI);
        let ground_mean = ground.average();
        // Weights: the sky's mean at the texel and its neighbours (the Mie peak
        // is narrow), a floor of 1e-3 of the row's mean so no direction with
        // radiance has zero density, times sin θ.
        let mut weights = vec![0.0f32; w * h];
        for j in 0..h {
            let sin = (PI * (j as f32 + 0.5) / h as f32).sin();
            for i in 0..w {
                let v = if j < h / 2 {
                    let mut m = 0.0f32;
                    for dj in -1i64..=1 {
                        let jj = (j as i64 + dj).clamp(0, h as i64 / 2 - 1) as usize;
                        for di in -1i64..=1 {
                            m = m.max(sky_means[jj * w + (i as i64 + di).rem_euclid(w as i64) as usize]);
                        }
                    }
                    m
                } else {
                    ground_mean
                };
                weights[j * w + i] = v * sin;
            }
        }
        let floor = weights.iter().sum::<f32>() / weights.len() as f32 * 1e-3;
        for v in &mut weights {
            *v = v.max(floor);
        }
        let table = Piecewise2D::new(&weights, w, h).ok_or_else(|| "the sky's sampling density is zero".to_string())?;
        // ∫ L dω of each part, for the sun's share of samples and the power.
        let mut sky_int = 0.0f64;
        for j in 0..h / 2 {
            let (t0, t1) = (PI * j as f32 / h as f32, PI * (j + 1) as f32 / h as f32);
            let solid = (2.0 * PI / w as f32) * (t0.cos() - t1.cos());
            for i in 0..w {
                sky_int += (sky_means[j * w + i] * solid) as f64;
            }
        }
        let sun_int = model.sun_irradiance().average();
        let ground_int = ground_mean * 2.0 * PI;
        let total = sky_int as f32 + sun_int + ground_int;
        let p_sun = if sun_int > 0.0 { (sun_int / total).clamp(0.05, 0.95) } else { 0.0 };
        let peak = Spectrum::from_fn(|b| {
            let zenith = model.radiance(FRAC_PI_2 - elevation, FRAC_PI_2 - elevation)[b];
            let disk =
                model.sun_radiance(FRAC_PI_2 - elevation, 0.0)[b] + model.radiance(FRAC_PI_2 - elevation, 0.0)[b];
            zenith.max(disk).max(ground[b]) * scale
        });
        Ok(EnvironmentLight {
            source: Source::Sky(Box::new(SkyEnv { model, sun, sun_one_minus_cos, ground, scale, table, p_sun })),
            to_map: Mat3::IDENTITY,
            from_map: Mat3::IDENTITY,
            peak,
            integral: total * scale,
            scene_center: Vec3::ZERO,
            scene_radius: 1.0,
            sun: true,
        })
    }
}

impl SkyEnv {
    /// True when unit direction `wi` lies in the sun's disk.
    #[inline]
    pub(super) fn in_sun(&self, wi: Vec3) -> bool {
        // 1 − cos γ from the chord: |wi − sun|² / 2, exact near the sun.
        (wi - self.sun).length_squared() * 0.5 <= self.sun_one_minus_cos
    }

    #[inline]
    pub(super) fn radiance(&self, wi: Vec3) -> Spectrum {
        if wi.y < 0.0 {
            return self.ground * self.scale;
        }
        let (theta, gamma) = (zenith_angle(wi), angle_between(wi, self.sun));
        let mut l = self.model.radiance(theta, gamma);
        if self.in_sun(wi) {
            l += self.model.sun_radiance(theta, gamma);
        }
        l * self.scale
    }

    /// The density of the sun's cone (uniform) mixed with the table's.
    #[inline]
    pub(super) fn pdf(&self, wi: Vec3) -> f32 {
        let sin = (wi.x * wi.x + wi.z * wi.z).sqrt();
        let table = if sin > 0.0 { self.table.pdf(to_uv(wi)) / (2.0 * PI * PI * sin) } else { 0.0 };
        let cone = if self.in_sun(wi) { 1.0 / (2.0 * PI * self.sun_one_minus_cos) } else { 0.0 };
        self.p_sun * cone + (1.0 - self.p_sun) * table
    }

    #[inline]
    pub(super) fn sample(&self, u: Vec2) -> Option<(Vec3, f32)> {
        let wi = if u.x < self.p_sun {
            // Uniform in the sun's cone: 1 − cos γ uniform in [0, 1 − cos R].
            let ux = u.x / self.p_sun;
            let om = ux * self.sun_one_minus_cos;
            let sin_g = (om * (2.0 - om)).max(0.0).sqrt();
            let (c, s) = crate::sampler::warp::cos_sin_2pi(u.y);
            crate::geometry::Frame::from_z(self.sun).to_world(Vec3::new(sin_g * c, sin_g * s, 1.0 - om)).normalize()
        } else {
            let uu = Vec2::new((u.x - self.p_sun) / (1.0 - self.p_sun), u.y).min(Vec2::splat(1.0 - f32::EPSILON));
            let (uv, _) = self.table.sample(uu);
            from_uv(uv).0
        };
        let pdf = self.pdf(wi);
        (pdf.is_finite() && pdf > 0.0).then_some((wi, pdf))
    }
}

/// The zenith angle of unit direction `d` (from +y), accurate at the zenith.
#[inline]
pub(super) fn zenith_angle(d: Vec3) -> f32 {
    (d.x * d.x + d.z * d.z).sqrt().atan2(d.y)
}

/// The angle between unit directions `a` and `b`, accurate when they are close.
#[inline]
pub(super) fn angle_between(a: Vec3, b: Vec3) -> f32 {
    a.cross(b).length().atan2(a.dot(b))
}
