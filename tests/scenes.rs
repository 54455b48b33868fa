//! Every scene file in `scenes/` loads and renders; renders are bit-identical
//! whatever the thread count.

use crate::common::{root, rust_v, temp_dir};

fn scene_files() -> Vec<std::path::PathBuf> {
    let mut v: Vec<_> = std::fs::read_dir(root().join("scenes"))
        .expect("scenes/ exists")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .collect();
    v.sort();
    v
}

#[test]
fn every_scene_renders_at_16x16() {
    let dir = temp_dir("scenes");
    let files = scene_files();
    assert!(files.len() >= 2, "expected scene files, found {files:?}");
    for scene in files {
        let out = dir.join(format!("{}.png", scene.file_stem().unwrap().to_string_lossy()));
        let o = rust_v(&[
            "render",
            scene.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--width",
            "16",
            "--height",
            "16",
            "--spp",
            "2",
            "--quiet",
        ]);
        assert!(o.status.success(), "{}: {}", scene.display(), String::from_utf8_lossy(&o.stderr));
        let img = image::open(&out).expect("output is a PNG");
        assert_eq!((img.width(), img.height()), (16, 16));
        assert!(matches!(img, image::DynamicImage::ImageRgb16(_)), "16-bit RGB PNG");
        // Something in every scene is lit, except the prism, whose only light
        // is 0.07 degrees across: at 16x16 no pixel is likely to see it.
        let lit_exempt = scene.ends_with("prism.ron");
        assert!(
            lit_exempt || img.to_rgb16().pixels().any(|p| p.0.iter().any(|&c| c > 0)),
            "{} is black",
            scene.display()
        );
    }
}

#[test]
fn render_is_bit_identical_for_any_thread_count() {
    let dir = temp_dir("threads");
    let mut outputs = Vec::new();
    for threads in ["1", "2", "3"] {
        let out = dir.join(format!("t{threads}.exr"));
        let o = rust_v(&[
            "render",
            "scenes/cornell.ron",
            "-o",
            out.to_str().unwrap(),
            "--width",
            "32",
            "--height",
            "32",
            "--spp",
            "4",
            "--threads",
            threads,
            "--quiet",
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        outputs.push(std::fs::read(&out).unwrap());
    }
    assert_eq!(outputs[0], outputs[1], "1 vs 2 threads");
    assert_eq!(outputs[0], outputs[2], "1 vs 3 threads");
}

/// The scene-format example in the README parses and loads (it uses every
/// shape, material, spectrum and IOR form), so the documentation stays true.
#[test]
fn readme_scene_example_loads() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let start = readme.find("```ron\n").expect("README has a ```ron block") + "```ron\n".len();
    let end = start + readme[start..].find("```").unwrap();
    let example = &readme[start..end];
    // Paths in the example are relative to a scene in scenes/.
    let scene = rust_v::scene::load_scene_str(example, &root().join("scenes/readme-example.ron"), &Default::default())
        .unwrap_or_else(|e| panic!("README example: {e}"));
    assert_eq!(scene.object_count(), 13);
    assert_eq!((scene.objects[7].priority, scene.objects[8].priority), (1, 2), "priorities of the nested glass");
    assert_eq!(
        scene.lights.len(),
        9,
        "disk, sphere, quad, cuboid and mesh emitters; point, spot, distant and beam lights"
    );
    assert!(scene.has_dispersion());
}
