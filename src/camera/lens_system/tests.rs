//! The lens system against independent truths: the paraxial focal lengths
//! of every shipped lens from ray-transfer matrices written here, the
//! longitudinal chromatic focal shift from the same matrices with Sellmeier
//! indices written here (SCHOTT's catalogue), Snell's law at every surface
//! of a traced ray, the reversibility of a trace, and the lens file's errors.

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

/// The Sellmeier index at `nm` of N-BK7 and F2, from SCHOTT's data sheets
/// (typed here, not read from the renderer's table): `n² − 1 = Σ Bᵢλ²/(λ² − Cᵢ)`, λ in µm.
fn sellmeier(glass: &str, nm: f64) -> f64 {
    let (b, c) = match glass {
        "N-BK7" => ([1.03961212, 0.231792344, 1.01046945], [0.00600069867, 0.0200179144, 103.560653]),
        "F2" => ([1.34533359, 0.209073176, 0.937357162], [0.00997743871, 0.0470450767, 111.886764]),
        other => panic!("no Sellmeier data here for {other}"),
    };
    let l2 = (nm * 1e-3).powi(2);
    (1.0 + (0..3).map(|i| b[i] * l2 / (l2 - c[i])).sum::<f64>()).sqrt()
}

/// The rows `(radius, thickness, index)` of a lens file, read here without
/// the parser under test; with `nm`, a row naming a glass takes its
/// Sellmeier index there instead of the index column.
fn rows(name: &str, nm: Option<f64>) -> Vec<(f64, f64, f64)> {
    std::fs::read_to_string(lens_file(name))
        .unwrap()
        .lines()
        .map(|l| l.split('#').next().unwrap().trim())
        .filter(|l| !l.is_empty())
        .map(|l| {
            let f: Vec<&str> = l.split_whitespace().collect();
            let v: Vec<f64> = f[..4].iter().map(|x| x.parse().unwrap()).collect();
            let index = match (f.get(4), nm) {
                (Some(glass), Some(nm)) => sellmeier(glass, nm),
                _ => v[2],
            };
            (v[0], v[1], index)
        })
        .collect()
}

