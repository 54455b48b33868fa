//! Pictures from radiance: exposure and tone mapping for 8/16-bit output.
//!
//! The film holds linear radiance; an EXR keeps it (scaled by the exposure
//! only). A PNG must fit [0, 1] per channel in sRGB, and the renderer's
//! spectra are often brighter than 1 and outside sRGB's gamut (a dispersed
//! rainbow is almost monochromatic). Two operators:
//!
//! - [`Tonemap::Clip`] (the default, the renderer's behaviour before the
//!   operator existed, so old PNGs stay bit-identical): each channel clipped
//!   to [0, 1]. A bright, saturated band turns into flat runs of the same
//!   pixel (the prism's rainbow became six blocks of colour).
//! - [`Tonemap::Filmic`]: the luminance Y of linear sRGB goes through
//!   Narkowicz's fit of the ACES filmic curve (K. Narkowicz, "ACES Filmic
//!   Tone Mapping Curve", 2016: `x (2.51 x + 0.03) / (x (2.43 x + 0.59) +
//!   0.14)`, clamped to 1; monotone, reaching 1 at Y ≈ 7.24), the colour is
//!   scaled by `Y' / Y` (same chromaticity), and a colour still outside [0, 1]
//!   moves toward the grey of the same luminance, `(Y', Y', Y')`, just as far
//!   as needed (constant luminance, shrinking chroma in linear sRGB), instead
//!   of clipping each channel. Highlights compress smoothly and a spectral
//!   ramp keeps its hue order with no flat runs.
//!
//! Exposure (`--exposure EV`) multiplies linear values by `2^EV` before
//! either, exactly (a power of two).

/// How linear sRGB becomes a displayable [0, 1] colour (see the module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Tonemap {
    /// Each channel clipped to [0, 1].
    #[default]
    Clip,
    /// Filmic luminance curve, then a constant-luminance gamut map.
    Filmic,
}

/// Luminance of linear sRGB (Rec. 709 / sRGB primaries, D65).
const LUMA: [f64; 3] = [0.2126, 0.7152, 0.0722];

impl Tonemap {
    /// The names the command line takes.
    pub const NAMES: [&'static str; 2] = ["clip", "filmic"];

    /// The operator of name `name` (see [`Tonemap::NAMES`]).
    pub fn from_name(name: &str) -> Option<Tonemap> {
        match name {
            "clip" => Some(Tonemap::Clip),
            "filmic" => Some(Tonemap::Filmic),
            _ => None,
        }
    }

    /// The operator's name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Tonemap::Clip => "clip",
            Tonemap::Filmic => "filmic",
        }
    }

    /// Linear sRGB (any values) to linear sRGB in [0, 1]³. NaN becomes 0.
    pub fn apply(self, rgb: [f64; 3]) -> [f64; 3] {
        let rgb = rgb.map(|v| if v.is_nan() { 0.0 } else { v });
        match self {
            Tonemap::Clip => rgb.map(|v| v.clamp(0.0, 1.0)),
            Tonemap::Filmic => filmic(rgb),
        }
    }
}

/// Narkowicz's ACES fit, clamped to [0, 1].
fn curve(x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x.is_infinite() {
        return 1.0;
    }
    (x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14)).min(1.0)
}

