//! Checkpoints: a film's whole passes plus everything needed to resume or
//! merge them, in a small versioned, checksummed file.
//!
//! A render can be stopped and resumed, or split into pass ranges rendered
//! by different processes and merged, with bit-identical results: the
//! sampler is keyed by `(seed, pixel, pass)` (the crate-internal `sampler`) and the
//! film's fixed-point sums are exactly associative ([`crate::film`]), so a
//! checkpoint only has to hold whole passes, their range, the settings, and
//! which scene they belong to.
//!
//! # File format (version 5)
//! All integers little-endian.
//!
//! | bytes | content |
//! |-------|---------|
//! | 8 | magic `RUSTVCKP` |
//! | 4 | format version (`u32`, [`FORMAT_VERSION`]) |
//! | 4 | header length `H` (`u32`) |
//! | 8 | payload length `P` (`u64`) |
//! | 8 | checksum: FNV-1a 64 of the header and payload bytes |
//! | H | header: bincode (standard config) of the writer's crate version, the scene file's absolute path and content hash, all [`Settings`], the pass range held, the target pass, the output path, then [`InputHashes`]: the scene file's hash and each file it reads (name in the scene, hash) |
//! | P | payload: lz4_flex block (size prepended) of bincode of the film: width, height and 3 fixed-point `i128` sums per pixel |
//!
//! A spectral film (`--spectral`) is written as version 6 ([`SPECTRAL_FORMAT_VERSION`]): the
//! same layout, its payload followed (inside the same lz4 block) by `width × height × 36`
//! fixed-point per-bin sums.
//!
//! A film made with a sensor file (`--sensor`, [`crate::color::Sensor`]) is written as version 7
//! ([`SENSOR_FORMAT_VERSION`]): version 5 whose header also holds the sensor, its name and the
//! file's whole text, after the inputs' hashes. A resume projects on exactly that sensor (the
//! file need not exist any more), and merging films of different sensors is refused. Renders with
//! the default sensor write versions 5 and 6, byte for byte as before.
//!
//! Versions 1 (colour) and 2 (spectral), written before the `sampler` setting existed,
//! are still read: their header's settings end before `sampler`, and they resume and
//! merge as `sampler: independent`, the sampler that wrote them (the independent
//! sampler's numbers are unchanged, so such a resume is bit-exact). Versions 3 and 4
//! are versions 1 and 2 with the sampler's name after the other settings. Versions 5 and
//! 6 are versions 3 and 4 with each input's hash after the header ([`InputHashes`]), so
//! that `resume` names exactly the inputs that changed; versions 1 to 4 still load, with
//! [`Checkpoint::inputs`] `None` (and such a checkpoint is written as version 3 or 4). A
//! rust-v that predates a version refuses it with its "format version" error.
//!
//! Reading checks the magic, the version, the exact length (a truncated
//! file is reported as such), the checksum, then decodes and validates every
//! field; any failure is an [`Error::Checkpoint`] naming the file. Writing
//! goes through [`crate::io::write_atomic`], so the file on disk is always a
//! complete old or new checkpoint. bincode is used in this module only.

use std::ops::Range;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::color::N_BINS;
use crate::error::{Error, Result, show_path};
use crate::film::Film;
use crate::io::Fnv1a;
use crate::io::write_atomic;
use crate::settings::{Settings, SettingsFormat1};

/// The first 8 bytes of every checkpoint.
pub const MAGIC: [u8; 8] = *b"RUSTVCKP";

/// The format version this build writes for colour-only films, and reads.
pub const FORMAT_VERSION: u32 = 5;

/// The format version of a spectral film's checkpoint (`--spectral`): version 5 whose payload
/// also holds 36 fixed-point per-bin sums per pixel after the XYZ sums. Colour-only renders
/// write version 5, so their checkpoints stay as small as before.
pub const SPECTRAL_FORMAT_VERSION: u32 = 6;

/// The format version of a colour film made with a sensor file: version 5 whose header also
/// holds the sensor (its name and the file's text).
pub const SENSOR_FORMAT_VERSION: u32 = 7;

/// The versions written before the `sampler` setting (colour, spectral): read, never written.
pub const FORMAT_1_VERSIONS: [u32; 2] = [1, 2];

/// The versions with the sampler but one hash over all inputs (colour, spectral): read, and
/// written only for a checkpoint without per-input hashes ([`Checkpoint::inputs`] `None`).
pub const FORMAT_3_VERSIONS: [u32; 2] = [3, 4];

