//! Render settings: the one definition that the scene file's `render` block,
//! the command-line overrides and the checkpoint header all use.
//!
//! Every setting is listed once, in the `settings!` invocation below, with
//! its type, default and doc. From that list come:
//! - [`Settings`], the complete settings of a render (what a checkpoint
//!   stores, what the integrators read);
//! - [`SettingsPatch`], every field optional: the scene file's `render` block
//!   (serde, unknown fields refused) and the command line's overrides;
//! - [`Settings::apply`], [`Settings::patch`] and [`Settings::differences`].
//!
//! Precedence: defaults, then the file's block, then the command line
//! (`Settings::default().apply(&file).apply(&cli)`).
//!
//! ```ron
//! render: (width: 512, height: 512, spp: 256, seed: 0, max_bounces: 8,
//!          integrator: auto, wavelengths: hero, packet_size: 4, sampler: sobol),
//! ```
//!
//! In a checkpoint the settings are encoded field by field in this order
//! (bincode), with the enums as their lowercase names. Checkpoint formats 1
//! and 2 stored every field before `sampler`, which they predate
//! (`SettingsFormat1`: such renders drew independent numbers).

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// Declares a closed set of named choices: the RON identifiers and
/// command-line values are the lowercase names.
macro_rules! named_enum {
    ($(#[$meta:meta])* $name:ident { $($(#[$vmeta:meta])* $variant:ident = $text:literal,)+ }) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
        #[serde(rename_all = "lowercase")]
        pub enum $name {
            $($(#[$vmeta])* $variant,)+
        }

        impl $name {
            /// Every value, in declaration order.
            pub const ALL: &'static [$name] = &[$($name::$variant,)+];
            /// Every name, in declaration order.
            pub const NAMES: &'static [&'static str] = &[$($text,)+];

            /// The name in scene files, on the command line and in checkpoints.
            pub fn name(self) -> &'static str {
                match self {
                    $($name::$variant => $text,)+
                }
            }

            /// The value of a name, if it is one.
            pub fn from_name(s: &str) -> Option<Self> {
                match s {
                    $($text => Some($name::$variant),)+
                    _ => None,
                }
            }
        }

        impl Value for $name {
            const CHOICES: &'static [&'static str] = $name::NAMES;
            fn text(&self) -> String {
                self.name().into()
            }
            fn parse(s: &str) -> std::result::Result<Self, String> {
                Self::from_name(s).ok_or_else(|| format!("expected one of {}, found {s:?}", Self::NAMES.join(", ")))
            }
        }
    };
}

named_enum! {
    /// The light-transport methods ([`crate::integrator`]).
    IntegratorKind {
        /// The default: picks `caustics` when a point, spot or distant light or a sun (the sky's, or a map's: half its power within 1% of the sphere) meets a specular surface (caustics path tracing cannot find; `bdpt` where a beam does, or with a scattering medium), `bdpt` when a delta light meets a scattering medium (light subpaths start in its beam), else path tracing with the full spectrum until a path refracts at a dispersive surface, then single wavelengths drawn by importance.
        Auto = "auto",
        /// Full-spectrum path tracing with next-event estimation and MIS; no dispersion.
        Path = "path",
        /// Whitted-style recursive ray tracing: E S* (D|G) L.
        Whitted = "whitted",
        /// Spectral path tracing with wavelength packets that split at dispersive surfaces.
        Spectral = "spectral",
        /// Bidirectional path tracing: every connection of a camera and a light subpath, combined by MIS.
        Bdpt = "bdpt",
        /// Light tracing alone: light subpaths connected to the camera.
        LightTrace = "lighttrace",
        /// Path tracing, except for the caustics of the environment and distant, point and spot lights through specular surfaces, which light subpaths aimed at those surfaces carry to the camera.
        Caustics = "caustics",
    }
}

named_enum! {
    /// Wavelength sampling of the `spectral` integrator (`crate::spectral`).
    WavelengthsKind {
        /// One uniform hero bin, the others at equal rotation.
        Hero = "hero",
        /// Independent uniform bins.
        Random = "random",
        /// Three fixed wavelengths (435.8, 546.1, 700 nm) read out as RGB.
        Rgb = "rgb",
        /// Hero packets at continuous wavelengths uniform over 360-830 nm in every scene, every
        /// spectrum interpolated at each wavelength (as Mitsuba 3 and pbrt-v4 integrate colour).
        Continuous = "continuous",
    }
}

