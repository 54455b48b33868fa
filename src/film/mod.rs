//! The film: per-pixel sums of XYZ in exact fixed point, the passes they
//! hold, and the image files made from them.
//!
//! The film stores what the output needs and nothing more: three sums per
//! pixel (XYZ, not 36 floats), because every integrator reduces a sample to
//! XYZ before it reaches the film; only a spectral film (`--spectral`,
//! [`Film::new_spectral`]) also sums each sample's 36 bins, in the same fixed
//! point, for the spectral EXR channels. It also records which passes it holds, a
//! contiguous range `[first, first + passes)`, so that checkpoints can be
//! resumed and films of disjoint pass ranges merged.
//!
//! # Why fixed point
//! Sums of f64 depend on the order of the additions in their last bits:
//! `(s(0..50)) + (s(50..100))` is not the f64 sum a single render accumulates
//! pass by pass. Integer addition is exactly associative, so each f32 sample
//! is converted to a signed 128-bit fixed-point number with [`FRAC_BITS`] = 64
//! fractional bits and added as an integer. Merging films of 0..50 and
//! 50..100, or resuming a checkpoint, then gives bit for bit the sums (and the
//! image) of one render of 0..100, in any merge order.
//!
//! Range and precision (48 bytes per pixel in memory):
//! - A sample converts **exactly** when `|v| >= 2^-41` (≈ 4.5e-13): its 24-bit
//!   mantissa then lies above 2^-64. Smaller magnitudes are rounded to the
//!   nearest multiple of 2^-64 (≈ 5.4e-20): an absolute error far below
//!   anything an f32 EXR or a 16-bit PNG can show.
//! - Samples are clamped to `±`[`MAX_SAMPLE`] = 2^31 (≈ 2.1e9, a billion
//!   times a bright light: a light that bright, or a bug) and counted apart
//!   from non-finite samples, which are dropped (`Faults`).
//!   With that bound, even `u32::MAX` passes cannot overflow an `i128`
//!   ((2^32 − 1) · 2^31 · 2^64 < 2^127), so every sum is exact.
//!
//! # Output
//! - PNG: 16-bit sRGB. The mean XYZ of each pixel goes to linear sRGB (D65,
//!   Rec. 709 primaries); each channel is clamped to [0, 1] (negative,
//!   out-of-gamut values become 0; values above 1 become 1: no tone mapping,
//!   no exposure) and encoded with the sRGB transfer curve.
//! - EXR (when the name ends in `.exr`): linear sRGB as 32-bit floats,
//!   unclamped, for measurements; or Rec. 2020, ACEScg or XYZ when the film's
//!   [`ColorSpace`] says so (`--color-space`).
//!
//! # Sensors
//! With a sensor file (`--sensor`, [`Sensor`]) the three sums are the sensor's camera RGB,
//! not XYZ: every output converts each pixel's mean with the sensor's colour-correction
//! matrix first (to linear sRGB, through the XYZ of that sRGB for the other spaces), except
//! `--color-space camera`, which writes the means as they are. A spectral film keeps the
//! default sensor (its bins' colour is XYZ).

use std::ops::Range;
use std::path::Path;

use std::sync::Arc;

use crate::color::{ColorSpace, N_BINS, Sensor, Spectrum, Tonemap, Xyz, bin_lambda_nm, xyz_to_linear_srgb_f64};
use crate::error::{Error, Result};
use crate::io::image::{is_exr, write_exr, write_exr_in, write_linear_srgb};

/// Fractional bits of the fixed-point sums.
pub const FRAC_BITS: u32 = 64;

/// The largest sample magnitude the film accepts; larger ones are clamped.
pub const MAX_SAMPLE: f32 = 2147483648.0; // 2^31

/// 2^FRAC_BITS as an f64 (exact).
const SCALE: f64 = 18446744073709551616.0; // 2^64

