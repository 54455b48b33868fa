//! Rows of the failure matrix for the environment light: glass seen against
//! a uniform environment, and a map whose sun is 10⁵ times its sky.

use glam::{Mat3, Vec3};
use rust_v::light::EnvironmentLight;

use super::{METHODS, full_spectrum, mean_se, method, pixel_tol, y};
use crate::common::{render_str, temp_dir};

/// A smooth glass sphere (n 1.5) in `Uniform(Constant(1))`, seen from outside,
/// filling the view's centre: lossless, so invisible: every pixel 1 (every
/// path carries the same value over the full spectrum: per pixel within
/// [`pixel_tol`]); the packet samplers within 5 s.e. of 1 in the mean.
/// Light tracing sees nothing through smooth glass: exactly 0 on the 4x4
/// pixels at the sphere's centre, exactly 1 (the sky seen directly) in the corners.
#[test]
fn glass_against_a_uniform_environment_is_invisible() {
    let scene = r#"(
        camera: (eye: (0, 0, 3), look_at: (0, 0, 0), fov_deg: 40),
        render: (width: 12, height: 12, max_bounces: 64),
        materials: { "glass": Dielectric(ior: Constant(1.5)) },
        objects: [ (shape: Sphere(center: (0, 0, 0), radius: 0.9), material: "glass") ],
        environment: Uniform(Constant(1)),
    )"#;
    for m in METHODS {
        let film = render_str(scene, &method(m, 32, 5));
        let v = y(&film);
        if m == "lighttrace" {
            for j in 4..8 {
                for i in 4..8 {
                    assert_eq!(v[j * 12 + i], 0.0, "lighttrace: the sphere's centre is seen through glass");
                }
            }
            assert!((v[0] - 1.0).abs() < 1e-6 && (v[143] - 1.0).abs() < 1e-6, "lighttrace: corners see the sky");
            continue;
        }
        let (mean, se) = mean_se(&v);
        eprintln!("glass in a uniform environment, {m}: Y = {mean:.5} ± {se:.5}, want 1");
        assert!((mean - 1.0).abs() < 5.0 * se + 2e-3, "{m}: Y = {mean} ± {se}");
        if full_spectrum(m) && m != "whitted" {
            assert!(v.iter().all(|p| (p - 1.0).abs() < pixel_tol(m)), "{m}: a pixel is off 1: {v:?}");
        }
    }
}

/// A 16x8 map: a sky of 0.01 and one texel, 35° up, of 1000 (10⁵ times the
/// sky: a sun), over a Lambertian floor (ρ 0.5, 6 x 6: light tracing's
/// light subpaths start on a disk of the scene's radius, so a floor 100
/// wide left almost none landing in view: 0 at 64 spp) filling the view. The floor's
/// radiance is ρE/π with E = ∫ L cos dω over the upper hemisphere, computed
/// here by the midpoint rule on a 2048 x 1024 grid of directions from the
/// map's own radiance (the bilinear filter included). Every method within
/// 5 s.e. (from the spread of pixel values) + 1% of it. Whitted's direct
/// light is the whole answer here (a plane sees no other surface).
#[test]
fn a_sun_in_a_map_lights_a_floor_with_every_method() {
    let dir = temp_dir("stability_env_sun");
    let (w, h) = (16usize, 8usize);
    let mut rgb = vec![[0.01f32; 3]; w * h];
    rgb[2 * w + 5] = [1000.0; 3];
    let px: Vec<f32> = rgb.iter().flatten().copied().collect();
    image::Rgb32FImage::from_raw(w as u32, h as u32, px).unwrap().save(dir.join("sun.exr")).unwrap();
    let env = EnvironmentLight::map(w, h, &rgb, 1.0, Mat3::IDENTITY).unwrap();
    let (nu, nv) = (2048usize, 1024usize);
    let mut e = 0.0f64;
    for j in 0..nv / 2 {
        for i in 0..nu {
            let (u, v) = ((i as f32 + 0.5) / nu as f32, (j as f32 + 0.5) / nv as f32);
            let (theta, phi) = (std::f32::consts::PI * v, 2.0 * std::f32::consts::PI * u);
            let d = Vec3::new(theta.sin() * phi.sin(), theta.cos(), -theta.sin() * phi.cos());
            let dw = 2.0 * std::f64::consts::PI.powi(2) * theta.sin() as f64 / (nu * nv) as f64;
            // Y of the texel spectrum: the test reads the film's Y, so weigh the same way.
            let l = rust_v::color::Spectrum::to_xyz(&env.radiance(d)).y as f64;
            e += l * d.y as f64 * dw;
        }
    }
    let want = 0.5 * e / std::f64::consts::PI;
    let scene = r#"(
        camera: (eye: (0, 1, 0), look_at: (0, 0, -0.2), fov_deg: 60),
        render: (width: 12, height: 12, max_bounces: 8),
        materials: { "floor": Lambertian(reflectance: Constant(0.5)) },
        objects: [ (shape: Quad(origin: (-3, 0, 3), edge_u: (6, 0, 0), edge_v: (0, 0, -6)), material: "floor") ],
        environment: Image(path: "sun.exr"),
    )"#;
    let path = dir.join("scene.ron");
    std::fs::write(&path, scene).unwrap();
    for m in METHODS {
        let film = crate::common::render_file(&path, &method(m, 64, 6));
        let (mean, se) = mean_se(&y(&film));
        eprintln!("a sun in a map over a floor, {m}: Y = {mean:.5} ± {se:.5}, want {want:.5}");
        assert!((mean - want).abs() < 5.0 * se + 0.01 * want, "{m}: Y = {mean} ± {se}, want {want}");
    }
}
