//! Checkpoints, resume, merge and signals: resumed and merged renders are
//! bit-identical to one render; bad, foreign, overlapping or mismatched
//! checkpoints are refused with a message naming the file; signals produce
//! snapshots and checkpoints, and SIGINT/SIGTERM save and exit 0.

use std::path::{Path, PathBuf};
use std::process::Output;
use std::sync::atomic::AtomicBool;

use rust_v::checkpoint::{Checkpoint, merge};
use rust_v::film::Film;
use rust_v::render::{Limits, render};
use rust_v::scene::{Scene, load_scene};
use rust_v::settings::SettingsPatch;

use crate::common::{root, rust_v, temp_dir};

fn cornell(size: u32) -> Scene {
    let o = SettingsPatch { width: Some(size), height: Some(size), ..SettingsPatch::default() };
    load_scene(&root().join("scenes/cornell.ron"), &o).expect("cornell loads")
}

fn render_into(scene: &Scene, film: &mut Film, passes: std::ops::Range<u32>) {
    let stop = AtomicBool::new(false);
    let stats = render(scene, film, passes, Limits { stop: &stop, time_budget: None }, &mut |_, _| {});
    assert_eq!(stats.invalid_samples, 0);
}

fn meta(scene: &Scene, film: Film) -> Checkpoint {
    Checkpoint {
        crate_version: env!("CARGO_PKG_VERSION").into(),
        scene_path: root().join("scenes/cornell.ron"),
        content_hash: scene.content_hash,
        settings: scene.settings.clone(),
        target_end: 100,
        output: "/tmp/x.png".into(),
        film,
        inputs: Some(scene.input_hashes.clone()),
    }
}

/// The core promise, through the library: 0..100 == merge(0..50, 50..100)
/// == 0..50 saved, loaded and continued to 100, bit for bit.
#[test]
fn library_merge_and_resume_are_bit_identical() {
    let scene = cornell(16);
    let mut whole = Film::new(16, 16);
    render_into(&scene, &mut whole, 0..100);
    let mut a = Film::new(16, 16);
    render_into(&scene, &mut a, 0..50);
    let mut b = Film::starting_at(16, 16, 50);
    render_into(&scene, &mut b, 50..100);
    assert_eq!(b.pass_range(), 50..100);

    let parts = vec![(PathBuf::from("b"), meta(&scene, b.clone())), (PathBuf::from("a"), meta(&scene, a.clone()))];
    let merged = merge(parts).expect("disjoint ranges merge");
    assert_eq!(merged.film, whole);
    assert_eq!(merged.film.mean_xyz(), whole.mean_xyz());

    let bytes = meta(&scene, a).encode().unwrap();
    let mut resumed = Checkpoint::decode(&bytes, Path::new("a.ckpt")).unwrap().film;
    render_into(&scene, &mut resumed, 50..100);
    assert_eq!(resumed, whole);
}

/// A stop while a batch of passes is in flight keeps the batch's passes that
/// finished whole and nothing else: the film equals a straight render of the
/// passes it reports, and continuing it gives the uninterrupted render. (The
/// moment of the stop varies; the assertions hold for any moment.)
#[test]
fn a_stop_mid_batch_keeps_whole_passes_only() {
    use std::sync::atomic::Ordering;
    let scene = cornell(64); // 16 tiles: batches of 16 passes, 256 tasks
    let mut film = Film::new(64, 64);
    let stop = AtomicBool::new(false);
    let stats = std::thread::scope(|s| {
        s.spawn(|| {
            std::thread::sleep(std::time::Duration::from_millis(40));
            stop.store(true, Ordering::Relaxed);
        });
        render(&scene, &mut film, 0..2000, Limits { stop: &stop, time_budget: None }, &mut |_, _| {})
    });
    assert!(stats.interrupted, "2000 passes cannot finish in 40 ms");
    let m = film.passes();
    assert!(m < 2000 && film.pass_range() == (0..m), "whole passes from 0: {:?}", film.pass_range());
    let mut straight = Film::new(64, 64);
    render_into(&scene, &mut straight, 0..m);
    assert_eq!(film, straight, "the kept passes are exactly passes 0..{m}");
    render_into(&scene, &mut film, m..m + 20);
    render_into(&scene, &mut straight, m..m + 20);
    assert_eq!(film, straight);
}

