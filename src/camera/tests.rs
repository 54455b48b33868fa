//! The camera's tests: the pinhole against the canonical scene, and the thin
//! lens against its geometry (focus, blur circle, importance).

use super::*;

/// The canonical scene's camera: the box front edges x = ±1 at z = 1
/// (2.5 from the eye) fall at film coordinate 128 ± 123.6 (SCENE-SPEC §1).
#[test]
fn canonical_camera_matches_the_spec() {
    let cam = Camera::new(Vec3::new(0.0, 1.0, 3.5), Vec3::new(0.0, 1.0, 0.0), Vec3::Y, 45.0, 256, 256);
    let centre = cam.ray(Vec2::new(128.0, 128.0));
    assert!((centre.dir - Vec3::NEG_Z).length() < 1e-6);
    let px = 128.0 + 123.6;
    let r = cam.ray(Vec2::new(px, 128.0));
    let t = 2.5 / -r.dir.z;
    assert!((r.at(t).x - 1.0).abs() < 1e-3, "edge at {}", r.at(t).x);
    // Row 0 is the top of the image.
    assert!(cam.ray(Vec2::new(128.0, 0.0)).dir.y > 0.0);
    assert!(cam.ray(Vec2::new(0.0, 128.0)).dir.x < 0.0);
}

/// `project` inverts `ray` over the film, and refuses directions off it
/// or behind the eye; the direction density integrates to 1 over the
/// film (a midpoint sum over a fine grid of film positions, with the
/// Jacobian dω = cos³θ dA of the image plane at distance 1).
#[test]
fn project_inverts_ray_and_the_density_integrates_to_one() {
    let cam = Camera::new(Vec3::new(0.3, 1.0, 3.0), Vec3::new(0.0, 0.8, 0.0), Vec3::Y, 40.0, 64, 48);
    for (x, y) in [(0.5f32, 0.5f32), (63.9, 0.1), (10.25, 47.75), (32.0, 24.0)] {
        let p = cam.project(cam.ray(Vec2::new(x, y)).dir).unwrap();
        assert!((p - Vec2::new(x, y)).length() < 2e-3, "{x},{y} -> {p}");
    }
    assert!(cam.project(-cam.forward()).is_none());
    assert!(cam.project(cam.ray(Vec2::new(-0.5, 3.0)).dir).is_none());
    let n = 400;
    let mut integral = 0.0f64;
    let da = cam.plane_area() as f64 / (n * n) as f64;
    for i in 0..n {
        for j in 0..n {
            let f = Vec2::new((i as f32 + 0.5) * 64.0 / n as f32, (j as f32 + 0.5) * 48.0 / n as f32);
            let d = cam.ray(f).dir;
            let cos = d.dot(cam.forward()) as f64;
            integral += cam.pdf_dir(d) as f64 * cos * cos * cos * da;
        }
    }
    assert!((integral - 1.0).abs() < 1e-4, "{integral}");
}

#[test]
fn non_square_images_keep_the_vertical_fov() {
    let cam = Camera::new(Vec3::ZERO, Vec3::NEG_Z, Vec3::Y, 90.0, 200, 100);
    let top = cam.ray(Vec2::new(100.0, 0.0)).dir;
    assert!((top.y / -top.z - 1.0).abs() < 1e-5);
    let right = cam.ray(Vec2::new(200.0, 50.0)).dir;
    assert!((right.x / -right.z - 2.0).abs() < 1e-5);
}

/// A thin-lens camera looking along an oblique direction (so that no axis is special).
fn lens_camera(radius: f32, focus: f32) -> Camera {
    Camera::new(Vec3::new(0.3, 1.0, 3.0), Vec3::new(-0.2, 0.6, -1.0), Vec3::Y, 40.0, 64, 48)
        .with_thin_lens(radius, focus)
}

