//! Textured quad and cuboid emitters are sampled by their texture's
//! brightness (issue 35): the points drawn follow the density the light
//! reports (`pdf_area`, `pdf_li`, `pdf_le`), that density integrates to 1,
//! and it puts the samples where the texture is bright.

use glam::{Vec2, Vec3};
use rust_v::color::Spectrum;
use rust_v::light::{AreaLight, EmissionTexture, Light};
use rust_v::scene::desc::Wrap;
use rust_v::shape::{Cuboid, Quad};
use rust_v::texture::{ImageTexture, Role, Texture};

/// Independent uniform pairs in [0, 1)² (SplitMix64; the crate's sampler is private).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f32 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
    }

    fn next_2d(&mut self) -> Vec2 {
        Vec2::new(self.next(), self.next())
    }
}

/// The unit square at height 1 facing down, (u, v) = (x + 0.5, z + 0.5).
fn square() -> Quad {
    Quad::new(Vec3::new(-0.5, 1.0, -0.5), Vec3::X, Vec3::Z)
}

fn textured(light: AreaLight, texture: Texture) -> AreaLight {
    let (mean, _) = texture.mean_and_peak();
    light.with_texture(Some(Box::new(EmissionTexture { texture, mean })), None)
}

/// `Checkerboard(even: 8, odd: 1, scale: 4)`: 16 squares of side 1/4.
fn checker() -> Texture {
    Texture::Checkerboard { even: Box::new(Spectrum::splat(8.0)), odd: Box::new(Spectrum::splat(1.0)), scale: 4.0 }
}

/// An 8 x 8 emission image, dim (0.05) but for three bright texels (100, 40, 20).
fn window_image() -> Texture {
    let mut rgb = vec![[0.05f32; 3]; 64];
    rgb[8 * 2 + 5] = [100.0; 3];
    rgb[8 * 6 + 1] = [40.0; 3];
    rgb[8 * 3 + 3] = [20.0; 3];
    let image = ImageTexture::new(8, 8, &rgb, 1.0, Vec2::ONE, Vec2::ZERO, Wrap::Repeat, Role::Emission).unwrap();
    Texture::Image(std::sync::Arc::new(image))
}

/// ∫ pdf_area over the unit square, by the midpoint rule on a 512 x 512 grid
/// (the density is constant on cells of side 1/64 or coarser, so the rule
/// is exact up to rounding), per cell of an `n` x `n` histogram.
fn integrated(light: &AreaLight, n: usize) -> Vec<f64> {
    let m = 512;
    let mut cells = vec![0.0f64; n * n];
    for j in 0..m {
        for i in 0..m {
            let (a, b) = ((i as f32 + 0.5) / m as f32, (j as f32 + 0.5) / m as f32);
            let p = Vec3::new(-0.5 + a, 1.0, -0.5 + b);
            cells[(j * n / m) * n + i * n / m] += light.pdf_area(p) as f64 / (m * m) as f64;
        }
    }
    cells
}

/// Pearson's statistic of `counts` against the probabilities `p`.
fn chi_square(counts: &[u64], p: &[f64]) -> f64 {
    let total: u64 = counts.iter().sum();
    counts.iter().zip(p).map(|(&c, &p)| (c as f64 - total as f64 * p).powi(2) / (total as f64 * p)).sum()
}

/// Draws `n` points with `sample_li` from below the square; histogram over
/// an `cells` x `cells` grid of (u, v), and how many samples' pdf differs
/// from `pdf_li` recomputed from the point (only a point on a cell border,
/// rounded across it, may).
fn histogram(light: &AreaLight, cells: usize, n: usize) -> (Vec<u64>, usize) {
    let from = Vec3::new(0.2, 0.0, -0.1);
    let mut s = Rng(17);
    let mut counts = vec![0u64; cells * cells];
    let mut mismatches = 0;
    for _ in 0..n {
        let ls = light.sample_li(from, s.next_2d()).expect("the square faces the point");
        let (a, b) = (ls.point.x + 0.5, ls.point.z + 0.5);
        assert!((ls.point.y - 1.0).abs() < 1e-6 && (0.0..1.0).contains(&a) && (0.0..1.0).contains(&b));
        let (i, j) = (((a * cells as f32) as usize).min(cells - 1), ((b * cells as f32) as usize).min(cells - 1));
        counts[j * cells + i] += 1;
        let back = light.pdf_li(from, ls.wi, ls.point, ls.n);
        if (back - ls.pdf).abs() > 1e-4 * ls.pdf {
            mismatches += 1;
        }
    }
    (counts, mismatches)
}