/// The identity of each input of a scene, for saying which one changed: the scene
/// file's FNV-1a hash, and each file it reads by its name as written in the scene
/// and the FNV-1a hash of its bytes, in the order read.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct InputHashes {
    /// FNV-1a of the scene file's bytes.
    pub scene: u64,
    /// Each file the scene reads (meshes, data): its name in the scene, FNV-1a of its bytes.
    pub files: Vec<(String, u64)>,
}

/// What changed between the inputs a checkpoint recorded (`old`) and the scene's now
/// (`new`): one phrase per changed input, the scene file first (named by `scene`), then
/// each file by its path (its name in the scene, relative to the scene's folder). Empty
/// when nothing differs.
pub fn changed_inputs(old: &InputHashes, new: &InputHashes, scene: &Path) -> Vec<String> {
    let dir = scene.parent().unwrap_or(Path::new(""));
    let file = |name: &str| show_path(&dir.join(name)).to_string();
    let mut changed = Vec::new();
    if old.scene != new.scene {
        changed.push(format!("the scene file {}", show_path(scene)));
    }
    let find = |list: &[(String, u64)], name: &str| list.iter().find(|(n, _)| n == name).map(|&(_, h)| h);
    let mut seen = std::collections::BTreeSet::new();
    for (name, hash) in &new.files {
        if !seen.insert(name.as_str()) {
            continue;
        }
        match find(&old.files, name) {
            Some(h) if h == *hash => {}
            Some(_) => changed.push(file(name)),
            None => changed.push(format!("{} (not read before)", file(name))),
        }
    }
    for (name, _) in &old.files {
        if find(&new.files, name).is_none() && seen.insert(name.as_str()) {
            changed.push(format!("{} (no longer read)", file(name)));
        }
    }
    changed
}

/// Bytes before the header: magic, version, two lengths, checksum.
const PREFIX_LEN: usize = 32;

/// Headers larger than this are refused (they hold two paths and some numbers).
const MAX_HEADER_LEN: u32 = 1 << 20;

/// A film with what it takes to resume or merge it.
#[derive(Clone, Debug, PartialEq)]
pub struct Checkpoint {
    /// The version of rust-v that wrote it.
    pub crate_version: String,
    /// The scene file (absolute path).
    pub scene_path: PathBuf,
    /// The scene file's content hash ([`crate::scene::Scene::content_hash`]).
    pub content_hash: u64,
    /// All render settings (after command-line overrides).
    pub settings: Settings,
    /// The pass the render was heading for: resume continues to it by default.
    pub target_end: u32,
    /// The image the render was writing.
    pub output: PathBuf,
    /// The passes done so far.
    pub film: Film,
    /// Each input's hash (versions 5 and 6), to name the inputs that changed; `None`
    /// when read from an older version, which holds only [`Checkpoint::content_hash`]
    /// (such a checkpoint is written as version 3 or 4 again).
    pub inputs: Option<InputHashes>,
}

/// The header as encoded. [`Settings`] encodes field by field with its enums
/// as names, so this is byte for byte the layout format 1 has always had, with
/// the sampler after the other settings (`S = SettingsFormat1` reads format 1).
#[derive(Serialize, Deserialize)]
struct Header<S = Settings> {
    crate_version: String,
    scene_path: PathBuf,
    content_hash: u64,
    settings: S,
    first_pass: u32,
    end_pass: u32,
    target_end: u32,
    output: PathBuf,
}

/// The header of versions 5 and 6: version 3's, then each input's hash.
#[derive(Serialize, Deserialize)]
struct HeaderWithInputs {
    header: Header,
    inputs: InputHashes,
}

/// The sensor of a version 7 checkpoint: its name (the file as given) and the file's text.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct SensorRecord {
    name: String,
    csv: String,
}

/// The header of version 7: version 5's, then the sensor.
#[derive(Serialize, Deserialize)]
struct HeaderWithSensor {
    header: Header,
    inputs: InputHashes,
    sensor: SensorRecord,
}

#[derive(Serialize)]
struct PayloadRef<'a> {
    width: u32,
    height: u32,
    sums: &'a [[i128; 3]],
}

#[derive(Deserialize)]
struct Payload {
    width: u32,
    height: u32,
    sums: Vec<[i128; 3]>,
}

