//! `render`, `resume` and `merge`: from a scene file (or checkpoints) to an
//! image. A render's passes run in a [`Session`] (signals, snapshots,
//! checkpoints); `merge` sums checkpoints of disjoint pass ranges.
//!
//! Before any pass is rendered, every file the command will write is
//! checked ([`check_files`]): each can be created, none is an input (the
//! scene, a mesh or data file, a checkpoint read) or another output, and the
//! film fits in the machine's memory.

use std::path::{Path, PathBuf};
use std::time::Instant;

use rust_v::checkpoint::{Checkpoint, default_checkpoint_path, merge};
use rust_v::color::{ColorSpace, Sensor, Tonemap};
use rust_v::error::{Error, Result, show_path};
use rust_v::film::{Film, MAX_SAMPLE};
use rust_v::io::{NAME_MAX, check_aliasing, check_output, is_snapshot_name, parent_dir};
use rust_v::scene::{Scene, load_scene_with_warnings};

use super::args::{MergeArgs, RenderArgs, ResumeArgs};
use super::console::{count, say, thread_pool, warn};
use super::session::{Session, SessionPlan};

fn default_output(scene: &Path) -> PathBuf {
    let stem = scene.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "render".into());
    PathBuf::from(format!("{stem}.png"))
}

pub fn render_command(args: RenderArgs) -> Result<()> {
    // Signals first: from here on SIGUSR1/2 no longer kill the process, and
    // the first line on stderr tells a script that it may send them.
    let session = Session::start()?;
    let output = args.output.clone().unwrap_or_else(|| default_output(&args.scene));
    check_output_extension(&output)?;
    check_color_space(&output, args.color_space)?;
    check_tonemap(&output, args.picture.tonemap)?;
    if args.spectral && !rust_v::io::image::is_exr(&output) {
        return Err(Error::Settings(format!("--spectral needs an .exr output, found {}", show_path(&output))));
    }
    let sensor = Sensor::from_arg(&args.sensor)?;
    check_sensor_space(&sensor, args.color_space)?;
    if args.spectral && !sensor.is_cie1931() {
        return Err(Error::Settings(format!(
            "--spectral writes the 36 bins with their CIE XYZ; it cannot take --sensor {}",
            show_path(&args.sensor)
        )));
    }
    let load_start = Instant::now();
    // Loading (meshes are read and built in parallel) uses the threads asked for too.
    let (mut scene, warnings) = thread_pool(args.run.threads)?
        .install(|| load_scene_with_warnings(&args.scene, &args.settings.overrides(), args.strict))?;
    scene.sensor = sensor.clone();
    for w in &warnings {
        warn(format_args!("{w}"));
    }
    let load_time = load_start.elapsed();
    let s = &scene.settings;
    if args.spectral
        && s.integrator == rust_v::settings::IntegratorKind::Spectral
        && s.wavelengths == rust_v::settings::WavelengthsKind::Rgb
    {
        return Err(Error::Settings("--spectral: the RGB mode (--wavelengths rgb) has no spectral bins".into()));
    }
    if args.spectral
        && s.integrator == rust_v::settings::IntegratorKind::Spectral
        && s.wavelengths == rust_v::settings::WavelengthsKind::Continuous
    {
        return Err(Error::Settings(
            "--spectral keeps the 36 bin centres, so it cannot follow --wavelengths continuous (use hero)".into(),
        ));
    }
    // With a time budget and no --spp (or --passes), render until the time is up.
    let open_ended = args.time.is_some() && !args.settings.spp_given() && args.passes.is_none();
    if !args.run.quiet {
        let spp = match (&args.passes, args.time) {
            (Some(p), _) => format!("passes {}..{} of {} spp", p.start, p.end, s.spp),
            (None, Some(t)) if open_ended => format!("as many passes as {t} s allow"),
            _ => format!("{} spp", s.spp),
        };
        say(format_args!(
            "{} ({}, {}, loaded in {:.2} s): {}x{}, {spp}, {}, seed {}",
            show_path(&args.scene),
            count(scene.object_count() as u64, "object"),
            count(scene.lights.len() as u64, "light"),
            load_time.as_secs_f64(),
            s.width,
            s.height,
            count(s.max_bounces, "bounce"),
            s.seed,
        ));
        say(format_args!("{}", rust_v::integrator::describe(&scene)));
        if !sensor.is_cie1931() {
            say(format_args!("{}", sensor.describe()));
        }
    }
    let passes = args.passes.clone().unwrap_or(0..if open_ended { u32::MAX } else { s.spp });
    let checkpoint_path = args.checkpoint.checkpoint.clone().unwrap_or_else(|| default_checkpoint_path(&output));
    let sensor_input = [("sensor", args.sensor.as_path())];
    let extra: &[(&str, &Path)] = if sensor.is_cie1931() { &[] } else { &sensor_input };
    check_files(&args.scene, &scene, extra, &output, &checkpoint_path, args.spectral)?;
    let scene_path = std::path::absolute(&args.scene).map_err(|e| Error::io(&args.scene, e))?;
    let mut checkpoint = Checkpoint {
        crate_version: env!("CARGO_PKG_VERSION").into(),
        scene_path,
        content_hash: scene.content_hash,
        settings: scene.settings.clone(),
        target_end: passes.end,
        output: std::path::absolute(&output).map_err(|e| Error::io(&output, e))?,
        film: if args.spectral {
            Film::new_spectral(s.width, s.height, passes.start)
        } else {
            Film::starting_at(s.width, s.height, passes.start)
        },
        inputs: Some(scene.input_hashes.clone()),
    };
    checkpoint.film.set_sensor(sensor)?;
    checkpoint.film.set_color_space(args.color_space);
    checkpoint.film.set_picture(args.picture.exposure, args.picture.tonemap);
    let plan = SessionPlan::new(checkpoint_path, &args.checkpoint, output, &args.run, args.time);
    session.run(&scene, checkpoint, passes.end, &plan)
}