/// Chi-square of 400k points over the checkerboard's 16 squares against the
/// pdf integrated per square: below 37.70, the 0.999 quantile of χ² with 15
/// degrees of freedom (a false failure one run in a thousand; the sampler
/// is seeded, so the run is fixed). The pdf integrates to 1 (|error| < 1e-4:
/// rounding only), a bright square is 8 times as dense as a dark one (within
/// the floor: the ratio is (8 + f) / (1 + f), f = 1e-3 × the mean 4.5), and
/// `pdf_li` agrees with the pdf of the sample for all but 0.1% of them.
#[test]
fn a_checkerboard_emitter_is_sampled_by_its_squares() {
    let light = textured(AreaLight::quad(&square(), Spectrum::ONE, false).unwrap(), checker());
    let p = integrated(&light, 4);
    let total: f64 = p.iter().sum();
    assert!((total - 1.0).abs() < 1e-4, "∫ pdf = {total}");
    let (even, odd) = (p[0], p[1]);
    let f = 1e-3 * 4.5;
    assert!((even / odd - (8.0 + f) / (1.0 + f)).abs() < 1e-3, "bright/dark density {}", even / odd);
    let n = 400_000;
    let (counts, mismatches) = histogram(&light, 4, n);
    let chi2 = chi_square(&counts, &p);
    eprintln!("checkerboard: χ² = {chi2:.2} (15 dof), even/odd density {:.4}, {mismatches} pdf mismatches", even / odd);
    assert!(chi2 < 37.70, "χ² = {chi2} over the 16 squares: {counts:?}");
    assert!(mismatches <= n / 1000, "{mismatches} samples whose pdf_li differs");
}

/// The same for an image of three bright texels on a dim panel, histogram
/// over its 8 x 8 texels: χ² below 103.44 (the 0.999 quantile with 63
/// degrees of freedom). The brightest texel's square, 1/64 of the area,
/// gets its share of the light: the lookup is bilinear, so a texel's
/// radiance spreads as a tent over its neighbours and (3/4)² of it stays in
/// its square: 100 × 0.5625 / 163.05 (the texels' sum) = 0.345 (the floor
/// takes 0.1% of it), where uniform sampling gives 1/64 = 0.016. A dim
/// square far from the bright ones still has a non-zero share (the floor).
#[test]
fn an_image_emitter_is_sampled_by_its_texels() {
    let light = textured(AreaLight::quad(&square(), Spectrum::ONE, false).unwrap(), window_image());
    let p = integrated(&light, 8);
    let total: f64 = p.iter().sum();
    assert!((total - 1.0).abs() < 1e-4, "∫ pdf = {total}");
    // Texel (x, y) from the top is at u = (x + 0.5) / 8, v = 1 - (y + 0.5) / 8.
    let cell = |x: usize, y: usize| (7 - y) * 8 + x;
    assert!((p[cell(5, 2)] - 0.345).abs() < 3e-3, "the brightest texel's share {}", p[cell(5, 2)]);
    assert!(p[cell(7, 7)] > 0.0);
    let n = 400_000;
    let (counts, mismatches) = histogram(&light, 8, n);
    let chi2 = chi_square(&counts, &p);
    eprintln!(
        "image: χ² = {chi2:.2} (63 dof), brightest texel {:.4} of the samples, {mismatches} pdf mismatches",
        counts[cell(5, 2)] as f64 / n as f64
    );
    assert!(chi2 < 103.44, "χ² = {chi2} over the 64 texels: {counts:?}");
    assert!(mismatches <= n / 1000, "{mismatches} samples whose pdf_li differs");
}

