//! The lens system against independent truths: the paraxial focal lengths
//! of every shipped lens from ray-transfer matrices written here, Snell's
//! law at every surface of a traced ray, the reversibility of a trace, and
//! the lens file's errors.

use std::path::{Path, PathBuf};

use super::*;

fn lens_file(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("lenses").join(name)
}

const SHIPPED: [&str; 3] = ["dgauss.50mm.dat", "singlet.50mm.dat", "achromat.100mm.dat"];

/// The paraxial effective focal length and back focal distance from the
/// lens file's rows `(radius, thickness, index)` (index 0 is air, radius 0 a
/// stop), by 2x2 ray-transfer matrices on `(y, n u)` (reduced angles):
/// refraction `[[1, 0], [-(n' - n) / R, 1]]`, transfer `[[1, t / n'], [0, 1]]`.
/// The system matrix from the front vertex to the rear vertex is `[[A, B],
/// [C, D]]`; a ray parallel to the axis, `(1, 0)`, leaves at `(A, C)`, so
/// `EFL = −1/C` and `BFD = −A/C` (air behind the lens).
fn transfer_matrix_focal_lengths(rows: &[(f64, f64, f64)]) -> (f64, f64) {
    let mul = |a: [[f64; 2]; 2], b: [[f64; 2]; 2]| {
        [
            [a[0][0] * b[0][0] + a[0][1] * b[1][0], a[0][0] * b[0][1] + a[0][1] * b[1][1]],
            [a[1][0] * b[0][0] + a[1][1] * b[1][0], a[1][0] * b[0][1] + a[1][1] * b[1][1]],
        ]
    };
    let mut m = [[1.0, 0.0], [0.0, 1.0]];
    let mut n = 1.0;
    for (i, &(radius, thickness, index)) in rows.iter().enumerate() {
        let n2 = if index == 0.0 { 1.0 } else { index };
        let power = if radius == 0.0 { 0.0 } else { (n2 - n) / radius };
        m = mul([[1.0, 0.0], [-power, 1.0]], m);
        if i + 1 < rows.len() {
            m = mul([[1.0, thickness / n2], [0.0, 1.0]], m);
        }
        n = n2;
    }
    let (a, c) = (m[0][0], m[1][0]);
    (-1.0 / c, -a / c)
}

/// The rows of a lens file, read here without the parser under test.
fn rows(name: &str) -> Vec<(f64, f64, f64)> {
    std::fs::read_to_string(lens_file(name))
        .unwrap()
        .lines()
        .map(|l| l.split('#').next().unwrap().trim())
        .filter(|l| !l.is_empty())
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            (v[0], v[1], v[2])
        })
        .collect()
}