pub fn resume_command(args: ResumeArgs) -> Result<()> {
    let session = Session::start()?;
    let mut ckpt = Checkpoint::read(&args.checkpoint_file)?;
    let path = &args.checkpoint_file;
    if ckpt.crate_version != env!("CARGO_PKG_VERSION") {
        warn(format_args!(
            "{} was written by rust-v {}, this is {}: new passes may differ from what it would have rendered",
            show_path(path),
            ckpt.crate_version,
            env!("CARGO_PKG_VERSION")
        ));
    }
    let done = ckpt.passes();
    let end = match args.spp {
        Some(n) => done.start.checked_add(n).ok_or_else(|| Error::Settings(format!("--spp {n} is too large")))?,
        None => ckpt.target_end,
    };
    if args.spp.is_some() {
        ckpt.settings.spp = end.max(done.end) - done.start;
    }
    let output = args.output.clone().unwrap_or_else(|| ckpt.output.clone());
    check_output_extension(&output)?;
    check_color_space(&output, args.color_space)?;
    check_tonemap(&output, args.picture.tonemap)?;
    check_sensor_space(ckpt.film.sensor(), args.color_space)?;
    ckpt.film.set_color_space(args.color_space);
    ckpt.film.set_picture(args.picture.exposure, args.picture.tonemap);
    let mut scene = thread_pool(args.run.threads)?
        .install(|| load_scene_with_warnings(&ckpt.scene_path, &ckpt.settings.patch(), false))
        .map_err(|e| Error::checkpoint(path, format!("cannot load its scene {}: {e}", show_path(&ckpt.scene_path))))?
        .0;
    // The checkpoint's sensor, whatever the file it came from holds now.
    scene.sensor = ckpt.film.sensor().clone();
    if scene.content_hash != ckpt.content_hash {
        let changed = match &ckpt.inputs {
            Some(old) => {
                let names = rust_v::checkpoint::changed_inputs(old, &scene.input_hashes, &ckpt.scene_path);
                format!("{} changed since the checkpoint was written", names.join(", "))
            }
            None => changed_inputs(path, &ckpt.scene_path, &scene.inputs),
        };
        if !args.force {
            return Err(Error::checkpoint(
                path,
                format!(
                    "{changed} (content hash {:016x}, was {:016x}); resuming needs the same inputs (or --force)",
                    scene.content_hash, ckpt.content_hash
                ),
            ));
        }
        warn(format_args!("{changed}; resuming anyway (--force)"));
        ckpt.content_hash = scene.content_hash;
    }
    // From here on the checkpoint records the scene's inputs as they are (an older
    // version's checkpoint gains its per-input hashes).
    ckpt.inputs = Some(scene.input_hashes.clone());
    if scene.settings != ckpt.settings {
        let diffs = scene.settings.differences(&ckpt.settings).join(", ");
        return Err(Error::checkpoint(path, format!("its settings load differently: {diffs}")));
    }
    if let Some(spp) = args.spp.filter(|_| end <= done.end && !args.run.quiet) {
        // Nothing to render: say why, then write the image of the passes held.
        say(format_args!(
            "the checkpoint already holds {}; --spp {spp} asks for {}: nothing to render",
            count(done.end - done.start, "pass"),
            if end < done.end { "fewer" } else { "no more" }
        ));
    }
    if !args.run.quiet {
        say(format_args!(
            "resuming {} ({}): passes {}..{} done, rendering to pass {}",
            show_path(path),
            show_path(&ckpt.scene_path),
            done.start,
            done.end,
            end.max(done.end)
        ));
        if !scene.sensor.is_cie1931() {
            say(format_args!("{}", scene.sensor.describe()));
        }
    }
    ckpt.target_end = end.max(done.end);
    ckpt.output = std::path::absolute(&output).map_err(|e| Error::io(&output, e))?;
    let checkpoint_path = args.checkpoint.checkpoint.clone().unwrap_or_else(|| path.clone());
    // The checkpoint resumed is an input unless it is also where new checkpoints
    // go: by default, or when `--checkpoint` names the same file.
    let resumed = [("checkpoint resumed", path.as_path())];
    let extra: &[(&str, &Path)] = if same_file(&checkpoint_path, path) { &[] } else { &resumed };
    check_files(&ckpt.scene_path, &scene, extra, &output, &checkpoint_path, ckpt.film.spectral_sums().is_some())?;
    let mut plan = SessionPlan::new(checkpoint_path, &args.checkpoint, output, &args.run, None);
    // A finished resume always leaves its checkpoint, holding every pass: without
    // it, the passes rendered since the checkpoint lived only in the image, and a
    // second `resume` of the same file started from the old pass count.
    plan.final_checkpoint = true;
    session.run(&scene, ckpt, end, &plan)
}