/// 8x8 stratified lens samples, corners included (they map to the lens's rim).
fn lens_samples() -> impl Iterator<Item = Vec2> {
    (0..8).flat_map(|i| (0..8).map(move |j| Vec2::new(i as f32 / 7.0, j as f32 / 7.0).min(Vec2::splat(0.999_999))))
}

/// Every ray through one film position, whatever its lens point, passes
/// through the point where the pinhole ray of that position (tested against
/// the canonical scene above) meets the plane in focus; the lens points lie
/// on the lens disk and reach its rim; `project_from` inverts
/// `ray_through`; and a zero radius leaves the pinhole's rays bit for bit.
#[test]
fn thin_lens_rays_of_a_film_point_meet_on_the_plane_in_focus() {
    let (radius, focus) = (0.2, 2.5);
    let cam = lens_camera(radius, focus);
    let lens = cam.lens().expect("a lens");
    assert_eq!(lens, ThinLens { radius, focus });
    let mut rim = 0.0f32;
    for f in [Vec2::new(0.5, 0.5), Vec2::new(32.0, 24.0), Vec2::new(63.5, 10.25), Vec2::new(7.0, 47.9)] {
        let pin = cam.ray(f).dir;
        let want = cam.eye() + pin * (focus / pin.dot(cam.forward()));
        for u in lens_samples() {
            let r = cam.ray_through(f, u);
            let off = r.origin - cam.eye();
            assert!(off.dot(cam.forward()).abs() < 1e-6 && off.length() <= radius * (1.0 + 1e-5), "{off}");
            rim = rim.max(off.length());
            let at = r.at(focus / r.dir.dot(cam.forward()));
            assert!((at - want).length() < 2e-6 * focus, "{f} {u}: {at} vs {want}");
            let back = cam.project_from(r.origin, r.dir).expect("on the film");
            assert!((back - f).length() < 2e-3, "{f} {u}: back to {back}");
            assert!(cam.pdf_dir_from(r.origin, r.dir) > 0.0);
        }
    }
    assert!(rim > radius * 0.999, "the samples reach the rim: {rim}");
    // Off the film, or behind the lens.
    let r = cam.ray_through(Vec2::new(32.0, 24.0), Vec2::new(0.1, 0.9));
    assert!(cam.project_from(r.origin, -r.dir).is_none());
    assert_eq!(cam.pdf_dir_from(r.origin, -r.dir), 0.0);
    let pinhole = Camera::new(Vec3::new(0.3, 1.0, 3.0), Vec3::new(-0.2, 0.6, -1.0), Vec3::Y, 40.0, 64, 48);
    let zero = pinhole.clone().with_thin_lens(0.0, 2.5);
    assert!(!zero.has_lens() && zero.lens_point(Vec2::new(0.9, 0.1)) == zero.eye());
    for f in [Vec2::new(0.5, 0.5), Vec2::new(33.3, 11.1)] {
        let (a, b) = (pinhole.ray(f), zero.ray_through(f, Vec2::new(0.9, 0.1)));
        assert!(a.origin == b.origin && a.dir == b.dir);
        assert_eq!(pinhole.project(a.dir), zero.project_from(a.origin, a.dir));
        assert_eq!(pinhole.pdf_dir(a.dir).to_bits(), zero.pdf_dir_from(a.origin, a.dir).to_bits());
    }
}

