//! Textures: a material's reflectance that varies over its surface, looked up
//! at a hit's (u, v) (each shape's parameterisation is in `shape/uv.rs`).
//!
//! ```ron
//! "floor": Lambertian(reflectance: Checkerboard(even: Constant(0.8), odd: Rgb(0.1, 0.1, 0.3), scale: 8)),
//! "wall": Lambertian(reflectance: Image(path: "textures/wood.png", uv_scale: (2, 1), wrap: Repeat)),
//! ```
//!
//! Data flow: the material's `reflectance:` ([`crate::scene::desc::SpectrumDesc`])
//! is built once at load into a [`Texture`]; a material whose reflectance is
//! not constant keeps it beside its [`crate::bxdf::Bxdf`], and
//! [`crate::scene::Scene::bsdf_in`] evaluates it once per hit (the lobe with
//! the texel's reflectance in place of the constant one). A scene without
//! textures never computes a (u, v) and pays one branch per hit.
//!
//! A material's `roughness:` and a thin film's `thickness_nm:` may be a
//! texture of numbers ([`ScalarTexture`]: an image's luminance times its
//! scale, or a checkerboard of two numbers); [`MaterialTextures`] holds every
//! texture of a material and applies them to its lobe once per hit.
//!
//! An object's `emission:` may be a texture too ([`Role::Emission`]): its
//! colours are uplifted as `Rgb(...)` emission is (the uplifted colour times
//! D65, scaled: [`crate::color::emission_uplift`]), and the area light keeps
//! it ([`crate::light::EmissionTexture`]), read at the (u, v) of a hit
//! ([`crate::scene::Scene::le`]) or of a point the light drew
//! ([`crate::light::Light::with_radiance`]).
//!
//! - `Image(path, uv_scale: (su, sv), uv_offset: (ou, ov), wrap: Repeat | Clamp, scale: S)`:
//!   a PNG (8 or 16 bits per channel, sRGB-decoded to linear with the
//!   IEC 61966-2-1 transfer function) or an EXR (linear). The lookup point is
//!   `(u·su + ou, v·sv + ov)`, with `v = 0` at the image's **bottom** row
//!   (OBJ's and pbrt's convention: the image is not upside down on a mesh
//!   with `vt`), filtered bilinearly between texel centres; `Repeat` wraps
//!   outside [0, 1], `Clamp` holds the edge texels. Each texel's colour,
//!   times `S`, becomes a reflectance as `Rgb(...)` does (the Jakob-Hanika
//!   sigmoid, fitted per texel at load: see [`crate::color::Uplift`]), so an
//!   image of one colour renders exactly like that `Rgb(...)`.
//! - `Checkerboard(even, odd, scale: N)`: `N` squares per unit of u and of v;
//!   the square `(⌊N u⌋, ⌊N v⌋)` is `even` when the sum is even.

use std::sync::Arc;

use glam::Vec2;

use crate::bxdf::Bxdf;
use crate::bxdf::microfacet::SMOOTH_ALPHA;
use crate::color::{N_BINS, Spectrum, Uplift, d65, emission_spectrum, emission_uplift, fit_rows};
use crate::error::Result;
use crate::io::image::decode_image;
use crate::scene::check::Check;
use crate::scene::desc::{ScalarTextureDesc, SpectrumDesc, Wrap};

/// The most texels an image texture may have (a 8192 x 8192 image).
pub const MAX_TEXELS: usize = 1 << 26;

/// A reflectance over a surface.
#[derive(Clone, Debug)]
pub enum Texture {
    /// Two reflectances in a checkerboard over (u, v).
    Checkerboard {
        /// Where `⌊N u⌋ + ⌊N v⌋` is even.
        even: Box<Spectrum>,
        /// Where it is odd.
        odd: Box<Spectrum>,
        /// Squares per unit of u and of v.
        scale: f32,
    },
    /// An image.
    Image(Arc<ImageTexture>),
}

/// An image of uplifted texels: reflectances, or emitted radiances.
#[derive(Clone, Debug)]
pub struct ImageTexture {
    grid: Grid,
    /// Row 0 is the image's top row.
    texels: Vec<Uplift>,
    /// For an emission: each texel's factor on `uplift · D65` (see
    /// [`crate::color::emission_uplift`]); `None` for a reflectance.
    emission: Option<Box<EmissionTexels>>,
}

