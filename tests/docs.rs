//! The documentation is checked like code.
//!
//! **Scene examples.** Every ```` ```ron ```` block of `docs/scene-format.md` must load
//! with [`load_scene_str`], as if it were a scene file in `docs/` (so `../meshes/...` and
//! `data/led.csv` resolve as they do from `scenes/`). A block that is a whole scene
//! (it starts with `(` and has a `camera:` field) is loaded as it stands. Any other block
//! is a fragment and must be preceded (blank lines aside) by an HTML comment naming where
//! it goes, `<!-- wrap: KIND -->`, with KIND one of:
//!
//! | KIND | the block is | it goes into |
//! |---|---|---|
//! | `camera` | a camera tuple | `camera: BLOCK` |
//! | `render` | a settings tuple | `render: BLOCK` |
//! | `spectrum` | one spectrum | the `emission:` of a sphere light |
//! | `ior` | one index of refraction | `Dielectric(ior: BLOCK)` |
//! | `material` | `"name": Material(...),` entries | `materials: { BLOCK }` |
//! | `coating` | one coating | `Conductor(metal: "Au", coating: BLOCK)` |
//! | `shape` | one shape | `(shape: BLOCK, material: "white")` |
//! | `object` | `(shape: ...),` entries | `objects: [ BLOCK ]`, with materials `"white"`, `"glass"` and `"water"` defined |
//! | `light` | `Light(...),` entries | `lights: [ BLOCK ]` |
//!
//! A fragment without a comment, an unknown KIND, or a block that does not load fails
//! the test with the block's line in the page and the loader's error.
//!
//! **In step with `desc.rs`.** Every variant of the scene format's enums and every field
//! name in `src/scene/desc.rs` and `src/scene/desc/` (and every render setting of `src/settings.rs`) must appear
//! in a `ron` block of the page.
//!
//! **Links.** Every relative link in `README.md`, `docs/*.md` and `tests/README.md` must
//! point to an existing file, and a `#anchor` into a Markdown file to one of its headings
//! (GitHub's heading slugs).
//!
//! **The README** stays at most 300 lines, shows the two commands verbatim, and its one
//! scene example is the first block of `docs/scene-format.md`.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use rust_v::scene::load_scene_str;
use rust_v::settings::SettingsPatch;

use crate::common::root;

/// A fenced ```` ```ron ```` block: its first line's number (1-based, the fence), the
/// `wrap:` kind of the comment before it, if any, and its text.
#[derive(Debug)]
struct Block {
    line: usize,
    wrap: Option<String>,
    text: String,
}

fn ron_blocks(md: &str) -> Vec<Block> {
    let mut out = Vec::new();
    let mut last_comment: Option<String> = None;
    let mut open: Option<Block> = None;
    let mut in_other_fence = false;
    for (i, line) in md.lines().enumerate() {
        let t = line.trim();
        if let Some(b) = open.as_mut() {
            if t == "```" {
                out.push(open.take().unwrap());
            } else {
                b.text.push_str(line);
                b.text.push('\n');
            }
            continue;
        }
        if in_other_fence {
            in_other_fence = t != "```";
            continue;
        }
        if t == "```ron" {
            open = Some(Block { line: i + 1, wrap: last_comment.take(), text: String::new() });
        } else if t.starts_with("```") {
            in_other_fence = true;
            last_comment = None;
        } else if let Some(kind) = t.strip_prefix("<!-- wrap:").and_then(|r| r.strip_suffix("-->")) {
            last_comment = Some(kind.trim().to_string());
        } else if !t.is_empty() {
            last_comment = None;
        }
    }
    assert!(open.is_none(), "a ```ron block is not closed");
    out
}

const CAMERA: &str = "(eye: (0, 1, 3.5), look_at: (0, 1, 0), fov_deg: 45)";
const LAMP: &str = "(shape: Sphere(center: (0, 3, 0), radius: 0.5), emission: Constant(1))";

fn scene(camera: &str, render: &str, materials: &str, objects: &str, lights: &str) -> String {
    format!(
        "(\n    camera: {camera},\n    render: {render},\n    materials: {{\n{materials}\n    }},\n    \
         objects: [\n{objects}\n    ],\n    lights: [\n{lights}\n    ],\n)\n"
    )
}

