//! Spectra from anywhere: `Table`, `File`, `Rgb` and `Luminance` in scene files, checked through
//! the loader and the renderer against closed forms.

use std::path::Path;

use rust_v::bxdf::Bxdf;
use rust_v::color::{Spectrum, bin_lambda_nm};
use rust_v::scene::load_scene_str;

use crate::common::{render_str, temp_dir};

/// A scene whose camera sees only the inside of a huge emitting disk (one-sided, facing it):
/// every camera ray hits it, so with `max_bounces: 0` every pixel is exactly its radiance.
fn emitter_scene(emission: &str) -> String {
    format!(
        r#"(
        camera: (eye: (0, 0, 0), look_at: (0, 0, -1), fov_deg: 30),
        render: (width: 4, height: 4, spp: 1, max_bounces: 0),
        objects: [ (shape: Disk(center: (0, 0, -1), normal: (0, 0, 1), radius: 100), emission: {emission}) ],
    )"#
    )
}

/// The linear sRGB every pixel of `emitter_scene(emission)` renders, after checking all agree.
fn seen_rgb(emission: &str) -> [f64; 3] {
    let film = render_str(&emitter_scene(emission), &Default::default());
    let px = film.linear_srgb();
    for p in &px {
        assert_eq!(*p, px[0], "every pixel sees the same radiance");
    }
    px[0]
}

/// An `Rgb(r, g, b)` emitter seen directly renders (r, g, b) within 2e-3 of its brightest
/// channel (the issue's bound: the fit's residual plus f32 sums).
#[test]
fn rgb_emitter_renders_its_colour() {
    for rgb in [[1.0, 1.0, 1.0], [0.8, 0.3, 0.1], [4.0, 3.0, 2.0], [0.05, 0.2, 0.9]] {
        let got = seen_rgb(&format!("Rgb({}, {}, {})", rgb[0], rgb[1], rgb[2]));
        let m = rgb.iter().cloned().fold(0.0, f64::max);
        for (g, w) in got.iter().zip(rgb) {
            assert!((g - w).abs() < 2e-3 * m, "Rgb{rgb:?} renders {got:?}");
        }
    }
}

/// `Luminance(y, s)` renders luminance y for any shape of spectrum (Y of linear sRGB is the
/// XYZ Y): a blackbody and D65 scaled to Y = 2.5.
#[test]
fn luminance_sets_y() {
    for inner in ["Blackbody(3000)", "D65", "Table([(400, 1), (700, 0)])"] {
        let film = render_str(&emitter_scene(&format!("Luminance(2.5, {inner})")), &Default::default());
        let y = film.mean_xyz()[0][1];
        assert!((y - 2.5).abs() < 1e-5 * 2.5, "{inner}: Y = {y}");
    }
}

fn reflectance(ron_spectrum: &str, dir: &Path) -> Result<Spectrum, String> {
    let scene = format!(
        r#"(
        camera: (eye: (0, 0, 3), look_at: (0, 0, 0), fov_deg: 30),
        materials: {{ "m": Lambertian(reflectance: {ron_spectrum}) }},
        objects: [ (shape: Sphere(center: (0, 0, 0), radius: 1), material: "m") ],
    )"#
    );
    let s = load_scene_str(&scene, &dir.join("scene.ron"), &Default::default()).map_err(|e| e.to_string())?;
    match &s.materials[1] {
        Bxdf::Lambertian(l) => Ok(l.reflectance),
        _ => unreachable!("the only material is Lambertian"),
    }
}