#[derive(Serialize)]
struct SpectralPayloadRef<'a> {
    width: u32,
    height: u32,
    sums: &'a [[i128; 3]],
    /// Pixel-major, 36 bins per pixel (serde has no 36-element arrays).
    spectral: &'a [i128],
}

#[derive(Deserialize)]
struct SpectralPayload {
    width: u32,
    height: u32,
    sums: Vec<[i128; 3]>,
    spectral: Vec<i128>,
}

/// FNV-1a 64-bit over several byte strings in turn.
fn checksum(parts: &[&[u8]]) -> u64 {
    let mut h = Fnv1a::default();
    for part in parts {
        h.write(part);
    }
    h.finish()
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    let mut a = [0; 4];
    a.copy_from_slice(&b[at..at + 4]);
    u32::from_le_bytes(a)
}

fn u64_at(b: &[u8], at: usize) -> u64 {
    let mut a = [0; 8];
    a.copy_from_slice(&b[at..at + 8]);
    u64::from_le_bytes(a)
}

impl Checkpoint {
    /// The passes held.
    pub fn passes(&self) -> Range<u32> {
        self.film.pass_range()
    }

    /// The file's bytes.
    pub fn encode(&self) -> Result<Vec<u8>> {
        self.encode_with(&self.film)
    }

    /// The file's bytes with `film` in place of this checkpoint's own (a
    /// render in progress writes its film without copying it).
    pub fn encode_with(&self, film: &Film) -> Result<Vec<u8>> {
        let range = film.pass_range();
        let header = Header {
            crate_version: self.crate_version.clone(),
            scene_path: self.scene_path.clone(),
            content_hash: self.content_hash,
            settings: self.settings.clone(),
            first_pass: range.start,
            end_pass: range.end,
            target_end: self.target_end,
            output: self.output.clone(),
        };
        let config = bincode::config::standard();
        let encode_error =
            |e: bincode::error::EncodeError| Error::checkpoint(&self.output, format!("cannot encode: {e}"));
        let sensor = film.sensor().csv().map(|csv| SensorRecord { name: film.sensor().name().into(), csv: csv.into() });
        let header = match (&self.inputs, &sensor) {
            (inputs, Some(sensor)) => bincode::serde::encode_to_vec(
                HeaderWithSensor { header, inputs: inputs.clone().unwrap_or_default(), sensor: sensor.clone() },
                config,
            ),
            (Some(inputs), None) => {
                bincode::serde::encode_to_vec(HeaderWithInputs { header, inputs: inputs.clone() }, config)
            }
            (None, None) => bincode::serde::encode_to_vec(&header, config),
        }
        .map_err(encode_error)?;
        let (width, height, sums) = (film.width(), film.height(), film.sums());
        let [colour_version, spectral_version] =
            if self.inputs.is_some() { [FORMAT_VERSION, SPECTRAL_FORMAT_VERSION] } else { FORMAT_3_VERSIONS };
        let (version, raw) = match film.spectral_sums() {
            None if sensor.is_some() => {
                (SENSOR_FORMAT_VERSION, bincode::serde::encode_to_vec(PayloadRef { width, height, sums }, config))
            }
            None => (colour_version, bincode::serde::encode_to_vec(PayloadRef { width, height, sums }, config)),
            Some(spectral) => (
                spectral_version,
                bincode::serde::encode_to_vec(
                    SpectralPayloadRef { width, height, sums, spectral: spectral.as_flattened() },
                    config,
                ),
            ),
        };
        let payload = lz4_flex::compress_prepend_size(&raw.map_err(encode_error)?);
        let mut out = Vec::with_capacity(PREFIX_LEN + header.len() + payload.len());
        out.extend_from_slice(&MAGIC);
        out.extend_from_slice(&version.to_le_bytes());
        out.extend_from_slice(&(header.len() as u32).to_le_bytes());
        out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
        out.extend_from_slice(&checksum(&[&header, &payload]).to_le_bytes());
        out.extend_from_slice(&header);
        out.extend_from_slice(&payload);
        Ok(out)
    }