/// A textured cuboid: emitted rays (`sample_le`, BDPT's and light tracing's)
/// report the position density `pdf_le` gives back from the point, on every
/// face; the density integrated over the six faces (midpoint rule, 128 x 128
/// per face) is 1; a one-colour texture keeps uniform sampling (`1 / A`).
#[test]
fn a_textured_cuboid_reports_the_density_it_samples() {
    let c = Cuboid::new(Vec3::new(-0.3, 0.8, -0.2), Vec3::new(0.4, 1.3, 0.5));
    let light = Light::Area(textured(AreaLight::cuboid(&c, Spectrum::ONE, false).unwrap(), checker()));
    let mut s = Rng(3);
    let mut faces = [0u32; 6];
    for _ in 0..20_000 {
        let Some(e) = light.sample_le(s.next_2d(), s.next_2d()) else { continue };
        let (pos, dir) = light.pdf_le(e.point, e.n, e.dir);
        assert!((pos - e.pdf_pos).abs() <= 1e-4 * e.pdf_pos, "pdf_pos {pos} vs {} at {}", e.pdf_pos, e.point);
        assert!((dir - e.pdf_dir).abs() <= 1e-4 * e.pdf_dir);
        let axis = e.n.abs().max_position();
        faces[axis * 2 + usize::from(e.n[axis] > 0.0)] += 1;
    }
    assert!(faces.iter().all(|&f| f > 1000), "every face is sampled: {faces:?}");
    let Light::Area(area) = &light else { unreachable!() };
    let d = c.max - c.min;
    let m = 128;
    let mut total = 0.0f64;
    for axis in 0..3 {
        let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
        for side in [0.0, 1.0] {
            for j in 0..m {
                for i in 0..m {
                    let mut p = c.min;
                    p[axis] += side * d[axis];
                    p[a] += (i as f32 + 0.5) / m as f32 * d[a];
                    p[b] += (j as f32 + 0.5) / m as f32 * d[b];
                    total += area.pdf_area(p) as f64 * (d[a] * d[b]) as f64 / (m * m) as f64;
                }
            }
        }
    }
    assert!((total - 1.0).abs() < 1e-4, "∫ pdf over the cuboid = {total}");
    let flat =
        Texture::Checkerboard { even: Box::new(Spectrum::splat(3.0)), odd: Box::new(Spectrum::splat(3.0)), scale: 4.0 };
    let one = textured(AreaLight::cuboid(&c, Spectrum::ONE, false).unwrap(), flat);
    let area_total = 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x);
    let got = one.pdf_area(c.min + Vec3::new(0.3 * d.x, 0.0, 0.3 * d.z));
    assert!((got * area_total - 1.0).abs() < 1e-5, "one colour: {got} vs 1 / {area_total}");
}

/// A rectangle `[x0, x1] × [z0, z1]` of the emitter and its luminance.
type Square = ((f64, f64), (f64, f64), f64);

