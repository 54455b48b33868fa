//! A small deterministic mutation fuzzer for the scene parser and the mesh loaders.
//!
//! Valid seeds (the scene files in `scenes/`, and small OBJ, ASCII PLY, binary PLY
//! and gzipped files built here) are mutated at random (bit flips, random bytes,
//! inserted RON/OBJ/PLY tokens and extreme numbers, deletions, truncations,
//! duplicated spans) and fed to the loaders inside `catch_unwind`. Every input must
//! load or fail with an error whose message is non-empty and names the file. A
//! third family writes structurally valid scenes with extreme numbers (zero,
//! negative, NaN, infinite sizes, huge coordinates): each must be an error or
//! render 4x4 at 1 spp without a NaN or infinite sample.
//!
//! The run is bounded: `FUZZ_CASES` cases in all by default (a few seconds);
//! `RUST_V_FUZZ_CASES=N` runs `N` (see tests/README.md for a long run). A failing
//! case prints its family, case number and input, so it can be replayed.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use rand::Rng;
use rand_pcg::Pcg32;
use rust_v::film::Film;
use rust_v::render::{Limits, render};
use rust_v::scene::load_scene_str;
use rust_v::settings::SettingsPatch;
use rust_v::shape::{Mesh, Transform};

use crate::common::{root, temp_dir};

/// Cases in all (over the three families) when `RUST_V_FUZZ_CASES` is not set.
const FUZZ_CASES: u64 = 20000;

fn cases() -> u64 {
    std::env::var("RUST_V_FUZZ_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(FUZZ_CASES)
}

/// Tokens inserted by the mutator: RON punctuation and keywords, numbers at the
/// edges of f32/u32/u64, and the keywords of the mesh formats.
const TOKENS: &[&str] = &[
    "(",
    ")",
    "[",
    "]",
    "{",
    "}",
    ",",
    ":",
    "\"",
    "'",
    "-",
    ".",
    "e",
    "#",
    "//",
    "/*",
    "*/",
    "\n",
    " ",
    "\t",
    "\0",
    "-1",
    "0",
    "1",
    "-0",
    "0.0",
    "1e39",
    "-1e39",
    "1e-45",
    "3.4e38",
    "NaN",
    "inf",
    "-inf",
    "4294967295",
    "4294967296",
    "18446744073709551615",
    "18446744073709551616",
    "99999999999999999999999",
    "-2147483649",
    "Some(",
    "None",
    "true",
    "false",
    "()",
    "r#\"",
    "\"\\u{0}\"",
    "Sphere",
    "Quad",
    "Mesh",
    "Disk",
    "Cuboid",
    "Plane",
    "Bubble",
    "Dielectric",
    "Mirror",
    "OrenNayar",
    "Constant(",
    "Scaled(",
    "D65",
    "Named(",
    "material:",
    "emission:",
    "radius:",
    "path:",
    "width:",
    "spp:",
    "max_bounces:",
    "v ",
    "vn ",
    "vt ",
    "f ",
    "o ",
    "g ",
    "mtllib x.mtl",
    "usemtl m",
    "/",
    "//",
    "ply\n",
    "format ascii 1.0\n",
    "format binary_little_endian 1.0\n",
    "format binary_big_endian 1.0\n",
    "element vertex ",
    "element face ",
    "property float x\n",
    "property list uchar int vertex_indices\n",
    "property list uint uint vertex_indices\n",
    "property double nx\n",
    "comment ",
    "end_header\n",
];

/// Returns a random integer in `0..n` (`n > 0`).
fn below(rng: &mut Pcg32, n: usize) -> usize {
    ((rng.next_u32() as u64 * n as u64) >> 32) as usize
}

/// Applies one to four random mutations to `data`.
fn mutate(rng: &mut Pcg32, data: &mut Vec<u8>) {
    for _ in 0..1 + below(rng, 4) {
        let len = data.len();
        let at = below(rng, len + 1);
        match below(rng, 9) {
            0 if len > 0 => data[at.min(len - 1)] ^= 1 << below(rng, 8),
            1 if len > 0 => data[at.min(len - 1)] = rng.next_u32() as u8,
            2 | 3 => {
                let t = TOKENS[below(rng, TOKENS.len())].as_bytes();
                data.splice(at..at, t.iter().copied());
            }
            4 => {
                // Replace a number (a run of digits, '.', '-', 'e') by an extreme token.
                let start = (at..len).find(|&i| data[i].is_ascii_digit());
                if let Some(s) = start {
                    let e = (s..len).find(|&i| !matches!(data[i], b'0'..=b'9' | b'.' | b'e' | b'-')).unwrap_or(len);
                    let t = TOKENS[21 + below(rng, 19)].as_bytes();
                    data.splice(s..e, t.iter().copied());
                }
            }
            5 => {
                let n = below(rng, 16.min(len - at) + 1);
                data.drain(at..at + n);
            }
            6 => data.truncate(at),
            7 | 8 if len > 0 => {
                // Duplicate (7) or move a copy of (8) a span elsewhere.
                let s = below(rng, len);
                let n = below(rng, 64.min(len - s)) + 1;
                let span: Vec<u8> = data[s..s + n].to_vec();
                let to = if below(rng, 2) == 0 { s + n } else { below(rng, len + 1) };
                data.splice(to..to, span);
            }
            _ => {}
        }
    }
}

/// Runs `f`, failing the test with `what` if it panics.
fn no_panic<T>(what: &dyn Fn() -> String, f: impl FnOnce() -> T) -> T {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(v) => v,
        Err(e) => {
            let msg = e
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| e.downcast_ref::<String>().cloned())
                .unwrap_or_default();
            panic!("panic ({msg}) on {}", what())
        }
    }
}