/// Whether `a` and `b` name the same existing file (links followed), or are the same path.
fn same_file(a: &Path, b: &Path) -> bool {
    a == b || matches!((std::fs::canonicalize(a), std::fs::canonicalize(b)), (Ok(x), Ok(y)) if x == y)
}

/// Says which inputs of a resumed scene changed, as far as can be told, for a
/// checkpoint of version 1 to 4 (a newer one has each input's hash). Such a
/// checkpoint stores one hash over the scene file and every file it reads
/// (meshes, data), not one per file, so: a scene that reads no other file
/// changed itself; otherwise the inputs modified after the checkpoint file
/// was written are named; when none was (or the times cannot be read), every
/// input is named as possibly changed.
fn changed_inputs(checkpoint: &Path, scene: &Path, inputs: &[PathBuf]) -> String {
    if inputs.is_empty() {
        return format!("the scene file {} changed since the checkpoint was written", show_path(scene));
    }
    let modified = |p: &Path| std::fs::metadata(p).and_then(|m| m.modified()).ok();
    let all: Vec<&Path> = std::iter::once(scene).chain(inputs.iter().map(|p| p.as_path())).collect();
    let newer: Vec<&Path> = match modified(checkpoint) {
        Some(written) => all.iter().copied().filter(|p| modified(p).is_some_and(|t| t > written)).collect(),
        None => Vec::new(),
    };
    let names = |ps: &[&Path]| ps.iter().map(|p| show_path(p).to_string()).collect::<Vec<_>>().join(", ");
    if newer.is_empty() {
        format!(
            "the scene {} or a file it reads (mesh, data: {}) changed since the checkpoint was written; none was modified after it, and the checkpoint keeps one hash over them all, so which is not known",
            show_path(scene),
            names(&all[1..])
        )
    } else {
        format!(
            "the scene {} or a file it reads (mesh, data) changed since the checkpoint was written: {} modified after it",
            show_path(scene),
            names(&newer)
        )
    }
}

