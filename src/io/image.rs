//! Image files: writing a film's mean as a 16-bit sRGB PNG or a linear
//! float EXR (atomically), and reading PNG or EXR images back for the
//! analysis tools.
//!
//! - PNG: 16-bit sRGB. Each linear channel is clamped to [0, 1] (negative,
//!   out-of-gamut values become 0; values above 1 become 1: no tone mapping,
//!   no exposure) and encoded with the sRGB transfer curve ([`encode_u16`]).
//! - EXR (when the name ends in `.exr`): linear sRGB as 32-bit floats,
//!   unclamped, for measurements; or, with `--color-space`, Rec. 2020, ACEScg or XYZ with a
//!   `chromaticities` attribute ([`write_exr_in`]).

use std::io::Cursor;
use std::path::Path;

use super::write_atomic;
use crate::color::{ColorSpace, srgb_oetf};
use crate::error::{Error, Result};

/// True when `path` names an EXR file (by its extension, any case).
pub fn is_exr(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr"))
}

/// Writes `width` x `height` linear sRGB pixels (row-major): linear EXR if
/// `path` ends in `.exr`, else 16-bit sRGB PNG. The file is encoded in
/// memory, written under a temporary name, synced and renamed into place,
/// so `path` never holds a partial image.
pub fn write_linear_srgb(path: &Path, width: u32, height: u32, rgb: &[[f64; 3]]) -> Result<()> {
    let mut bytes = Cursor::new(Vec::new());
    let image_error = |e: image::ImageError| Error::Image { path: path.to_path_buf(), message: e.to_string() };
    let size_error = || Error::Image { path: path.to_path_buf(), message: "buffer size does not match".into() };
    if is_exr(path) {
        let data: Vec<f32> = rgb.iter().flat_map(|p| p.map(|v| v as f32)).collect();
        image::Rgb32FImage::from_raw(width, height, data)
            .ok_or_else(size_error)?
            .write_to(&mut bytes, image::ImageFormat::OpenExr)
            .map_err(image_error)?;
    } else {
        let data: Vec<u16> = rgb.iter().flat_map(|p| p.map(encode_u16)).collect();
        image::ImageBuffer::<image::Rgb<u16>, Vec<u16>>::from_raw(width, height, data)
            .ok_or_else(size_error)?
            .write_to(&mut bytes, image::ImageFormat::Png)
            .map_err(image_error)?;
    }
    write_atomic(path, &bytes.into_inner())
}

/// Writes `width` x `height` pixels (row-major, already in `space`) as a 32-bit float EXR whose
/// `chromaticities` attribute names the space, atomically. XYZ gets channels X, Y, Z (the
/// OpenEXR convention, as Mitsuba writes it); the RGB spaces R, G, B.
pub fn write_exr_in(path: &Path, width: u32, height: u32, pixels: &[[f64; 3]], space: ColorSpace) -> Result<()> {
    write_exr(path, width, height, pixels, space, None)
}

/// The channel name of spectral bin `lambda_nm` in the layout of Fichet et al. 2021 ("An
/// OpenEXR Layout for Spectral Images", JCGT 10(3)): emissive Stokes component 0, the
/// wavelength with a comma as the decimal separator, then the unit: `S0.380,000000nm`.
pub fn spectral_channel_name(lambda_nm: f32) -> String {
    format!("S0.{:.6}nm", lambda_nm).replace('.', ",").replacen(',', ".", 1)
}

