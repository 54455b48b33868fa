//! Tests of the film: exact fixed-point sums, faults, batches against tile-by-tile addition, merging.

use super::*;
use crate::render::tiles;

#[test]
fn non_finite_samples_are_dropped_and_counted() {
    let mut f = Film::new(2, 1);
    let t = Tile { x0: 0, y0: 0, x1: 2, y1: 1 };
    let bad = f.add_tile(&t, &[Xyz::new(f32::NAN, 0.0, 0.0), Xyz::new(1.0, 2.0, 3.0)]);
    assert_eq!(bad, Faults { dropped: 1, clamped: 0 });
    assert_eq!(f.sums, vec![[0; 3], [to_fixed(1.0), to_fixed(2.0), to_fixed(3.0)]]);
}

#[test]
fn fixed_point_is_exact_in_its_range_and_clamps_outside() {
    for v in [1.0f32, 0.1, 3.5e-12, 1e6, -0.25, 2147483648.0] {
        assert_eq!(from_fixed(to_fixed(v)), v as f64, "{v}");
    }
    assert_eq!(to_fixed(1e30), to_fixed(MAX_SAMPLE));
    assert_eq!(to_fixed(1e-25), 0);
    let mut f = Film::new(1, 1);
    let t = Tile { x0: 0, y0: 0, x1: 1, y1: 1 };
    assert_eq!(f.add_tile(&t, &[Xyz::new(1e30, 0.0, 0.0)]), Faults { dropped: 0, clamped: 1 });
}

/// Batches of passes and splats added band by band in parallel give the sums of
/// adding every tile of every pass one at a time, then every splat (odd sizes, partial
/// tiles, an invalid sample and an invalid splat counted once, splats off the film dropped).
#[test]
fn parallel_batches_equal_tile_by_tile_addition() {
    let (w, h, size) = (37, 21, 8);
    let ts = tiles(w, h, size);
    let passes = 3;
    let mut samples: Vec<Vec<Xyz>> = Vec::new();
    for p in 0..passes {
        for (k, t) in ts.iter().enumerate() {
            let v: Vec<Xyz> = (0..t.len())
                .map(|i| {
                    let x = (p * 1000 + k * 37 + i) as f32 * 0.013 - 3.0;
                    Xyz::new(x, x * x, if p == 1 && k == 2 && i == 5 { f32::NAN } else { 1.0 / (1.0 + x) })
                })
                .collect();
            samples.push(v);
        }
    }
    let mut serial = Film::new(w, h);
    let mut invalid = Faults::default();
    for (j, s) in samples.iter().enumerate() {
        invalid += serial.add_tile(&ts[j % ts.len()], s);
    }
    // Splats anywhere, some outside the film (dropped) and one NaN (counted), in lists
    // ordered by band as the renderer makes them.
    let mut splats: Vec<Vec<Splat<Xyz>>> = (0..4)
        .map(|l| {
            (0..50u32)
                .map(|i| {
                    let (x, y) = ((i * 7 + l * 3) % (w + 2), (i * 5 + l * 11) % (h + 3));
                    let v = if l == 2 && i == 9 { f32::NAN } else { (i + l) as f32 * 0.37 - 4.0 };
                    Splat { x, y, value: Xyz::new(v, 0.5 * v, v * v) }
                })
                .collect()
        })
        .collect();
    for l in &splats {
        invalid += serial.add_splats(l);
    }
    splats.iter_mut().for_each(|l| l.sort_by_key(|s| s.y / size));
    let mut parallel = Film::new(w, h);
    assert_eq!(parallel.add_tiles_parallel(&ts, &samples, &splats, size), invalid);
    assert!(invalid.dropped + invalid.clamped >= 2);
    assert_eq!(parallel.sums(), serial.sums());
}

/// f64 sums in another grouping differ; fixed-point sums do not.
#[test]
fn merging_halves_equals_one_accumulation() {
    let t = Tile { x0: 0, y0: 0, x1: 1, y1: 1 };
    // A bright sample, then dim ones each below half an f64 ulp of the sum.
    let samples: Vec<f32> = (0..100).map(|i| if i == 0 { 2f32.powi(30) } else { 2f32.powi(-25) }).collect();
    let mut whole = Film::new(1, 1);
    let (mut a, mut b) = (Film::new(1, 1), Film::new(1, 1));
    b.start_at(50);
    for (i, &v) in samples.iter().enumerate() {
        let x = [Xyz::new(v, v * 0.5, v * 3.0)];
        whole.add_tile(&t, &x);
        whole.end_pass();
        let part = if i < 50 { &mut a } else { &mut b };
        part.add_tile(&t, &x);
        part.end_pass();
    }
    let mut ab = a.clone();
    ab.merge(&b).unwrap();
    assert_eq!(ab, whole);
    assert!(a.clone().merge(&a).is_err(), "overlap refused");
    // The f64 way differs in the last bits for these samples.
    let seq: f64 = samples.iter().fold(0.0, |s, &v| s + v as f64);
    let halves: f64 =
        samples[..50].iter().fold(0.0, |s, &v| s + v as f64) + samples[50..].iter().fold(0.0, |s, &v| s + v as f64);
    assert_ne!(seq, halves, "f64 grouping matters for these samples");
}

/// The bit-level conversion equals the straightforward f64 one
/// (`round(v · 2^64)`, halves away from zero) on every exponent, both
/// signs, the clamp bounds, zero and subnormals.
#[test]
fn to_fixed_matches_the_f64_definition() {
    let reference = |v: f32| (v.clamp(-MAX_SAMPLE, MAX_SAMPLE) as f64 * SCALE).round() as i128;
    let mut values =
        vec![0.0f32, -0.0, 1.0, -1.0, 0.5, 3.0e-20, 5.4e-20, 1e-30, f32::MIN_POSITIVE, 1e-45, 2.0e9, -3.0e9, 1e30];
    let mut x = 0x1234_5678u32;
    for _ in 0..100_000 {
        // xorshift32 over all bit patterns, finite ones only
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        let v = f32::from_bits(x);
        if v.is_finite() {
            values.push(v);
        }
    }
    for e in -80..40 {
        values.push(2f32.powi(e) * 1.5);
        values.push(-(2f32.powi(e) * 1.25));
    }
    for v in values {
        assert_eq!(to_fixed(v), reference(v), "v = {v:e}");
    }
}