/// One f32 sample as a fixed-point integer (exact for `|v| >= 2^-41`; smaller
/// magnitudes round to the nearest multiple of 2^-64, halves away from zero).
///
/// Works on the float's bits: `v = m · 2^(e - 150)` with a 24-bit `m`, so the
/// fixed-point value is `m` shifted by `e - 86`. This avoids the software
/// f64 → i128 conversion, which made the (serial) film update a tenth of a
/// sample's cost.
#[inline]
pub(crate) fn to_fixed(v: f32) -> i128 {
    let v = v.clamp(-MAX_SAMPLE, MAX_SAMPLE);
    let bits = v.to_bits();
    let exp = ((bits >> 23) & 0xff) as i32;
    let mant = (bits & 0x7f_ffff) as i128;
    // Subnormals (exp 0) are below 2^-126: they round to 0 at 2^-64 resolution.
    let magnitude = if exp == 0 {
        0
    } else {
        let m = mant | 0x80_0000;
        let shift = exp - 86;
        if shift >= 0 {
            m << shift
        } else if shift > -64 {
            // Round half away from zero on the magnitude.
            (m + (1 << (-shift - 1))) >> -shift
        } else {
            0
        }
    };
    if bits >> 31 == 1 { -magnitude } else { magnitude }
}

/// A fixed-point sum as an f64 (rounded to nearest).
#[inline]
pub(crate) fn from_fixed(v: i128) -> f64 {
    v as f64 / SCALE
}

/// A contribution that lands in a pixel other than its camera sample's: a
/// light subpath connected to the camera (light tracing, BDPT's t = 1).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Splat<S> {
    /// Column.
    pub x: u32,
    /// Row.
    pub y: u32,
    /// The contribution, already divided by the light subpaths per pass.
    pub value: S,
}

/// Samples the film could not add as they were: non-finite ones are
/// dropped (a bug: the renderer reports it), ones beyond ±[`MAX_SAMPLE`]
/// clamped (a light brighter than the film's range: reported as such).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Faults {
    /// NaN or infinite samples, dropped.
    pub dropped: usize,
    /// Samples beyond ±[`MAX_SAMPLE`], clamped.
    pub clamped: usize,
}

impl std::ops::Add for Faults {
    type Output = Faults;
    fn add(self, o: Faults) -> Faults {
        Faults { dropped: self.dropped + o.dropped, clamped: self.clamped + o.clamped }
    }
}

impl std::ops::AddAssign for Faults {
    fn add_assign(&mut self, o: Faults) {
        *self = *self + o;
    }
}

impl std::iter::Sum for Faults {
    fn sum<I: Iterator<Item = Faults>>(iter: I) -> Faults {
        iter.fold(Faults::default(), |a, b| a + b)
    }
}

/// A rectangle of pixels `[x0, x1) × [y0, y1)`: what the film adds a buffer of
/// samples to. The scheduler (`crate::render::tiles`) decides how an image is
/// cut into them and in what order they run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Tile {
    /// First column.
    pub x0: u32,
    /// First row.
    pub y0: u32,
    /// One past the last column.
    pub x1: u32,
    /// One past the last row.
    pub y1: u32,
}

impl Tile {
    /// Number of pixels.
    pub fn len(&self) -> usize {
        ((self.x1 - self.x0) * (self.y1 - self.y0)) as usize
    }
}

/// Per-pixel XYZ sums (fixed point, see the module docs) over a contiguous
/// range of whole passes.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    width: u32,
    height: u32,
    /// Row-major sums of XYZ, scaled by 2^[`FRAC_BITS`].
    sums: Vec<[i128; 3]>,
    /// The first pass held.
    first_pass: u32,
    /// Passes (samples per pixel) summed so far.
    passes: u32,
    /// The colour space of EXR output (an output choice: not stored in checkpoints).
    color_space: ColorSpace,
    /// The exposure of every output, in stops (`--exposure`; not stored either).
    exposure_ev: f64,
    /// How a PNG maps radiance to [0, 1] (`--tonemap`; not stored either).
    tonemap: Tonemap,
    /// Row-major per-bin radiance sums (fixed point like `sums`), when the film is spectral
    /// (`--spectral`): 36 more sums per pixel, whose colour integral is `sums`.
    spectral: Option<Vec<[i128; N_BINS]>>,
    /// The sensor whose channels the sums hold ([`Sensor::cie1931`]: XYZ). Checkpoints store it.
    sensor: Arc<Sensor>,
}

