//! A density on a voxel grid (`Grid(path: "smoke.vol", ...)`): Mitsuba's
//! `.vol` format, the one its `gridvolume` reads and public smoke and cloud
//! data is shared in (chosen for that: a 48-byte header and raw floats, no
//! library needed). Layout, little-endian: `VOL`, the version byte 3, an
//! `i32` encoding (1: `f32`; the only one read here), `i32` sizes x, y, z, an
//! `i32` channel count (1 here), six `f32` of bounds (ignored: the grid fills
//! its object's bounding box), then `x·y·z` floats, x fastest, then y, then z.
//!
//! Values are samples at the voxel centres, blended trilinearly (clamped at
//! the faces); outside the box the density is 0. [`DensityGrid::max`] is the
//! majorant the tracking uses (one for the whole grid: a medium that is
//! mostly thin wastes tentative collisions; a coarse majorant grid would
//! spend fewer, see the module docs of `crate::medium`).

use glam::Vec3;

/// The most voxels a grid may have (a 512³ grid, 512 MiB of floats).
pub const MAX_VOXELS: usize = 1 << 27;

/// A scalar density on a voxel grid over the unit cube.
#[derive(Clone, Debug, PartialEq)]
pub struct DensityGrid {
    n: [usize; 3],
    data: Vec<f32>,
    max: f32,
}

impl DensityGrid {
    /// A grid of `n` voxels (x fastest) from `data`: non-negative and finite.
    pub fn new(n: [usize; 3], data: Vec<f32>) -> Result<DensityGrid, String> {
        let count = n[0].checked_mul(n[1]).and_then(|v| v.checked_mul(n[2])).unwrap_or(usize::MAX);
        if n.contains(&0) || count > MAX_VOXELS {
            return Err(format!("expected between 1 and {MAX_VOXELS} voxels, found {}x{}x{}", n[0], n[1], n[2]));
        }
        if data.len() != count {
            return Err(format!("expected {count} values for {}x{}x{} voxels, found {}", n[0], n[1], n[2], data.len()));
        }
        if let Some(k) = data.iter().position(|v| !(v.is_finite() && *v >= 0.0)) {
            return Err(format!(
                "voxel ({}, {}, {}) is {}: expected a finite, non-negative density",
                k % n[0],
                (k / n[0]) % n[1],
                k / (n[0] * n[1]),
                data[k]
            ));
        }
        let max = data.iter().copied().fold(0.0f32, f32::max);
        Ok(DensityGrid { n, data, max })
    }

    /// Parses a `.vol` file (see the module docs).
    pub fn parse_vol(bytes: &[u8]) -> Result<DensityGrid, String> {
        if bytes.len() < 48 {
            return Err(format!("a .vol file has a 48-byte header; this one has {} bytes", bytes.len()));
        }
        if &bytes[0..3] != b"VOL" {
            return Err("expected a Mitsuba .vol file (it starts with \"VOL\")".into());
        }
        if bytes[3] != 3 {
            return Err(format!("expected .vol version 3, found {}", bytes[3]));
        }
        let int = |at: usize| i32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes"));
        let encoding = int(4);
        if encoding != 1 {
            return Err(format!("expected encoding 1 (32-bit floats), found {encoding}"));
        }
        let (nx, ny, nz, channels) = (int(8), int(12), int(16), int(20));
        if channels != 1 {
            return Err(format!("expected 1 channel (a density), found {channels}"));
        }
        if nx <= 0 || ny <= 0 || nz <= 0 {
            return Err(format!("expected positive sizes, found {nx}x{ny}x{nz}"));
        }
        let n = [nx as usize, ny as usize, nz as usize];
        let count = n[0].checked_mul(n[1]).and_then(|v| v.checked_mul(n[2])).unwrap_or(usize::MAX);
        if count > MAX_VOXELS {
            return Err(format!("{nx}x{ny}x{nz} is more than the {MAX_VOXELS} voxels a grid may have"));
        }
        let body = &bytes[48..];
        if body.len() != count * 4 {
            return Err(format!(
                "{nx}x{ny}x{nz} voxels need {} bytes of data after the header, found {}",
                count * 4,
                body.len()
            ));
        }
        let data = body.chunks_exact(4).map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes"))).collect();
        DensityGrid::new(n, data)
    }

