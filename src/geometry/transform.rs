//! A placement in the scene: scale, then rotations about x, y and z, then a
//! translation, as the scene format's `transform:` and a mesh's own
//! `scale`/`rotate_deg`/`translate` write it. Here, below both the shapes
//! that apply it and the checks that build it from a description.

use glam::{Mat3, Vec3};

/// Placement of a shape: scale, then rotate about X, then Y, then Z (degrees), then
/// translate. The default is the identity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// Per-axis scale (applied first).
    pub scale: Vec3,
    /// Rotation angles in degrees about X, Y and Z, applied in that order.
    pub rotate_deg: Vec3,
    /// Translation (applied last).
    pub translate: Vec3,
}

impl Default for Transform {
    fn default() -> Self {
        Transform { scale: Vec3::ONE, rotate_deg: Vec3::ZERO, translate: Vec3::ZERO }
    }
}

impl Transform {
    /// The linear part: `Rz * Ry * Rx * S`.
    pub fn linear(&self) -> Mat3 {
        let r = self.rotate_deg * (std::f32::consts::PI / 180.0);
        Mat3::from_rotation_z(r.z)
            * Mat3::from_rotation_y(r.y)
            * Mat3::from_rotation_x(r.x)
            * Mat3::from_diagonal(self.scale)
    }

    /// Transforms a point.
    pub fn point(&self, p: Vec3) -> Vec3 {
        self.linear() * p + self.translate
    }
}