/// Checks that an error message is non-empty and names every file in `names`.
fn clear_error(msg: &str, names: &[&str], what: &dyn Fn() -> String) {
    assert!(!msg.trim().is_empty(), "empty error on {}", what());
    for n in names {
        assert!(msg.contains(n), "error '{msg}' does not name {n}, on {}", what());
    }
}

fn overrides() -> SettingsPatch {
    SettingsPatch { width: Some(4), height: Some(4), spp: Some(1), ..Default::default() }
}

fn scene_seeds() -> Vec<(String, Vec<u8>)> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(root().join("scenes"))
        .expect("scenes/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .collect();
    files.sort();
    assert!(files.len() >= 3, "scene seeds");
    files.iter().map(|p| (p.display().to_string(), std::fs::read(p).expect("scene file"))).collect()
}

#[test]
fn fuzz_scene_parser() {
    let seeds = scene_seeds();
    let dir = temp_dir("fuzz-scene");
    // A path in an empty directory: mesh references in mutated scenes fail fast.
    let path = dir.join("fuzzed.ron");
    let name = path.display().to_string();
    let n = cases() * 9 / 20;
    let (mut ok, mut err) = (0, 0);
    for case in 0..n {
        let mut rng = Pcg32::new(case, 1);
        let (seed_name, seed) = &seeds[below(&mut rng, seeds.len())];
        let mut data = seed.clone();
        mutate(&mut rng, &mut data);
        let text = String::from_utf8_lossy(&data).into_owned();
        let what = || format!("scene case {case} (from {seed_name}):\n{text}");
        match no_panic(&what, || load_scene_str(&text, &path, &overrides())) {
            Ok(_) => ok += 1,
            Err(e) => {
                clear_error(&e.to_string(), &[&name], &what);
                err += 1;
            }
        }
    }
    eprintln!("fuzz_scene_parser: {n} cases, {ok} loaded, {err} clear errors");
    assert!(n < 50 || (ok > 0 && err > 0), "the mutations should produce both outcomes");
}

/// A unit cube as OBJ: positions, normals, quads and triangles, negative indices.
const OBJ: &str = "# cube\no cube\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
vn 0 0 -1\nvn 0 0 1\ng sides\nf 1//1 4//1 3//1 2//1\nf 5//2 6//2 7//2 8//2\nf 1 2 6\nf -8 -2 -3\nf 4 8 7 3\n";

fn ply_header(format: &str) -> String {
    format!(
        "ply\nformat {format} 1.0\ncomment fuzz seed\nelement vertex 4\nproperty float x\nproperty float y\n\
property float z\nproperty float nx\nproperty float ny\nproperty float nz\nelement face 2\n\
property list uchar int vertex_indices\nend_header\n"
    )
}

const PLY_V: [[f32; 6]; 4] =
    [[0., 0., 0., 0., 0., 1.], [1., 0., 0., 0., 0., 1.], [1., 1., 0., 0., 0., 1.], [0., 1., 0., 0., 0., 1.]];