/// Where an image's texels lie over (u, v): its size, the lookup's scale and
/// offset, and how it continues outside [0, 1].
#[derive(Clone, Copy, Debug)]
struct Grid {
    width: usize,
    height: usize,
    uv_scale: Vec2,
    uv_offset: Vec2,
    wrap: Wrap,
}

impl Grid {
    /// The four texels around `uv` and their bilinear weights (see the module doc).
    #[inline]
    fn taps(&self, uv: Vec2) -> [(usize, f32); 4] {
        let st = uv * self.uv_scale + self.uv_offset;
        let x = st.x * self.width as f32 - 0.5;
        let y = (1.0 - st.y) * self.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (i0, i1) = (self.index(x0, self.width), self.index(x0 + 1.0, self.width));
        let (j0, j1) = (self.index(y0, self.height), self.index(y0 + 1.0, self.height));
        [
            (j0 * self.width + i0, (1.0 - fx) * (1.0 - fy)),
            (j0 * self.width + i1, fx * (1.0 - fy)),
            (j1 * self.width + i0, (1.0 - fx) * fy),
            (j1 * self.width + i1, fx * fy),
        ]
    }

    /// Texel index along an axis of `n` texels for the integer coordinate `x`.
    #[inline]
    fn index(&self, x: f32, n: usize) -> usize {
        // Far outside (or NaN) the coordinate saturates; both modes stay in range.
        let x = if x.is_finite() { x.clamp(-1e9, 1e9) as i64 } else { 0 };
        match self.wrap {
            Wrap::Repeat => x.rem_euclid(n as i64) as usize,
            Wrap::Clamp => x.clamp(0, n as i64 - 1) as usize,
        }
    }
}

/// True on the squares `(⌊N u⌋, ⌊N v⌋)` of a checkerboard of `scale` squares
/// per unit whose sum is even.
#[inline]
fn even_square(uv: Vec2, scale: f32) -> bool {
    let (i, j) = ((uv.x * scale).floor() as i64, (uv.y * scale).floor() as i64);
    (i + j).rem_euclid(2) == 0
}

/// What an emission image keeps besides its uplifted texels.
#[derive(Clone, Debug)]
struct EmissionTexels {
    /// Per texel, index for index with `texels`.
    scales: Vec<f32>,
    d65: Spectrum,
}

/// What an image's texels stand for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// A reflectance: each texel uplifted as `Rgb(...)` is for a material.
    Reflectance,
    /// An emitted radiance: each texel uplifted as `Rgb(...)` is for an
    /// `emission:` (the uplifted colour times D65, scaled).
    Emission,
}

impl Texture {
    /// The reflectance at surface coordinates `uv` (out of line: the hot path of
    /// an untextured scene stays small).
    #[inline(never)]
    pub fn eval(&self, uv: Vec2) -> Spectrum {
        match self {
            Texture::Checkerboard { even, odd, scale } => {
                if even_square(uv, *scale) {
                    **even
                } else {
                    **odd
                }
            }
            Texture::Image(image) => image.eval(uv),
        }
    }

    /// The mean over the texture's domain and the per-bin peak: the mean of
    /// the two squares for a checkerboard; for an image the mean of its
    /// texels (the mean over any whole number of repeats of the image) and
    /// their per-bin maximum.
    pub fn mean_and_peak(&self) -> (Spectrum, Spectrum) {
        match self {
            Texture::Checkerboard { even, odd, .. } => {
                ((**even + **odd) * 0.5, Spectrum::from_fn(|b| even[b].max(odd[b])))
            }
            Texture::Image(image) => image.mean_and_peak(),
        }
    }
}