/// The scene a block is loaded as, or why it cannot be checked.
fn as_scene(b: &Block) -> Result<String, String> {
    let text = b.text.trim_end();
    let whole = text.trim_start().starts_with('(') && text.contains("camera:");
    let white = "\"white\": Lambertian(reflectance: Constant(0.8)),";
    Ok(match b.wrap.as_deref() {
        None if whole => b.text.clone(),
        None => return Err("a fragment without a `<!-- wrap: KIND -->` comment before it".into()),
        Some("camera") => scene(text, "()", "", LAMP, ""),
        Some("render") => scene(CAMERA, text, "", LAMP, ""),
        Some("spectrum") => {
            scene(CAMERA, "()", "", &format!("(shape: Sphere(center: (0, 3, 0), radius: 0.5), emission: {text})"), "")
        }
        Some("ior") => scene(
            CAMERA,
            "()",
            &format!("\"m\": Dielectric(ior: {text}),"),
            &format!("{LAMP}, (shape: Sphere(center: (0, 1, 0), radius: 0.5), material: \"m\")"),
            "",
        ),
        Some("material") => scene(CAMERA, "()", text, LAMP, ""),
        Some("coating") => scene(
            CAMERA,
            "()",
            &format!("\"m\": Conductor(metal: \"Au\", coating: {text}),"),
            &format!("{LAMP}, (shape: Sphere(center: (0, 1, 0), radius: 0.5), material: \"m\")"),
            "",
        ),
        Some("shape") => scene(CAMERA, "()", white, &format!("{LAMP}, (shape: {text}, material: \"white\")"), ""),
        Some("object") => scene(
            CAMERA,
            "()",
            &format!(
                "{white} \"glass\": Dielectric(ior: Named(\"N-BK7\")), \"water\": Dielectric(ior: Named(\"water_20C\")),"
            ),
            text,
            "",
        ),
        Some("light") => {
            scene(CAMERA, "()", white, "(shape: Plane(point: (0, 0, 0), normal: (0, 1, 0)), material: \"white\")", text)
        }
        Some(other) => return Err(format!("unknown wrap kind `{other}`")),
    })
}

/// Loads every `ron` block of `md` as a scene file at `path`; returns one line per
/// block that fails.
fn check_blocks(md: &str, path: &Path) -> Vec<String> {
    let mut failures = Vec::new();
    for b in ron_blocks(md) {
        let result = as_scene(&b).and_then(|text| {
            load_scene_str(&text, path, &SettingsPatch::default()).map(|_| ()).map_err(|e| format!("{e}\n{text}"))
        });
        if let Err(e) = result {
            failures.push(format!("block at line {}: {e}", b.line));
        }
    }
    failures
}

