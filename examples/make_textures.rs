//! Writes the small images the shipped scenes use, deterministically:
//!
//! - `scenes/textures/outdoor.exr`: a 128x64 equirectangular environment
//!   (linear sRGB, +y up, u = 0 towards −z; see `crate::light::EnvironmentLight`):
//!   a blue sky graded to a pale horizon, a warm sun 5x5 texels wide at 35°
//!   elevation towards +x, a bright overcast panel towards +z, and a
//!   brown-grey ground.
//! - `scenes/textures/outdoor-equal-area.exr`: the same sky as a 64x64 equal-area
//!   square (`mapping: EqualArea`, pbrt-v4's layout: the centre looks up).
//! - `scenes/textures/chart.png`: a 96x64 8-bit sRGB chart of 6x4 coloured
//!   patches (the ColorChecker's order, approximate sRGB values) on a black grid.
//! - `scenes/media/smoke.vol`: a 24³ density grid (Mitsuba's `.vol`, see
//!   `rust_v::medium::grid`): a soft cloud of three overlapping blobs, 0 to about 1.
//! - `scenes/media/plume.vol`: a 32x48x32 grid of a thin, rising, swirling plume of
//!   puffs (0 to 0.9; zero in most of the box, as real smoke is: 93% of the voxels).
//!
//! Run: `cargo run --release --example make_textures` (from the repository root).

use std::f32::consts::PI;

/// The sky of `outdoor.exr` in direction `d` (+y up).
fn sky(d: [f32; 3]) -> [f32; 3] {
    if d[1] >= 0.0 {
        let t = d[1].powf(0.4);
        let mut c = [0.75 - 0.45 * t, 0.85 - 0.35 * t, 1.0 - 0.1 * t];
        // The sun: towards +x, 35° up; 5x5 texels of about 200x the sky.
        let sun = [35f32.to_radians().cos(), 35f32.to_radians().sin(), 0.0];
        let cos = d[0] * sun[0] + d[1] * sun[1] + d[2] * sun[2];
        if cos > (5.0f32 * PI / 64.0 / 2.0).cos() {
            c = [220.0, 190.0, 150.0];
        }
        // A soft bright panel towards +z, low in the sky.
        if d[2] > 0.9 && d[1] < 0.35 {
            c = c.map(|x| x * 4.0);
        }
        c
    } else {
        [0.22, 0.18, 0.14]
    }
}

/// The direction of the equal-area square's point `(u, v)` in [0, 1]² (`mapping:
/// EqualArea`: centre up, u towards +x, v towards +z; Clarberg 2008).
fn equal_area_direction(u: f32, v: f32) -> [f32; 3] {
    let (u, v) = (2.0 * u - 1.0, 2.0 * v - 1.0);
    let signed = 1.0 - (u.abs() + v.abs());
    let r = 1.0 - signed.abs();
    let phi = if r == 0.0 { PI / 4.0 } else { ((v.abs() - u.abs()) / r + 1.0) * PI / 4.0 };
    let s = r * (2.0 - r * r).max(0.0).sqrt();
    [phi.cos().copysign(u) * s, (1.0 - r * r).copysign(signed), phi.sin().copysign(v) * s]
}