impl ImageTexture {
    /// An image texture of `width` x `height` linear sRGB colours (row 0 at
    /// the top), each times `scale`, uplifted for `role`; errors name no field
    /// (the caller does). An emission's texels must be finite and
    /// non-negative after scaling.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        width: usize,
        height: usize,
        rgb: &[[f32; 3]],
        scale: f32,
        uv_scale: Vec2,
        uv_offset: Vec2,
        wrap: Wrap,
        role: Role,
    ) -> Result<ImageTexture, String> {
        let grid = Grid::new(width, height, rgb, uv_scale, uv_offset, wrap)?;
        if role == Role::Emission {
            if let Some(k) = rgb.iter().position(|p| p.iter().any(|c| *c < 0.0)) {
                return Err(format!(
                    "texel ({}, {}) is negative, {:?}; expected an emitted colour >= 0",
                    k % width,
                    k / width,
                    rgb[k]
                ));
            }
            if let Some(k) = rgb.iter().position(|p| p.iter().any(|c| !(c * scale).is_finite())) {
                return Err(format!("texel ({}, {}) times the scale {scale} is not finite", k % width, k / width));
            }
            let fitted = fit_rows(width, rgb, scale, emission_uplift, |t: &(Uplift, f32)| t.0.coefficients());
            let (texels, scales) = fitted.into_iter().unzip();
            let emission = Some(Box::new(EmissionTexels { scales, d65: d65() }));
            return Ok(ImageTexture { grid, texels, emission });
        }
        let texels = fit_rows(width, rgb, scale, Uplift::reflectance, Uplift::coefficients);
        Ok(ImageTexture { grid, texels, emission: None })
    }

    /// Texel `k`'s spectrum.
    #[inline]
    fn texel(&self, k: usize) -> Spectrum {
        match &self.emission {
            None => self.texels[k].spectrum(),
            Some(e) => emission_spectrum(&self.texels[k], e.scales[k], &e.d65),
        }
    }

    /// True when texels `a` and `b` are the same spectrum.
    #[inline]
    fn same(&self, a: usize, b: usize) -> bool {
        self.texels[a] == self.texels[b] && self.emission.as_ref().is_none_or(|e| e.scales[a] == e.scales[b])
    }

    /// See [`Texture::mean_and_peak`].
    fn mean_and_peak(&self) -> (Spectrum, Spectrum) {
        let mut sum = [0.0f64; N_BINS];
        let mut peak = Spectrum::ZERO;
        let mut prev: Option<(usize, Spectrum)> = None;
        for k in 0..self.texels.len() {
            let s = match prev {
                Some((p, s)) if self.same(p, k) => s,
                _ => self.texel(k),
            };
            for b in 0..N_BINS {
                sum[b] += s[b] as f64;
                peak[b] = peak[b].max(s[b]);
            }
            prev = Some((k, s));
        }
        let n = self.texels.len() as f64;
        (Spectrum::from_fn(|b| (sum[b] / n) as f32), peak)
    }

    /// The bilinear blend of the four texels around `uv` (see the module doc).
    #[inline]
    pub fn eval(&self, uv: Vec2) -> Spectrum {
        let t = self.grid.taps(uv);
        if t.iter().all(|&(k, _)| self.same(k, t[0].0)) {
            return self.texel(t[0].0);
        }
        let mut s = Spectrum::ZERO;
        for (k, weight) in t {
            if weight > 0.0 {
                s += self.texel(k) * weight;
            }
        }
        s
    }
}

impl Grid {
    /// The grid of a `width` x `height` image of colours `rgb` (checked:
    /// non-empty, at most [`MAX_TEXELS`], finite).
    fn new(
        width: usize,
        height: usize,
        rgb: &[[f32; 3]],
        uv_scale: Vec2,
        uv_offset: Vec2,
        wrap: Wrap,
    ) -> Result<Grid, String> {
        if width == 0 || height == 0 || rgb.len() != width * height {
            return Err(format!("expected a non-empty image, found {width}x{height}"));
        }
        if width * height > MAX_TEXELS {
            return Err(format!("{width}x{height} is more than the {MAX_TEXELS} texels a texture may have"));
        }
        if let Some(k) = rgb.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
            return Err(format!("texel ({}, {}) is not a finite colour", k % width, k / width));
        }
        Ok(Grid { width, height, uv_scale, uv_offset, wrap })
    }
}

/// A number over a surface: a roughness (GGX α) or a thin film's thickness
/// that varies (a material's `roughness:` or `thickness_nm:` given as a
/// texture, [`crate::scene::desc::ScalarDesc`]).
#[derive(Clone, Debug)]
pub enum ScalarTexture {
    /// Two values in a checkerboard over (u, v), as [`Texture::Checkerboard`].
    Checkerboard {
        /// Where `⌊N u⌋ + ⌊N v⌋` is even.
        even: f32,
        /// Where it is odd.
        odd: f32,
        /// Squares per unit of u and of v.
        scale: f32,
    },
    /// An image of values, looked up as [`ImageTexture`] is.
    Image(Arc<ScalarImage>),
}