fn ply_binary(big: bool) -> Vec<u8> {
    let mut out = ply_header(if big { "binary_big_endian" } else { "binary_little_endian" }).into_bytes();
    for v in PLY_V {
        for c in v {
            out.extend(if big { c.to_be_bytes() } else { c.to_le_bytes() });
        }
    }
    for face in [&[0i32, 1, 2, 3][..], &[0, 2, 3]] {
        out.push(face.len() as u8);
        for &i in face {
            out.extend(if big { i.to_be_bytes() } else { i.to_le_bytes() });
        }
    }
    out
}

fn gzip(data: &[u8]) -> Vec<u8> {
    use std::io::Write;
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    e.write_all(data).expect("gzip");
    e.finish().expect("gzip")
}

/// The mesh seeds: (file name, bytes).
fn mesh_seeds() -> Vec<(&'static str, Vec<u8>)> {
    let mut ascii = ply_header("ascii");
    for v in PLY_V {
        ascii += &format!("{} {} {} {} {} {}\n", v[0], v[1], v[2], v[3], v[4], v[5]);
    }
    ascii += "4 0 1 2 3\n3 0 2 3\n";
    vec![
        ("m.obj", OBJ.as_bytes().to_vec()),
        ("m.ply", ascii.clone().into_bytes()),
        ("m.ply", ply_binary(false)),
        ("m.ply", ply_binary(true)),
        ("m.obj.gz", gzip(OBJ.as_bytes())),
        ("m.ply.gz", gzip(ascii.as_bytes())),
    ]
}

#[test]
fn fuzz_mesh_loaders() {
    let seeds = mesh_seeds();
    let dir = temp_dir("fuzz-mesh");
    let scene_path = dir.join("mesh-scene.ron");
    let scene_name = scene_path.display().to_string();
    // Every seed loads as it is.
    for (i, (file, data)) in seeds.iter().enumerate() {
        let p = dir.join(format!("seed{i}-{file}"));
        std::fs::write(&p, data).expect("write seed");
        let m = Mesh::load(&p, &Transform::default()).unwrap_or_else(|e| panic!("seed {i}: {e}"));
        assert!(m.triangle_count() >= 3, "seed {i}");
    }
    let n = cases() * 9 / 20;
    let (mut ok, mut err) = (0, 0);
    for case in 0..n {
        let mut rng = Pcg32::new(case, 2);
        let (file, seed) = &seeds[below(&mut rng, seeds.len())];
        let mut data = seed.clone();
        mutate(&mut rng, &mut data);
        // Mutations inside a gzip stream mostly test the decompressor; mutate the
        // content and recompress half of the time.
        if file.ends_with(".gz") && below(&mut rng, 2) == 0 {
            let mut plain = seeds[if file.starts_with("m.obj") { 0 } else { 1 }].1.clone();
            mutate(&mut rng, &mut plain);
            data = gzip(&plain);
        }
        let path = dir.join(file);
        std::fs::write(&path, &data).expect("write mesh");
        let mesh_name = path.display().to_string();
        let what = || format!("mesh case {case} ({file}):\n{}", String::from_utf8_lossy(&data));
        let direct = no_panic(&what, || Mesh::load(&path, &Transform::default()));
        if let Err(e) = &direct {
            clear_error(&e.to_string(), &[&mesh_name], &what);
        }
        let scene = format!(
            "(camera: (eye: (0.5, 0.5, 3), look_at: (0.5, 0.5, 0), fov_deg: 40),\n\
             objects: [(shape: Mesh(path: \"{file}\", scale: 1), material: \"white\")],\n\
             materials: {{\"white\": Lambertian(reflectance: Constant(0.5))}})"
        );
        let via_scene = no_panic(&what, || load_scene_str(&scene, &scene_path, &overrides()));
        match (&direct, &via_scene) {
            (Ok(_), Ok(_)) => ok += 1,
            (Err(_), Err(e)) => {
                clear_error(&e.to_string(), &[&scene_name, &mesh_name], &what);
                err += 1;
            }
            (Ok(_), Err(e)) => {
                // A mesh that loads can still leave a scene without anything to render.
                clear_error(&e.to_string(), &[&scene_name], &what);
                err += 1;
            }
            (Err(e), Ok(_)) => panic!("Mesh::load failed ({e}) but the scene loaded, on {}", what()),
        }
    }
    eprintln!("fuzz_mesh_loaders: {n} cases, {ok} loaded, {err} clear errors");
    assert!(n < 50 || (ok > 0 && err > 0), "the mutations should produce both outcomes");
}

