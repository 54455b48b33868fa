//! A density on a voxel grid (`Grid(path: "smoke.vol", ...)`): Mitsuba's
//! `.vol` format, the one its `gridvolume` reads and public smoke and cloud
//! data is shared in (chosen for that: a 48-byte header and raw floats, no
//! library needed). Layout, little-endian: `VOL`, the version byte 3, an
//! `i32` encoding (1: `f32`; the only one read here), `i32` sizes x, y, z, an
//! `i32` channel count (1 here), six `f32` of bounds (ignored: the grid fills
//! its object's bounding box), then `x·y·z` floats, x fastest, then y, then z.
//!
//! Values are samples at the voxel centres, blended trilinearly (clamped at
//! the faces); outside the box the density is 0.
//!
//! # Majorants
//! Tracking draws tentative collisions against a majorant, a bound on the
//! density; the tighter it is, the fewer collisions are null. The grid keeps a
//! coarse majorant grid (pbrt-v4's idea, written here): at most
//! [`MAJORANT_CELLS`] cells per axis, each holding the largest voxel value
//! that the trilinear blend can reach inside it (the voxels whose centres lie
//! within the cell, one more on each side for the blend, and one more for
//! rounding). [`DensityGrid::segments`] walks a ray through the cells
//! (Amanatides and Woo's 3D DDA) and gives each piece of the ray with its
//! cell's bound; a piece with bound 0 costs no collision at all. Where the
//! density is mostly thin (smoke, clouds) most of the ray crosses such cells.

use glam::Vec3;

/// The most voxels a grid may have (a 512³ grid, 512 MiB of floats).
pub const MAX_VOXELS: usize = 1 << 27;

/// The most majorant cells per axis.
pub const MAJORANT_CELLS: usize = 16;

/// A scalar density on a voxel grid over the unit cube.
#[derive(Clone, Debug, PartialEq)]
pub struct DensityGrid {
    n: [usize; 3],
    data: Vec<f32>,
    max: f32,
    /// Majorant cells per axis.
    cells: [usize; 3],
    /// The bound of each majorant cell, x fastest.
    cell_max: Vec<f32>,
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
        let cells = n.map(|v| v.min(MAJORANT_CELLS));
        let mut grid = DensityGrid { n, data, max, cells, cell_max: Vec::new() };
        grid.cell_max = grid.majorants();
        Ok(grid)
    }

    /// The bound of every majorant cell: the largest voxel among those whose
    /// trilinear support reaches into the cell, plus one voxel of margin.
    fn majorants(&self) -> Vec<f32> {
        // The voxel range a cell's blend can read along an axis: cell c spans
        // [c/m, (c+1)/m], voxel coordinates x = v·n − ½ there, and the blend
        // reads ⌊x⌋ and ⌊x⌋ + 1; one voxel more each side for rounding.
        let range = |axis: usize, c: usize| {
            let (n, m) = (self.n[axis] as f64, self.cells[axis] as f64);
            let lo = (c as f64 * n / m - 0.5).floor() as i64 - 1;
            let hi = ((c + 1) as f64 * n / m - 0.5).floor() as i64 + 2;
            (lo.max(0) as usize, (hi.max(0) as usize).min(self.n[axis] - 1))
        };
        let [cx, cy, cz] = self.cells;
        let mut out = Vec::with_capacity(cx * cy * cz);
        for z in 0..cz {
            let (z0, z1) = range(2, z);
            for y in 0..cy {
                let (y0, y1) = range(1, y);
                for x in 0..cx {
                    let (x0, x1) = range(0, x);
                    let mut m = 0.0f32;
                    for vz in z0..=z1 {
                        for vy in y0..=y1 {
                            let row = (vz * self.n[1] + vy) * self.n[0];
                            m = self.data[row + x0..=row + x1].iter().copied().fold(m, f32::max);
                        }
                    }
                    out.push(m);
                }
            }
        }
        out
    }

    /// The pieces of the ray `o + d t` (unit-cube coordinates), `0 <= t <
    /// t_max`, inside the grid's box, in order, each with the bound of the
    /// majorant cell it crosses.
    pub fn segments(&self, o: Vec3, d: Vec3, t_max: f32) -> Segments<'_> {
        let mut seg = Segments {
            grid: self,
            cell: [0; 3],
            step: [0; 3],
            next: [f32::INFINITY; 3],
            delta: [0.0; 3],
            t: 0.0,
            end: -1.0,
        };
        // Clip to the unit box (slabs; a zero direction component keeps the
        // ray inside or outside that slab for good).
        let (mut t0, mut t1) = (0.0f32, t_max);
        for a in 0..3 {
            if d[a] == 0.0 {
                if !(0.0..=1.0).contains(&o[a]) {
                    return seg;
                }
                continue;
            }
            let (ta, tb) = ((0.0 - o[a]) / d[a], (1.0 - o[a]) / d[a]);
            t0 = t0.max(ta.min(tb));
            t1 = t1.min(ta.max(tb));
        }
        if !(t0 < t1) {
            return seg;
        }
        let p = o + d * t0;
        for a in 0..3 {
            let m = self.cells[a];
            let c = ((p[a] * m as f32) as isize).clamp(0, m as isize - 1) as usize;
            seg.cell[a] = c;
            if d[a] > 0.0 {
                seg.step[a] = 1;
                seg.next[a] = t0 + ((c + 1) as f32 / m as f32 - p[a]) / d[a];
                seg.delta[a] = 1.0 / (m as f32 * d[a]);
            } else if d[a] < 0.0 {
                seg.step[a] = -1;
                seg.next[a] = t0 + (c as f32 / m as f32 - p[a]) / d[a];
                seg.delta[a] = -1.0 / (m as f32 * d[a]);
            }
        }
        seg.t = t0;
        seg.end = t1;
        seg
    }

    /// The bound of majorant cell `c`.
    #[inline]
    fn cell_max(&self, c: [usize; 3]) -> f32 {
        self.cell_max[(c[2] * self.cells[1] + c[1]) * self.cells[0] + c[0]]
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

/// A ray's walk through the majorant cells ([`DensityGrid::segments`]): each
/// item is `(t_enter, t_exit, bound)`, contiguous, in order.
pub struct Segments<'a> {
    grid: &'a DensityGrid,
    cell: [usize; 3],
    step: [i8; 3],
    /// The ray parameter of the next cell boundary along each axis.
    next: [f32; 3],
    /// The ray parameter between boundaries along each axis.
    delta: [f32; 3],
    t: f32,
    end: f32,
}

