//! Sampling a textured quad or cuboid by its texture's brightness.
//!
//! Each parallelogram face of the emitter is split into a grid of cells over
//! its (a, b) = (u, v) square: a checkerboard's squares (`⌈scale⌉` per axis),
//! or 64 x 64 cells for an image, at most 64 x 64 in any case. A cell weighs
//! its area times the mean brightness (the mean over wavelength bins of the
//! radiance, as the light's power for choosing among lights) of the texture
//! at 4 x 4 points spread over it, plus a floor of 1e-3 of the mean brightness
//! over the whole emitter: no cell where the texture is non-zero has weight 0,
//! so the estimate stays unbiased whatever the weights miss. A cell is chosen
//! by its weight, then a point uniformly in it, so the density per unit area
//! at a point of cell `c` is `w_c / (W · A_c)` (exactly: the width of the
//! cell's step of the f32 CDF over `A_c`, what the sampling does; every cell
//! weighs at least 2^-20 of the total, so that no step rounds to zero width
//! and every point where the texture emits has a positive density), and [`TextureGrid::density`]
//! gives it back from the point alone (its face: the one whose plane it lies
//! on; its cell: its (a, b) on that face), for `pdf_li` and `pdf_le`.
//!
//! Triangle meshes, spheres and disks are still sampled uniformly by area
//! (a mesh's density at a point would need its triangle, which BDPT's light
//! vertices do not keep).

use glam::{Vec2, Vec3};

use crate::texture::Texture;

/// The most cells along each axis of one face.
const MAX_CELLS: usize = 64;
/// Points per axis at which a cell's brightness is evaluated.
const PROBES: usize = 4;
/// A cell's weight floor, relative to the emitter's mean brightness.
const FLOOR: f64 = 1e-3;

/// One face: `origin + a u + b v`, `a, b` in [0, 1].
#[derive(Clone, Copy, Debug)]
pub(super) struct Face {
    pub origin: Vec3,
    pub u: Vec3,
    pub v: Vec3,
    pub n: Vec3,
}

/// A face's grid and how to find a point's (a, b) on it.
#[derive(Clone, Copy, Debug)]
struct FaceGrid {
    face: Face,
    /// Dual basis: `a = (p - origin) · du`, `b = (p - origin) · dv`.
    du: Vec3,
    dv: Vec3,
    /// Unit normal, for the distance of a point to the face's plane.
    n: Vec3,
    /// Index of the face's first cell; cells are row-major, `nx` per row.
    first: usize,
    nx: usize,
    ny: usize,
}

/// Cells of textured parallelogram faces, chosen by brightness.
#[derive(Clone, Debug)]
pub(super) struct TextureGrid {
    faces: Vec<FaceGrid>,
    /// Cumulative cell weights divided by the total.
    cdf: Vec<f32>,
    /// Per cell, the density per unit area of a point in it.
    density: Vec<f32>,
}