/// Every shipped lens loads, and its effective focal length and back focal
/// distance at the d line, from rays traced near the axis, match the
/// ray-transfer-matrix computation within 1e-5 relative (the index columns,
/// or for a row naming a glass its Sellmeier index at the d line; the
/// trace's height is 1e-4 of the aperture: its aberrations are of order 1e-8).
#[test]
fn shipped_lenses_have_the_paraxial_focal_lengths_of_their_transfer_matrices() {
    for name in SHIPPED {
        let lens = LensSystem::load(&lens_file(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        let (efl, bfd) = transfer_matrix_focal_lengths(&rows(name, Some(D_LINE_NM as f64)));
        let d = D_LINE_NM;
        let (got_efl, got_bfd) = (lens.effective_focal_length(d).unwrap(), lens.back_focal_distance(d).unwrap());
        eprintln!("{name}: EFL {got_efl:.4} mm (matrices {efl:.4}), BFD {got_bfd:.4} mm (matrices {bfd:.4})");
        assert!((got_efl / efl - 1.0).abs() < 1e-5, "{name}: EFL {got_efl} vs {efl}");
        assert!((got_bfd / bfd - 1.0).abs() < 1e-5, "{name}: BFD {got_bfd} vs {bfd}");
    }
    // The designs' nominal focal lengths, loosely (they are thin-lens designs or scaled).
    let efl = |name| LensSystem::load(&lens_file(name)).unwrap().effective_focal_length(D_LINE_NM).unwrap();
    assert!((efl("dgauss.50mm.dat") - 50.0).abs() < 2.0);
    assert!((efl("singlet.50mm.dat") - 50.0).abs() < 2.0);
    assert!((efl("achromat.100mm.dat") - 100.0).abs() < 4.0);
}

/// The singlet's back focal distance moves with the wavelength as the
/// transfer matrices with N-BK7's Sellmeier index say: at 450, 550 and
/// 650 nm within 1e-5 relative, and the shift from 450 to 650 nm within
/// 1e-4 mm; the achromat's shift over the same range, relative to its focal
/// length, is less than a fifth of the singlet's. A lens without a glass
/// column focuses every wavelength alike. Measured: the singlet −1.028 mm
/// (−2.03% of its focal length: blue focuses nearer), the achromat −0.048 mm
/// (−0.049%, 41 times less).
#[test]
fn chromatic_focal_shift_of_the_singlet_and_the_achromat() {
    let shift = |name: &str| {
        let lens = LensSystem::load(&lens_file(name)).unwrap();
        assert!(lens.is_dispersive(), "{name}");
        let mut at = Vec::new();
        for nm in [450.0, 550.0, 650.0] {
            let (_, want) = transfer_matrix_focal_lengths(&rows(name, Some(nm)));
            let got = lens.back_focal_distance(nm as f32).unwrap();
            assert!((got / want - 1.0).abs() < 1e-5, "{name} at {nm} nm: BFD {got} vs {want}");
            at.push((got, want));
        }
        let (got, want) = (at[0].0 - at[2].0, at[0].1 - at[2].1);
        let efl = lens.effective_focal_length(D_LINE_NM).unwrap();
        eprintln!(
            "{name}: BFD(450) − BFD(650) = {got:.5} mm (matrices {want:.5}), {:.5} of the focal length",
            got / efl
        );
        assert!((got - want).abs() < 1e-4, "{name}: shift {got} vs {want}");
        got / efl
    };
    let singlet = shift("singlet.50mm.dat");
    let achromat = shift("achromat.100mm.dat");
    assert!(singlet < 0.0, "blue focuses nearer: {singlet}");
    assert!(achromat.abs() < singlet.abs() / 5.0, "achromat {achromat} vs singlet {singlet}");
    let plain = LensSystem::load(&lens_file("dgauss.50mm.dat")).unwrap();
    assert!(!plain.is_dispersive());
    assert_eq!(plain.back_focal_distance(450.0), plain.back_focal_distance(650.0));
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
        let out = prefix.trace_from_scene(start, D_LINE_NM).expect("the ray passes");
        let s = &lens.surfaces[k];
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
    let back = lens
        .trace_from_film(LensRay { origin: r.origin + r.dir * 5.0, dir: -r.dir }, D_LINE_NM)
        .expect("the reversed ray passes");
    let d = back.dir.normalize();
    assert!((d + start.dir).length() < 1e-9, "{d} vs {}", -start.dir);
    // On the line of the entering ray.
    assert!((back.origin - start.origin).cross(start.dir).length() < 1e-9);
    // A ray beyond the front aperture (radius 12.6) is blocked.
    assert!(lens.trace_from_scene(LensRay { origin: DVec3::new(0.0, 13.0, -5.0), dir: DVec3::Z }, D_LINE_NM).is_none());
    // So is one outside a stop of radius 1 behind a lens of radius 4 (it
    // reaches the stop at a height of about 1.9), not one near the axis.
    let stopped = LensSystem::parse("10 2 1.5 8\n0 1 0 2\n-10 0 1 8\n", Path::new("x.dat")).unwrap();
    let parallel = |y: f64| LensRay { origin: DVec3::new(0.0, y, -1.0), dir: DVec3::Z };
    assert!(stopped.trace_from_scene(parallel(2.0), D_LINE_NM).is_none());
    assert!(stopped.trace_from_scene(parallel(0.5), D_LINE_NM).is_some());
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
        ("10 2 1.5 8 N-BK7 9\n", "bad.dat:1:18", "found 6"),
        ("10 2 1.5 8 crown\n", "bad.dat:1:12", "expected a glass name (N-BK7, N-SF11"),
        ("10 2 1.5 8 -30\n", "bad.dat:1:12", "Abbe number must be positive"),
        ("10 2 1.5 8 NaN\n", "bad.dat:1:12", "Abbe number must be positive"),
        ("10 2 1 8 N-BK7\n", "bad.dat:1:10", "after air"),
        ("10 2 1.6 8 N-BK7\n", "bad.dat:1:12", "index at the d line is 1.5168"),
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
    // An Abbe number: Cauchy through n_d with n_F − n_C = (n_d − 1) / V_d.
    let abbe = LensSystem::parse("10 2 1.6 8 40\n-10 0 1 8\n", Path::new("x.dat")).unwrap();
    let s = &abbe.surfaces[0];
    assert!((s.index_at(D_LINE_NM) - 1.6).abs() < 1e-6);
    let dn = s.index_at(486.13) - s.index_at(656.27);
    assert!((dn - 0.6 / 40.0).abs() < 1e-6, "n_F − n_C = {dn}");
    // Comments, tabs and blank lines are fine; index 0 is air.
    let lens =
        LensSystem::parse("# r t n a\n\n10\t2 1.5 8   # front\n0 1 0 6\n-10 0 1 8\n", Path::new("x.dat")).unwrap();
    assert_eq!(lens.surfaces.len(), 3);
    assert_eq!(lens.surfaces[1].index, 1.0);
    assert_eq!(lens.vertices(), vec![0.0, 2.0, 3.0]);
}

/// Focusing places the film where the lens images the plane in focus: a ray
/// from the on-axis point `distance` in front of the film, at a small angle,
/// traced through each shipped lens crosses the axis again on the film
/// (within 1e-5 of the distance; the trace, not the thick-lens formula
/// under test, decides where); at a great distance the film sits at the back
/// focal distance. Too near, or inside the lens, is an error.
#[test]
fn focusing_images_the_plane_in_focus_on_the_film() {
    for name in SHIPPED {
        let lens = LensSystem::load(&lens_file(name)).unwrap();
        let f = lens.effective_focal_length(D_LINE_NM).unwrap();
        for distance in [5.0 * f, 1000.0, 1e5] {
            let focused = lens.focused(distance).unwrap_or_else(|e| panic!("{name} at {distance}: {e}"));
            let film = focused.film_z();
            let object = film - distance;
            let h = lens.surfaces[0].aperture_radius * 1e-4;
            let ray = LensRay { origin: DVec3::new(0.0, 0.0, object), dir: DVec3::new(0.0, h, -object).normalize() };
            let out = focused.trace_from_scene(ray, D_LINE_NM).expect("the ray passes");
            let crossing = out.origin.z - out.origin.y * out.dir.z / out.dir.y;
            assert!(
                (crossing - film).abs() < 1e-5 * distance,
                "{name} at {distance}: image at {crossing}, film at {film}"
            );
        }
        let far = lens.focused(1e9).unwrap();
        let bfd = lens.back_focal_distance(D_LINE_NM).unwrap();
        let last = far.surfaces.last().unwrap().thickness;
        assert!((last - bfd).abs() < 1e-3, "{name}: film {last} mm behind the lens at infinity, BFD {bfd}");
    }
    let dgauss = LensSystem::load(&lens_file("dgauss.50mm.dat")).unwrap();
    let e = dgauss.focused(150.0).unwrap_err();
    assert!(e.contains("nearer than this lens can focus"), "{e}");
    let singlet = LensSystem::load(&lens_file("singlet.50mm.dat")).unwrap();
    // A thin lens cannot bring an object nearer than 4f to a real image.
    assert!(singlet.focused(150.0).unwrap_err().contains("at least 20"));
    let diverging = LensSystem::parse("-20 2 1.5 10\n20 5 1 10\n", Path::new("x.dat")).unwrap();
    assert!(diverging.focused(1000.0).unwrap_err().contains("diverges"));
}