fn scene_format_path() -> PathBuf {
    root().join("docs/scene-format.md")
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

#[test]
fn every_ron_block_in_scene_format_loads() {
    let path = scene_format_path();
    let md = read(&path);
    let blocks = ron_blocks(&md);
    // The page walks every form: far more than a handful of examples.
    assert!(blocks.len() >= 40, "only {} ```ron blocks found in {}", blocks.len(), path.display());
    let failures = check_blocks(&md, &path.with_extension("ron"));
    assert!(failures.is_empty(), "{} of {} blocks fail:\n{}", failures.len(), blocks.len(), failures.join("\n\n"));
}

/// The checker itself: a wrong block, an unwrapped fragment and an unknown kind fail;
/// a right one passes.
#[test]
fn broken_blocks_are_caught() {
    let path = scene_format_path().with_extension("ron");
    let good = "<!-- wrap: material -->\n```ron\n\"m\": Mirror(reflectance: Constant(0.5)),\n```\n";
    assert_eq!(check_blocks(good, &path), Vec::<String>::new());
    for (bad, why) in [
        ("<!-- wrap: material -->\n```ron\n\"m\": Mirror(reflectance: Constant(0.5), tint: 1),\n```\n", "tint"),
        ("<!-- wrap: material -->\n```ron\n\"m\": Mirror(reflectance: Constant(1.5)),\n```\n", "reflectance"),
        ("<!-- wrap: shape -->\n```ron\nSphere(centre: (0, 0, 0), radius: 1)\n```\n", "centre"),
        (
            "<!-- wrap: light -->\n```ron\nSpot(position: (0, 1, 0), look_at: (0, 0, 0), cone_deg: 120, falloff_deg: 5, intensity: D65),\n```\n",
            "cone_deg",
        ),
        ("```ron\n\"m\": Black,\n```\n", "wrap: KIND"),
        ("<!-- wrap: materiel -->\n```ron\n\"m\": Black,\n```\n", "materiel"),
        (
            "text\n\n```ron\n(camera: (eye: (0, 0, 1), look_at: (0, 0, 0), fov_deg: 40), objects: [])\n```\n",
            "at least one object",
        ),
    ] {
        let failures = check_blocks(bad, &path);
        assert_eq!(failures.len(), 1, "{bad}: {failures:?}");
        assert!(failures[0].contains(why), "{bad}: expected `{why}` in {}", failures[0]);
    }
}

/// Variant names of `pub enum NAME` and field names (`name:` at the start of a line) in
/// a Rust source, skipping enums in `skip`.
fn desc_names(src: &str, skip: &[&str]) -> (BTreeSet<String>, BTreeSet<String>) {
    let mut variants = BTreeSet::new();
    let mut fields = BTreeSet::new();
    let mut in_enum: Option<bool> = None; // Some(true) inside an enum we keep
    let ident = |s: &str| s.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect::<String>();
    for line in src.lines() {
        if line.starts_with("#[cfg(test)]") {
            break;
        }
        if let Some(rest) = line.strip_prefix("pub enum ") {
            in_enum = Some(!skip.contains(&ident(rest).as_str()));
            continue;
        }
        if line.starts_with("pub struct ") {
            in_enum = Some(false);
            if !line.trim_end().ends_with('{') {
                in_enum = None;
            }
            continue;
        }
        if line.starts_with('}') {
            in_enum = None;
            continue;
        }
        if in_enum.is_none() || line.trim_start().starts_with("//") || line.trim_start().starts_with('#') {
            continue;
        }
        let t = line.trim_start();
        let indent = line.len() - t.len();
        if in_enum == Some(true) && indent == 4 && t.starts_with(|c: char| c.is_ascii_uppercase()) {
            variants.insert(ident(t));
            continue;
        }
        let t = t.strip_prefix("pub ").unwrap_or(t);
        let name = ident(t);
        if !name.is_empty() && t[name.len()..].starts_with(": ") && name.starts_with(|c: char| c.is_ascii_lowercase()) {
            fields.insert(name);
        }
    }
    (variants, fields)
}

#[test]
fn scene_format_covers_every_variant_and_field_of_desc() {
    let md = read(&scene_format_path());
    let ron: String = ron_blocks(&md).into_iter().map(|b| b.text).collect::<Vec<_>>().join("\n");
    let words: BTreeSet<String> =
        ron.split(|c: char| !(c.is_alphanumeric() || c == '_')).filter(|w| !w.is_empty()).map(str::to_string).collect();
    // ScaleDesc and ScalarDesc are untagged: their variants are never written (`scale: 0.5`
    // or `(x, y, z)`; `roughness: 0.2` or a texture).
    // desc.rs and its parts in src/scene/desc/, in name order.
    let mut parts: Vec<_> = std::fs::read_dir(root().join("src/scene/desc"))
        .expect("src/scene/desc/")
        .map(|e| e.expect("a file of src/scene/desc/").path())
        .filter(|p| p.extension().is_some_and(|x| x == "rs"))
        .collect();
    parts.sort();
    let desc = std::iter::once(root().join("src/scene/desc.rs")).chain(parts).map(|p| read(&p)).collect::<Vec<_>>();
    let (variants, fields) = desc_names(&desc.join("\n"), &["ScaleDesc", "ScalarDesc"]);
    assert!(variants.len() >= 30 && fields.len() >= 30, "desc.rs parsed badly: {variants:?} {fields:?}");
    let settings_src = read(&root().join("src/settings.rs"));
    let start = settings_src.find("\nsettings! {").expect("the settings! invocation in src/settings.rs");
    let settings: Vec<String> = settings_src[start..]
        .lines()
        .skip(2)
        .take_while(|l| !l.starts_with('}'))
        .filter_map(|l| l.trim().split_once(':').map(|(n, _)| n.to_string()))
        .filter(|n| !n.starts_with("///"))
        .collect();
    assert!(settings.len() >= 9, "settings parsed badly: {settings:?}");
    let mut missing = Vec::new();
    for v in &variants {
        if !words.contains(v) {
            missing.push(format!("variant {v}"));
        }
    }
    for f in fields.iter().chain(&settings) {
        if !ron.contains(&format!("{f}:")) {
            missing.push(format!("field {f}:"));
        }
    }
    assert!(missing.is_empty(), "docs/scene-format.md has no ron example with: {}", missing.join(", "));
}

/// GitHub's anchor for a heading: lower case, punctuation dropped, spaces to hyphens;
/// repeated headings get `-1`, `-2`, ...
fn anchors(md: &str) -> BTreeSet<String> {
    let mut seen: BTreeMap<String, usize> = BTreeMap::new();
    let mut out = BTreeSet::new();
    let mut fence = false;
    for line in md.lines() {
        if line.trim_start().starts_with("```") {
            fence = !fence;
            continue;
        }
        if fence || !line.starts_with('#') {
            continue;
        }
        let text = line.trim_start_matches('#');
        if !text.starts_with(' ') {
            continue;
        }
        let slug: String = text
            .trim()
            .to_lowercase()
            .chars()
            .filter(|c| c.is_alphanumeric() || *c == ' ' || *c == '-' || *c == '_')
            .map(|c| if c == ' ' { '-' } else { c })
            .collect();
        let n = seen.entry(slug.clone()).or_insert(0);
        out.insert(if *n == 0 { slug.clone() } else { format!("{slug}-{n}") });
        *n += 1;
    }
    out
}

/// Relative link targets of a Markdown text (outside fenced code), with their lines.
fn links(md: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut fence = false;
    for (i, line) in md.lines().enumerate() {
        if line.trim_start().starts_with("```") {
            fence = !fence;
            continue;
        }
        if fence {
            continue;
        }
        let mut rest = line;
        while let Some(at) = rest.find("](") {
            let after = &rest[at + 2..];
            let Some(end) = after.find(')') else { break };
            let target = after[..end].split_whitespace().next().unwrap_or("").to_string();
            rest = &after[end..];
            if target.is_empty() || target.contains("://") || target.starts_with("mailto:") {
                continue;
            }
            out.push((i + 1, target));
        }
    }
    out
}

fn markdown_files() -> Vec<PathBuf> {
    let mut files = vec![root().join("README.md"), root().join("tests/README.md")];
    let mut docs: Vec<PathBuf> = std::fs::read_dir(root().join("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    docs.sort();
    files.extend(docs);
    files
}

#[test]
fn relative_links_point_to_existing_files_and_headings() {
    let files = markdown_files();
    assert!(files.len() >= 8, "{files:?}");
    let mut bad = Vec::new();
    let mut checked = 0;
    for file in &files {
        let md = read(file);
        for (line, target) in links(&md) {
            checked += 1;
            let (path, anchor) = match target.split_once('#') {
                Some((p, a)) => (p, Some(a)),
                None => (target.as_str(), None),
            };
            let dest = if path.is_empty() { file.clone() } else { file.parent().unwrap().join(path) };
            if !dest.exists() {
                bad.push(format!("{}:{line}: {target}: no such file", file.display()));
                continue;
            }
            if let Some(a) = anchor
                && dest.extension().is_some_and(|e| e == "md")
                && !anchors(&read(&dest)).contains(a)
            {
                bad.push(format!("{}:{line}: {target}: no heading with anchor #{a}", file.display()));
            }
        }
    }
    assert!(checked >= 20, "only {checked} links found");
    assert!(bad.is_empty(), "broken links:\n{}", bad.join("\n"));
}

#[test]
fn anchors_follow_github() {
    let a = anchors("# The scene (`SceneDesc`)\n## Speed, one sitting\n## Speed, one sitting\n```\n# not\n```\n");
    let want: BTreeSet<String> =
        ["the-scene-scenedesc", "speed-one-sitting", "speed-one-sitting-1"].iter().map(|s| s.to_string()).collect();
    assert_eq!(a, want);
    assert_eq!(
        links("[a](x.md#y) ![b](images/c.png) [w](https://e.org) `code`\n"),
        vec![(1, "x.md#y".to_string()), (1, "images/c.png".to_string())]
    );
}

#[test]
fn readme_is_short_and_shows_the_two_commands() {
    let readme = read(&root().join("README.md"));
    let lines = readme.lines().count();
    assert!(lines <= 300, "README.md has {lines} lines; at most 300");
    let two = "```sh\ncargo run --release -- render scenes/cornell.ron -o cornell.png   # render the thesis's Cornell box\n\
               cargo test --release --locked                                     # the test suite (what CI runs)\n```";
    assert!(readme.contains(two), "README.md lost its two-commands block:\n{two}");
    // CI runs the README's test command as written (and the test profile's after it).
    let ci = read(&root().join(".ci/run"));
    let runs: Vec<&str> = ci.lines().filter(|l| l.starts_with("cargo test")).collect();
    assert_eq!(runs, ["cargo test --release --locked", "cargo test --locked"], ".ci/run's test commands");
    // The README's one scene example (loaded by tests/scenes.rs) is scene-format.md's first.
    let readme_ron = ron_blocks(&readme);
    let page_ron = ron_blocks(&read(&scene_format_path()));
    assert_eq!(readme_ron.len(), 1, "README.md should hold exactly one ```ron block");
    assert_eq!(
        readme_ron[0].text, page_ron[0].text,
        "README.md's scene example differs from docs/scene-format.md's first"
    );
}

/// Every `fn` defined in the crate's Rust files (src/, tests/), by name.
fn defined_fns() -> BTreeSet<String> {
    fn walk(dir: &Path, out: &mut BTreeSet<String>) {
        for e in std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()) {
            if e.is_dir() {
                walk(&e, out);
            } else if e.extension().is_some_and(|x| x == "rs") {
                for line in read(&e).lines() {
                    let t = line.trim_start();
                    let t = t.strip_prefix("pub ").or_else(|| t.strip_prefix("pub(crate) ")).unwrap_or(t);
                    if let Some(rest) = t.strip_prefix("fn ") {
                        let name: String = rest.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
                        out.insert(name);
                    }
                }
            }
        }
    }
    let mut out = BTreeSet::new();
    walk(&root().join("src"), &mut out);
    walk(&root().join("tests"), &mut out);
    out
}

/// The failure matrix names the tests that back its cells (issue 33): every
/// name in the last column of its table (`file.rs::name`, or a bare test
/// name) and every `file.rs::name` anywhere in `tests/README.md` must be a
/// function that exists. A renamed or deleted test fails this, not silently
/// the matrix.
#[test]
fn every_test_the_failure_matrix_names_exists() {
    let md = read(&root().join("tests/README.md"));
    let fns = defined_fns();
    let is_name =
        |s: &str| !s.is_empty() && s.chars().all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_');
    let mut missing = Vec::new();
    let mut seen = 0;
    for (n, line) in md.lines().enumerate() {
        let cells: Vec<&str> = line.split('|').collect();
        // A matrix row: its last cell (before the closing `|`) names the tests.
        let last = if line.starts_with("| ") && cells.len() >= 10 { cells[cells.len() - 2] } else { "" };
        for quoted in line.split('`').skip(1).step_by(2) {
            let name = match quoted.rsplit_once("::") {
                Some((file, name)) if file.ends_with(".rs") => name,
                Some(_) => continue,
                None if last.contains(&format!("`{quoted}`")) && quoted.contains('_') => quoted,
                None => continue,
            };
            if !is_name(name) {
                continue;
            }
            seen += 1;
            if !fns.contains(name) {
                missing.push(format!("tests/README.md:{}: {quoted}", n + 1));
            }
        }
    }
    assert!(seen > 40, "found only {seen} test names: is the table's format still understood?");
    assert!(missing.is_empty(), "tests named in the matrix that do not exist:\n{}", missing.join("\n"));
}

/// Every source file under `src/` stays within 700 lines (the house limit:
/// a longer file holds more than one concept and is split along them).
#[test]
fn source_files_stay_within_700_lines() {
    fn walk(dir: &Path, long: &mut Vec<String>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let p = entry.unwrap().path();
            if p.is_dir() {
                walk(&p, long);
            } else if p.extension().is_some_and(|e| e == "rs") {
                let n = read(&p).lines().count();
                if n > 700 {
                    long.push(format!("{} ({n} lines)", p.display()));
                }
            }
        }
    }
    let mut long = Vec::new();
    walk(&root().join("src"), &mut long);
    assert!(long.is_empty(), "split these along the concepts they hold: {long:?}");
}