/// One camera sample as the film takes it: its XYZ and, for a spectral film, its per-bin
/// radiance.
pub(crate) trait FilmSample: Copy + Send + Sync {
    /// The sample's XYZ.
    fn xyz(&self) -> Xyz;
    /// The sample's per-bin radiance, if it has one.
    fn bins(&self) -> Option<&Spectrum>;
}

impl FilmSample for Xyz {
    #[inline]
    fn xyz(&self) -> Xyz {
        *self
    }
    #[inline]
    fn bins(&self) -> Option<&Spectrum> {
        None
    }
}

impl FilmSample for Spectrum {
    #[inline]
    fn xyz(&self) -> Xyz {
        self.to_xyz()
    }
    #[inline]
    fn bins(&self) -> Option<&Spectrum> {
        Some(self)
    }
}

impl Film {
    /// An empty film (its pass range starts where the first render starts).
    pub fn new(width: u32, height: u32) -> Self {
        Film {
            width,
            height,
            sums: vec![[0; 3]; width as usize * height as usize],
            first_pass: 0,
            passes: 0,
            color_space: ColorSpace::Srgb,
            exposure_ev: 0.0,
            tonemap: Tonemap::Clip,
            spectral: None,
            sensor: Sensor::cie1931().clone(),
        }
    }

    /// An empty spectral film: it also sums each sample's 36 bins (`--spectral`).
    pub fn new_spectral(width: u32, height: u32, first_pass: u32) -> Self {
        let n = width as usize * height as usize;
        Film { spectral: Some(vec![[0; N_BINS]; n]), ..Film::starting_at(width, height, first_pass) }
    }

    /// The per-bin sums of a spectral film (row-major, fixed point), or `None`.
    pub fn spectral_sums(&self) -> Option<&[[i128; N_BINS]]> {
        self.spectral.as_deref()
    }

    /// Adds stored per-bin sums (a checkpoint of a spectral film), checked like
    /// [`Film::from_parts`] checks the XYZ sums.
    pub fn with_spectral_sums(mut self, sums: Vec<[i128; N_BINS]>) -> Result<Self> {
        if sums.len() != self.sums.len() {
            return Err(Error::Mismatch(format!("{} spectral sums for {} pixels", sums.len(), self.sums.len())));
        }
        let bound = to_fixed(MAX_SAMPLE) * self.passes as i128;
        if let Some(i) = sums.iter().position(|s| s.iter().any(|v| v.unsigned_abs() > bound.unsigned_abs())) {
            return Err(Error::Mismatch(format!(
                "pixel {i} holds a spectral sum out of range for {} passes",
                self.passes
            )));
        }
        self.spectral = Some(sums);
        Ok(self)
    }

    /// The most memory a render of a `width` x `height` film takes, in bytes
    /// (a bound: the parts are not all held at once): the film's sums (48
    /// bytes a pixel), a batch's sample buffers (12 bytes a pixel a pass: one
    /// pass from 512² up; smaller images hold a few passes, at most 64 MiB), a
    /// checkpoint being encoded (up to 51 bytes a pixel, twice: bincode, then
    /// lz4) and the output image being made (the mean colour in f64, 24 bytes,
    /// its 16-bit or f32 copy, 12, and the encoded file and the encoder's
    /// buffers, up to 36); a spectral film adds 36 sums (576 bytes), 36 floats
    /// of samples (160 with alignment), their encoding (up to 612, twice) and
    /// the EXR's 36 channels (144 bytes, copied once by the encoder, and
    /// encoded: 432). Renders refuse sizes the process cannot hold before
    /// allocating anything (`ulimit -v` and cgroup limits included): a render
    /// that passes the check does not abort at its end for want of memory.
    pub fn bytes_needed(width: u32, height: u32, spectral: bool) -> u64 {
        let output = 24 + 12 + 36;
        let per_pixel = 48 + 12 + 2 * 51 + output + if spectral { 576 + 160 + 2 * 612 + 432 } else { 0 };
        width as u64 * height as u64 * per_pixel
    }