pub fn merge_command(args: MergeArgs) -> Result<()> {
    let is_ckpt = args.output.extension().is_some_and(|e| e.eq_ignore_ascii_case("ckpt"));
    if !is_ckpt {
        check_output_extension(&args.output).map_err(|_| {
            Error::Settings(format!("output {}: expected .png, .exr or .ckpt", show_path(&args.output)))
        })?;
    }
    check_output(&args.output, "output")?;
    let inputs: Vec<(&str, &Path)> = args.parts.iter().map(|p| ("checkpoint", p.as_path())).collect();
    check_aliasing(&inputs, &[("output", &args.output)])?;
    let mut parts = Vec::with_capacity(args.parts.len());
    for p in &args.parts {
        parts.push((p.clone(), Checkpoint::read(p)?));
    }
    let mut merged = merge(parts)?;
    if !is_ckpt {
        check_color_space(&args.output, args.color_space)?;
        check_tonemap(&args.output, args.picture.tonemap)?;
        check_sensor_space(merged.film.sensor(), args.color_space)?;
        merged.film.set_color_space(args.color_space);
        merged.film.set_picture(args.picture.exposure, args.picture.tonemap);
    }
    if is_ckpt {
        merged.write(&args.output)?;
    } else {
        merged.film.write(&args.output)?;
    }
    if !args.quiet {
        let r = merged.passes();
        say(format_args!(
            "merged {} (passes {}..{}) into {}",
            count(args.parts.len() as u64, "checkpoint"),
            r.start,
            r.end,
            show_path(&args.output)
        ));
    }
    Ok(())
}

/// A colour space other than sRGB needs an EXR output.
/// Tone mapping is for PNG output: an EXR stays linear and unclipped.
fn check_tonemap(output: &Path, tonemap: Tonemap) -> Result<()> {
    if tonemap != Tonemap::Clip && rust_v::io::image::is_exr(output) {
        return Err(Error::Settings(format!(
            "--tonemap {} is for PNG output; {} is an EXR, which stays linear (--exposure applies to both)",
            tonemap.name(),
            show_path(output)
        )));
    }
    Ok(())
}

fn check_color_space(output: &Path, space: ColorSpace) -> Result<()> {
    if space != ColorSpace::Srgb && !rust_v::io::image::is_exr(output) {
        return Err(Error::Settings(format!(
            "--color-space {} needs an .exr output; {} is a PNG, always sRGB",
            space.name(),
            show_path(output)
        )));
    }
    Ok(())
}

/// `--color-space camera` is a sensor file's raw camera RGB: the default sensor has none.
fn check_sensor_space(sensor: &Sensor, space: ColorSpace) -> Result<()> {
    if space == ColorSpace::Camera && sensor.is_cie1931() {
        return Err(Error::Settings(
            "--color-space camera writes a sensor file's raw camera RGB; the sensor is cie1931, whose film holds CIE XYZ (use --color-space xyz, or give --sensor FILE.csv)".into(),
        ));
    }
    Ok(())
}

fn check_output_extension(output: &Path) -> Result<()> {
    match output.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()) {
        Some(e) if e == "png" || e == "exr" => Ok(()),
        _ => Err(Error::Settings(format!("output {}: expected a name ending in .png or .exr", show_path(output)))),
    }
}