/// An image of numbers: each texel's luminance times the texture's scale.
#[derive(Clone, Debug)]
pub struct ScalarImage {
    grid: Grid,
    /// Row 0 is the image's top row.
    texels: Vec<f32>,
}

impl ScalarTexture {
    /// The value at surface coordinates `uv` (out of line, as [`Texture::eval`]).
    #[inline(never)]
    pub fn eval(&self, uv: Vec2) -> f32 {
        match self {
            ScalarTexture::Checkerboard { even, odd, scale } => {
                if even_square(uv, *scale) {
                    *even
                } else {
                    *odd
                }
            }
            ScalarTexture::Image(image) => image.eval(uv),
        }
    }
}

impl ScalarImage {
    /// An image of `width` x `height` linear sRGB colours (row 0 at the top):
    /// each texel's luminance, `0.2126 R + 0.7152 G + 0.0722 B` (the grey
    /// itself where R = G = B), times `scale`. Errors name no field.
    pub fn new(
        width: usize,
        height: usize,
        rgb: &[[f32; 3]],
        scale: f32,
        uv_scale: Vec2,
        uv_offset: Vec2,
        wrap: Wrap,
    ) -> Result<ScalarImage, String> {
        let grid = Grid::new(width, height, rgb, uv_scale, uv_offset, wrap)?;
        let texels = rgb.iter().map(|&[r, g, b]| if r == g && g == b { r } else { luminance(r, g, b) } * scale);
        Ok(ScalarImage { grid, texels: texels.collect() })
    }

    /// The bilinear blend of the four texels around `uv`.
    #[inline]
    pub fn eval(&self, uv: Vec2) -> f32 {
        let t = self.grid.taps(uv);
        if t.iter().all(|&(k, _)| self.texels[k] == self.texels[t[0].0]) {
            return self.texels[t[0].0];
        }
        t.iter().filter(|(_, w)| *w > 0.0).map(|&(k, w)| self.texels[k] * w).sum()
    }

    /// The first texel whose value is outside `[lo, hi]` (or NaN), as `(x, y, value)`.
    fn outside(&self, lo: f32, hi: f32) -> Option<(usize, usize, f32)> {
        let k = self.texels.iter().position(|v| !(lo..=hi).contains(v))?;
        Some((k % self.grid.width, k / self.grid.width, self.texels[k]))
    }
}

/// The luminance Y of linear sRGB.
#[inline]
fn luminance(r: f32, g: f32, b: f32) -> f32 {
    0.2126 * r + 0.7152 * g + 0.0722 * b
}

/// Every texture of a material: its reflectance, its GGX α (Conductor,
/// rough Dielectric, Plastic) and its thin film's thickness (a `ThinFilm`
/// coating, a `ThinSheet`), each where it varies. [`crate::scene::Scene::bsdf_in`]
/// applies them once per hit ([`MaterialTextures::apply`]).
#[derive(Clone, Debug, Default)]
pub struct MaterialTextures {
    /// The reflectance (Lambertian, OrenNayar, Mirror, Plastic).
    pub reflectance: Option<Texture>,
    /// GGX α: values below [`SMOOTH_ALPHA`] are raised to it at each hit, so
    /// the material stays a microfacet lobe everywhere (whether a material
    /// is delta is decided once, not per hit).
    pub roughness: Option<ScalarTexture>,
    /// The thickness in nm of the thin film.
    pub thickness_nm: Option<ScalarTexture>,
}

impl MaterialTextures {
    /// True when nothing varies.
    pub fn is_empty(&self) -> bool {
        self.reflectance.is_none() && self.roughness.is_none() && self.thickness_nm.is_none()
    }

    /// The lobe `bxdf` (a material's, built with stand-in values where a
    /// texture applies) with every texture evaluated at `uv`: exactly the
    /// lobe of the same material with those values as constants.
    pub fn apply(&self, bxdf: &Bxdf, uv: Vec2) -> Bxdf {
        let mut b = match &self.reflectance {
            Some(t) => bxdf.with_reflectance(t.eval(uv)),
            None => bxdf.clone(),
        };
        if let Some(r) = &self.roughness {
            b.set_roughness(r.eval(uv).max(SMOOTH_ALPHA));
        }
        if let Some(t) = &self.thickness_nm {
            b.set_thickness_nm(t.eval(uv));
        }
        b
    }
}

