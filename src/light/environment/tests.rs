//! Tests of the environment light.
use super::*;
use crate::sampler::Sampler;

/// The orientation the module doc states: u = 0 looks to −z, 0.25 to +x,
/// 0.5 to +z, 0.75 to −x; v = 0 up, 1 down; `to_uv` inverts `from_uv`.
#[test]
fn orientation_follows_the_documented_convention() {
    let dir = |u: f32, v: f32| from_uv(Vec2::new(u, v)).0;
    assert!((dir(0.0, 0.5) - Vec3::NEG_Z).length() < 1e-6);
    assert!((dir(0.25, 0.5) - Vec3::X).length() < 1e-6);
    assert!((dir(0.5, 0.5) - Vec3::Z).length() < 1e-6);
    assert!((dir(0.75, 0.5) - Vec3::NEG_X).length() < 1e-6);
    assert!((dir(0.3, 0.0) - Vec3::Y).length() < 1e-6);
    for (u, v) in [(0.1f32, 0.2f32), (0.6, 0.7), (0.95, 0.5), (0.26, 0.99)] {
        let uv = to_uv(dir(u, v));
        assert!((uv - Vec2::new(u, v)).length() < 1e-5, "{u},{v} -> {uv}");
    }
}

/// A 16x8 map with one bright texel, turned: the density per solid angle
/// integrates to 1 over the sphere (midpoint rule on a fine grid of
/// (u, v), |error| < 1e-3), `pdf_li` agrees with the density
/// `sample_li` returned, and the estimator `L/pdf` of the irradiance-like
/// integral ∫ mean L dω matches the map's own sum (20k samples; the
/// estimate's spread is small because sampling follows the radiance, so 2%).
#[test]
fn map_density_integrates_to_one_and_matches_its_samples() {
    let (w, h) = (16usize, 8usize);
    let mut rgb = vec![[0.05f32, 0.1, 0.2]; w * h];
    rgb[2 * w + 5] = [40.0, 30.0, 10.0];
    rgb[6 * w + 12] = [0.0, 0.0, 0.0];
    let rot = Transform { rotate_deg: Vec3::new(10.0, 70.0, -20.0), ..Transform::default() }.linear();
    let env = EnvironmentLight::map(w, h, &rgb, 1.0, rot).unwrap();
    let n = 800;
    let mut integral = 0.0f64;
    for j in 0..n {
        for i in 0..n {
            let uv = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
            let (m, sin) = from_uv(uv);
            let wi = rot * m;
            integral += (env.pdf_li(wi) * 2.0 * PI * PI * sin) as f64 / (n * n) as f64;
        }
    }
    assert!((integral - 1.0).abs() < 1e-3, "∫pdf = {integral}");
    let mut s = Sampler::new(3, 0, 0);
    let mut est = 0.0f64;
    let samples = 20_000;
    let mut off = 0;
    for _ in 0..samples {
        let ls = env.sample_li(Vec3::ZERO, s.next_2d()).unwrap();
        let back = env.pdf_li(ls.wi);
        // A direction sampled within f32 rounding of a cell's edge may map
        // back into the neighbouring cell (rotation and normalisation round):
        // then the two densities differ by the cells' ratio. Rare.
        if (back - ls.pdf).abs() > 1e-3 * ls.pdf {
            off += 1;
        }
        est += (env.radiance(ls.wi).average() / ls.pdf) as f64;
    }
    assert!(off < samples / 200, "{off} of {samples} samples map back to another density");
    est /= samples as f64;
    // The same integral by the midpoint rule over directions (bilinear radiance).
    let mut want = 0.0f64;
    for j in 0..n {
        for i in 0..n {
            let uv = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
            let (m, sin) = from_uv(uv);
            want += (env.radiance(rot * m).average() * 2.0 * PI * PI * sin) as f64 / (n * n) as f64;
        }
    }
    assert!((est / want - 1.0).abs() < 0.02, "estimate {est} vs {want}");
}