    /// Parses a checkpoint's bytes; `path` names the file in errors.
    pub fn decode(bytes: &[u8], path: &Path) -> Result<Checkpoint> {
        let bad = |m: String| Error::checkpoint(path, m);
        if bytes.len() < MAGIC.len() && MAGIC.starts_with(bytes) {
            return Err(bad(format!("truncated: {} bytes, not even the magic number", bytes.len())));
        }
        if !bytes.starts_with(&MAGIC) {
            return Err(bad("not a rust-v checkpoint (no RUSTVCKP magic number at the start)".into()));
        }
        if bytes.len() < PREFIX_LEN {
            return Err(bad(format!("truncated: {} bytes, the fixed header alone is {PREFIX_LEN}", bytes.len())));
        }
        let version = u32_at(bytes, 8);
        if !(1..=SENSOR_FORMAT_VERSION).contains(&version) {
            return Err(bad(format!(
                "format version {version}; this rust-v ({}) reads versions 1 to {SENSOR_FORMAT_VERSION}",
                env!("CARGO_PKG_VERSION")
            )));
        }
        let spectral = [2, 4, SPECTRAL_FORMAT_VERSION].contains(&version);
        let format_1 = FORMAT_1_VERSIONS.contains(&version);
        let format_3 = FORMAT_3_VERSIONS.contains(&version);
        let header_len = u32_at(bytes, 12);
        let payload_len = u64_at(bytes, 16);
        if header_len > MAX_HEADER_LEN {
            return Err(bad(format!("corrupt: header length {header_len} is implausible")));
        }
        let expected = (PREFIX_LEN as u64 + header_len as u64).saturating_add(payload_len);
        if (bytes.len() as u64) < expected {
            return Err(bad(format!("truncated: {} bytes of the {expected} its header announces", bytes.len())));
        }
        if bytes.len() as u64 > expected {
            return Err(bad(format!(
                "corrupt: {} bytes, {} more than its header announces",
                bytes.len(),
                bytes.len() as u64 - expected
            )));
        }
        let header_bytes = &bytes[PREFIX_LEN..PREFIX_LEN + header_len as usize];
        let payload_bytes = &bytes[PREFIX_LEN + header_len as usize..];
        if checksum(&[header_bytes, payload_bytes]) != u64_at(bytes, 24) {
            return Err(bad("corrupt: checksum mismatch (the file was damaged after it was written)".into()));
        }

        let config = bincode::config::standard();
        let header_config = config.with_limit::<{ 1 << 20 }>();
        let corrupt_header = |e: bincode::error::DecodeError| bad(format!("corrupt header: {e}"));
        let mut inputs = None;
        let mut sensor = None;
        let (h, used): (Header, usize) = if version == SENSOR_FORMAT_VERSION {
            let (h, used): (HeaderWithSensor, usize) =
                bincode::serde::decode_from_slice(header_bytes, header_config).map_err(corrupt_header)?;
            inputs = Some(h.inputs);
            sensor = Some(h.sensor);
            (h.header, used)
        } else if format_1 {
            let (h, used): (Header<SettingsFormat1>, usize) =
                bincode::serde::decode_from_slice(header_bytes, header_config).map_err(corrupt_header)?;
            let Header { crate_version, scene_path, content_hash, settings, first_pass, end_pass, target_end, output } =
                h;
            let settings = settings.into();
            (
                Header { crate_version, scene_path, content_hash, settings, first_pass, end_pass, target_end, output },
                used,
            )
        } else if format_3 {
            bincode::serde::decode_from_slice(header_bytes, header_config).map_err(corrupt_header)?
        } else {
            let (h, used): (HeaderWithInputs, usize) =
                bincode::serde::decode_from_slice(header_bytes, header_config).map_err(corrupt_header)?;
            inputs = Some(h.inputs);
            (h.header, used)
        };
        if used != header_bytes.len() {
            return Err(bad("corrupt header: trailing bytes".into()));
        }
        let settings = h.settings;
        if let Err(e) = settings.check() {
            return Err(bad(format!("corrupt header: {e}")));
        }
        if h.end_pass < h.first_pass {
            return Err(bad("corrupt header: invalid pass range".into()));
        }

        // The decompressed size is prepended; bound it by what the film can need
        // (17 bytes per varint i128) before allocating.
        let pixels = settings.width as u64 * settings.height as u64;
        let limit = pixels * if spectral { 3 + N_BINS as u64 } else { 3 } * 17 + 64;
        if payload_bytes.len() < 4 || u32_at(payload_bytes, 0) as u64 > limit {
            return Err(bad("corrupt payload: implausible size".into()));
        }
        let raw = lz4_flex::decompress_size_prepended(payload_bytes)
            .map_err(|e| bad(format!("corrupt payload: does not decompress: {e}")))?;
        let corrupt = |e: bincode::error::DecodeError| bad(format!("corrupt payload: {e}"));
        let (p, spectral_sums, used) = if spectral {
            let (p, used): (SpectralPayload, usize) =
                bincode::serde::decode_from_slice(&raw, config).map_err(corrupt)?;
            if p.spectral.len() != p.sums.len() * N_BINS {
                return Err(bad("corrupt payload: spectral sums do not match the size".into()));
            }
            let bins: Vec<[i128; N_BINS]> =
                p.spectral.chunks_exact(N_BINS).map(|c| std::array::from_fn(|b| c[b])).collect();
            (Payload { width: p.width, height: p.height, sums: p.sums }, Some(bins), used)
        } else {
            let (p, used): (Payload, usize) = bincode::serde::decode_from_slice(&raw, config).map_err(corrupt)?;
            (p, None, used)
        };
        if used != raw.len() || (p.width, p.height) != (settings.width, settings.height) {
            return Err(bad("corrupt payload: size does not match the header".into()));
        }
        let mut film = Film::from_parts(p.width, p.height, h.first_pass..h.end_pass, p.sums)
            .map_err(|e| bad(format!("corrupt payload: {e}")))?;
        if let Some(s) = spectral_sums {
            film = film.with_spectral_sums(s).map_err(|e| bad(format!("corrupt payload: {e}")))?;
        }
        if let Some(SensorRecord { name, csv }) = sensor {
            let s = crate::color::Sensor::from_csv(&name, &csv, Path::new(&name))
                .map_err(|e| bad(format!("corrupt header: its sensor: {e}")))?;
            film.set_sensor(std::sync::Arc::new(s)).map_err(|e| bad(format!("corrupt header: {e}")))?;
        }
        Ok(Checkpoint {
            crate_version: h.crate_version,
            scene_path: h.scene_path,
            content_hash: h.content_hash,
            settings,
            target_end: h.target_end,
            output: h.output,
            film,
            inputs,
        })
    }