    /// The largest density.
    #[inline]
    pub fn max(&self) -> f32 {
        self.max
    }

    /// The trilinear density at `p` in the unit cube (0 outside it).
    #[inline]
    pub fn density(&self, p: Vec3) -> f32 {
        if !(p.cmpge(Vec3::ZERO).all() && p.cmple(Vec3::ONE).all()) {
            return 0.0;
        }
        let g = |axis: usize, v: f32| {
            let x = (v * self.n[axis] as f32 - 0.5).clamp(0.0, (self.n[axis] - 1) as f32);
            let i0 = (x as usize).min(self.n[axis] - 1);
            (i0, (i0 + 1).min(self.n[axis] - 1), x - i0 as f32)
        };
        let (x0, x1, fx) = g(0, p.x);
        let (y0, y1, fy) = g(1, p.y);
        let (z0, z1, fz) = g(2, p.z);
        let at = |x: usize, y: usize, z: usize| self.data[(z * self.n[1] + y) * self.n[0] + x];
        let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
        let c00 = lerp(at(x0, y0, z0), at(x1, y0, z0), fx);
        let c10 = lerp(at(x0, y1, z0), at(x1, y1, z0), fx);
        let c01 = lerp(at(x0, y0, z1), at(x1, y0, z1), fx);
        let c11 = lerp(at(x0, y1, z1), at(x1, y1, z1), fx);
        lerp(lerp(c00, c10, fy), lerp(c01, c11, fy), fz)
    }
}

/// The bytes of a `.vol` file holding `grid`'s values (for tests and scripts).
pub fn write_vol(n: [usize; 3], data: &[f32]) -> Vec<u8> {
    let mut out = b"VOL\x03".to_vec();
    for v in [1i32, n[0] as i32, n[1] as i32, n[2] as i32, 1] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    for v in [0.0f32, 0.0, 0.0, 1.0, 1.0, 1.0] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    for v in data {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Trilinear blending between voxel centres, clamped at the faces, and 0 outside.
    #[test]
    fn trilinear_density() {
        // 2x1x1: 1 at x = 0.25, 3 at x = 0.75.
        let g = DensityGrid::parse_vol(&write_vol([2, 1, 1], &[1.0, 3.0])).unwrap();
        assert_eq!(g.density(Vec3::new(0.25, 0.5, 0.5)), 1.0);
        assert_eq!(g.density(Vec3::new(0.75, 0.5, 0.5)), 3.0);
        assert!((g.density(Vec3::new(0.5, 0.5, 0.5)) - 2.0).abs() < 1e-6);
        assert_eq!(g.density(Vec3::new(0.0, 0.5, 0.5)), 1.0, "clamped at the face");
        assert_eq!(g.density(Vec3::new(1.1, 0.5, 0.5)), 0.0, "outside");
        assert_eq!(g.max(), 3.0);
    }

    /// Bad files are refused with a message.
    #[test]
    fn bad_vol_files_are_refused() {
        let good = write_vol([2, 2, 2], &[1.0; 8]);
        assert!(DensityGrid::parse_vol(&good).is_ok());
        assert!(DensityGrid::parse_vol(&good[..40]).unwrap_err().contains("48-byte"));
        assert!(DensityGrid::parse_vol(&good[..good.len() - 4]).unwrap_err().contains("bytes of data"));
        let mut long = good.clone();
        long.extend_from_slice(&[0; 4]);
        assert!(DensityGrid::parse_vol(&long).unwrap_err().contains("bytes of data"));
        let mut bad = good.clone();
        bad[0] = b'X';
        assert!(DensityGrid::parse_vol(&bad).unwrap_err().contains("VOL"));
        assert!(DensityGrid::parse_vol(&write_vol([2, 1, 1], &[1.0, f32::NAN])).unwrap_err().contains("(1, 0, 0)"));
        assert!(DensityGrid::parse_vol(&write_vol([2, 1, 1], &[-1.0, 1.0])).unwrap_err().contains("(0, 0, 0)"));
        let mut huge = good.clone();
        huge[8..12].copy_from_slice(&100_000i32.to_le_bytes());
        huge[12..16].copy_from_slice(&100_000i32.to_le_bytes());
        assert!(DensityGrid::parse_vol(&huge).unwrap_err().contains("voxels"));
    }
}
