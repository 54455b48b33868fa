//! The `camera:` block of the scene file (part of [`super`], the scene format).

use serde::{Deserialize, Serialize};

use super::{V3, is_zero_f32};

/// A pinhole camera, a thin lens with depth of field, or a lens system.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct CameraDesc {
    /// Position of the eye.
    pub eye: V3,
    /// The point looked at.
    pub look_at: V3,
    /// The up direction (default `(0, 1, 0)`).
    #[serde(default = "default_up")]
    pub up: V3,
    /// Vertical field of view in degrees (required, except with a `lens`,
    /// whose focal length and film set it).
    #[serde(default)]
    pub fov_deg: Option<f32>,
    /// The thin lens's radius in scene units (default 0: a pinhole, no depth of field).
    #[serde(default, skip_serializing_if = "is_zero_f32")]
    pub aperture_radius: f32,
    /// The distance of the plane in focus along the view direction (default:
    /// from `eye` to `look_at`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub focus_distance: Option<f32>,
    /// A lens system in front of a film, instead of the pinhole or thin lens.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lens: Option<LensDesc>,
    /// The name of a medium in `media` that the camera sits in: it fills the
    /// space around the scene, out to a sphere enclosing every bounded object
    /// and the eye (vacuum beyond, so the environment and distant lights are
    /// seen through the haze's thickness): `medium: "haze"`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub medium: Option<String>,
}

/// A lens system camera: a lens file (pbrt's format, with an optional glass
/// column) and its settings.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LensDesc {
    /// The lens file, relative to the scene file.
    pub file: String,
    /// The aperture stop's opening, a diameter in mm (at most the stop's own).
    pub aperture_diameter_mm: f32,
    /// The distance from the film to the plane in focus, in scene units (metres).
    pub focus_distance: f32,
    /// The film's diagonal in mm (default 35).
    #[serde(default = "default_film_diagonal")]
    pub film_diagonal_mm: f32,
}

fn default_film_diagonal() -> f32 {
    35.0
}

fn default_up() -> V3 {
    [0.0, 1.0, 0.0]
}