/// Out of focus, a point is seen through the lens's rim on a circle whose
/// diameter on the plane in focus is the circle of confusion `c = A |d − F| / d`
/// (`A = 2R` the aperture's diameter: similar triangles through the point),
/// `c · H / (2 F tan(fov/2))` pixels on the film: computed here from the
/// field of view, for points in front of and behind the plane in focus, on
/// and off the axis; within 1e-2 px (the geometry is exact: the bound is
/// rounding). A point on the plane in focus is seen at one film position
/// from every lens point.
#[test]
fn out_of_focus_points_blur_to_the_thin_lens_circle_of_confusion() {
    let (radius, focus) = (0.15, 3.0);
    let cam = lens_camera(radius, focus);
    let px_per_unit = 48.0 / (2.0 * focus as f64 * (20.0f64).to_radians().tan());
    let rim: Vec<Vec2> = (0..256)
        .map(|k| {
            // The boundary of the unit square maps to the rim of the disk.
            let t = k as f32 / 64.0;
            match k / 64 {
                0 => Vec2::new(t, 0.0),
                1 => Vec2::new(0.999_999, t - 1.0),
                2 => Vec2::new(3.0 - t, 0.999_999),
                _ => Vec2::new(0.0, 4.0 - t),
            }
        })
        .collect();
    for (depth, across, up) in
        [(1.5f32, 0.0f32, 0.0f32), (2.2, 0.3, -0.2), (4.5, -0.5, 0.4), (8.0, 1.0, 0.6), (3.0, 0.4, 0.1)]
    {
        let p = cam.eye() + cam.forward() * depth + cam.right * across + cam.up * up;
        let seen: Vec<Vec2> = rim
            .iter()
            .map(|&u| {
                let o = cam.lens_point(u);
                cam.project_from(o, (p - o).normalize()).expect("in view")
            })
            .collect();
        let diameter = seen.iter().flat_map(|a| seen.iter().map(move |b| (*a - *b).length())).fold(0.0f32, f32::max);
        let c = 2.0 * radius as f64 * (depth as f64 - focus as f64).abs() / depth as f64;
        let want = c * px_per_unit;
        eprintln!("depth {depth}: blur circle {diameter:.4} px, thin-lens formula {want:.4} px");
        assert!((diameter as f64 - want).abs() < 1e-2, "depth {depth}: {diameter} px vs {want} px");
    }
}

/// The camera's importance over the density of a connection (what a light
/// subpath's vertex adds to the film, `Camera::importance`) integrates to 1
/// over a plane that fills the view, for each lens point: a plane of unit
/// radiance makes every pixel 1, so the film's mean is 1 (pbrt-v4's
/// `PerspectiveCamera` importance test checks the same). The plane at depth 5
/// is perpendicular to the view direction (its cosine is the camera's);
/// midpoint sums over 800x800 cells with 16 lens points, within 2e-3 (the
/// film's edge cut through cells). The pinhole's integral is the same.
#[test]
fn importance_integrates_to_one_over_a_plane_filling_the_view() {
    for (radius, focus) in [(0.4f32, 2.0f32), (0.0, 1.0)] {
        let cam = lens_camera(radius, focus);
        let depth = 5.0f32;
        // Half-extents covering the view from every lens point.
        let (hx, hy) = (depth * 0.5 * 1.1 + radius * 3.0, depth * 0.37 + radius * 3.0);
        let n = 800;
        let (dx, dy) = (2.0 * hx / n as f32, 2.0 * hy / n as f32);
        let mut total = 0.0f64;
        let lens: Vec<Vec2> = (0..16).map(|k| Vec2::new((k % 4) as f32 + 0.5, (k / 4) as f32 + 0.5) / 4.0).collect();
        for &u in &lens {
            let o = cam.lens_point(u);
            let mut sum = 0.0f64;
            for i in 0..n {
                for j in 0..n {
                    let (x, y) = (-hx + (i as f32 + 0.5) * dx, -hy + (j as f32 + 0.5) * dy);
                    let p = cam.eye() + cam.forward() * depth + cam.right * x + cam.up * y;
                    let d = p - o;
                    let d2 = d.length_squared();
                    let dir = d / d2.sqrt();
                    if let Some((_, w)) = cam.importance(o, dir, d2) {
                        sum += w as f64 * dir.dot(cam.forward()) as f64;
                    }
                }
            }
            total += sum * (dx * dy) as f64 / lens.len() as f64;
        }
        eprintln!("radius {radius}: importance integral {total:.5}");
        assert!((total - 1.0).abs() < 2e-3, "radius {radius}: {total}");
    }
}
