//! pbrt-v4 files not written for rust-v: the scenes of the comparison against pbrt-v4
//! itself (`tests/data/pbrt/peer/`, docs/accuracy.md "Against pbrt-v4"), and real files
//! of the public pbrt-v4-scenes collection when a copy is present (see
//! tests/data/pbrt/README.md: their licences do not let them be kept here). Each loads
//! with exactly the warnings listed and renders a tiny image with no NaN and some light.

use std::path::{Path, PathBuf};

use rust_v::scene::load_scene_with_warnings;
use rust_v::settings::SettingsPatch;

use crate::common::{root, temp_dir};
use crate::pbrt::film_of;

fn tiny() -> SettingsPatch {
    SettingsPatch { width: Some(16), height: Some(16), spp: Some(1), ..Default::default() }
}

/// Loads `path` (not strict), checks its warnings are exactly `expected` (each given as
/// `LINE:COL: start of the message`, after the file's path), renders it at 16x16, 1 spp,
/// and returns the image's summed luminance.
fn load_and_render(path: &Path, expected: &[&str]) -> f64 {
    let (scene, warnings) =
        load_scene_with_warnings(path, &tiny(), false).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let file = path.file_name().unwrap().to_str().unwrap();
    assert_eq!(warnings.len(), expected.len(), "{}: {warnings:#?}", path.display());
    for (w, want) in warnings.iter().zip(expected) {
        let tail = format!("{file}:{want}");
        assert!(w.contains(&tail), "{}: expected a warning containing {tail:?}, got {w:?}", path.display());
    }
    let film = film_of(&scene);
    let y: f64 = film.mean_xyz().iter().map(|p| p[1]).sum();
    assert!(y.is_finite() && y > 0.0, "{}: summed luminance {y}", path.display());
    y
}

#[test]
fn the_peer_scenes_load_with_only_the_expected_warnings_and_render() {
    let dir = root().join("tests/data/pbrt/peer");
    let coated = "27:14: coateddiffuse is rendered as Plastic";
    for (name, expected) in
        [("glass", &[][..]), ("gold", &[]), ("coated", &[coated]), ("envlight", &[]), ("medium", &[])]
    {
        load_and_render(&dir.join(format!("{name}.pbrt")), expected);
    }
    // Everything but coateddiffuse is understood: --strict accepts them.
    for name in ["glass", "gold", "envlight", "medium"] {
        let p = dir.join(format!("{name}.pbrt"));
        load_scene_with_warnings(&p, &tiny(), true).unwrap_or_else(|e| panic!("{name}: {e}"));
    }
}

/// The copy of pbrt-v4-scenes: `$RUST_V_PBRT_SCENES`, else `../shared/pbrt-v4-scenes`.
fn real_scenes() -> Option<PathBuf> {
    let dir = match std::env::var_os("RUST_V_PBRT_SCENES") {
        Some(d) => PathBuf::from(d),
        None => root().join("../shared/pbrt-v4-scenes"),
    };
    dir.is_dir().then_some(dir)
}

/// A file of the copy, checked to be the version tests/data/pbrt/README.md lists (its
/// length in bytes), or None (with a note) when absent.
fn real_file(dir: &Path, rel: &str, len: u64) -> Option<PathBuf> {
    let p = dir.join(rel);
    let Ok(meta) = std::fs::metadata(&p) else {
        eprintln!("skipped: {} is absent (see tests/data/pbrt/README.md)", p.display());
        return None;
    };
    assert_eq!(meta.len(), len, "{}: not the version tests/data/pbrt/README.md lists", p.display());
    Some(p)
}

#[test]
fn killeroo_simple_and_moving_load_with_only_the_expected_warnings_and_render() {
    let Some(dir) = real_scenes() else {
        eprintln!("skipped: no copy of pbrt-v4-scenes (set RUST_V_PBRT_SCENES; see tests/data/pbrt/README.md)");
        return;
    };
    if real_file(&dir, "killeroos/geometry/killeroo.pbrt", 286_606).is_none() {
        return;
    }
    let film_name = "11:5: Film \"filename\" is ignored";
    let coated = "51:14: coateddiffuse is rendered as Plastic";
    if let Some(p) = real_file(&dir, "killeroos/killeroo-simple.pbrt", 1587) {
        load_and_render(&p, &[film_name, coated]);
    }
    if let Some(p) = real_file(&dir, "killeroos/killeroo-moving.pbrt", 1815) {
        let motion = "55:21: ActiveTransform StartTime/EndTime: motion blur is not supported";
        load_and_render(&p, &[film_name, coated, motion]);
    }
}

#[test]
fn clouds_loads_with_only_the_expected_warnings_and_renders_under_a_stand_in_sky() {
    let Some(dir) = real_scenes() else {
        eprintln!("skipped: no copy of pbrt-v4-scenes (set RUST_V_PBRT_SCENES; see tests/data/pbrt/README.md)");
        return;
    };
    let Some(src) = real_file(&dir, "clouds/clouds.pbrt", 610) else {
        return;
    };
    // Its sky map (textures/sky.exr) is binary and not part of the copy: a uniform 8x8
    // equal-area map of 0.5 stands in for it, beside an unchanged copy of the file.
    let d = temp_dir("pbrt-real-clouds");
    std::fs::copy(&src, d.join("clouds.pbrt")).unwrap();
    std::fs::create_dir_all(d.join("textures")).unwrap();
    let data = vec![0.5f32; 8 * 8 * 3];
    image::Rgb32FImage::from_raw(8, 8, data).unwrap().save(d.join("textures/sky.exr")).unwrap();
    load_and_render(
        &d.join("clouds.pbrt"),
        &[
            "12:3: Film \"filename\" is ignored",
            "10:3: Film \"sensor\" \"nikon_d850\" is not supported",
            "11:3: Film \"whitebalance\" is not supported",
            "21:21: MakeNamedMedium \"c\": medium \"cloud\" is not supported",
        ],
    );
}
