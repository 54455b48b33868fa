//! The film: per-pixel sums of XYZ in f64, and the image files made from them.
//!
//! The film stores what the output needs and nothing more: three f64 sums
//! per pixel (not 36 floats; 24 bytes per pixel), because every integrator
//! reduces a sample to XYZ before it reaches the film. Samples are added one
//! whole pass at a time, each pixel in pass order, so the sums (and so the
//! image) do not depend on thread count or tile order.
//!
//! # Output
//! - PNG: 16-bit sRGB. The mean XYZ of each pixel goes to linear sRGB (D65,
//!   Rec. 709 primaries); each channel is clamped to [0, 1] (negative,
//!   out-of-gamut values become 0; values above 1 become 1: no tone mapping,
//!   no exposure) and encoded with the sRGB transfer curve.
//! - EXR (when the name ends in `.exr`): linear sRGB as 32-bit floats,
//!   unclamped, for measurements.

use std::path::Path;

use crate::color::{Xyz, srgb_oetf, xyz_to_linear_srgb_f64};
use crate::error::{Error, Result};

/// A rectangle of pixels `[x0, x1) × [y0, y1)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tile {
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

    /// True for an empty tile.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Splits a `width × height` image into tiles of at most `size × size`, row-major.
pub fn tiles(width: u32, height: u32, size: u32) -> Vec<Tile> {
    let mut out = Vec::new();
    for y0 in (0..height).step_by(size as usize) {
        for x0 in (0..width).step_by(size as usize) {
            out.push(Tile { x0, y0, x1: (x0 + size).min(width), y1: (y0 + size).min(height) });
        }
    }
    out
}

/// Per-pixel XYZ sums over whole passes.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    width: u32,
    height: u32,
    /// Row-major sums of XYZ.
    pub sums: Vec<[f64; 3]>,
    /// Passes (samples per pixel) summed so far.
    pub passes: u32,
}

impl Film {
    /// An empty film.
    pub fn new(width: u32, height: u32) -> Self {
        Film { width, height, sums: vec![[0.0; 3]; (width * height) as usize], passes: 0 }
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Adds one sample per pixel of `tile` (row-major within the tile).
    /// Returns the number of non-finite samples, which are dropped (counted
    /// and reported by the renderer: they are bugs, never expected).
    pub fn add_tile(&mut self, tile: &Tile, samples: &[Xyz]) -> usize {
        debug_assert_eq!(samples.len(), tile.len());
        let mut bad = 0;
        let mut k = 0;
        for y in tile.y0..tile.y1 {
            let row = (y * self.width) as usize;
            for x in tile.x0..tile.x1 {
                let s = samples[k];
                k += 1;
                if !(s.x.is_finite() && s.y.is_finite() && s.z.is_finite()) {
                    bad += 1;
                    continue;
                }
                let sum = &mut self.sums[row + x as usize];
                sum[0] += s.x as f64;
                sum[1] += s.y as f64;
                sum[2] += s.z as f64;
            }
        }
        bad
    }

    /// The mean XYZ of every pixel, row-major.
    pub fn mean_xyz(&self) -> Vec<[f64; 3]> {
        let inv = if self.passes == 0 { 0.0 } else { 1.0 / self.passes as f64 };
        self.sums.iter().map(|s| s.map(|v| v * inv)).collect()
    }

    /// The mean linear sRGB of every pixel, row-major, unclamped.
    pub fn linear_srgb(&self) -> Vec<[f64; 3]> {
        self.mean_xyz().into_iter().map(xyz_to_linear_srgb_f64).collect()
    }

    /// Writes the image: linear EXR if `path` ends in `.exr`, else 16-bit sRGB PNG.
    /// The file is written under a temporary name and renamed into place.
    pub fn write(&self, path: &Path) -> Result<()> {
        let is_exr = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr"));
        let rgb = self.linear_srgb();
        let tmp = temp_path(path);
        let result = if is_exr {
            let data: Vec<f32> = rgb.iter().flat_map(|p| p.map(|v| v as f32)).collect();
            image::Rgb32FImage::from_raw(self.width, self.height, data)
                .expect("buffer size matches the film")
                .save_with_format(&tmp, image::ImageFormat::OpenExr)
        } else {
            let data: Vec<u16> = rgb.iter().flat_map(|p| p.map(encode_u16)).collect();
            image::ImageBuffer::<image::Rgb<u16>, Vec<u16>>::from_raw(self.width, self.height, data)
                .expect("buffer size matches the film")
                .save_with_format(&tmp, image::ImageFormat::Png)
        };
        result.map_err(|e| Error::Image { path: path.to_path_buf(), message: e.to_string() })?;
        std::fs::rename(&tmp, path).map_err(|e| Error::io(path, e))
    }
}

/// Linear value to a 16-bit sRGB code: clamp to [0, 1], transfer curve, round.
#[inline]
pub fn encode_u16(linear: f64) -> u16 {
    let v = if linear.is_nan() { 0.0 } else { linear.clamp(0.0, 1.0) as f32 };
    (srgb_oetf(v) * 65535.0 + 0.5) as u16
}

/// `dir/.name.tmp-PID`: a temporary name in the same directory (so the rename is atomic).
pub fn temp_path(path: &Path) -> std::path::PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    path.with_file_name(format!(".{name}.tmp-{}", std::process::id()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_cover_any_size_exactly_once() {
        for (w, h) in [(1, 1), (17, 5), (64, 64), (65, 33)] {
            let mut seen = vec![0; (w * h) as usize];
            for t in tiles(w, h, 16) {
                for y in t.y0..t.y1 {
                    for x in t.x0..t.x1 {
                        seen[(y * w + x) as usize] += 1;
                    }
                }
            }
            assert!(seen.iter().all(|&c| c == 1), "{w}x{h}");
        }
    }

    #[test]
    fn encoding_clamps_and_follows_the_transfer_curve() {
        assert_eq!(encode_u16(-0.5), 0);
        assert_eq!(encode_u16(f64::NAN), 0);
        assert_eq!(encode_u16(2.0), 65535);
        assert_eq!(encode_u16(1.0), 65535);
        // 0.5 linear is 0.7354 encoded (IEC 61966-2-1).
        assert!((encode_u16(0.5) as f64 / 65535.0 - 0.73536).abs() < 1e-4);
    }

    #[test]
    fn non_finite_samples_are_dropped_and_counted() {
        let mut f = Film::new(2, 1);
        let t = Tile { x0: 0, y0: 0, x1: 2, y1: 1 };
        let bad = f.add_tile(&t, &[Xyz::new(f32::NAN, 0.0, 0.0), Xyz::new(1.0, 2.0, 3.0)]);
        assert_eq!(bad, 1);
        assert_eq!(f.sums, vec![[0.0; 3], [1.0, 2.0, 3.0]]);
    }
}
