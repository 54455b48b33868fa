//! An `Image` environment: the map (equirectangular or equal-area), its texels
//! and their sampling density, and the map's coordinates.

use std::f32::consts::{FRAC_PI_2, FRAC_PI_4, PI};

use glam::{Vec2, Vec3};

use crate::color::{Sampled, Spectrum, Uplift, emission_spectrum, emission_uplift, fit_rows};
use crate::sampler::piecewise::Piecewise2D;
use crate::scene::desc::EnvMapping;

/// A map of emission texels and its sampling density.
#[derive(Clone, Debug)]
pub(super) struct EnvMap {
    pub(super) width: usize,
    pub(super) height: usize,
    /// How the texels cover the sphere.
    pub(super) mapping: EnvMapping,
    pub(super) texels: Vec<Texel>,
    /// Each texel's emission spectrum, evaluated once at load, for maps of at
    /// most [`CACHED_TEXELS`] texels (empty for larger ones, whose lookups
    /// evaluate the sigmoid of four texels each). A lookup without the cache
    /// spent 34% of `environment.ron`'s render time re-evaluating it.
    pub(super) spectra: Vec<Spectrum>,
    /// With `spectra`: for each bilinear footprint, whose top-left texel is
    /// column `x0` in `[-1, w)` and row `y0` in `[-1, h)`, whether its four
    /// texels are one and the same colour (at `(y0 + 1)(w + 1) + x0 + 1`): a
    /// lookup then reads one flag instead of four texels.
    pub(super) uniform: Vec<bool>,
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
        let x = uv.x * self.width as f32 - 0.5;
        let y = uv.y * self.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let at = |i: i64, j: i64| self.texel_index(i, j);
        let k = [at(x0, y0), at(x0 + 1, y0), at(x0, y0 + 1), at(x0 + 1, y0 + 1)];
        if !self.spectra.is_empty() {
            let uniform = match self.footprint(x0, y0) {
                Some(q) => self.uniform[q],
                None => self.same_texels(k),
            };
            if uniform {
                return self.spectra[k[0]];
            }
            // A texel of scale 0 has the spectrum 0 (`emission_spectrum`): adding
            // it changes no bin of the non-negative sum, as skipping it did.
            let wts = [(1.0 - fx) * (1.0 - fy), fx * (1.0 - fy), (1.0 - fx) * fy, fx * fy];
            if wts.iter().all(|&w| w > 0.0) {
                // The loop below with every term added, bin by bin in the same
                // order (0 + a·w0 + b·w1 + c·w2 + d·w3), written out so that the
                // sum stays in registers (the loop's went through memory).
                let [a, b, c, d] = k.map(|k| &self.spectra[k].0);
                let [w0, w1, w2, w3] = wts;
                return Sampled(std::array::from_fn(|i| 0.0 + a[i] * w0 + b[i] * w1 + c[i] * w2 + d[i] * w3));
            }
            let mut s = Spectrum::ZERO;
            for (k, weight) in k.into_iter().zip(wts) {
                if weight > 0.0 {
                    s += self.spectra[k] * weight;
                }
            }
            return s;
        }
        let t = [
            (self.texels[k[0]], (1.0 - fx) * (1.0 - fy)),
            (self.texels[k[1]], fx * (1.0 - fy)),
            (self.texels[k[2]], (1.0 - fx) * fy),
            (self.texels[k[3]], fx * fy),
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

impl EnvMap {
    /// True when the texels at `k` are all the same.
    #[inline]
    fn same_texels(&self, k: [usize; 4]) -> bool {
        let first = self.texels[k[0]];
        k.iter().all(|&i| self.texels[i] == first)
    }

    /// The index into `uniform` of the footprint whose top-left texel is
    /// `(x0, y0)`, if that is in `[-1, w) x [-1, h)`.
    #[inline]
    fn footprint(&self, x0: i64, y0: i64) -> Option<usize> {
        let (w, h) = (self.width as i64, self.height as i64);
        ((-1..w).contains(&x0) && (-1..h).contains(&y0)).then(|| ((y0 + 1) * (w + 1) + x0 + 1) as usize)
    }

    /// Keeps every texel's emission spectrum (`spectra`) and which
    /// footprints have four equal texels (`uniform`).
    pub(super) fn cache_spectra(&mut self) {
        self.spectra = self.texels.iter().map(|t| emission_spectrum(&t.uplift, t.scale, &self.d65)).collect();
        let (w, h) = (self.width as i64, self.height as i64);
        self.uniform = (-1..h)
            .flat_map(|y0| (-1..w).map(move |x0| (x0, y0)))
            .map(|(x0, y0)| {
                let at = |i: i64, j: i64| self.texel_index(i, j);
                self.same_texels([at(x0, y0), at(x0 + 1, y0), at(x0, y0 + 1), at(x0 + 1, y0 + 1)])
            })
            .collect();
    }

    /// The map coordinates of a unit direction `m` in the map's frame.
    #[inline]
    pub(super) fn uv_of(&self, m: Vec3) -> Vec2 {
        match self.mapping {
            EnvMapping::Equirectangular => to_uv(m),
            EnvMapping::EqualArea => to_square(m),
        }
    }

    /// The texel at column `i`, row `j`, each possibly one beyond the image's edge:
    /// equirectangular maps wrap around in `i` and clamp `j` at the poles; the
    /// equal-area square folds over its edges onto the texels that border the
    /// same directions (pbrt-v4's `WrapMode::OctahedralSphere`).
    #[inline(always)]
    pub(super) fn texel_index(&self, i: i64, j: i64) -> usize {
        let (w, h) = (self.width as i64, self.height as i64);
        let (i, j) = match self.mapping {
            EnvMapping::Equirectangular => (wrap(i, w), j.clamp(0, h - 1)),
            EnvMapping::EqualArea => fold_square(i, j, w, h),
        };
        j as usize * self.width + i as usize
    }
}

/// `i.rem_euclid(w)` without a division where `i` is at most one turn
/// beyond `[0, w)` (a bilinear lookup's columns are in `[-1, w]`): an
/// integer division was most of a lookup's texel indexing.
#[inline(always)]
pub(super) fn wrap(i: i64, w: i64) -> i64 {
    if (0..w).contains(&i) {
        i
    } else if (-w..0).contains(&i) {
        i + w
    } else if (w..2 * w).contains(&i) {
        i - w
    } else {
        i.rem_euclid(w)
    }
}

/// Texel `(i, j)` of a `w` x `h` equal-area square, one texel beyond an edge at
/// most, folded onto the texel inside that borders the same directions: across
/// the left or right edge the square continues mirrored top to bottom, across the
/// top or bottom edge mirrored left to right (and both at a corner).
#[inline]
pub(super) fn fold_square(mut i: i64, mut j: i64, w: i64, h: i64) -> (i64, i64) {
    if i < 0 || i >= w {
        i = if i < 0 { -1 - i } else { 2 * w - 1 - i };
        j = h - 1 - j;
    }
    if j < 0 || j >= h {
        j = if j < 0 { -1 - j } else { 2 * h - 1 - j };
        i = w - 1 - i;
    }
    (i.clamp(0, w - 1), j.clamp(0, h - 1))
}

/// The equal-area square's coordinates of a unit direction `m` in the map's frame
/// (Clarberg 2008, "Fast Equal-Area Mapping of the (Hemi)Sphere using SIMD"; the
/// layout of pbrt-v4's `EqualAreaSphereToSquare` for the direction `(m.x, m.z, m.y)`,
/// pbrt's +z being the map's +y): the centre looks up (+y), the corners down (−y);
/// u grows towards +x, v towards +z. Each octant is a triangle of the square, its
/// area the octant's solid angle over 4π.
#[inline]
pub(super) fn to_square(m: Vec3) -> Vec2 {
    let (a, b, up) = (m.x, m.z, m.y);
    let (ax, ay) = (a.abs(), b.abs());
    // The distance from the centre (|u| + |v| in [-1, 1]² coordinates) grows as √(1 − |up|).
    let r = (1.0 - up.abs()).max(0.0).sqrt();
    // The share of the quadrant's right angle from the u axis, in [0, 1].
    let phi = if ax == 0.0 && ay == 0.0 { 0.0 } else { ay.atan2(ax) / FRAC_PI_2 };
    let mut v = phi * r;
    let mut u = r - v;
    if up < 0.0 {
        // The lower hemisphere: the outer triangles, folded over the diagonal.
        (u, v) = (1.0 - v, 1.0 - u);
    }
    let (u, v) = (u.copysign(a), v.copysign(b));
    Vec2::new((0.5 * (u + 1.0)).clamp(0.0, 1.0 - f32::EPSILON), (0.5 * (v + 1.0)).clamp(0.0, 1.0 - f32::EPSILON))
}

/// The unit direction in the map's frame of equal-area square coordinates `uv`
/// (the inverse of [`to_square`]).
#[inline]
pub(super) fn from_square(uv: Vec2) -> Vec3 {
    let (u, v) = (2.0 * uv.x - 1.0, 2.0 * uv.y - 1.0);
    let (au, av) = (u.abs(), v.abs());
    // Signed distance from the diagonal |u| + |v| = 1: positive inside (upper hemisphere).
    let signed = 1.0 - (au + av);
    let r = 1.0 - signed.abs();
    let phi = if r == 0.0 { FRAC_PI_4 } else { ((av - au) / r + 1.0) * FRAC_PI_4 };
    let up = (1.0 - r * r).copysign(signed);
    let s = r * (2.0 - r * r).max(0.0).sqrt();
    let (sin_p, cos_p) = phi.sin_cos();
    Vec3::new(cos_p.copysign(u) * s, up, sin_p.copysign(v) * s)
}

/// The map coordinates of a unit direction `m` in the map's frame: `u =
/// atan2(m.x, −m.z) / 2π` wrapped into [0, 1), `v = θ / π` with θ taken as
/// `atan2(√(m.x² + m.z²), m.y)`, which is `acos(m.y)` and accurate near the
/// poles too ([`atan2`]: within 3·10⁻⁷ rad, 4·10⁻⁴ of a texel of an
/// 8192-wide map).
#[inline]
pub(super) fn to_uv(m: Vec3) -> Vec2 {
    let mut u = atan2(m.x, -m.z) / (2.0 * PI);
    if u < 0.0 {
        u += 1.0;
    }
    let v = atan2((m.x * m.x + m.z * m.z).sqrt(), m.y) / PI;
    Vec2::new(u.min(1.0 - f32::EPSILON), v.min(1.0 - f32::EPSILON))
}

/// `atan2(y, x)` in [−π, π], within 3·10⁻⁷ rad of the exact value (libm's
/// `atan2f` and `acosf` were 8% of `environment.ron`'s render time, two per
/// lookup). The octant's ratio `a = min/max` of `|x|, |y|` in [0, 1] goes
/// through `atan a ≈ a·P(a²)`, `P` of degree 7 fitted to `atan` (weighted
/// least squares on [0, 1]; the largest error 1.4·10⁻⁷ rad, evaluated in f32
/// by Horner's rule without fused multiply-adds, which targets without FMA
/// would emulate), then the octant's symmetries (rounding near π adds up to
/// half an ulp of π, 1.2·10⁻⁷): exact at the axes (0, ±π/2, ±π), 0 at the origin.
#[inline]
pub(super) fn atan2(y: f32, x: f32) -> f32 {
    const C: [f32; 8] = [
        0.999_999_34,
        -0.333_298_6,
        0.199_465_66,
        -0.139_086_29,
        0.096_421_98,
        -0.055_912_346,
        0.021_862_974,
        -0.004_054_573,
    ];
    let (ax, ay) = (x.abs(), y.abs());
    let (lo, hi) = (ax.min(ay), ax.max(ay));
    if hi == 0.0 || hi.is_nan() {
        return 0.0f32.copysign(y);
    }
    let a = lo / hi;
    let t = a * a;
    let p = C.iter().rev().fold(0.0f32, |p, &c| p * t + c);
    let mut r = a * p;
    if ay > ax {
        r = FRAC_PI_2 - r;
    }
    if x < 0.0 {
        r = PI - r;
    }
    r.copysign(y)
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