    /// An empty film whose first pass will be `first_pass` (a render of a
    /// pass range `first_pass..`).
    pub fn starting_at(width: u32, height: u32, first_pass: u32) -> Self {
        Film { first_pass, ..Film::new(width, height) }
    }

    /// A film from stored parts (a checkpoint). Fails when the number of
    /// sums does not match the size, the pass range is invalid, or a sum is
    /// larger than its number of passes allows (so later additions cannot
    /// overflow).
    pub fn from_parts(width: u32, height: u32, passes: Range<u32>, sums: Vec<[i128; 3]>) -> Result<Self> {
        if sums.len() != width as usize * height as usize {
            return Err(Error::Mismatch(format!("{} pixel sums for a {width}x{height} film", sums.len())));
        }
        if passes.end < passes.start {
            return Err(Error::Mismatch(format!("invalid pass range {}..{}", passes.start, passes.end)));
        }
        let n = passes.end - passes.start;
        let bound = to_fixed(MAX_SAMPLE) * n as i128;
        if let Some(i) = sums.iter().position(|s| s.iter().any(|v| v.unsigned_abs() > bound.unsigned_abs())) {
            return Err(Error::Mismatch(format!("pixel {i} holds a sum out of range for {n} passes")));
        }
        Ok(Film {
            width,
            height,
            sums,
            first_pass: passes.start,
            passes: n,
            color_space: ColorSpace::Srgb,
            exposure_ev: 0.0,
            tonemap: Tonemap::Clip,
            spectral: None,
            sensor: Sensor::cie1931().clone(),
        })
    }

    /// Sets the sensor whose channels the film sums (before anything is added: a render
    /// gives its scene's, a checkpoint the one it stored). A spectral film keeps the default:
    /// its bins' colour is XYZ.
    pub fn set_sensor(&mut self, sensor: Arc<Sensor>) -> Result<()> {
        if self.spectral.is_some() && !sensor.is_cie1931() {
            return Err(Error::Mismatch(format!(
                "a spectral film (--spectral) holds XYZ with its 36 bins; it cannot take the sensor {}",
                sensor.name()
            )));
        }
        self.sensor = sensor;
        Ok(())
    }

    /// The sensor whose channels the film sums.
    pub fn sensor(&self) -> &Arc<Sensor> {
        &self.sensor
    }

    /// Sets the colour space of EXR output (PNG output is always sRGB).
    pub fn set_color_space(&mut self, space: ColorSpace) {
        self.color_space = space;
    }

    /// The colour space of EXR output.
    pub fn color_space(&self) -> ColorSpace {
        self.color_space
    }