/// Writes an EXR like [`write_exr_in`] plus, when `spectral` is given (per pixel, the mean
/// radiance of each bin at `wavelengths_nm`), one float channel per bin named as Fichet et al.
/// 2021 specify ([`spectral_channel_name`]), with their `spectralLayoutVersion` attribute.
pub fn write_exr(
    path: &Path,
    width: u32,
    height: u32,
    pixels: &[[f64; 3]],
    space: ColorSpace,
    spectral: Option<(&[f32], &[Vec<f32>])>,
) -> Result<()> {
    use exr::meta::attribute::{AttributeValue, Chromaticities, Text};
    use exr::prelude::{AnyChannel, AnyChannels, Encoding, FlatSamples, Layer, LayerAttributes, Vec2, WritableImage};
    let bad = |message: String| Error::Image { path: path.to_path_buf(), message };
    if pixels.len() != width as usize * height as usize {
        return Err(bad("buffer size does not match".into()));
    }
    let names = space.channels();
    let mut channels: Vec<AnyChannel<FlatSamples>> = (0..3)
        .map(|c| AnyChannel::new(names[c], FlatSamples::F32(pixels.iter().map(|p| p[c] as f32).collect())))
        .collect();
    let mut attributes = LayerAttributes::default();
    if let Some((wavelengths, bins)) = spectral {
        if bins.len() != wavelengths.len() || bins.iter().any(|b| b.len() != pixels.len()) {
            return Err(bad("spectral buffer size does not match".into()));
        }
        for (l, b) in wavelengths.iter().zip(bins) {
            channels.push(AnyChannel::new(spectral_channel_name(*l).as_str(), FlatSamples::F32(b.clone())));
        }
        // The layout's one required attribute. Its optional `emissiveUnits` is left out: the exr
        // crate keeps custom attributes in a HashMap whose order changes from run to run, and
        // with two of them the file's bytes would too (renders must be byte-reproducible).
        attributes.other.insert(Text::from("spectralLayoutVersion"), AttributeValue::Text(Text::from("1.0")));
    }
    let layer = Layer::new(
        (width as usize, height as usize),
        attributes,
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(channels.into()),
    );
    let mut image = exr::image::Image::from_layer(layer);
    if space != ColorSpace::Camera {
        let xy = space.chromaticities().map(|[x, y]| Vec2(x as f32, y as f32));
        image.attributes.chromaticities = Some(Chromaticities { red: xy[0], green: xy[1], blue: xy[2], white: xy[3] });
    }
    let mut bytes = Cursor::new(Vec::new());
    image.write().non_parallel().to_buffered(&mut bytes).map_err(|e| bad(e.to_string()))?;
    write_atomic(path, &bytes.into_inner())
}

/// The pixels of an image file as stored.
#[derive(Debug)]
pub enum Pixels {
    /// Linear sRGB floats (EXR).
    Linear(Vec<[f64; 3]>),
    /// 16-bit sRGB codes (PNG of 8 or 16 bits per channel, widened).
    Code16(Vec<[u16; 3]>),
}

impl Pixels {
    /// Linear sRGB values: EXR values as they are, PNG codes through the sRGB
    /// transfer function (IEC 61966-2-1; 8-bit codes were widened exactly).
    pub fn linear_rgb(self) -> Vec<[f32; 3]> {
        match self {
            Pixels::Linear(p) => p.into_iter().map(|c| c.map(|v| v as f32)).collect(),
            Pixels::Code16(p) => {
                p.into_iter().map(|c| c.map(|v| crate::color::srgb_eotf(v as f32 / 65535.0))).collect()
            }
        }
    }
}

/// Reads a PNG (8 or 16 bits per channel) or an EXR (linear sRGB floats):
/// width, height and pixels.
pub fn read_image(path: &Path) -> Result<(u32, u32, Pixels)> {
    decode_image(path, &crate::io::read_input(path)?)
}

/// Decodes `bytes`, the content of the PNG or EXR file at `path` (named in errors), as
/// [`read_image`] does.
pub fn decode_image(path: &Path, bytes: &[u8]) -> Result<(u32, u32, Pixels)> {
    let reader = image::ImageReader::new(Cursor::new(bytes)).with_guessed_format().map_err(|e| Error::io(path, e))?;
    let bad = |message: String| Error::Image { path: path.to_path_buf(), message };
    let format = reader.format();
    let img = reader.decode().map_err(|e| bad(format!("cannot decode: {e}")))?;
    match format {
        Some(image::ImageFormat::OpenExr) => {
            let rgb = img.into_rgb32f();
            let (w, h) = rgb.dimensions();
            Ok((w, h, Pixels::Linear(rgb.pixels().map(|p| p.0.map(f64::from)).collect())))
        }
        Some(image::ImageFormat::Png) => {
            let rgb = img.into_rgb16();
            let (w, h) = rgb.dimensions();
            Ok((w, h, Pixels::Code16(rgb.pixels().map(|p| p.0).collect())))
        }
        other => Err(bad(format!("expected a PNG or EXR image, found {other:?}"))),
    }
}

/// Linear value to a 16-bit sRGB code: clamp to [0, 1], transfer curve, round.
#[inline]
pub fn encode_u16(linear: f64) -> u16 {
    let v = if linear.is_nan() { 0.0 } else { linear.clamp(0.0, 1.0) as f32 };
    (srgb_oetf(v) * 65535.0 + 0.5) as u16
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spectral_channel_names_follow_fichet_2021() {
        assert_eq!(spectral_channel_name(380.0), "S0.380,000000nm");
        assert_eq!(spectral_channel_name(435.8), "S0.435,799988nm");
        assert_eq!(spectral_channel_name(730.0), "S0.730,000000nm");
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
}
