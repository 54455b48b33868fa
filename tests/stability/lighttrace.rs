//! The failure matrix's `lighttrace` column. Light tracing connects light
//! subpath vertices to the eye; a specular vertex (mirror, smooth glass)
//! cannot be connected, so whatever the camera sees *through or in* a
//! specular surface is missing by design (Mitsuba's `ptracer` shares this),
//! while everything seen on diffuse surfaces, caustics included, is
//! unbiased. Each row here asserts one side of that.

use super::*;

/// Lambertian sphere (ρ 0.5, R 1) with a point light of intensity 1 at its
/// centre: L = ρ I / (π R² (1 − ρ)) = 1/π with all bounces. Light subpaths
/// bounce inside and every vertex is diffuse: unbiased, within 5 standard
/// errors (pixel spread at 64 spp) + 0.3%.
#[test]
fn lighttrace_lambertian_sphere_with_a_point_light_inside() {
    let film = render_str(POINT_IN_SPHERE, &method("lighttrace", 64, 1));
    let (mean, se) = mean_and_stderr(&film, 1);
    let want = 1.0 / std::f64::consts::PI;
    eprintln!("point light in sphere, lighttrace: Y = {mean:.5} ± {se:.5}, want {want:.5}");
    assert!((mean - want).abs() < 5.0 * se + 3e-3 * want, "Y = {mean} ± {se}, want {want}");
}

/// Emitting mirror enclosure (ρ 0.5, L_e 1): the camera sees the emission
/// (the `s = 1` connection of a point on the light) but none of its mirror
/// reflections: L_e = 1 instead of L_e / (1 − ρ) = 2. Within 5 s.e. + 1%.
#[test]
fn lighttrace_sees_no_mirror_reflections() {
    let film = render_str(&mirror_enclosure(0.5), &method("lighttrace", 256, 2));
    let (mean, se) = mean_and_stderr(&film, 1);
    eprintln!("mirror furnace ρ 0.5, lighttrace: Y = {mean:.5} ± {se:.5}, want 1 (emission only)");
    assert!((mean - 1.0).abs() < 5.0 * se + 0.01, "Y = {mean} ± {se}");
}

/// Camera inside glass (n 1.5) in the uniform enclosure: everything the
/// camera sees is through glass, so light tracing gives exactly 0 (right:
/// n² L = 2.25), and no NaN.
#[test]
fn lighttrace_sees_nothing_through_glass() {
    let film = render_str(&camera_in_glass(), &method("lighttrace", 16, 3));
    assert!(y(&film).iter().all(|&v| v == 0.0), "light tracing cannot connect through smooth glass");
}

/// Grazing view of a diffuse plane under a uniform sky of radius 1000
/// (cosines to 1e-4, a 2° view): light tracing's failure of variance. Light
/// subpaths start anywhere on the huge sky, and almost none lands on the
/// sliver of plane in view: at 256 spp the plane (ρ L = 0.5) is still
/// black, and the sky pixels (L = 1, `s = 1` connections) are a few
/// fireflies. Asserted: no NaN (as everywhere), the sky's mean is 1 within
/// 5 standard errors (unbiased, however noisy), and at most a tenth of the
/// plane's pixels received any light (the mean is no measure here: one light
/// path that lands on the plane is a firefly of the mean's order, and the
/// plane's expected value is 0.5; the sobol sampler's realization has one).
#[test]
fn lighttrace_grazing_view_of_a_diffuse_plane() {
    let v = y(&render_str(&grazing_plane(), &method("lighttrace", 256, 16)));
    let (plane, se) = mean_se(&v[40..]);
    let (sky, se_sky) = mean_se(&v[..32]);
    eprintln!(
        "grazing diffuse, lighttrace: plane Y = {plane:.4} ± {se:.4} (want 0.5), sky {sky:.4} ± {se_sky:.4} (want 1)"
    );
    let lit = v[40..].iter().filter(|&&x| x > 0.0).count();
    assert!(lit * 10 <= v[40..].len(), "plane {plane} ± {se}: {lit} pixels lit");
    assert!((sky - 1.0).abs() < 5.0 * se_sky + 0.02, "sky {sky} ± {se_sky}");
}