/// Every shipped lens loads, and its effective focal length and back focal
/// distance, from rays traced near the axis, match the ray-transfer-matrix
/// computation within 1e-5 relative (the trace's height is 1e-4 of the
/// aperture: its aberrations are of order 1e-8).
#[test]
fn shipped_lenses_have_the_paraxial_focal_lengths_of_their_transfer_matrices() {
    for name in SHIPPED {
        let lens = LensSystem::load(&lens_file(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        let (efl, bfd) = transfer_matrix_focal_lengths(&rows(name));
        let (got_efl, got_bfd) = (lens.effective_focal_length().unwrap(), lens.back_focal_distance().unwrap());
        eprintln!("{name}: EFL {got_efl:.4} mm (matrices {efl:.4}), BFD {got_bfd:.4} mm (matrices {bfd:.4})");
        assert!((got_efl / efl - 1.0).abs() < 1e-5, "{name}: EFL {got_efl} vs {efl}");
        assert!((got_bfd / bfd - 1.0).abs() < 1e-5, "{name}: BFD {got_bfd} vs {bfd}");
    }
    // The designs' nominal focal lengths, loosely (they are thin-lens designs or scaled).
    let efl = |name| LensSystem::load(&lens_file(name)).unwrap().effective_focal_length().unwrap();
    assert!((efl("dgauss.50mm.dat") - 50.0).abs() < 2.0);
    assert!((efl("singlet.50mm.dat") - 50.0).abs() < 2.0);
    assert!((efl("achromat.100mm.dat") - 100.0).abs() < 4.0);
}

/// A ray traced through the double Gauss obeys Snell's law at every surface
/// (checked here with the sines of the angles, not the vector form the
/// tracer uses), and the ray leaving the lens traced back from the film side
/// returns to where it entered, reversed.
#[test]
fn traced_rays_obey_snell_and_retrace_their_way_back() {
    let lens = LensSystem::load(&lens_file("dgauss.50mm.dat")).unwrap();
    let start = LensRay { origin: DVec3::new(3.0, -2.0, -20.0), dir: DVec3::new(-0.05, 0.08, 1.0).normalize() };
    // Snell surface by surface, on prefixes of the system.
    let mut r = start;
    let mut n1 = 1.0;
    for k in 0..lens.surfaces.len() {
        let prefix = LensSystem { surfaces: lens.surfaces[..=k].to_vec() };
        let out = prefix.trace_from_scene(start).expect("the ray passes");
        let s = lens.surfaces[k];
        if !s.is_stop() {
            let centre = DVec3::new(0.0, 0.0, prefix.vertices()[k] + s.radius);
            let normal = (out.origin - centre).normalize();
            let sin = |d: DVec3| d.normalize().cross(normal).length();
            let (sin_i, sin_t) = (sin(r.dir), sin(out.dir));
            assert!((n1 * sin_i - s.index * sin_t).abs() < 1e-12, "surface {k}: {n1} {sin_i} vs {} {sin_t}", s.index);
            // Both directions and the normal lie in one plane.
            assert!(r.dir.cross(normal).normalize().dot(out.dir).abs() < 1e-9, "surface {k}: out of the plane");
        }
        r = out;
        n1 = s.index;
    }
    let back =
        lens.trace_from_film(LensRay { origin: r.origin + r.dir * 5.0, dir: -r.dir }).expect("the reversed ray passes");
    let d = back.dir.normalize();
    assert!((d + start.dir).length() < 1e-9, "{d} vs {}", -start.dir);
    // On the line of the entering ray.
    assert!((back.origin - start.origin).cross(start.dir).length() < 1e-9);
    // A ray beyond the front aperture (radius 12.6) is blocked.
    assert!(lens.trace_from_scene(LensRay { origin: DVec3::new(0.0, 13.0, -5.0), dir: DVec3::Z }).is_none());
    // So is one outside a stop of radius 1 behind a lens of radius 4 (it
    // reaches the stop at a height of about 1.9), not one near the axis.
    let stopped = LensSystem::parse("10 2 1.5 8\n0 1 0 2\n-10 0 1 8\n", Path::new("x.dat")).unwrap();
    let parallel = |y: f64| LensRay { origin: DVec3::new(0.0, y, -1.0), dir: DVec3::Z };
    assert!(stopped.trace_from_scene(parallel(2.0)).is_none());
    assert!(stopped.trace_from_scene(parallel(0.5)).is_some());
}

fn parse_err(text: &str) -> String {
    LensSystem::parse(text, Path::new("lenses/bad.dat")).expect_err(text).to_string()
}

/// Hostile lens files: each mistake is one error naming the file, the line
/// and the column, and what was expected.
#[test]
fn lens_file_errors_name_the_file_line_and_column() {
    let cases = [
        ("# a lens\n10 2 1.5 8\n-10 0 1\n", "bad.dat:3:8", "aperture is missing"),
        ("10 2 1.5 8 9\n", "bad.dat:1:12", "found 5"),
        ("10 2 1.5 -8\n", "bad.dat:1:10", "aperture diameter must be positive"),
        ("10 2 NaN 8\n", "bad.dat:1:6", "finite number"),
        ("10 2 1.5 8\n-10 inf 1 8\n", "bad.dat:2:5", "finite number"),
        ("10 2 1.5 8\n-10 0 1 8x\n", "bad.dat:2:9", "finite number"),
        ("10 -2 1.5 8\n", "bad.dat:1:4", "must not be negative"),
        ("10 2 0.5 8\n", "bad.dat:1:6", "index must be 1 or more"),
        ("0 2 1.5 8\n", "bad.dat:1:5", "aperture stop"),
        ("3 2 1.5 8\n", "bad.dat:1:1", "cannot span"),
        // A biconvex lens 0.5 mm thick at the axis: its surfaces cross at height 1.3.
        ("10 0.5 1.5 8\n-10 0 1 8\n", "bad.dat:1:4", "cross inside their apertures"),
        ("# nothing\n\n", "bad.dat:1:1", "at least one surface"),
    ];
    for (text, at, what) in cases {
        let e = parse_err(text);
        assert!(e.contains(at) && e.contains(what), "{text:?}: {e}");
        assert_eq!(e.lines().count(), 1, "{e}");
    }
    // Comments, tabs and blank lines are fine; index 0 is air.
    let lens =
        LensSystem::parse("# r t n a\n\n10\t2 1.5 8   # front\n0 1 0 6\n-10 0 1 8\n", Path::new("x.dat")).unwrap();
    assert_eq!(lens.surfaces.len(), 3);
    assert_eq!(lens.surfaces[1].index, 1.0);
    assert_eq!(lens.vertices(), vec![0.0, 2.0, 3.0]);
}