impl Iterator for Segments<'_> {
    type Item = (f32, f32, f32);

    #[inline]
    fn next(&mut self) -> Option<(f32, f32, f32)> {
        if !(self.t < self.end) {
            return None;
        }
        let a = if self.next[0] <= self.next[1] && self.next[0] <= self.next[2] {
            0
        } else if self.next[1] <= self.next[2] {
            1
        } else {
            2
        };
        let exit = self.next[a].min(self.end).max(self.t);
        let item = (self.t, exit, self.grid.cell_max(self.cell));
        self.t = exit;
        let c = self.cell[a] as isize + self.step[a] as isize;
        if exit >= self.end || c < 0 || c >= self.grid.cells[a] as isize {
            self.end = -1.0;
        } else {
            self.cell[a] = c as usize;
            self.next[a] += self.delta[a];
        }
        Some(item)
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

    /// The majorant walk: on random rays through a random sparse grid (a
    /// coarser 16-cell majorant over 37x5x23 voxels), the pieces are
    /// contiguous, cover exactly the parameters whose points lie in the unit
    /// box (checked at 400 points per ray, away from the faces by 1e-4), and
    /// the density at every checked point is at most its piece's bound.
    #[test]
    fn majorant_cells_bound_the_density_along_every_ray() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_pcg::Pcg32::seed_from_u64(7);
        let n = [37usize, 5, 23];
        let data: Vec<f32> = (0..n[0] * n[1] * n[2])
            .map(|_| if rng.random::<f32>() < 0.1 { rng.random::<f32>() * 5.0 } else { 0.0 })
            .collect();
        let g = DensityGrid::new(n, data).unwrap();
        for _ in 0..300 {
            let o = Vec3::new(rng.random(), rng.random(), rng.random()) * 3.0 - Vec3::splat(1.0);
            let d = (Vec3::new(rng.random(), rng.random(), rng.random()) * 2.0 - Vec3::ONE).normalize();
            let t_max = rng.random::<f32>() * 4.0;
            let pieces: Vec<(f32, f32, f32)> = g.segments(o, d, t_max).collect();
            for w in pieces.windows(2) {
                assert_eq!(w[0].1, w[1].0, "contiguous");
            }
            for k in 0..400 {
                let t = t_max * (k as f32 + 0.5) / 400.0;
                let p = o + d * t;
                let inside = p.cmpge(Vec3::splat(1e-4)).all() && p.cmple(Vec3::splat(1.0 - 1e-4)).all();
                let piece = pieces.iter().find(|s| s.0 <= t && t < s.1);
                match piece {
                    Some(&(_, _, bound)) => assert!(g.density(p) <= bound, "density {} above {bound}", g.density(p)),
                    None => assert!(!inside, "{p} in the box but in no piece"),
                }
                if !(p.cmpge(Vec3::splat(-1e-4)).all() && p.cmple(Vec3::splat(1.0 + 1e-4)).all()) {
                    assert!(piece.is_none(), "{p} outside the box in a piece");
                }
            }
        }
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
