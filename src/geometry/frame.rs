//! An orthonormal frame around a normal, for moving directions between world
//! space and the local shading space of the BxDFs (where the normal is +z).

use glam::Vec3;

/// An orthonormal basis `(s, t, n)`; `n` is the local +z axis.
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    /// Local +x.
    pub s: Vec3,
    /// Local +y.
    pub t: Vec3,
    /// Local +z (the normal).
    pub n: Vec3,
}

impl Frame {
    /// A frame whose z axis is the unit vector `n` (Duff et al. 2017, "Building an
    /// orthonormal basis, revisited": branchless and continuous except at n.z = -1's sign flip).
    pub fn from_z(n: Vec3) -> Self {
        let sign = 1.0f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let s = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let t = Vec3::new(b, sign + n.y * n.y * a, -n.y);
        Frame { s, t, n }
    }

    /// World direction to local coordinates.
    #[inline]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }

    /// Local direction to world coordinates.
    #[inline]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.s * v.x + self.t * v.y + self.n * v.z
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_is_orthonormal_and_round_trips() {
        for n in
            [Vec3::Z, -Vec3::Z, Vec3::X, Vec3::new(0.3, -0.5, 0.81).normalize(), Vec3::new(1e-7, 0.0, -1.0).normalize()]
        {
            let f = Frame::from_z(n);
            assert!((f.s.length() - 1.0).abs() < 1e-5 && (f.t.length() - 1.0).abs() < 1e-5);
            assert!(f.s.dot(f.t).abs() < 1e-5 && f.s.dot(f.n).abs() < 1e-5 && f.t.dot(f.n).abs() < 1e-5);
            assert!((f.s.cross(f.t) - f.n).length() < 1e-5, "right-handed for {n:?}");
            let v = Vec3::new(0.2, 0.7, -0.4);
            assert!((f.to_world(f.to_local(v)) - v).length() < 1e-5);
        }
    }
}