/// `Table` and `File` give the same spectrum as the same points, linear between them and flat
/// beyond; `Rgb(1, 1, 1)` is exactly 1; `Rgb` reflectances stay in [0, 1].
#[test]
fn table_file_and_rgb_reflectances() {
    let dir = temp_dir("spectra-table");
    std::fs::create_dir_all(dir.join("data")).unwrap();
    std::fs::write(dir.join("data/r.csv"), "wavelength_nm,reflectance\n400,0.1\n550, 0.8\n# note\n700,0.3\n").unwrap();
    let t = reflectance("Table([(400, 0.1), (550, 0.8), (700, 0.3)])", &dir).unwrap();
    let f = reflectance(r#"File("data/r.csv")"#, &dir).unwrap();
    assert_eq!(t, f);
    for b in 0..36 {
        let l = bin_lambda_nm(b);
        let want = if l <= 400.0 {
            0.1
        } else if l <= 550.0 {
            0.1 + 0.7 * (l - 400.0) / 150.0
        } else if l <= 700.0 {
            0.8 - 0.5 * (l - 550.0) / 150.0
        } else {
            0.3
        };
        assert!((t[b] - want).abs() < 1e-6, "{l} nm: {} vs {want}", t[b]);
    }
    assert_eq!(reflectance("Rgb(1, 1, 1)", &dir).unwrap(), Spectrum::ONE);
    let red = reflectance("Rgb(0.9, 0.05, 0.02)", &dir).unwrap();
    assert!(red.min_value() >= 0.0 && red.max_value() <= 1.0);
    assert!(red[30] > 0.5 && red[5] < 0.1, "a red reflectance: {red:?}");
}

/// Bad input names the file and what was expected: the CSV's own path and line for a bad
/// row, the scene's field path for a bad table or colour.
#[test]
fn bad_spectra_are_errors_naming_where() {
    let dir = temp_dir("spectra-errors");
    std::fs::write(dir.join("bad.csv"), "nm,value\n400,0.1\n410,oops\n").unwrap();
    let e = reflectance(r#"File("bad.csv")"#, &dir).unwrap_err();
    assert!(e.contains("bad.csv:3:5") && e.contains("oops"), "{e}");
    let e = reflectance(r#"File("missing.csv")"#, &dir).unwrap_err();
    assert!(e.contains("materials.\"m\".reflectance") && e.contains("missing.csv"), "{e}");
    let e = reflectance("Table([(500, 0.1), (400, 0.2)])", &dir).unwrap_err();
    assert!(e.contains("reflectance[1]") && e.contains("increase"), "{e}");
    let e = reflectance("Table([])", &dir).unwrap_err();
    assert!(e.contains("at least one"), "{e}");
    let e = reflectance("Table([(400, 1.5)])", &dir).unwrap_err();
    assert!(e.contains("[0, 1]"), "{e}");
    let e = reflectance("Rgb(1.2, 0, 0)", &dir).unwrap_err();
    assert!(e.contains("[0, 1]"), "{e}");
    let e = reflectance("Rgb(-0.1, 0, 0)", &dir).unwrap_err();
    assert!(e.contains("linear sRGB"), "{e}");
}

/// Paths after a dispersive split carry any wavelength in 360-830 nm, so an index of refraction
/// must be finite and positive on all of it: a Sellmeier term whose pole (√C µm) lies at 780 nm,
/// beyond the last bin but inside the range, is refused with the field and the pole named; a
/// Cauchy index that reaches 0 at 770 nm (positive at every bin) is refused with the first
/// wavelength where it is not positive; N-SF11 loads.
#[test]
fn an_index_with_a_pole_or_a_zero_in_the_visible_range_is_refused() {
    let scene = |ior: &str| {
        format!(
            r#"(
            camera: (eye: (0, 0, 3), look_at: (0, 0, 0), fov_deg: 30),
            materials: {{ "g": Dielectric(ior: {ior}) }},
            objects: [ (shape: Sphere(center: (0, 0, 0), radius: 1), material: "g") ],
        )"#
        )
    };
    let err =
        |ior: &str| load_scene_str(&scene(ior), Path::new("ior.ron"), &Default::default()).err().map(|e| e.to_string());
    let pole = err("Sellmeier(b: (1.0, 0.2, 0.9), c: (0.6084, 0.06, 100.0))").expect("a pole at 780 nm is refused");
    assert!(pole.contains("ior.ron") && pole.contains("780.0 nm") && pole.contains("materials"), "{pole}");
    let zero = err("Cauchy(a: -1.0, b: 0.5929)").expect("a negative index is refused");
    assert!(zero.contains("770 nm") && zero.contains("positive"), "{zero}");
    assert_eq!(err("Named(\"N-SF11\")"), None);
}