/// The checks before a render (see the module docs): outputs creatable and
/// distinct from every input and from each other, snapshot names legal and
/// free, the film within memory; warns when an emitter is brighter than the
/// film's sample range.
fn check_files(
    scene_path: &Path,
    scene: &Scene,
    extra_inputs: &[(&str, &Path)],
    output: &Path,
    checkpoint: &Path,
    spectral: bool,
) -> Result<()> {
    check_output(output, "image")?;
    check_output(checkpoint, "checkpoint")?;
    let mut inputs: Vec<(&str, &Path)> = vec![("scene", scene_path)];
    inputs.extend(scene.inputs.iter().map(|p| ("file the scene reads", p.as_path())));
    inputs.extend_from_slice(extra_inputs);
    let outputs = [("image", output), ("checkpoint", checkpoint)];
    check_aliasing(&inputs, &outputs)?;
    // Snapshots: `stem-NNNNN.png` beside the image, up to ten digits.
    let stem = output.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    if stem.len() + "-4294967295.png".len() > NAME_MAX {
        return Err(Error::Settings(format!(
            "image {}: its snapshots (`{stem}-00128.png`) would have names longer than {NAME_MAX} bytes; choose a shorter name",
            show_path(output)
        )));
    }
    let dir = std::fs::canonicalize(parent_dir(output)).ok();
    for (role, path) in inputs.iter().chain(&outputs[1..]) {
        let same_dir = std::fs::canonicalize(parent_dir(path)).ok() == dir;
        if same_dir && path.file_name().is_some_and(|n| is_snapshot_name(n, &stem)) {
            return Err(Error::Settings(format!(
                "{role} {} has the name of a snapshot of {}: a snapshot would overwrite it",
                show_path(path),
                show_path(output)
            )));
        }
    }
    check_memory(scene.settings.width, scene.settings.height, spectral)?;
    warn_no_effect(scene);
    for (i, light) in scene.lights.iter().enumerate() {
        let peak = light.spectrum().max_value();
        if peak > MAX_SAMPLE {
            // A point, spot, distant or beam light is never seen by the camera: what
            // may be clamped is what it lights.
            let what = if light.is_delta() { "samples it lights brightly" } else { "pixels that see it directly" };
            warn(format_args!(
                "light {i} emits up to {peak:e}, beyond the film's sample range ±{MAX_SAMPLE:e}: {what} are clamped"
            ));
        }
    }
    Ok(())
}

/// Warns about what the scene asks for that cannot happen: a `priority` on an
/// object that is not a dielectric (only dielectric volumes nest), two
/// dielectrics with the same surface, and a scene without any light (the
/// image is black).
fn warn_no_effect(scene: &Scene) {
    // Two dielectric objects with the same surface: a ray meets one of the two surfaces
    // at each crossing, so the medium stack cannot follow (measured: coincident glass and
    // water spheres act as neither). Shapes compared exactly; meshes are not compared.
    let mut seen = std::collections::HashMap::new();
    for (i, o) in scene.objects.iter().enumerate() {
        let dielectric = scene.materials.get(o.material as usize).is_some_and(|m| m.bounds_volume());
        if o.priority != 0 && !dielectric {
            warn(format_args!(
                "objects[{i}].priority: {} has no effect: the object is not a dielectric, and only dielectric volumes nest by priority",
                o.priority
            ));
        }
        if !dielectric || matches!(o.shape, rust_v::shape::Shape::Mesh(_) | rust_v::shape::Shape::Instance(_)) {
            continue;
        }
        if let Some(first) = seen.insert(format!("{:?}", o.shape), i) {
            warn(format_args!(
                "objects[{first}] and objects[{i}] are dielectrics with the same surface: a ray meets only one of two coincident surfaces, so neither volume is rendered right; make one volume overlap the other and give it a higher priority (docs/scene-format.md, Nested dielectrics)"
            ));
        }
    }
    if scene.lights.is_empty() {
        warn(format_args!(
            "the scene has no light (no `lights` and no object with an `emission`): the image will be black"
        ));
    }
}

/// Refuses a render larger than the memory this process may take: the least of
/// what the machine has available, what its address-space limit (`ulimit -v`)
/// leaves and what its cgroup leaves ([`super::memory`]). Not checked where none
/// can be read.
fn check_memory(width: u32, height: u32, spectral: bool) -> Result<()> {
    let need = Film::bytes_needed(width, height, spectral);
    let Some(budget) = super::memory::budget() else { return Ok(()) };
    if need > budget.bytes {
        return Err(Error::Settings(format!(
            "a {width}x{height} render{} needs about {:.1} GB of memory; {} {:.1} GB",
            if spectral { " with --spectral" } else { "" },
            need as f64 / 1e9,
            budget.limit,
            budget.bytes as f64 / 1e9
        )));
    }
    Ok(())
}