/// The reflectance at field `field`: a [`Texture`] for `Image` and
/// `Checkerboard`, else `None` (the caller builds the constant spectrum).
pub(crate) fn from_desc(check: &Check, field: &str, d: &SpectrumDesc) -> Result<Option<Texture>> {
    texture_as(check, field, d, Role::Reflectance)
}

/// The emitted radiance at field `field` (an object's `emission`), as
/// [`from_desc`]: each colour uplifted as `Rgb(...)` emission is.
pub(crate) fn emission_from_desc(check: &Check, field: &str, d: &SpectrumDesc) -> Result<Option<Texture>> {
    texture_as(check, field, d, Role::Emission)
}

fn texture_as(check: &Check, field: &str, d: &SpectrumDesc, role: Role) -> Result<Option<Texture>> {
    let spectrum = |name: &str, s: &SpectrumDesc| match role {
        Role::Reflectance => check.reflectance(&format!("{field}.{name}"), s),
        Role::Emission => check.spectrum(&format!("{field}.{name}"), s),
    };
    Ok(Some(match d {
        SpectrumDesc::Checkerboard { even, odd, scale } => Texture::Checkerboard {
            even: Box::new(spectrum("even", even)?),
            odd: Box::new(spectrum("odd", odd)?),
            scale: check.positive(&format!("{field}.scale"), *scale)?,
        },
        SpectrumDesc::Image { path, uv_scale, uv_offset, wrap, scale } => {
            let path_field = format!("{field}.path");
            let scale = check.positive(&format!("{field}.scale"), *scale)?;
            let (uv_scale, uv_offset) =
                (finite2(check, field, "uv_scale", *uv_scale)?, finite2(check, field, "uv_offset", *uv_offset)?);
            let (resolved, bytes) = check.read_input(&path_field, path)?;
            let (w, h, pixels) = decode_image(&resolved, &bytes).map_err(|e| check.err(&path_field, e.to_string()))?;
            let rgb = pixels.linear_rgb();
            let image = ImageTexture::new(w as usize, h as usize, &rgb, scale, uv_scale, uv_offset, *wrap, role)
                .map_err(|m| check.err(&path_field, format!("{path}: {m}")))?;
            Texture::Image(Arc::new(image))
        }
        _ => return Ok(None),
    }))
}

/// The texture of a scalar at field `field` (`materials."m".roughness`),
/// every value in `[lo, hi]`; `what` names the quantity in errors (a GGX
/// alpha, a thickness in nm).
pub(crate) fn scalar_from_desc(
    check: &Check,
    field: &str,
    d: &ScalarTextureDesc,
    (lo, hi): (f32, f32),
    what: &str,
) -> Result<ScalarTexture> {
    let in_range = |name: &str, v: f32| {
        if (lo..=hi).contains(&v) {
            Ok(v)
        } else {
            Err(check.err(format!("{field}.{name}"), format!("expected {what} in [{lo}, {hi}], found {v}")))
        }
    };
    Ok(match d {
        ScalarTextureDesc::Checkerboard { even, odd, scale } => ScalarTexture::Checkerboard {
            even: in_range("even", *even)?,
            odd: in_range("odd", *odd)?,
            scale: check.positive(&format!("{field}.scale"), *scale)?,
        },
        ScalarTextureDesc::Image { path, uv_scale, uv_offset, wrap, scale } => {
            let path_field = format!("{field}.path");
            let scale = check.positive(&format!("{field}.scale"), *scale)?;
            let (uv_scale, uv_offset) =
                (finite2(check, field, "uv_scale", *uv_scale)?, finite2(check, field, "uv_offset", *uv_offset)?);
            let (resolved, bytes) = check.read_input(&path_field, path)?;
            let (w, h, pixels) = decode_image(&resolved, &bytes).map_err(|e| check.err(&path_field, e.to_string()))?;
            let image =
                ScalarImage::new(w as usize, h as usize, &pixels.linear_rgb(), scale, uv_scale, uv_offset, *wrap)
                    .map_err(|m| check.err(&path_field, format!("{path}: {m}")))?;
            if let Some((x, y, v)) = image.outside(lo, hi) {
                return Err(check.err(
                    &path_field,
                    format!("{path}: texel ({x}, {y}) times the scale is {v}; expected {what} in [{lo}, {hi}]"),
                ));
            }
            ScalarTexture::Image(Arc::new(image))
        }
    })
}

