//! What surrounds and fills the scene in the file: the `environment:` and the
//! participating `media:` (part of [`super`], the scene format).

use serde::{Deserialize, Serialize};

use super::{SpectrumDesc, V3, one};

/// The scene's `environment:`.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub enum EnvironmentDesc {
    /// The same radiance from every direction: `Uniform(Constant(1))`.
    Uniform(SpectrumDesc),
    /// An environment map (PNG, sRGB-decoded, or EXR, linear), +y up:
    /// `Image(path: "sky.exr", scale: 1, rotate_deg: (0, 90, 0))`, equirectangular
    /// unless `mapping: EqualArea` (pbrt-v4's square maps).
    Image {
        /// The image file, relative to the scene file.
        path: String,
        /// A factor on every texel (default 1).
        #[serde(default = "one")]
        scale: f32,
        /// Turns the map about X, then Y, then Z, in degrees (default none).
        #[serde(default)]
        rotate_deg: V3,
        /// How the image covers the sphere (default `Equirectangular`).
        #[serde(default, skip_serializing_if = "EnvMapping::is_equirectangular")]
        mapping: EnvMapping,
    },
    /// The spectral Hosek-Wilkie sky with its sun, in absolute units
    /// (W m⁻² sr⁻¹ nm⁻¹): `Sky(sun_elevation_deg: 20, sun_azimuth_deg: 30, turbidity: 3, ground_albedo: 0.3)`.
    Sky {
        /// The sun's height above the horizon, degrees in [0, 90].
        sun_elevation_deg: f32,
        /// The sun's direction about +y, degrees: 0 towards −z, 90 towards +x (default 0).
        #[serde(default)]
        sun_azimuth_deg: f32,
        /// Atmospheric turbidity in [1, 10] (default 3: a clear day).
        #[serde(default = "default_turbidity")]
        turbidity: f32,
        /// The ground's reflectance in [0, 1] (default 0.3).
        #[serde(default = "default_ground_albedo")]
        ground_albedo: f32,
        /// A factor on the sky, sun and ground (default 1).
        #[serde(default = "one")]
        scale: f32,
    },
}

/// How an environment `Image` covers the sphere of directions
/// (`crate::light::EnvironmentLight`'s module docs give the orientations).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
pub enum EnvMapping {
    /// Latitude-longitude: rows from +y down to −y, u around +y (the default).
    #[default]
    Equirectangular,
    /// The equal-area octahedral square (Clarberg 2008) of pbrt-v4's image
    /// infinite lights: a square image, every texel the same solid angle, its
    /// centre looking up (+y), its corners down.
    EqualArea,
}

impl EnvMapping {
    fn is_equirectangular(&self) -> bool {
        *self == EnvMapping::Equirectangular
    }
}

fn default_turbidity() -> f32 {
    3.0
}

fn default_ground_albedo() -> f32 {
    0.3
}

/// A participating medium (`crate::medium`): coefficients per scene unit.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub enum MediumDesc {
    /// The same everywhere:
    /// `Homogeneous(sigma_a: Constant(0.01), sigma_s: Rayleigh(0.5), phase: Isotropic)`.
    Homogeneous {
        /// Absorption coefficient per scene unit.
        sigma_a: SpectrumDesc,
        /// Scattering coefficient per scene unit.
        sigma_s: SpectrumDesc,
        /// The phase function (default `Isotropic`).
        #[serde(default)]
        phase: PhaseDesc,
    },
    /// A density on a voxel grid (Mitsuba's `.vol`, 32-bit floats, one channel)
    /// filling the object's bounding box, times the coefficients:
    /// `Grid(path: "smoke.vol", sigma_a: Constant(0.5), sigma_s: Constant(4), density_scale: 1, phase: Isotropic)`.
    Grid {
        /// The `.vol` file, relative to the scene file.
        path: String,
        /// Absorption coefficient per scene unit at density 1.
        sigma_a: SpectrumDesc,
        /// Scattering coefficient per scene unit at density 1.
        sigma_s: SpectrumDesc,
        /// A factor on the density (default 1).
        #[serde(default = "one")]
        density_scale: f32,
        /// The phase function (default `Isotropic`).
        #[serde(default)]
        phase: PhaseDesc,
    },
}

/// A medium's phase function.
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub enum PhaseDesc {
    /// The same in every direction (the default).
    #[default]
    Isotropic,
    /// Henyey-Greenstein of mean cosine `g` in [−0.999, 0.999] (> 0 forward):
    /// `HenyeyGreenstein(g: 0.7)`.
    HenyeyGreenstein {
        /// The mean cosine of the scattering angle.
        g: f32,
    },
}