    /// Writes the checkpoint atomically (never a partial file under `path`);
    /// returns its size in bytes.
    pub fn write(&self, path: &Path) -> Result<u64> {
        self.write_with(&self.film, path)
    }

    /// [`Checkpoint::write`] with `film` in place of this checkpoint's own.
    pub fn write_with(&self, film: &Film, path: &Path) -> Result<u64> {
        let bytes = self.encode_with(film)?;
        write_atomic(path, &bytes)?;
        Ok(bytes.len() as u64)
    }

    /// Reads and verifies a checkpoint file.
    pub fn read(path: &Path) -> Result<Checkpoint> {
        let bytes = crate::io::read_input(path)?;
        Checkpoint::decode(&bytes, path)
    }

    /// Why `other` cannot be merged with `self`: a different scene, or
    /// different settings other than the target `spp` (which does not change
    /// any sample).
    pub fn incompatibility(&self, other: &Checkpoint) -> Option<String> {
        if self.content_hash != other.content_hash {
            return Some(format!(
                "different scene: {} (content hash {:016x}) vs {} (content hash {:016x})",
                show_path(&other.scene_path),
                other.content_hash,
                show_path(&self.scene_path),
                self.content_hash
            ));
        }
        let diffs = self.settings.differences(&other.settings);
        if !diffs.is_empty() {
            return Some(format!("different settings: {}", diffs.join(", ")));
        }
        let (mine, theirs) = (self.film.sensor(), other.film.sensor());
        (mine != theirs).then(|| {
            let same_name = mine.name() == theirs.name();
            format!(
                "different sensors: {} vs {}{}",
                theirs.name(),
                mine.name(),
                if same_name { " (the same name, different curves)" } else { "" }
            )
        })
    }
}