/// A pair of finite numbers at `field.name`.
fn finite2(check: &Check, field: &str, name: &str, v: [f32; 2]) -> Result<Vec2> {
    if v.iter().all(|c| c.is_finite()) {
        Ok(Vec2::from(v))
    } else {
        Err(check.err(format!("{field}.{name}"), format!("expected finite numbers, found {v:?}")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(w: usize, h: usize, rgb: &[[f32; 3]], wrap: Wrap) -> ImageTexture {
        ImageTexture::new(w, h, rgb, 1.0, Vec2::ONE, Vec2::ZERO, wrap, Role::Reflectance).unwrap()
    }

    /// Bilinear weights: at a texel's centre the texel itself; halfway between
    /// two horizontal neighbours their mean; v = 0 is the bottom row.
    #[test]
    fn bilinear_weights_and_orientation() {
        // 2x2 greys: top row 0.2, 0.4; bottom row 0.6, 0.8.
        let t = image(2, 2, &[[0.2; 3], [0.4; 3], [0.6; 3], [0.8; 3]], Wrap::Clamp);
        let at = |u: f32, v: f32| t.eval(Vec2::new(u, v))[0];
        assert_eq!(at(0.25, 0.75), 0.2, "top-left texel centre");
        assert_eq!(at(0.75, 0.25), 0.8, "bottom-right texel centre");
        assert!((at(0.5, 0.75) - 0.3).abs() < 1e-6, "halfway along the top row");
        assert!((at(0.5, 0.5) - 0.5).abs() < 1e-6, "the centre: all four equally");
        // Weights 3/4 and 1/4 a quarter of the way.
        assert!((at(0.375, 0.75) - (0.75 * 0.2 + 0.25 * 0.4)).abs() < 1e-6);
    }

    /// Wrap modes outside [0, 1]: Repeat is periodic, Clamp holds the edge.
    #[test]
    fn wrap_modes() {
        let px = [[0.1; 3], [0.9; 3]];
        let rep = image(2, 1, &px, Wrap::Repeat);
        let cla = image(2, 1, &px, Wrap::Clamp);
        for u in [0.25f32, 0.75] {
            assert_eq!(rep.eval(Vec2::new(u + 3.0, 0.5)), rep.eval(Vec2::new(u, 0.5)));
            assert_eq!(rep.eval(Vec2::new(u - 5.0, 0.5)), rep.eval(Vec2::new(u, 0.5)));
        }
        assert_eq!(cla.eval(Vec2::new(7.0, 0.5))[0], 0.9);
        assert_eq!(cla.eval(Vec2::new(-7.0, 0.5))[0], 0.1);
        // Repeat blends across the seam: at u = 0 the two texels equally.
        assert!((rep.eval(Vec2::new(0.0, 0.5))[0] - 0.5).abs() < 1e-6);
        // Huge and NaN coordinates stay in range (no panic).
        for u in [1e30f32, -1e30, f32::NAN, f32::INFINITY] {
            let _ = rep.eval(Vec2::new(u, u));
            let _ = cla.eval(Vec2::new(u, u));
        }
    }

    /// A one-colour image is bit for bit `Rgb(...)`'s reflectance everywhere.
    #[test]
    fn a_one_colour_image_is_rgb_reflectance() {
        let c = [0.7f32, 0.2, 0.1];
        let want = crate::color::rgb_reflectance(c);
        let t = image(5, 3, &[c; 15], Wrap::Repeat);
        for (u, v) in [(0.0f32, 0.0f32), (0.13, 0.77), (0.5, 0.5), (0.99, 0.01), (-3.2, 8.1)] {
            assert_eq!(t.eval(Vec2::new(u, v)), want);
        }
    }

    /// The checkerboard's squares.
    #[test]
    fn checkerboard_squares() {
        let t = Texture::Checkerboard {
            even: Box::new(Spectrum::splat(0.8)),
            odd: Box::new(Spectrum::splat(0.1)),
            scale: 4.0,
        };
        assert_eq!(t.eval(Vec2::new(0.1, 0.1))[0], 0.8);
        assert_eq!(t.eval(Vec2::new(0.3, 0.1))[0], 0.1);
        assert_eq!(t.eval(Vec2::new(0.3, 0.3))[0], 0.8);
        assert_eq!(t.eval(Vec2::new(-0.1, 0.1))[0], 0.1);
    }
}