fn main() {
    let (w, h) = (128u32, 64u32);
    let mut px = Vec::with_capacity((w * h * 3) as usize);
    for j in 0..h {
        for i in 0..w {
            let (u, v) = ((i as f32 + 0.5) / w as f32, (j as f32 + 0.5) / h as f32);
            let (theta, phi) = (PI * v, 2.0 * PI * u);
            let d = [theta.sin() * phi.sin(), theta.cos(), -theta.sin() * phi.cos()];
            px.extend_from_slice(&sky(d));
        }
    }
    std::fs::create_dir_all("scenes/textures").unwrap();
    image::Rgb32FImage::from_raw(w, h, px).unwrap().save("scenes/textures/outdoor.exr").unwrap();
    // The same sky as a 64x64 equal-area square.
    let n = 64u32;
    let mut px = Vec::with_capacity((n * n * 3) as usize);
    for j in 0..n {
        for i in 0..n {
            let d = equal_area_direction((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
            px.extend_from_slice(&sky(d));
        }
    }
    image::Rgb32FImage::from_raw(n, n, px).unwrap().save("scenes/textures/outdoor-equal-area.exr").unwrap();

    // Approximate sRGB (8-bit) of the 24 ColorChecker patches, row by row.
    const PATCHES: [[u8; 3]; 24] = [
        [115, 82, 68],
        [194, 150, 130],
        [98, 122, 157],
        [87, 108, 67],
        [133, 128, 177],
        [103, 189, 170],
        [214, 126, 44],
        [80, 91, 166],
        [193, 90, 99],
        [94, 60, 108],
        [157, 188, 64],
        [224, 163, 46],
        [56, 61, 150],
        [70, 148, 73],
        [175, 54, 60],
        [231, 199, 31],
        [187, 86, 149],
        [8, 133, 161],
        [243, 243, 242],
        [200, 200, 200],
        [160, 160, 160],
        [122, 122, 121],
        [85, 85, 85],
        [52, 52, 52],
    ];
    let (cw, ch) = (96u32, 64u32);
    let img = image::RgbImage::from_fn(cw, ch, |x, y| {
        let (px, py) = (x % 16, y % 16);
        if px < 2 || py < 2 {
            return image::Rgb([20, 20, 20]);
        }
        image::Rgb(PATCHES[((y / 16) * 6 + x / 16) as usize])
    });
    img.save("scenes/textures/chart.png").unwrap();

    let n = 24usize;
    let blobs = [([0.45f32, 0.4, 0.5], 0.22f32), ([0.62, 0.55, 0.45], 0.18), ([0.38, 0.62, 0.55], 0.15)];
    let data: Vec<f32> = (0..n * n * n)
        .map(|k| {
            let p = [(k % n) as f32, ((k / n) % n) as f32, (k / (n * n)) as f32].map(|v| (v + 0.5) / n as f32);
            blobs
                .iter()
                .map(|(c, r)| {
                    let d2: f32 = (0..3).map(|i| (p[i] - c[i]).powi(2)).sum();
                    (-d2 / (r * r)).exp()
                })
                .sum::<f32>()
                .min(1.0)
        })
        .collect();
    std::fs::create_dir_all("scenes/media").unwrap();
    std::fs::write("scenes/media/smoke.vol", rust_v::medium::grid::write_vol([n, n, n], &data)).unwrap();

    // A plume: puffs along a helix rising from the bottom centre, growing and thinning.
    let (nx, ny, nz) = (32usize, 48usize, 32usize);
    let puffs: Vec<([f32; 3], f32, f32)> = (0..40)
        .map(|i| {
            let h = i as f32 / 39.0;
            let a = 5.0 * h;
            let c = [0.5 + 0.18 * h * a.cos(), 0.06 + 0.86 * h, 0.5 + 0.18 * h * a.sin()];
            (c, 0.035 + 0.07 * h, 1.0 - 0.6 * h)
        })
        .collect();
    let plume: Vec<f32> = (0..nx * ny * nz)
        .map(|k| {
            let v = [k % nx, (k / nx) % ny, k / (nx * ny)];
            let p = [(v[0] as f32 + 0.5) / nx as f32, (v[1] as f32 + 0.5) / ny as f32, (v[2] as f32 + 0.5) / nz as f32];
            let d: f32 = puffs
                .iter()
                .map(|(c, r, w)| {
                    let d2: f32 = (0..3).map(|i| (p[i] - c[i]).powi(2)).sum();
                    w * (-d2 / (r * r)).exp()
                })
                .fold(0.0, f32::max);
            if d < 0.02 { 0.0 } else { d.min(1.0) }
        })
        .collect();
    std::fs::write("scenes/media/plume.vol", rust_v::medium::grid::write_vol([nx, ny, nz], &plume)).unwrap();
}