/// Merges checkpoints of disjoint pass ranges of one scene and settings, in
/// any order, into one whose film is bit-identical to a single render of the
/// combined range. The ranges must tile a contiguous range: overlaps, gaps,
/// different scenes or different settings are refused, naming the file.
pub fn merge(mut parts: Vec<(PathBuf, Checkpoint)>) -> Result<Checkpoint> {
    if parts.is_empty() {
        return Err(Error::Settings("merge: no checkpoints given".into()));
    }
    parts.retain(|(_, c)| c.film.passes() > 0);
    if parts.is_empty() {
        return Err(Error::Settings("merge: every checkpoint is empty (0 passes)".into()));
    }
    parts.sort_by_key(|(_, c)| c.passes().start);
    let (first_path, first) = &parts[0];
    let mut merged = first.clone();
    let mut prev_path = first_path.clone();
    for (path, c) in &parts[1..] {
        if let Some(why) = merged.incompatibility(c) {
            return Err(Error::checkpoint(path, format!("cannot be merged with {}: {why}", show_path(first_path))));
        }
        let (have, next) = (merged.passes(), c.passes());
        if next.start < have.end {
            return Err(Error::checkpoint(
                path,
                format!(
                    "its passes {}..{} overlap passes {}..{} of {}",
                    next.start,
                    next.end,
                    have.start,
                    have.end,
                    show_path(&prev_path)
                ),
            ));
        }
        if next.start > have.end {
            return Err(Error::checkpoint(
                path,
                format!(
                    "passes {}..{} are missing between {} (ends at {}) and this file (starts at {})",
                    have.end,
                    next.start,
                    show_path(&prev_path),
                    have.end,
                    next.start
                ),
            ));
        }
        merged.film.merge(&c.film).map_err(|e| Error::checkpoint(path, e.to_string()))?;
        merged.target_end = merged.target_end.max(c.target_end);
        merged.settings.spp = merged.settings.spp.max(c.settings.spp);
        prev_path = path.clone();
    }
    merged.target_end = merged.target_end.max(merged.passes().end);
    Ok(merged)
}

/// `dir/stem-00128.png` for `dir/stem.ext` after 128 passes: a snapshot's name.
pub fn snapshot_path(output: &Path, passes: u32) -> PathBuf {
    let stem = output.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "render".into());
    output.with_file_name(format!("{stem}-{passes:05}.png"))
}