/// A mostly dark emitter lights a floor with the irradiance the closed form
/// gives, through every method that draws points on it. The emitter: the
/// unit square at height 1 facing down, a 16 x 16 grey EXR at 0.02 but for a
/// 2 x 2 window at 50 (1.6% of the area, 94% of the power), so nearly every
/// light sample lands on the window. The closed form: the texture's
/// luminance (a grey texel's Y is its value; the lookup is bilinear between
/// texel centres, wrapping, as `texture.rs` documents, written out here) at
/// the centres of 64 x 64 sub-squares (a midpoint rule: error below 1e-4
/// of E here), each a rectangle summed with the point-to-rectangle form
/// factor, `Y = ρ E / π` on a floor of ρ = 0.5. The floor pixels within 0.9
/// of the emitter's centre (101 of a 16 x 16 film) are summed per method:
/// each sum must be within 2% (path 256 spp, spectral hero 256, BDPT 1024,
/// light tracing 4096), and every path-traced pixel within 5% (+ 2e-3).
/// Measured: 0.9956, 0.9957, 0.9958 and 0.9959 of the closed form (the
/// same small offset for every method, so not the sampling; the grey
/// uplift's Y and the midpoint rule are the candidates).
#[test]
fn a_window_emitter_gives_the_closed_form_irradiance() {
    use crate::common::{render_str, temp_dir};
    use rust_v::scene::load_scene_str;
    use rust_v::settings::{IntegratorKind, SettingsPatch, WavelengthsKind};
    const RHO: f64 = 0.5;
    let n = 16;
    let value = |x: usize, y: usize| if (10..12).contains(&x) && (4..6).contains(&y) { 50.0f32 } else { 0.02 };
    let mut texels = Vec::with_capacity(n * n * 3);
    for y in 0..n {
        for x in 0..n {
            texels.extend([value(x, y); 3]);
        }
    }
    let dir = temp_dir("emitsample_window");
    let exr = dir.join("window.exr");
    image::Rgb32FImage::from_raw(n as u32, n as u32, texels).unwrap().save(&exr).unwrap();
    let text = format!(
        r#"(
    camera: (eye: (1.6, 0.5, 0.3), look_at: (0, 0, 0.1), fov_deg: 50),
    materials: {{ "floor": Lambertian(reflectance: Constant(0.5)) }},
    objects: [
        (shape: Quad(origin: (-5, 0, 5), edge_u: (10, 0, 0), edge_v: (0, 0, -10)), material: "floor"),
        (shape: Quad(origin: (-0.5, 1, -0.5), edge_u: (1, 0, 0), edge_v: (0, 0, 1)),
            emission: Image(path: "{}")),
    ],
)"#,
        exr.display()
    );
    // Bilinear between texel centres, wrapping; v = 0 at the image's bottom row.
    let lum = |u: f64, v: f64| -> f64 {
        let (x, y) = (u * n as f64 - 0.5, (1.0 - v) * n as f64 - 0.5);
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let at = |i: f64, j: f64| {
            value((i as i64).rem_euclid(n as i64) as usize, (j as i64).rem_euclid(n as i64) as usize) as f64
        };
        (1.0 - fx) * (1.0 - fy) * at(x0, y0)
            + fx * (1.0 - fy) * at(x0 + 1.0, y0)
            + (1.0 - fx) * fy * at(x0, y0 + 1.0)
            + fx * fy * at(x0 + 1.0, y0 + 1.0)
    };
    let m = 64;
    let squares: Vec<Square> = (0..m * m)
        .map(|k| {
            let (i, j) = ((k % m) as f64, (k / m) as f64);
            let h = 1.0 / m as f64;
            // (u, v) = (x + 0.5, z + 0.5).
            ((i * h - 0.5, (i + 1.0) * h - 0.5), (j * h - 0.5, (j + 1.0) * h - 0.5), lum((i + 0.5) * h, (j + 0.5) * h))
        })
        .collect();
    let irradiance =
        |p: Vec3| -> f64 { squares.iter().map(|&(x, z, l)| crate::textures::rectangle(p, x, z, 1.0, l)).sum() };
    for (method, wavelengths, spp) in [
        (IntegratorKind::Path, None, 256),
        (IntegratorKind::Spectral, Some(WavelengthsKind::Hero), 256),
        (IntegratorKind::Bdpt, None, 1024),
        (IntegratorKind::LightTrace, None, 4096),
    ] {
        let o = SettingsPatch {
            width: Some(16),
            height: Some(16),
            spp: Some(spp),
            integrator: Some(method),
            max_bounces: Some(1),
            wavelengths,
            ..Default::default()
        };
        let scene = load_scene_str(&text, &dir.join("window.ron"), &o).unwrap();
        let film = render_str(&text, &o);
        let (mut checked, mut got_sum, mut want_sum) = (0, 0.0, 0.0);
        for (k, xyz) in film.mean_xyz().iter().enumerate() {
            let (x, y) = (k % 16, k / 16);
            let ray = scene.camera.ray(Vec2::new(x as f32 + 0.5, y as f32 + 0.5));
            let Some(hit) = scene.intersect(&ray, f32::INFINITY) else { continue };
            let p = hit.hit.p;
            if p.y.abs() > 1e-4 || (p.x.powi(2) + p.z.powi(2)).sqrt() > 0.9 {
                continue;
            }
            let want = RHO * irradiance(p) / std::f64::consts::PI;
            let got = xyz[1];
            if method == IntegratorKind::Path {
                assert!((got - want).abs() <= 0.05 * want + 2e-3, "pixel ({x}, {y}) at {p}: Y {got} vs {want}");
            }
            checked += 1;
            got_sum += got;
            want_sum += want;
        }
        assert!(checked >= 100, "{method:?}: {checked} pixels checked");
        eprintln!("{method:?} {wavelengths:?}: {checked} pixels, {:.4} of the closed form", got_sum / want_sum);
        assert!((got_sum / want_sum - 1.0).abs() < 0.02, "{method:?}: Σ Y {got_sum} vs {want_sum}");
    }
}