impl TextureGrid {
    /// The grid over `faces` (each of positive area) for `texture`; `None`
    /// when the texture is equally bright at every probe (black, or one
    /// colour: uniform by area is then what the weights would give).
    pub(super) fn new(faces: &[Face], texture: &Texture) -> Option<TextureGrid> {
        let cells = match texture {
            Texture::Checkerboard { scale, .. } if scale.is_finite() && *scale > 0.0 => {
                (scale.ceil() as usize).clamp(1, MAX_CELLS)
            }
            _ => MAX_CELLS,
        };
        let mut grids = Vec::with_capacity(faces.len());
        // Per cell: (area, brightness).
        let mut raw: Vec<(f64, f64)> = Vec::new();
        for f in faces {
            let vn = f.v.cross(f.n);
            let nu = f.n.cross(f.u);
            let (du, dv) = (vn / f.u.dot(vn), nu / f.v.dot(nu));
            let area = f.u.cross(f.v).length() as f64 / (cells * cells) as f64;
            grids.push(FaceGrid { face: *f, du, dv, n: f.n.normalize(), first: raw.len(), nx: cells, ny: cells });
            for j in 0..cells {
                for i in 0..cells {
                    let mut sum = 0.0f64;
                    for pj in 0..PROBES {
                        for pi in 0..PROBES {
                            let a = (i as f32 + (pi as f32 + 0.5) / PROBES as f32) / cells as f32;
                            let b = (j as f32 + (pj as f32 + 0.5) / PROBES as f32) / cells as f32;
                            sum += texture.eval(Vec2::new(a, b)).average() as f64;
                        }
                    }
                    raw.push((area, sum / (PROBES * PROBES) as f64));
                }
            }
        }
        // A texture of one brightness (a one-colour image) keeps uniform-by-area
        // sampling: the same as its constant, to the bit.
        if raw.iter().all(|c| c.1 == raw[0].1) {
            return None;
        }
        let total_area: f64 = raw.iter().map(|c| c.0).sum();
        let mean = raw.iter().map(|c| c.0 * c.1).sum::<f64>() / total_area;
        if !(mean > 0.0 && mean.is_finite()) {
            return None;
        }
        let weights: Vec<f64> = raw.iter().map(|&(a, l)| a * (l + FLOOR * mean)).collect();
        // Every cell at least 2^-20 of the total: 16 steps of the f32 CDF near 1
        // (spacing 2^-24), so no cell's step rounds to zero width (zero density
        // where the texture emits would lose its light for light tracing). With
        // the most cells (6 faces of 64 x 64) the raised cells take at most 2.3%.
        let least = weights.iter().sum::<f64>() * (1.0 / 1_048_576.0);
        let weights: Vec<f64> = weights.into_iter().map(|w| w.max(least)).collect();
        let w_total: f64 = weights.iter().sum();
        let mut acc = 0.0f64;
        let cdf: Vec<f32> = weights
            .iter()
            .map(|w| {
                acc += w;
                (acc / w_total) as f32
            })
            .collect();
        // Each cell's probability as `sample` draws it: the width of its step
        // of the f32 CDF (so sampling and density agree to the rounding).
        let density = (0..cdf.len())
            .map(|c| {
                let lo = if c == 0 { 0.0 } else { cdf[c - 1] };
                ((cdf[c] - lo) as f64 / raw[c].0) as f32
            })
            .collect::<Vec<f32>>();
        debug_assert!(density.iter().all(|&d| d > 0.0), "a cell of zero density");
        Some(TextureGrid { faces: grids, cdf, density })
    }

    /// A point drawn by the cells' weights, then uniformly in its cell: the
    /// point, its face's normal, its (a, b) on the face, and its area density.
    #[inline]
    pub(super) fn sample(&self, u: Vec2) -> (Vec3, Vec3, Vec2, f32) {
        let c = self.cdf.partition_point(|&x| x <= u.x).min(self.cdf.len() - 1);
        let lo = if c == 0 { 0.0 } else { self.cdf[c - 1] };
        let ux = ((u.x - lo) / (self.cdf[c] - lo)).clamp(0.0, 1.0 - f32::EPSILON);
        let k = self.faces.partition_point(|g| g.first <= c) - 1;
        let g = &self.faces[k];
        let (i, j) = ((c - g.first) % g.nx, (c - g.first) / g.nx);
        let a = ((i as f32 + ux) / g.nx as f32).min(1.0 - f32::EPSILON);
        let b = ((j as f32 + u.y.min(1.0 - f32::EPSILON)) / g.ny as f32).min(1.0 - f32::EPSILON);
        let f = &g.face;
        (f.origin + f.u * a + f.v * b, f.n, Vec2::new(a, b), self.density[c])
    }

    /// The density per unit area with which [`Self::sample`] draws `point`,
    /// a point of one of the faces.
    #[inline]
    pub(super) fn density(&self, point: Vec3) -> f32 {
        let mut best = (f32::INFINITY, 0);
        for (k, g) in self.faces.iter().enumerate() {
            let d = (point - g.face.origin).dot(g.n).abs();
            if d < best.0 {
                best = (d, k);
            }
        }
        let g = &self.faces[best.1];
        let d = point - g.face.origin;
        let cell = |x: f32, n: usize| ((x * n as f32).floor().max(0.0) as usize).min(n - 1);
        let (i, j) = (cell(d.dot(g.du), g.nx), cell(d.dot(g.dv), g.ny));
        self.density[g.first + j * g.nx + i]
    }
}
