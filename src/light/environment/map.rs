//! An `Image` environment: the equirectangular map, its texels and their
//! sampling density, and the map's coordinates.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use crate::color::{Spectrum, Uplift, emission_spectrum, emission_uplift, fit_rows};
use crate::sampler::piecewise::Piecewise2D;

/// An equirectangular map of emission texels and its sampling density.
#[derive(Clone, Debug)]
pub(super) struct EnvMap {
    pub(super) width: usize,
    pub(super) height: usize,
    pub(super) texels: Vec<Texel>,
    /// Each texel's emission spectrum, evaluated once at load, for maps of at
    /// most [`CACHED_TEXELS`] texels (empty for larger ones, whose lookups
    /// evaluate the sigmoid of four texels each). A lookup without the cache
    /// spent 34% of `environment.ron`'s render time re-evaluating it.
    pub(super) spectra: Vec<Spectrum>,
    pub(super) dist: Piecewise2D,
    pub(super) d65: Spectrum,
}

/// The largest map whose texel spectra are kept (512 x 512: 38 MB of spectra).
pub(super) const CACHED_TEXELS: usize = 1 << 18;

/// One texel: the uplifted colour and its scale (see [`emission_uplift`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Texel {
    pub(super) uplift: Uplift,
    pub(super) scale: f32,
}

impl EnvMap {
    /// The bilinear blend of the four texels around `uv`.
    #[inline]
    pub(super) fn radiance(&self, uv: Vec2) -> Spectrum {
        let (w, h) = (self.width as i64, self.height as i64);
        let x = uv.x * self.width as f32 - 0.5;
        let y = uv.y * self.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (i0, i1) = ((x0 as i64).rem_euclid(w) as usize, (x0 as i64 + 1).rem_euclid(w) as usize);
        let (j0, j1) = ((y0 as i64).clamp(0, h - 1) as usize, (y0 as i64 + 1).clamp(0, h - 1) as usize);
        if !self.spectra.is_empty() {
            let k = [j0 * self.width + i0, j0 * self.width + i1, j1 * self.width + i0, j1 * self.width + i1];
            let first = self.texels[k[0]];
            if k.iter().all(|&i| self.texels[i] == first) {
                return self.spectra[k[0]];
            }
            let wts = [(1.0 - fx) * (1.0 - fy), fx * (1.0 - fy), (1.0 - fx) * fy, fx * fy];
            let mut s = Spectrum::ZERO;
            for (k, weight) in k.into_iter().zip(wts) {
                if weight > 0.0 && self.texels[k].scale > 0.0 {
                    s += self.spectra[k] * weight;
                }
            }
            return s;
        }
        let t = [
            (self.texels[j0 * self.width + i0], (1.0 - fx) * (1.0 - fy)),
            (self.texels[j0 * self.width + i1], fx * (1.0 - fy)),
            (self.texels[j1 * self.width + i0], (1.0 - fx) * fy),
            (self.texels[j1 * self.width + i1], fx * fy),
        ];
        if t.iter().all(|(texel, _)| *texel == t[0].0) {
            // One colour all round (a constant map): exactly that texel's spectrum.
            return emission_spectrum(&t[0].0.uplift, t[0].0.scale, &self.d65);
        }
        let mut s = Spectrum::ZERO;
        for (texel, weight) in t {
            if weight > 0.0 && texel.scale > 0.0 {
                s += emission_spectrum(&texel.uplift, texel.scale, &self.d65) * weight;
            }
        }
        s
    }
}

/// The map coordinates of a unit direction `m` in the map's frame.
#[inline]
pub(super) fn to_uv(m: Vec3) -> Vec2 {
    let mut u = m.x.atan2(-m.z) / (2.0 * PI);
    if u < 0.0 {
        u += 1.0;
    }
    let v = m.y.clamp(-1.0, 1.0).acos() / PI;
    Vec2::new(u.min(1.0 - f32::EPSILON), v.min(1.0 - f32::EPSILON))
}

/// The unit direction in the map's frame of map coordinates `uv`, and its `sin θ`.
#[inline]
pub(super) fn from_uv(uv: Vec2) -> (Vec3, f32) {
    let (theta, phi) = (PI * uv.y, 2.0 * PI * uv.x);
    let (sin_t, cos_t) = theta.sin_cos();
    let (sin_p, cos_p) = phi.sin_cos();
    (Vec3::new(sin_t * sin_p, cos_t, -sin_t * cos_p), sin_t)
}

/// Every texel's emission uplift, `scale` folded in ([`crate::color::fit_rows`]:
/// a map of one colour gives exactly `Rgb(...)`'s spectrum everywhere).
pub(super) fn fit_texels(width: usize, rgb: &[[f32; 3]], scale: f32) -> Vec<Texel> {
    let fit = |c, near| {
        let (uplift, scale) = emission_uplift(c, near);
        Texel { uplift, scale }
    };
    fit_rows(width, rgb, scale, fit, |t: &Texel| t.uplift.coefficients())
}