fn filmic(rgb: [f64; 3]) -> [f64; 3] {
    let y = LUMA[0] * rgb[0] + LUMA[1] * rgb[1] + LUMA[2] * rgb[2];
    if y.is_nan() || y <= 0.0 || !y.is_finite() {
        // No light (or only negative lobes): black; infinite: white.
        return if y.is_infinite() && y > 0.0 { [1.0; 3] } else { [0.0; 3] };
    }
    let y2 = curve(y);
    let c = rgb.map(|v| v * (y2 / y));
    // Toward the grey of the same luminance, as far as the gamut needs.
    let mut t = 1.0f64;
    for v in c {
        let d = v - y2;
        if d > 0.0 {
            t = t.min((1.0 - y2) / d);
        } else if d < 0.0 {
            t = t.min(y2 / -d);
        }
    }
    let t = t.clamp(0.0, 1.0);
    c.map(|v| (y2 + t * (v - y2)).clamp(0.0, 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::color::cmf_at;
    use crate::color::xyz_to_linear_srgb_f64;
    use crate::io::image::encode_u16;

    fn encode(rgb: [f64; 3]) -> [u16; 3] {
        rgb.map(encode_u16)
    }

    /// HSV hue in degrees of an encoded colour.
    fn hue(c: [u16; 3]) -> f64 {
        let [r, g, b] = c.map(|v| v as f64);
        let (max, min) = (r.max(g).max(b), r.min(g).min(b));
        if max == min {
            return f64::NAN;
        }
        let h = if max == r {
            60.0 * ((g - b) / (max - min))
        } else if max == g {
            60.0 * (2.0 + (b - r) / (max - min))
        } else {
            60.0 * (4.0 + (r - g) / (max - min))
        };
        h.rem_euclid(360.0)
    }

    #[test]
    fn filmic_is_monotone_in_luminance_and_keeps_grey_grey() {
        let mut last = [0u16; 3];
        let mut distinct = 0;
        for k in 0..=2000 {
            let v = k as f64 * 0.005; // 0 to 10
            let c = encode(Tonemap::Filmic.apply([v; 3]));
            assert!(c[0] == c[1] && c[1] == c[2], "grey stays grey: {v} -> {c:?}");
            assert!(c[0] >= last[0], "not monotone at {v}: {c:?} after {last:?}");
            distinct += usize::from(c[0] != last[0]);
            last = c;
        }
        // Strictly increasing below the curve's white point (Y ≈ 7.24): ~1400 steps.
        assert!(distinct > 1300, "{distinct}");
        assert_eq!(encode(Tonemap::Filmic.apply([1e9; 3])), [65535; 3]);
        assert_eq!(encode(Tonemap::Filmic.apply([0.0; 3])), [0; 3]);
        assert_eq!(Tonemap::Filmic.apply([f64::NAN, f64::INFINITY, -1.0]), [1.0; 3]);
    }

    /// An equal-energy spectrum spread out as a prism spreads it: each
    /// wavelength from 420 to 680 nm (1 nm steps) alone, at a radiance that
    /// makes 555 nm's luminance 2 (brighter than white; the colours are
    /// outside sRGB's gamut almost everywhere). With `filmic` the hue falls
    /// monotonically from blue to red (within 1.5° of rounding) and no two
    /// neighbouring wavelengths give the same pixel; with `clip` runs of
    /// identical pixels appear (the flat blocks of the old rainbow), which
    /// shows the test can fail.
    #[test]
    fn a_spectral_ramp_keeps_its_hue_order_without_flat_runs() {
        let ramp = |op: Tonemap| -> Vec<[u16; 3]> {
            (420..=680)
                .map(|nm| {
                    let k = 2.0 / cmf_at(555.0)[1] as f64;
                    let rgb = xyz_to_linear_srgb_f64(cmf_at(nm as f32).map(|v| v as f64 * k));
                    encode(op.apply(rgb))
                })
                .collect()
        };
        let filmic = ramp(Tonemap::Filmic);
        for (k, w) in filmic.windows(2).enumerate() {
            assert_ne!(w[0], w[1], "a flat run in the filmic ramp at {} nm", 420 + k);
        }
        let hues: Vec<f64> = filmic.iter().map(|&c| hue(c)).map(|h| if h > 300.0 { h - 360.0 } else { h }).collect();
        for (k, w) in hues.windows(2).enumerate() {
            assert!(w[1] <= w[0] + 1.5, "hue rises at {} nm: {} -> {}", 420 + k, w[0], w[1]);
        }
        assert!(hues[0] > 200.0 && hues[hues.len() - 1] < 20.0, "blue to red: {} .. {}", hues[0], hues[hues.len() - 1]);
        let clip = ramp(Tonemap::Clip);
        assert!(clip.windows(2).filter(|w| w[0] == w[1]).count() > 10, "clip has flat runs");
    }

    #[test]
    fn names_round_trip() {
        for n in Tonemap::NAMES {
            assert_eq!(Tonemap::from_name(n).map(Tonemap::name), Some(n));
        }
        assert_eq!(Tonemap::from_name("aces"), None);
    }
}