/// `dir/stem.ckpt` for `dir/stem.ext`: where a render checkpoints by default.
pub fn default_checkpoint_path(output: &Path) -> PathBuf {
    output.with_extension("ckpt")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::color::Xyz;
    use crate::render::tiles;

    fn sample() -> Checkpoint {
        let mut film = Film::new(5, 3);
        for (i, t) in tiles(5, 3, 2).iter().enumerate() {
            let s: Vec<Xyz> = (0..t.len()).map(|k| Xyz::new(i as f32 * 0.3, k as f32 + 0.1, 1e-3)).collect();
            film.add_tile(t, &s);
        }
        film.start_at(7);
        film.end_pass();
        Checkpoint {
            crate_version: env!("CARGO_PKG_VERSION").into(),
            scene_path: "/scenes/x.ron".into(),
            content_hash: 0x1234,
            settings: Settings { width: 5, height: 3, ..Settings::default() },
            target_end: 20,
            output: "/out/x.png".into(),
            film,
            inputs: Some(InputHashes { scene: 7, files: vec![("mesh.obj".into(), 8), ("refl.csv".into(), 9)] }),
        }
    }

    #[test]
    fn round_trip() {
        let c = sample();
        let bytes = c.encode().unwrap();
        assert_eq!(Checkpoint::decode(&bytes, Path::new("x.ckpt")).unwrap(), c);
    }

    #[test]
    fn every_truncation_and_every_flipped_byte_is_a_clear_error() {
        let bytes = sample().encode().unwrap();
        let p = Path::new("dir/x.ckpt");
        for n in 0..bytes.len() {
            let e = Checkpoint::decode(&bytes[..n], p).unwrap_err().to_string();
            assert!(e.starts_with("checkpoint dir/x.ckpt: ") && e.contains("truncated"), "{n}: {e}");
        }
        for i in 0..bytes.len() {
            let mut b = bytes.clone();
            b[i] ^= 0x10;
            let e = Checkpoint::decode(&b, p).unwrap_err().to_string();
            assert!(e.starts_with("checkpoint dir/x.ckpt: "), "{i}: {e}");
        }
        let e = Checkpoint::decode(b"\x89PNG\r\n\x1a\n and more", p).unwrap_err().to_string();
        assert!(e.contains("not a rust-v checkpoint"), "{e}");
    }

    /// The sampler is part of the settings a checkpoint records: a `sobol` and an
    /// `independent` part do not merge; an unknown format version is a clear error.
    #[test]
    fn the_sampler_is_recorded_and_versions_are_checked() {
        use crate::settings::SamplerKind;
        let c = sample();
        let mut other = c.clone();
        other.settings.sampler = match c.settings.sampler {
            SamplerKind::Sobol => SamplerKind::Independent,
            SamplerKind::Independent => SamplerKind::Sobol,
        };
        let bytes = other.encode().unwrap();
        assert_eq!(u32_at(&bytes, 8), FORMAT_VERSION);
        assert_eq!(Checkpoint::decode(&bytes, Path::new("o.ckpt")).unwrap().settings, other.settings);
        assert!(c.incompatibility(&other).is_some_and(|why| why.contains("sampler")));
        let mut bytes = c.encode().unwrap();
        bytes[8..12].copy_from_slice(&8u32.to_le_bytes());
        let e = Checkpoint::decode(&bytes, Path::new("x.ckpt")).unwrap_err().to_string();
        assert!(e.contains("format version 8") && e.contains("reads versions 1 to 7"), "{e}");
    }

    /// Versions 5 and 6 keep each input's hash; a checkpoint without them (read from an
    /// older version) is written as version 3 and reads back without them.
    #[test]
    fn per_input_hashes_and_version_3() {
        let c = sample();
        let bytes = c.encode().unwrap();
        assert_eq!(u32_at(&bytes, 8), FORMAT_VERSION);
        assert_eq!(Checkpoint::decode(&bytes, Path::new("x.ckpt")).unwrap().inputs, c.inputs);
        let old = Checkpoint { inputs: None, ..c.clone() };
        let bytes = old.encode().unwrap();
        assert_eq!(u32_at(&bytes, 8), 3);
        assert_eq!(Checkpoint::decode(&bytes, Path::new("x.ckpt")).unwrap(), old);
    }

    /// A film of a sensor file is version 7, holding the sensor's text: it reads back with the
    /// same sensor (its curves and matrix), and does not merge with a default-sensor part.
    #[test]
    fn the_sensor_is_recorded() {
        let c = sample();
        let text = "wavelength_nm,r,g,b\n400,0,0.2,1\n500,0.1,1,0.2\n600,1,0.3,0\n700,0.5,0,0\n";
        let sensor = crate::color::Sensor::from_csv("s.csv", text, Path::new("s.csv")).unwrap();
        let mut with = c.clone();
        with.film.set_sensor(std::sync::Arc::new(sensor)).unwrap();
        let bytes = with.encode().unwrap();
        assert_eq!(u32_at(&bytes, 8), SENSOR_FORMAT_VERSION);
        let back = Checkpoint::decode(&bytes, Path::new("x.ckpt")).unwrap();
        assert_eq!(back, with);
        assert_eq!(back.film.sensor().csv(), Some(text));
        let why = c.incompatibility(&with).unwrap();
        assert!(why.contains("different sensors: s.csv vs cie1931"), "{why}");
        assert!(merge(vec![("a.ckpt".into(), with), ("b.ckpt".into(), c)]).is_err());
    }

    /// Exactly the inputs whose hash differs are named, the scene file by its path.
    #[test]
    fn changed_inputs_names_exactly_the_changed_ones() {
        let files = |v: &[(&str, u64)]| v.iter().map(|&(n, h)| (n.to_string(), h)).collect();
        let old = InputHashes { scene: 1, files: files(&[("a.obj", 2), ("b.csv", 3), ("c.ply", 4)]) };
        let scene = Path::new("d/s.ron");
        assert!(changed_inputs(&old, &old, scene).is_empty());
        let new = InputHashes { scene: 1, files: files(&[("a.obj", 2), ("b.csv", 30), ("d.ply", 5)]) };
        assert_eq!(
            changed_inputs(&old, &new, scene),
            ["d/b.csv", "d/d.ply (not read before)", "d/c.ply (no longer read)"]
        );
        let new = InputHashes { scene: 10, ..old.clone() };
        assert_eq!(changed_inputs(&old, &new, scene), ["the scene file d/s.ron"]);
    }

    #[test]
    fn names() {
        assert_eq!(snapshot_path(Path::new("out/cornell.png"), 128), Path::new("out/cornell-00128.png"));
        assert_eq!(default_checkpoint_path(Path::new("out/cornell.exr")), Path::new("out/cornell.ckpt"));
    }
}