/// A film without pixels (a library caller's edge case) takes whole passes
/// without a panic: zero tiles make zero tasks, not a division by zero.
#[test]
fn an_empty_film_takes_whole_passes() {
    let scene = cornell(16);
    let mut film = Film::new(0, 0);
    render_into(&scene, &mut film, 0..40);
    assert_eq!(film.pass_range(), 0..40);
}

fn ok(o: &Output) {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// Fails without a panic; returns stderr.
fn fails(o: &Output) -> String {
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(!o.status.success(), "expected failure");
    assert!(!err.contains("panicked"), "panic: {err}");
    err
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// `render SCENE --width 24 --height 24 -o OUT --checkpoint CKPT --quiet EXTRA...`
fn render_part(scene: &Path, out: &Path, ckpt: &Path, extra: &[&str]) -> Output {
    let mut args =
        vec!["render", s(scene), "--width", "24", "--height", "24", "-o", s(out), "--checkpoint", s(ckpt), "--quiet"];
    args.extend_from_slice(extra);
    rust_v(&args)
}

#[test]
fn resume_through_the_binary_is_bit_identical() {
    let dir = temp_dir("resume");
    let scene = root().join("scenes/cornell.ron");
    ok(&render_part(&scene, &dir.join("full.exr"), &dir.join("full.ckpt"), &["--spp", "8"]));
    ok(&render_part(&scene, &dir.join("half.exr"), &dir.join("half.ckpt"), &["--spp", "4"]));
    ok(&rust_v(&["resume", s(&dir.join("half.ckpt")), "--spp", "8", "-o", s(&dir.join("resumed.exr")), "--quiet"]));
    assert_eq!(std::fs::read(dir.join("full.exr")).unwrap(), std::fs::read(dir.join("resumed.exr")).unwrap());

    // Resume without --spp continues to the original target; the default output is the original one.
    ok(&render_part(&scene, &dir.join("q.exr"), &dir.join("q.ckpt"), &["--spp", "8", "--passes", "0..3"]));
    let mut q = Checkpoint::read(&dir.join("q.ckpt")).unwrap();
    q.target_end = 8;
    q.write(&dir.join("q.ckpt")).unwrap();
    ok(&rust_v(&[
        "resume",
        s(&dir.join("q.ckpt")),
        "--quiet",
        "--threads",
        "1",
        "--checkpoint",
        s(&dir.join("r.ckpt")),
    ]));
    assert_eq!(std::fs::read(dir.join("full.exr")).unwrap(), std::fs::read(dir.join("q.exr")).unwrap());
    let r = Checkpoint::read(&dir.join("r.ckpt")).unwrap();
    assert_eq!((r.passes(), &r.film), (0..8, &Checkpoint::read(&dir.join("full.ckpt")).unwrap().film));
}

#[test]
fn resume_refuses_a_changed_or_missing_scene() {
    let dir = temp_dir("resume-changed");
    let scene = dir.join("box.ron");
    std::fs::copy(root().join("scenes/cornell.ron"), &scene).unwrap();
    ok(&render_part(&scene, &dir.join("a.png"), &dir.join("a.ckpt"), &["--spp", "1"]));
    let text = std::fs::read_to_string(&scene).unwrap();
    std::fs::write(&scene, text.replace("radius: 0.35", "radius: 0.36")).unwrap();
    let err = fails(&rust_v(&["resume", s(&dir.join("a.ckpt")), "--spp", "2"]));
    assert!(err.contains("a.ckpt") && err.contains("box.ron") && err.contains("changed"), "{err}");
    // --force resumes anyway, with a warning, and records the new scene.
    let forced = rust_v(&["resume", s(&dir.join("a.ckpt")), "--spp", "2", "--force", "-o", s(&dir.join("f.png"))]);
    ok(&forced);
    assert!(String::from_utf8_lossy(&forced.stderr).contains("--force"));
    assert!(dir.join("f.png").exists());
    std::fs::remove_file(&scene).unwrap();
    let err = fails(&rust_v(&["resume", s(&dir.join("a.ckpt")), "--spp", "2"]));
    assert!(err.contains("a.ckpt") && err.contains("box.ron"), "{err}");
}

#[test]
fn merge_is_bit_identical_and_refuses_mismatches() {
    let dir = temp_dir("merge");
    let scene = root().join("scenes/cornell.ron");
    let d = |n: &str| dir.join(n);
    ok(&render_part(&scene, &d("full.exr"), &d("full.ckpt"), &["--spp", "8"]));
    // Two processes, two halves; merged in either order.
    ok(&render_part(&scene, &d("b.exr"), &d("b.ckpt"), &["--spp", "8", "--passes", "4..8"]));
    ok(&render_part(&scene, &d("a.exr"), &d("a.ckpt"), &["--spp", "8", "--passes", "0..4"]));
    ok(&rust_v(&["merge", s(&d("b.ckpt")), s(&d("a.ckpt")), "-o", s(&d("m.exr")), "--quiet"]));
    assert_eq!(std::fs::read(d("full.exr")).unwrap(), std::fs::read(d("m.exr")).unwrap());
    ok(&rust_v(&["merge", s(&d("a.ckpt")), s(&d("b.ckpt")), "-o", s(&d("m.ckpt")), "--quiet"]));
    assert_eq!(Checkpoint::read(&d("m.ckpt")).unwrap().film, Checkpoint::read(&d("full.ckpt")).unwrap().film);

    // Overlap.
    ok(&render_part(&scene, &d("o.exr"), &d("o.ckpt"), &["--spp", "8", "--passes", "2..6"]));
    let err = fails(&rust_v(&["merge", s(&d("a.ckpt")), s(&d("o.ckpt")), "-o", s(&d("x.png"))]));
    assert!(err.contains("o.ckpt") && err.contains("overlap") && err.contains("2..6"), "{err}");
    // A gap.
    ok(&render_part(&scene, &d("g.exr"), &d("g.ckpt"), &["--spp", "8", "--passes", "6..8"]));
    let err = fails(&rust_v(&["merge", s(&d("a.ckpt")), s(&d("g.ckpt")), "-o", s(&d("x.png"))]));
    assert!(err.contains("missing") && err.contains("4..6"), "{err}");
    // Different settings.
    ok(&render_part(&scene, &d("s.exr"), &d("s.ckpt"), &["--passes", "4..8", "--seed", "9"]));
    let err = fails(&rust_v(&["merge", s(&d("a.ckpt")), s(&d("s.ckpt")), "-o", s(&d("x.png"))]));
    assert!(err.contains("s.ckpt") && err.contains("different settings") && err.contains("seed"), "{err}");
    // A different scene.
    let other = root().join("scenes/cornell-lambert.ron");
    ok(&render_part(&other, &d("l.exr"), &d("l.ckpt"), &["--passes", "4..8"]));
    let err = fails(&rust_v(&["merge", s(&d("a.ckpt")), s(&d("l.ckpt")), "-o", s(&d("x.png"))]));
    assert!(err.contains("l.ckpt") && err.contains("different scene"), "{err}");

    // Truncated, corrupt and foreign files.
    let bytes = std::fs::read(d("b.ckpt")).unwrap();
    std::fs::write(d("t.ckpt"), &bytes[..bytes.len() / 2]).unwrap();
    let err = fails(&rust_v(&["merge", s(&d("a.ckpt")), s(&d("t.ckpt")), "-o", s(&d("x.png"))]));
    assert!(err.contains("t.ckpt") && err.contains("truncated"), "{err}");
    let mut bad = bytes.clone();
    let n = bad.len();
    bad[n - 100] ^= 0x55;
    std::fs::write(d("c.ckpt"), &bad).unwrap();
    let err = fails(&rust_v(&["merge", s(&d("a.ckpt")), s(&d("c.ckpt")), "-o", s(&d("x.png"))]));
    assert!(err.contains("c.ckpt") && err.contains("corrupt"), "{err}");
    let err = fails(&rust_v(&["resume", s(&d("full.exr"))]));
    assert!(err.contains("full.exr") && err.contains("not a rust-v checkpoint"), "{err}");
    assert!(!d("x.png").exists());
}

#[cfg(unix)]
mod signals {
    use std::io::{BufRead, BufReader};
    use std::path::{Path, PathBuf};
    use std::process::{Child, Command, Stdio};
    use std::sync::mpsc;
    use std::time::Duration;

    use rust_v::checkpoint::Checkpoint;

    use super::s;
    use crate::common::{root, rust_v, temp_dir, wait_for};

    const LONG: Duration = Duration::from_secs(60);

    /// A long render of a tiny image; returns once its signal handlers are installed.
    fn start(dir: &Path, extra: &[&str]) -> Child {
        let mut child = Command::new(env!("CARGO_BIN_EXE_rust-v"))
            .args(["render", s(&root().join("scenes/cornell.ron")), "--width", "24", "--height", "24"])
            .args(["--spp", "10000000", "--threads", "2", "-o", s(&dir.join("c.png"))])
            .args(extra)
            .stderr(Stdio::piped())
            .spawn()
            .expect("binary runs");
        // Drain stderr (so the progress bar never blocks on a full pipe) and
        // report the first line: it is printed after the handlers are installed.
        let stderr = child.stderr.take().unwrap();
        let (tx, rx) = mpsc::channel();
        std::thread::spawn(move || {
            let mut r = BufReader::new(stderr);
            let mut line = Vec::new();
            let _ = r.read_until(b'\n', &mut line);
            let _ = tx.send(());
            let _ = std::io::copy(&mut r, &mut std::io::sink());
        });
        rx.recv_timeout(LONG).expect("the render starts");
        child
    }

    fn kill(sig: &str, child: &Child) {
        let st = Command::new("kill").args([sig, &child.id().to_string()]).status().expect("kill runs");
        assert!(st.success());
    }

    fn snapshots(dir: &Path) -> Vec<PathBuf> {
        let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
            .unwrap()
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| {
                let n = p.file_name().unwrap().to_string_lossy().into_owned();
                n.len() == "c-00000.png".len() && n.starts_with("c-") && n.ends_with(".png")
            })
            .collect();
        v.sort();
        v
    }

    /// Waits for the exit; asserts status 0.
    fn exits_zero(child: &mut Child) {
        let mut status = None;
        assert!(
            wait_for(LONG, || {
                status = child.try_wait().unwrap();
                status.is_some()
            }),
            "no exit"
        );
        assert!(status.unwrap().success(), "exit status {:?}", status);
    }

    fn no_temporaries(dir: &Path) {
        for e in std::fs::read_dir(dir).unwrap() {
            let n = e.unwrap().file_name().to_string_lossy().into_owned();
            assert!(!n.contains(".tmp-"), "temporary file left: {n}");
        }
    }

    #[test]
    fn usr1_snapshots_usr2_checkpoints_int_saves_and_exits_zero() {
        let dir = temp_dir("signals");
        let mut child = start(&dir, &[]);
        kill("-USR1", &child);
        assert!(wait_for(LONG, || !snapshots(&dir).is_empty()), "no snapshot");
        let img = image::open(&snapshots(&dir)[0]).expect("snapshot is a valid PNG");
        assert_eq!((img.width(), img.height()), (24, 24));
        let ckpt = dir.join("c.ckpt");
        kill("-USR2", &child);
        assert!(wait_for(LONG, || ckpt.exists()), "no checkpoint");
        assert!(Checkpoint::read(&ckpt).expect("valid checkpoint").film.passes() > 0);
        assert!(child.try_wait().unwrap().is_none(), "the render goes on");

        // SIGINT twice: the second one arrives while saving and changes nothing.
        let before = Checkpoint::read(&ckpt).unwrap().film.passes();
        kill("-INT", &child);
        kill("-INT", &child);
        exits_zero(&mut child);
        let c = Checkpoint::read(&ckpt).expect("valid checkpoint after SIGINT");
        let n = c.film.passes();
        assert!(n >= before);
        assert!(dir.join(format!("c-{n:05}.png")).exists(), "final snapshot");
        no_temporaries(&dir);
        let out = dir.join("r.png");
        let o = rust_v(&["resume", s(&ckpt), "--spp", &(n + 2).to_string(), "-o", s(&out), "--quiet"]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert!(image::open(&out).is_ok());
    }

    #[test]
    fn a_burst_of_signals_never_crashes_or_tears_a_file_and_term_exits_zero() {
        let dir = temp_dir("signal-burst");
        let mut child = start(&dir, &[]);
        let ckpt = dir.join("c.ckpt");
        kill("-USR2", &child);
        assert!(wait_for(LONG, || ckpt.exists()), "no checkpoint");
        let pid = child.id().to_string();
        let script = "for i in $(seq 25); do kill -USR1 $0; kill -USR2 $0; done";
        let mut burst = Command::new("sh").args(["-c", script, &pid]).spawn().unwrap();
        // Read the checkpoint over and over while it is being replaced.
        let mut reads = 0;
        while burst.try_wait().unwrap().is_none() || reads < 20 {
            Checkpoint::read(&ckpt).expect("never a torn checkpoint");
            reads += 1;
        }
        assert!(burst.wait().unwrap().success());
        std::thread::sleep(Duration::from_millis(200));
        assert!(child.try_wait().unwrap().is_none(), "the render survives the burst");
        kill("-TERM", &child);
        exits_zero(&mut child);
        Checkpoint::read(&ckpt).expect("valid checkpoint after SIGTERM");
        for p in snapshots(&dir) {
            image::open(&p).expect("every snapshot is a valid PNG");
        }
        no_temporaries(&dir);
    }

    /// SIGKILL at 20 varied moments of renders that rewrite their checkpoint
    /// after every pass: whatever the moment, the checkpoint on disk loads
    /// (temporary file, fsync, rename), at worst leaving a stale temporary.
    #[test]
    fn sigkill_during_checkpoint_writes_never_breaks_the_checkpoint() {
        let dir = temp_dir("sigkill");
        let ckpt = dir.join("k.ckpt");
        for i in 0..20u64 {
            let mut child = start(&dir, &["--checkpoint", s(&ckpt), "--checkpoint-every", "0.001"]);
            if i == 0 {
                assert!(wait_for(LONG, || ckpt.exists()), "no checkpoint");
            }
            std::thread::sleep(Duration::from_millis(2 + 9 * (i % 8)));
            kill("-KILL", &child);
            let _ = child.wait();
            let c = Checkpoint::read(&ckpt).unwrap_or_else(|e| panic!("after kill {i}: {e}"));
            assert!(c.film.passes() > 0);
        }
    }

    #[test]
    fn checkpoint_every_writes_periodically() {
        let dir = temp_dir("signal-every");
        let ckpt = dir.join("every.ckpt");
        let mut child = start(&dir, &["--checkpoint", s(&ckpt), "--checkpoint-every", "0.05"]);
        assert!(wait_for(LONG, || ckpt.exists()), "no periodic checkpoint");
        let first = Checkpoint::read(&ckpt).unwrap().film.passes();
        assert!(wait_for(LONG, || Checkpoint::read(&ckpt).unwrap().film.passes() > first), "not periodic");
        kill("-INT", &child);
        exits_zero(&mut child);
        Checkpoint::read(&ckpt).expect("valid checkpoint");
    }
}

#[test]
fn help_documents_the_checkpoint_flags_and_subcommands() {
    let help = |args: &[&str]| String::from_utf8_lossy(&rust_v(args).stdout).into_owned();
    let render = help(&["render", "--help"]);
    for flag in ["--passes", "--checkpoint", "--checkpoint-every", "SIGUSR1"] {
        assert!(render.contains(flag), "render --help lacks {flag}");
    }
    let resume = help(&["resume", "--help"]);
    for flag in ["--spp", "--output", "--threads", "--quiet", "--checkpoint", "--checkpoint-every"] {
        assert!(resume.contains(flag), "resume --help lacks {flag}");
    }
    assert!(help(&["merge", "--help"]).contains("--output"));
}

/// The same promise for a spectral film (`--spectral`) on a dispersive scene (the prism: `auto`
/// splits into single wavelengths there): 0..40 == merge(0..20, 20..40) == 0..20 saved (format
/// version 6), loaded and continued, bit for bit in the XYZ and the 36 per-bin sums; and a
/// colour-only checkpoint writes version 5.
#[test]
fn spectral_films_merge_and_resume_bit_identically() {
    let mut o = SettingsPatch::default();
    (o.width, o.height) = (Some(12), Some(12));
    let scene = load_scene(&root().join("scenes/prism.ron"), &o).expect("prism loads");
    let mut whole = Film::new_spectral(12, 12, 0);
    render_into(&scene, &mut whole, 0..40);
    let mut a = Film::new_spectral(12, 12, 0);
    render_into(&scene, &mut a, 0..20);
    let mut b = Film::new_spectral(12, 12, 20);
    render_into(&scene, &mut b, 20..40);
    let parts = vec![(PathBuf::from("b"), meta(&scene, b)), (PathBuf::from("a"), meta(&scene, a.clone()))];
    let merged = merge(parts).expect("disjoint ranges merge");
    assert_eq!(merged.film, whole);
    assert!(whole.spectral_sums().unwrap().iter().any(|p| p.iter().any(|&v| v != 0)));

    let bytes = meta(&scene, a.clone()).encode().unwrap();
    assert_eq!(u32::from_le_bytes(bytes[8..12].try_into().unwrap()), rust_v::checkpoint::SPECTRAL_FORMAT_VERSION);
    let mut resumed = Checkpoint::decode(&bytes, Path::new("a.ckpt")).unwrap().film;
    assert_eq!(resumed, a);
    render_into(&scene, &mut resumed, 20..40);
    assert_eq!(resumed, whole);

    // A spectral and a colour-only film do not merge; colour-only checkpoints are version 5.
    let mut plain = Film::starting_at(12, 12, 20);
    render_into(&scene, &mut plain, 20..40);
    assert!(a.clone().merge(&plain).is_err());
    let bytes = meta(&scene, plain).encode().unwrap();
    assert_eq!(u32::from_le_bytes(bytes[8..12].try_into().unwrap()), rust_v::checkpoint::FORMAT_VERSION);
}

/// Issue 34 item 6: `resume CKPT --checkpoint CKPT` names resume's own default
/// and is accepted (it was refused as "overwriting an input"), and a finished
/// resume leaves its checkpoint holding every pass, so a second resume of the
/// same file continues from there (it restarted from the old pass count: the
/// passes in between lived only in the image).
#[test]
fn resume_keeps_its_checkpoint_up_to_date() {
    let dir = temp_dir("resume-own-checkpoint");
    let scene = root().join("scenes/cornell.ron");
    let ckpt = dir.join("long.ckpt");
    ok(&render_part(&scene, &dir.join("a.exr"), &ckpt, &["--spp", "3"]));
    // The same file named explicitly, also through another spelling of its path.
    let other = dir.join(".").join("long.ckpt");
    ok(&rust_v(&["resume", s(&ckpt), "--spp", "5", "--checkpoint", s(&other), "-o", s(&dir.join("b.exr")), "--quiet"]));
    assert_eq!(Checkpoint::read(&ckpt).unwrap().passes(), 0..5);
    // Without --checkpoint the resumed file is updated too.
    ok(&rust_v(&["resume", s(&ckpt), "--spp", "8", "-o", s(&dir.join("c.exr")), "--quiet"]));
    assert_eq!(Checkpoint::read(&ckpt).unwrap().passes(), 0..8);
    // And it is exactly a render of 8 passes.
    ok(&render_part(&scene, &dir.join("full.exr"), &dir.join("full.ckpt"), &["--spp", "8"]));
    assert_eq!(std::fs::read(dir.join("c.exr")).unwrap(), std::fs::read(dir.join("full.exr")).unwrap());
    assert_eq!(Checkpoint::read(&ckpt).unwrap().film, Checkpoint::read(&dir.join("full.ckpt")).unwrap().film);
}