/// Extreme values for the number slots of [`extreme_scene`].
const EXTREMES: &[&str] =
    &["0", "-1", "1", "0.5", "1e-30", "-1e-30", "1e-45", "1e30", "-1e30", "3.4e38", "1e39", "NaN", "inf", "-inf", "2"];

/// A structurally valid scene whose numbers are drawn from [`EXTREMES`] (or kept sane).
fn extreme_scene(rng: &mut Pcg32) -> String {
    let mut x = || {
        if below(rng, 8) == 0 { EXTREMES[below(rng, EXTREMES.len())].to_string() } else { "0.5".to_string() }
    };
    format!(
        "(camera: (eye: ({}, 1, 3), look_at: (0, {}, 0), up: (0, 1, {}), fov_deg: {}),\n\
         materials: {{\"w\": Lambertian(reflectance: Constant({})), \"g\": Dielectric(ior: Constant({})),\n\
           \"o\": OrenNayar(reflectance: Constant(0.5), sigma_deg: {})}},\n\
         objects: [\n\
           (shape: Sphere(center: (0, {}, 0), radius: {}), material: \"g\"),\n\
           (shape: Sphere(center: ({}, 1.5, 0), radius: {}), emission: Scaled({}, D65)),\n\
           (shape: Quad(origin: (-1, 0, -1), edge_u: ({}, 0, 0), edge_v: (0, 0, {})), material: \"w\"),\n\
           (shape: Disk(center: (0, 2, 0), normal: (0, -1, {}), radius: {}), material: \"o\", emission: Scaled({}, D65)),\n\
           (shape: Cuboid(min: (-0.6, 0, -0.5), max: ({}, {}, 0.5)), material: \"w\"),\n\
         ],\n\
         lights: [Point(position: (0, 1, {}), intensity: Scaled({}, D65))])",
        x(),
        x(),
        x(),
        x(),
        x(),
        x(),
        x(),
        x(),
        x(),
        x(),
        x(),
        x(),
        x(),
        x(),
        x(),
        x(),
        x(),
        x(),
        x(),
        x(),
        x()
    )
}

#[test]
fn fuzz_extreme_scenes_are_errors_or_render_without_nan() {
    let dir = temp_dir("fuzz-extreme");
    let path = dir.join("extreme.ron");
    let name = path.display().to_string();
    let n = (cases() / 10).max(1);
    let (mut ok, mut err) = (0, 0);
    for case in 0..n {
        let mut rng = Pcg32::new(case, 3);
        let text = extreme_scene(&mut rng);
        let what = || format!("extreme case {case}:\n{text}");
        let loaded = no_panic(&what, || load_scene_str(&text, &path, &overrides()));
        let scene = match loaded {
            Ok(s) => s,
            Err(e) => {
                clear_error(&e.to_string(), &[&name], &what);
                err += 1;
                continue;
            }
        };
        let s = &scene.settings;
        let mut film = Film::new(s.width, s.height);
        let stop = AtomicBool::new(false);
        let stats = no_panic(&what, || {
            render(&scene, &mut film, 0..s.spp, Limits { stop: &stop, time_budget: None }, &mut |_, _| {})
        });
        assert_eq!(stats.invalid_samples, 0, "NaN or infinite samples on {}", what());
        ok += 1;
    }
    eprintln!("fuzz_extreme_scenes: {n} cases, {ok} rendered, {err} clear errors");
    assert!(n < 20 || ok > 0, "some extreme scenes should render");
}

#[test]
fn the_fuzz_path_helpers_name_files() {
    // The errors checked above name files by their displayed path.
    let p = Path::new("/nonexistent/dir/x.ply");
    let e = Mesh::load(p, &Transform::default()).expect_err("missing file");
    assert!(e.to_string().contains("x.ply"));
}

/// Command-line invocations in [`fuzz_command_line`] when
/// `RUST_V_CLI_FUZZ_CASES` is not set (each starts a process: ~0.1 s).
const CLI_CASES: u64 = 48;

/// Values a flag is given: the edges of every numeric type, signs, NaN,
/// infinities, empty and malformed text, paths that are not files.
const FLAG_VALUES: &[&str] = &[
    "0",
    "1",
    "2",
    "3",
    "8",
    "16",
    "-1",
    "40000",
    "4294967295",
    "4294967296",
    "18446744073709551616",
    "1e300",
    "-1e300",
    "nan",
    "NaN",
    "inf",
    "-inf",
    "0.5",
    "1e-300",
    "",
    " ",
    "x",
    "0..2",
    "2..1",
    "3..3",
    "a..b",
    "0..4294967296",
    "auto",
    "path",
    "whitted",
    "spectral",
    "hero",
    "random",
    "rgb",
    "/dev/null",
    "/proc",
    "/nonexistent/out.png",
    ".",
    "out.png",
    "out.exr",
    "out.ckpt",
    "é.png",
];