/// A map of one colour is the same spectrum in every direction, bit for
/// bit the emission `Rgb(...)` gives for that colour; a 1x1 map works.
#[test]
fn a_constant_map_is_rgb_emission_everywhere() {
    let c = [0.7f32, 0.4, 0.2];
    let want = crate::color::rgb_emission(c);
    for (w, h) in [(1usize, 1usize), (7, 3)] {
        let env = EnvironmentLight::map(w, h, &vec![c; w * h], 1.0, Mat3::IDENTITY).unwrap();
        let mut s = Sampler::new(4, 0, 0);
        for _ in 0..200 {
            let wi = uniform_sphere(s.next_2d());
            assert_eq!(env.radiance(wi), want);
        }
    }
}

/// The sky's density (sun cone mixed with the table) integrates to 1 over
/// the sphere: the table part by the midpoint rule on a fine grid, the
/// sun's part exactly (its cone density times its solid angle is 1, and
/// the grid would miss the 0.26° disk). The irradiance of the sun and
/// sky on a horizontal surface, estimated from `sample_li` (50k samples;
/// the sun's part has almost no variance since its cone is sampled
/// uniformly), matches the sun's irradiance from the model's own integral
/// times sin(elevation) plus the sky's by the midpoint rule, within 2%.
#[test]
fn sky_density_integrates_to_one_and_sampling_finds_the_sun() {
    let elevation = 25f32.to_radians();
    let env = EnvironmentLight::sky(3.0, 0.3, elevation, 0.7, 1.0).unwrap();
    let Source::Sky(sky) = &env.source else { unreachable!() };
    let n = 1000;
    let mut table = 0.0f64;
    let mut sky_e = 0.0f64;
    for j in 0..n {
        for i in 0..n {
            let uv = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
            let (d, sin) = from_uv(uv);
            let w = (2.0 * PI * PI * sin) as f64 / (n * n) as f64;
            table += (sky.table.pdf(uv) / (2.0 * PI * PI * sin)) as f64 * w;
            if d.y > 0.0 && !sky.in_sun(d) {
                sky_e += (env.radiance(d)[17] * d.y) as f64 * w;
            }
        }
    }
    let cone = 2.0 * PI * sky.sun_one_minus_cos * (1.0 / (2.0 * PI * sky.sun_one_minus_cos));
    let total = sky.p_sun as f64 * cone as f64 + (1.0 - sky.p_sun as f64) * table;
    assert!((total - 1.0).abs() < 2e-3, "∫pdf = {total} (table {table})");
    let mut s = Sampler::new(11, 0, 0);
    let samples = 50_000;
    let (mut e, mut hits) = (0.0f64, 0);
    for _ in 0..samples {
        let ls = env.sample_li(Vec3::ZERO, s.next_2d()).unwrap();
        assert!((env.pdf_li(ls.wi) - ls.pdf).abs() <= 1e-3 * ls.pdf);
        if ls.wi.y > 0.0 {
            e += (env.radiance(ls.wi)[17] * ls.wi.y / ls.pdf) as f64;
        }
        hits += sky.in_sun(ls.wi) as usize;
    }
    e /= samples as f64;
    let want = sky.model.sun_irradiance()[17] as f64 * elevation.sin() as f64 + sky_e;
    assert!(hits > samples / 20, "the sun's cone was sampled {hits} times");
    assert!((e / want - 1.0).abs() < 0.02, "E(550 nm) = {e}, want {want} (sky part {sky_e})");
}

/// Bad maps are refused with a message: NaN or negative texels, all black, empty.
#[test]
fn bad_maps_are_refused() {
    let id = Mat3::IDENTITY;
    assert!(EnvironmentLight::map(2, 1, &[[1.0, f32::NAN, 0.0], [1.0; 3]], 1.0, id).unwrap_err().contains("(0, 0)"));
    assert!(EnvironmentLight::map(2, 1, &[[1.0; 3], [-1.0, 0.0, 0.0]], 1.0, id).unwrap_err().contains("(1, 0)"));
    assert!(EnvironmentLight::map(2, 1, &[[0.0; 3]; 2], 1.0, id).unwrap_err().contains("black"));
    assert!(EnvironmentLight::map(0, 0, &[], 1.0, id).is_err());
}