    /// Sets the exposure (stops: every output is scaled by `2^ev`, exactly) and
    /// the tone mapping of PNG output ([`Tonemap`]; EXR stays linear).
    pub fn set_picture(&mut self, exposure_ev: f64, tonemap: Tonemap) {
        self.exposure_ev = exposure_ev;
        self.tonemap = tonemap;
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Passes (samples per pixel) summed so far.
    pub fn passes(&self) -> u32 {
        self.passes
    }

    /// The passes held: `first..first + passes`.
    pub fn pass_range(&self) -> Range<u32> {
        self.first_pass..self.first_pass + self.passes
    }

    /// The row-major fixed-point sums (X, Y, Z scaled by 2^[`FRAC_BITS`]).
    pub fn sums(&self) -> &[[i128; 3]] {
        &self.sums
    }

    /// Makes an empty film start at pass `first` (the renderer does this).
    pub(crate) fn start_at(&mut self, first: u32) {
        debug_assert_eq!(self.passes, 0);
        self.first_pass = first;
    }

    /// Records that one more whole pass has been added (the renderer does this).
    pub(crate) fn end_pass(&mut self) {
        self.passes += 1;
    }

    /// Adds one sample per pixel of `tile` (row-major within the tile).
    /// Returns the samples it could not add as they were ([`Faults`]):
    /// non-finite ones are dropped, ones beyond ±[`MAX_SAMPLE`] clamped. (The renderer adds
    /// whole batches with [`Film::add_tiles_parallel`]; this is the tests'
    /// tile-by-tile reference.)
    #[cfg(test)]
    pub(crate) fn add_tile<S: FilmSample>(&mut self, tile: &Tile, samples: &[S]) -> Faults {
        add_tile_to_rows(&mut self.sums, self.spectral.as_deref_mut(), self.width, 0, tile, samples)
    }

    /// Adds whole passes of samples of `tiles` (row-major tiles of edge
    /// `tile_size`, as `crate::render::tiles` makes them), and splats: `samples` holds one buffer per
    /// tile per pass, pass-major (`samples[p * tiles.len() + k]` belongs to
    /// `tiles[k]` in the `p`-th pass); `splats` holds lists of splats, each ordered
    /// by band (`y / tile_size`). Each band of tile rows is added in
    /// parallel: bands own disjoint pixel rows, and integer sums do not depend
    /// on the order of the additions, so the sums are those of adding tile by
    /// tile, pass by pass, then the splats one by one (`add_splats`).
    /// A band finds its splats in each list by binary search, so splats cost no
    /// serial time (adding them after the parallel loop, on one thread, was 3% of
    /// a light-tracing render: a 1.94x ceiling on two threads).
    /// The caller records the passes with `end_pass`.
    /// Returns the samples and splats it dropped or clamped.
    pub(crate) fn add_tiles_parallel<S: FilmSample>(
        &mut self,
        tiles: &[Tile],
        samples: &[Vec<S>],
        splats: &[Vec<Splat<S>>],
        tile_size: u32,
    ) -> Faults {
        use rayon::prelude::*;
        assert!(!tiles.is_empty() && samples.len().is_multiple_of(tiles.len()), "samples must hold whole passes");
        let width = self.width;
        let tiles_x = width.div_ceil(tile_size).max(1) as usize;
        let band_len = width as usize * tile_size as usize;
        debug_assert!(splats.iter().all(|l| l.is_sorted_by_key(|s| s.y / tile_size)), "splats must be ordered by band");
        let add_band = |band: usize, rows: &mut [[i128; 3]], mut spec: Option<&mut [[i128; N_BINS]]>| {
            let first_row = band as u32 * tile_size;
            let end_row = first_row + (rows.len() / width as usize) as u32;
            let band_tiles = band * tiles_x..((band + 1) * tiles_x).min(tiles.len());
            let tiled = samples
                .chunks(tiles.len())
                .map(|pass| {
                    band_tiles
                        .clone()
                        .map(|k| add_tile_to_rows(rows, spec.as_deref_mut(), width, first_row, &tiles[k], &pass[k]))
                        .sum::<Faults>()
                })
                .sum::<Faults>();
            let mut splatted = Faults::default();
            for list in splats {
                let b = band as u32;
                let mine =
                    list.partition_point(|s| s.y / tile_size < b)..list.partition_point(|s| s.y / tile_size <= b);
                // The last band's list also holds splats below the film (dropped, as off-film splats are).
                for s in list[mine].iter().filter(|s| s.x < width && s.y < end_row) {
                    let i = (s.y - first_row) as usize * width as usize + s.x as usize;
                    splatted += add_sample(&mut rows[i], spec.as_deref_mut().map(|spec| &mut spec[i]), &s.value);
                }
            }
            tiled + splatted
        };
        match self.spectral.as_mut() {
            None => self.sums.par_chunks_mut(band_len).enumerate().map(|(band, rows)| add_band(band, rows, None)).sum(),
            Some(spectral) => self
                .sums
                .par_chunks_mut(band_len)
                .zip(spectral.par_chunks_mut(band_len))
                .enumerate()
                .map(|(band, (rows, spec))| add_band(band, rows, Some(spec)))
                .sum(),
        }
    }

    /// Adds splats to their pixels. Like samples, they are summed in fixed
    /// point, so the result does not depend on the order of the splats or of
    /// the calls; non-finite ones are dropped and counted, oversized ones
    /// clamped and counted (the return value). (The renderer adds splats with the
    /// samples in [`Film::add_tiles_parallel`]; this is the tests' reference.)
    #[cfg(test)]
    pub(crate) fn add_splats<S: FilmSample>(&mut self, splats: &[Splat<S>]) -> Faults {
        let mut bad = Faults::default();
        for s in splats {
            if s.x >= self.width || s.y >= self.height {
                continue;
            }
            let k = s.y as usize * self.width as usize + s.x as usize;
            let spec = self.spectral.as_mut().map(|spec| &mut spec[k]);
            bad += add_sample(&mut self.sums[k], spec, &s.value);
        }
        bad
    }

    /// Adds the passes of `other`, which must be the same size and hold the
    /// passes right after this film's (or this film must be empty). The
    /// result is bit-identical to one render of the combined range.
    pub fn merge(&mut self, other: &Film) -> Result<()> {
        if (self.width, self.height) != (other.width, other.height) {
            return Err(Error::Mismatch(format!(
                "a {}x{} film cannot be merged with a {}x{} one",
                other.width, other.height, self.width, self.height
            )));
        }
        if self.passes == 0 {
            self.first_pass = other.first_pass;
        } else if other.passes > 0 && other.first_pass != self.pass_range().end {
            let (a, b) = (self.pass_range(), other.pass_range());
            return Err(Error::Mismatch(format!(
                "passes {}..{} do not follow passes {}..{}",
                b.start, b.end, a.start, a.end
            )));
        }
        if self.sensor != other.sensor {
            return Err(Error::Mismatch(format!(
                "a film of the sensor {} cannot be merged with one of the sensor {}",
                other.sensor.name(),
                self.sensor.name()
            )));
        }
        if self.spectral.is_some() != other.spectral.is_some() {
            return Err(Error::Mismatch("a spectral film (--spectral) cannot be merged with a colour-only one".into()));
        }
        let passes =
            self.passes.checked_add(other.passes).ok_or_else(|| Error::Mismatch("more than 2^32 passes".into()))?;
        if let (Some(mine), Some(theirs)) = (self.spectral.as_mut(), other.spectral.as_ref()) {
            for (s, o) in mine.iter_mut().zip(theirs) {
                for b in 0..N_BINS {
                    s[b] = s[b].checked_add(o[b]).ok_or_else(|| Error::Mismatch("a pixel sum overflows".into()))?;
                }
            }
        }
        for (s, o) in self.sums.iter_mut().zip(&other.sums) {
            for c in 0..3 {
                s[c] = s[c].checked_add(o[c]).ok_or_else(|| Error::Mismatch("a pixel sum overflows".into()))?;
            }
        }
        self.passes = passes;
        Ok(())
    }

    /// The mean XYZ of every pixel, row-major: the sums' means, or with a sensor file the XYZ of
    /// their colour-corrected linear sRGB.
    pub fn mean_xyz(&self) -> Vec<[f64; 3]> {
        let means = self.mean_sums();
        match self.sensor.to_xyz() {
            None => means,
            Some(m) => means
                .into_iter()
                .map(|c| std::array::from_fn(|i| m[i][0] * c[0] + m[i][1] * c[1] + m[i][2] * c[2]))
                .collect(),
        }
    }

    /// The mean of each pixel's three sums, row-major: XYZ, or a sensor file's camera RGB.
    pub fn mean_sums(&self) -> Vec<[f64; 3]> {
        let inv = if self.passes == 0 { 0.0 } else { 1.0 / self.passes as f64 };
        self.sums.iter().map(|s| s.map(|v| from_fixed(v) * inv)).collect()
    }

    /// The mean linear sRGB of every pixel, row-major, unclamped.
    pub fn linear_srgb(&self) -> Vec<[f64; 3]> {
        self.mean_xyz().into_iter().map(xyz_to_linear_srgb_f64).collect()
    }

    /// Writes the image: linear EXR if `path` ends in `.exr` (in the film's colour space), else
    /// 16-bit sRGB PNG ([`crate::io::image::write_linear_srgb`]), atomically.
    pub fn write(&self, path: &Path) -> Result<()> {
        // 2^ev is exact, and at 0 stops nothing is multiplied: images bit-identical.
        let scale = self.exposure_ev.exp2();
        let expose = |v: f64| if self.exposure_ev == 0.0 { v } else { v * scale };
        if is_exr(path) && (self.color_space != ColorSpace::Srgb || self.spectral.is_some()) {
            let pixels: Vec<[f64; 3]> = if self.color_space == ColorSpace::Camera {
                self.mean_sums().into_iter().map(|p| p.map(expose)).collect()
            } else {
                self.mean_xyz().into_iter().map(|p| self.color_space.from_xyz(p).map(expose)).collect()
            };
            let Some(spectral) = &self.spectral else {
                return write_exr_in(path, self.width, self.height, &pixels, self.color_space);
            };
            let inv = if self.passes == 0 { 0.0 } else { 1.0 / self.passes as f64 };
            let bins: Vec<Vec<f32>> =
                (0..N_BINS).map(|b| spectral.iter().map(|s| expose(from_fixed(s[b]) * inv) as f32).collect()).collect();
            let wavelengths: Vec<f32> = (0..N_BINS).map(bin_lambda_nm).collect();
            return write_exr(path, self.width, self.height, &pixels, self.color_space, Some((&wavelengths, &bins)));
        }
        let mut rgb = self.linear_srgb();
        if self.exposure_ev != 0.0 {
            rgb.iter_mut().for_each(|p| *p = p.map(expose));
        }
        if !is_exr(path) && self.tonemap != Tonemap::Clip {
            rgb.iter_mut().for_each(|p| *p = self.tonemap.apply(*p));
        }
        write_linear_srgb(path, self.width, self.height, &rgb)
    }
}

/// Adds a tile's samples into `rows`, the film rows from `first_row` on
/// (`width` pixels each). Non-finite samples are dropped, ones beyond
/// ±[`MAX_SAMPLE`] clamped; both are counted in the return value.
fn add_tile_to_rows<S: FilmSample>(
    rows: &mut [[i128; 3]],
    mut spectral: Option<&mut [[i128; N_BINS]]>,
    width: u32,
    first_row: u32,
    tile: &Tile,
    samples: &[S],
) -> Faults {
    debug_assert_eq!(samples.len(), tile.len());
    let mut bad = Faults::default();
    let mut k = 0;
    for y in tile.y0..tile.y1 {
        let row = (y - first_row) as usize * width as usize;
        for x in tile.x0..tile.x1 {
            let i = row + x as usize;
            bad += add_sample(&mut rows[i], spectral.as_deref_mut().map(|spec| &mut spec[i]), &samples[k]);
            k += 1;
        }
    }
    bad
}

/// Adds one sample to a pixel's sums (and its spectral sums, if the film has
/// them). A non-finite sample is dropped, one beyond ±[`MAX_SAMPLE`] clamped;
/// returns which (the renderer reports them).
#[inline]
fn add_sample<S: FilmSample>(sum: &mut [i128; 3], spectral: Option<&mut [i128; N_BINS]>, sample: &S) -> Faults {
    let s = sample.xyz();
    let bins = sample.bins();
    if !(s.x.is_finite() && s.y.is_finite() && s.z.is_finite()) || bins.is_some_and(|b| b.has_nan_or_inf()) {
        return Faults { dropped: 1, clamped: 0 };
    }
    if let (Some(spec), Some(b)) = (spectral, bins) {
        for (acc, &v) in spec.iter_mut().zip(&b.0) {
            *acc += to_fixed(v);
        }
    }
    sum[0] += to_fixed(s.x);
    sum[1] += to_fixed(s.y);
    sum[2] += to_fixed(s.z);
    Faults { dropped: 0, clamped: usize::from(s.x.abs().max(s.y.abs()).max(s.z.abs()) > MAX_SAMPLE) }
}

#[cfg(test)]
mod tests;