/// Flags with values, per subcommand; `--time 0.3` bounds every render.
const RENDER_FLAGS: &[&str] = &[
    "--spp",
    "--seed",
    "--width",
    "--height",
    "--max-bounces",
    "--integrator",
    "--wavelengths",
    "--packet-size",
    "--threads",
    "--passes",
    "--checkpoint",
    "--checkpoint-every",
    "--time",
    "-o",
];
const RESUME_FLAGS: &[&str] = &["--spp", "--threads", "--checkpoint", "--checkpoint-every", "-o"];
const SWITCHES: &[&str] = &["-q", "--quiet", "--force", "--json", "--bogus", "-"];

/// Random subcommands, flags and values through the binary: every run ends
/// with status 0, 1 (an error) or 2 (a usage error), never a panic, and
/// every failure is exactly one `rust-v: error:` line. A failing case prints
/// its command line.
#[test]
fn fuzz_command_line() {
    let n = std::env::var("RUST_V_CLI_FUZZ_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(CLI_CASES);
    let dir = temp_dir("fuzz-cli");
    let scene = dir.join("s.ron");
    std::fs::write(
        &scene,
        r#"(camera: (eye: (0, 0, 4), look_at: (0, 0, 0), fov_deg: 30), render: (width: 4, height: 4, spp: 1),
            materials: { "w": Lambertian(reflectance: Constant(0.5)) },
            objects: [ (shape: Sphere(center: (0, 0, 0), radius: 1), material: "w") ],
            lights: [ Point(position: (0, 3, 3), intensity: Constant(10)) ])"#,
    )
    .unwrap();
    let bin = env!("CARGO_BIN_EXE_rust-v");
    let ok = std::process::Command::new(bin)
        .current_dir(&dir)
        .args(["render", "s.ron", "-q", "-o", "ref.png", "--checkpoint", "ref.ckpt"])
        .status()
        .unwrap();
    assert!(ok.success());
    let mut rng = Pcg32::new(0x05ee_dc11, 0xda3e_39cb_94b9_5bdb);
    let (mut codes, mut panics) = ([0u32; 3], Vec::new());
    for case in 0..n {
        let pick = |rng: &mut Pcg32, v: &[&'static str]| v[below(rng, v.len())];
        let sub = pick(&mut rng, &["render", "render", "render", "resume", "merge", "compare"]);
        let mut args: Vec<String> = vec![sub.into()];
        let flags = match sub {
            "render" => {
                args.push("s.ron".into());
                RENDER_FLAGS
            }
            "resume" => {
                args.push("ref.ckpt".into());
                RESUME_FLAGS
            }
            "merge" => {
                args.extend(["ref.ckpt".into(), "-o".into()]);
                &["--quiet"][..]
            }
            _ => {
                args.extend(["ref.png".into(), "ref.png".into()]);
                &["--json"][..]
            }
        };
        for _ in 0..below(&mut rng, 5) {
            if below(&mut rng, 4) == 0 {
                args.push(pick(&mut rng, SWITCHES).into());
            } else {
                args.push(pick(&mut rng, flags).into());
                args.push(pick(&mut rng, FLAG_VALUES).into());
            }
        }
        if sub == "render" || sub == "resume" {
            args.extend(["--time".into(), "0.3".into()]);
        }
        let what = format!("case {case}: rust-v {}", args.join(" "));
        let o = std::process::Command::new(bin).current_dir(&dir).args(&args).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        if err.contains("panicked") || err.contains("backtrace") {
            panics.push(format!("{what}\n{err}"));
            continue;
        }
        let code = o.status.code().unwrap_or_else(|| panic!("{what}: killed by a signal\n{err}"));
        assert!(code <= 2, "{what}: exit {code}\n{err}");
        codes[code as usize] += 1;
        if code != 0 {
            let lines = err.lines().filter(|l| l.starts_with("rust-v: error:")).count();
            assert_eq!(lines, 1, "{what}: expected one error line\n{err}");
        }
    }
    assert!(panics.is_empty(), "panics:\n{}", panics.join("\n"));
    eprintln!("fuzz_command_line: {n} runs: {} ok, {} errors, {} usage errors", codes[0], codes[1], codes[2]);
}