named_enum! {
    /// The per-sample number source (the crate-internal `sampler` module).
    SamplerKind {
        /// Independent uniform numbers (a PCG32 stream per sample), as before the choice existed.
        Independent = "independent",
        /// Owen-scrambled Sobol points, padded: one stratified 1D or 2D point set per draw of a fixed layout.
        Sobol = "sobol",
    }
}

/// Encodes a setting's value as its text (binary formats: the checkpoint
/// header stores the enums as their names).
mod by_name {
    use serde::{Deserialize, Deserializer, Serializer, de::Error as _};

    use super::Value;

    pub fn serialize<T: Value, S: Serializer>(v: &T, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&v.text())
    }

    pub fn deserialize<'de, T: Value, D: Deserializer<'de>>(d: D) -> Result<T, D::Error> {
        T::parse(&String::deserialize(d)?).map_err(D::Error::custom)
    }
}

/// Declares every setting once: name, type, default, doc, the constraint
/// its value must meet, and (optionally) how the checkpoint encodes it.
macro_rules! settings {
    ($($(#[doc = $doc:literal])+ $field:ident: $ty:ty = $default:expr, check($check:path) $(, serde($($serde:tt)*))?;)+) => {
        /// The complete settings of a render (defaults, the scene file's
        /// `render` block and the command line, combined).
        #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
        pub struct Settings {
            $($(#[doc = $doc])+ $(#[serde($($serde)*)])? pub $field: $ty,)+
        }

        /// Settings where each field may be absent: the scene file's `render`
        /// block and the command line's overrides.
        #[derive(Clone, Debug, Default, PartialEq, Deserialize)]
        #[serde(deny_unknown_fields)]
        pub struct SettingsPatch {
            $($(#[doc = $doc])+ pub $field: Option<$ty>,)+
        }

        /// Every setting's name, doc and choices, in declaration order (the
        /// command line builds its flags from it).
        pub const FIELDS: &[Field] = &[$(Field {
            name: stringify!($field),
            doc: concat!($($doc),+),
            choices: <$ty as Value>::CHOICES,
        },)+];

        impl Default for Settings {
            fn default() -> Self {
                Settings { $($field: $default,)+ }
            }
        }

        impl Settings {
            /// These settings with every field that `patch` gives replaced.
            pub fn apply(mut self, patch: &SettingsPatch) -> Settings {
                $(if let Some(v) = patch.$field.clone() {
                    self.$field = v;
                })+
                self
            }

            /// Every field as a patch (to load a scene exactly as it was rendered).
            pub fn patch(&self) -> SettingsPatch {
                SettingsPatch { $($field: Some(self.$field.clone()),)+ }
            }

            /// `(field, value)` for every field, values as in a scene file.
            pub fn fields(&self) -> Vec<(&'static str, String)> {
                vec![$((stringify!($field), self.$field.text()),)+]
            }

            /// The first setting out of range ([`Error::Setting`]).
            pub fn check(&self) -> Result<()> {
                $($check(&self.$field).map_err(|message| Error::Setting { name: stringify!($field), message })?;)+
                Ok(())
            }
        }

        impl SettingsPatch {
            /// Sets field `name` from its text (as in a scene file or on the
            /// command line), checking the value's constraint ([`Error::Setting`]).
            pub fn set(&mut self, name: &str, text: &str) -> Result<()> {
                match name {
                    $(stringify!($field) => {
                        let name = stringify!($field);
                        let v = <$ty as Value>::parse(text).map_err(|message| Error::Setting { name, message })?;
                        $check(&v).map_err(|message| Error::Setting { name, message })?;
                        self.$field = Some(v);
                        Ok(())
                    })+
                    _ => Err(Error::Settings(format!("unknown setting {name:?}"))),
                }
            }
        }
    };
}

/// The largest image side, in pixels.
pub const MAX_SIDE: u32 = 1 << 15;

/// The packet sizes the integrators are compiled for.
pub const PACKET_SIZES: [u32; 4] = [1, 2, 4, 8];

settings! {
    /// Image width in pixels (default 512).
    width: u32 = 512, check(side);
    /// Image height in pixels (default 512).
    height: u32 = 512, check(side);
    /// Samples per pixel; one pass adds one sample to every pixel (default 64).
    spp: u32 = 64, check(positive);
    /// Seed of the deterministic sampler (default 0).
    seed: u64 = 0, check(any);
    /// Maximum scattering events per path, as pbrt's maxdepth; Mitsuba's max_depth is one more (default 8).
    max_bounces: u32 = 8, check(any);
    /// Light transport method (default auto).
    integrator: IntegratorKind = IntegratorKind::Auto, check(any), serde(with = "by_name");
    /// Wavelength sampling of the spectral integrator (default hero).
    wavelengths: WavelengthsKind = WavelengthsKind::Hero, check(any), serde(with = "by_name");
    /// Wavelengths per packet of the spectral integrator, and the wavelengths auto draws where a path refracts into dispersive glass: 1, 2, 4 or 8 (default 4).
    packet_size: u32 = 4, check(packet_size);
    /// Per-sample numbers: sobol (stratified, Owen-scrambled Sobol) or independent (default sobol: faster to an equal error in the sampler study).
    sampler: SamplerKind = SamplerKind::Sobol, check(any), serde(with = "by_name");
}

/// The settings as checkpoint formats 1 and 2 stored them: every field before
/// `sampler`, which they predate. Their renders drew independent numbers (the
/// only sampler then), so they read as `sampler: independent`.
#[derive(Debug, Deserialize)]
pub(crate) struct SettingsFormat1 {
    width: u32,
    height: u32,
    spp: u32,
    seed: u64,
    max_bounces: u32,
    #[serde(with = "by_name")]
    integrator: IntegratorKind,
    #[serde(with = "by_name")]
    wavelengths: WavelengthsKind,
    packet_size: u32,
}

impl From<SettingsFormat1> for Settings {
    fn from(s: SettingsFormat1) -> Settings {
        let SettingsFormat1 { width, height, spp, seed, max_bounces, integrator, wavelengths, packet_size } = s;
        Settings {
            width,
            height,
            spp,
            seed,
            max_bounces,
            integrator,
            wavelengths,
            packet_size,
            sampler: SamplerKind::Independent,
        }
    }
}

/// What the command line needs to know of one setting.
#[derive(Clone, Copy, Debug)]
pub struct Field {
    /// The name in the scene file (`max_bounces`); the flag is `--max-bounces`.
    pub name: &'static str,
    /// What it means, with its default.
    pub doc: &'static str,
    /// The values it takes, when they are a closed set of names.
    pub choices: &'static [&'static str],
}

/// A setting's constraint: `Err` holds what was expected (the caller adds
/// the setting's name, making an [`Error::Setting`]).
type Check = std::result::Result<(), String>;

fn any<T>(_: &T) -> Check {
    Ok(())
}

fn positive(v: &u32) -> Check {
    if *v == 0 { Err("expected a positive number, found 0".into()) } else { Ok(()) }
}

fn side(v: &u32) -> Check {
    positive(v)?;
    if *v > MAX_SIDE { Err(format!("expected at most {MAX_SIDE} pixels per side, found {v}")) } else { Ok(()) }
}

fn packet_size(v: &u32) -> Check {
    if PACKET_SIZES.contains(v) { Ok(()) } else { Err(format!("expected 1, 2, 4 or 8, found {v}")) }
}

/// A setting's value as text, both ways.
trait Value: Sized {
    /// The closed set of names it takes (empty for numbers).
    const CHOICES: &'static [&'static str];
    fn text(&self) -> String;
    fn parse(s: &str) -> std::result::Result<Self, String>;
}

/// Whole numbers as settings.
macro_rules! number_value {
    ($($ty:ty),+) => {$(
        impl Value for $ty {
            const CHOICES: &'static [&'static str] = &[];
            fn text(&self) -> String {
                self.to_string()
            }
            fn parse(s: &str) -> std::result::Result<Self, String> {
                s.trim().parse().map_err(|_| format!("expected a whole number from 0 to {}, found {s:?}", <$ty>::MAX))
            }
        }
    )+};
}

number_value!(u32, u64);

impl Settings {
    /// Defaults, then `file` (the scene's `render` block), then `cli`.
    pub fn combine(file: &SettingsPatch, cli: &SettingsPatch) -> Settings {
        Settings::default().apply(file).apply(cli)
    }

    /// The settings that differ from `other`'s, as `name other vs self`,
    /// ignoring `spp` (a target, which changes no sample).
    pub fn differences(&self, other: &Settings) -> Vec<String> {
        self.fields()
            .into_iter()
            .zip(other.fields())
            .filter(|((name, a), (_, b))| *name != "spp" && a != b)
            .map(|((name, a), (_, b))| format!("{name} {b} vs {a}"))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patches_apply_in_order_and_round_trip() {
        let file = SettingsPatch { width: Some(64), integrator: Some(IntegratorKind::Path), ..Default::default() };
        let cli = SettingsPatch { width: Some(32), seed: Some(9), ..Default::default() };
        let s = Settings::combine(&file, &cli);
        assert_eq!((s.width, s.height, s.seed, s.integrator), (32, 512, 9, IntegratorKind::Path));
        assert_eq!(Settings::default().apply(&s.patch()), s);
    }

    #[test]
    fn names_round_trip() {
        for k in IntegratorKind::ALL {
            assert_eq!(IntegratorKind::from_name(k.name()), Some(*k));
        }
        for k in WavelengthsKind::ALL {
            assert_eq!(WavelengthsKind::from_name(k.name()), Some(*k));
        }
        for k in SamplerKind::ALL {
            assert_eq!(SamplerKind::from_name(k.name()), Some(*k));
        }
        assert_eq!(IntegratorKind::from_name("bdpt"), Some(IntegratorKind::Bdpt));
        assert_eq!(IntegratorKind::from_name("BDPT"), None);
    }

    #[test]
    fn set_parses_and_checks_each_field() {
        let mut p = SettingsPatch::default();
        p.set("max_bounces", "12").unwrap();
        p.set("integrator", "spectral").unwrap();
        assert_eq!((p.max_bounces, p.integrator), (Some(12), Some(IntegratorKind::Spectral)));
        assert!(p.set("width", "0").unwrap_err().to_string().contains("width: expected a positive"));
        assert!(p.set("width", "40000").unwrap_err().to_string().contains("at most 32768"));
        assert!(p.set("packet_size", "3").unwrap_err().to_string().contains("1, 2, 4 or 8"));
        assert!(p.set("seed", "-1").unwrap_err().to_string().contains("whole number"));
        assert!(p.set("integrator", "bdpt").is_ok());
        let err = p.set("integrator", "photon").unwrap_err().to_string();
        assert!(err.contains("auto, path, whitted, spectral, bdpt, lighttrace"), "{err}");
        assert!(p.set("focus", "1").is_err());
        assert_eq!(
            FIELDS.iter().map(|f| f.name).collect::<Vec<_>>(),
            Settings::default().fields().iter().map(|f| f.0).collect::<Vec<_>>()
        );
        assert_eq!(FIELDS[5].choices, IntegratorKind::NAMES);
    }

    #[test]
    fn checks_and_differences() {
        let s = Settings::default();
        assert!(s.check().is_ok());
        let name = |s: Settings| match s.check() {
            Err(Error::Setting { name, .. }) => name,
            other => panic!("{other:?}"),
        };
        assert_eq!(name(Settings { width: 0, ..s.clone() }), "width");
        assert_eq!(name(Settings { height: MAX_SIDE + 1, ..s.clone() }), "height");
        assert_eq!(name(Settings { packet_size: 3, ..s.clone() }), "packet_size");
        let t = Settings { spp: 5, seed: 2, wavelengths: WavelengthsKind::Rgb, ..s.clone() };
        assert_eq!(s.differences(&t), vec!["seed 2 vs 0".to_string(), "wavelengths rgb vs hero".to_string()]);
    }

    /// The header layout of checkpoint format 3: the fields in order, the enums
    /// as strings (bincode's standard configuration); format 1 is the same
    /// without the sampler, and decodes as `independent`.
    #[test]
    fn binary_encoding_is_format_3_and_format_1_reads() {
        let s = Settings { integrator: IntegratorKind::Spectral, sampler: SamplerKind::Sobol, ..Settings::default() };
        let config = bincode::config::standard();
        let bytes = bincode::serde::encode_to_vec(&s, config).unwrap();
        let old = (512u32, 512u32, 64u32, 0u64, 8u32, "spectral", "hero", 4u32);
        let new = (512u32, 512u32, 64u32, 0u64, 8u32, "spectral", "hero", 4u32, "sobol");
        assert_eq!(bytes, bincode::serde::encode_to_vec(new, config).unwrap());
        let (back, _): (Settings, usize) = bincode::serde::decode_from_slice(&bytes, config).unwrap();
        assert_eq!(back, s);
        let old = bincode::serde::encode_to_vec(old, config).unwrap();
        let (v1, used): (SettingsFormat1, usize) = bincode::serde::decode_from_slice(&old, config).unwrap();
        assert_eq!(used, old.len());
        assert_eq!(Settings::from(v1), Settings { sampler: SamplerKind::Independent, ..s });
    }
}
