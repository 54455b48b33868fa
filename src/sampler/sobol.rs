//! Owen-scrambled, shuffled Sobol points: the low-discrepancy sampler (`--sampler sobol`).
//!
//! Every draw ([`super::Dim`]) of sample `i` (the pass index) in a pixel is a point of
//! the first two dimensions of the Sobol sequence, which form a (0,2)-sequence in base 2:
//! any `2^m` consecutive points that start at a multiple of `2^m` have exactly one point
//! in each elementary interval `[a/2^k, (a+1)/2^k) × [b/2^(m-k), (b+1)/2^(m-k))`. A 1D
//! draw uses the first dimension (the van der Corput sequence) alone. Different draws are
//! decorrelated by *padding* (Kollig and Keller 2002; pbrt-v4's `PaddedSobolSampler`;
//! Burley 2020, "Practical Hash-based Owen Scrambling", JCGT 9(4), §4):
//! - the sample index is **shuffled** by a nested uniform scramble of its bits read from
//!   the most significant one down, seeded by `(seed, pixel, draw)`. Bit `k` of the index
//!   then flips by a hash of the bits above it, so the indices `0..2^m` (and every aligned
//!   block of `2^m`) map onto one aligned block of `2^m` indices: every prefix of a
//!   power-of-two length is still a (0,m,2)-net, and the order does not depend on the
//!   sample count (so `--passes`, resume and merge need no knowledge of the final spp);
//! - each coordinate is **Owen-scrambled** (nested uniform scrambling in base 2) by a
//!   hash seeded by `(seed, pixel, draw, coordinate)`: bit `k` below the binary point flips
//!   by a hash of the bits above it. Such a permutation maps elementary intervals onto
//!   elementary intervals, so the net property survives, and it decorrelates pixels.
//!
//! # Unbiased
//! The scramble starts by adding its seed modulo `2^32` (then only bijections follow), so
//! for a uniformly random seed each coordinate is uniform on the `2^32` grid, and the two
//! coordinates of a 2D draw have independent seeds: every single point is uniform over
//! `[0, 1)²` (at 24-bit resolution, as the independent sampler). The seeds are hashes of
//! `(seed, pixel, draw)`, as the independent sampler's stream is a hash of
//! `(seed, pixel, pass)`. Points of the same pixel are correlated on purpose (stratified).
//!
//! # Sample counts that are not powers of two
//! Any spp works and stays unbiased. What is lost: only the first `2^⌊log2 spp⌋` samples
//! of a pixel form a complete net per draw; the remaining `spp − 2^⌊log2 spp⌋` are part of
//! the next net, well spread but not one per stratum, so the error is about that of the
//! power of two below plus an independent-like remainder (e.g. 96 spp converges like 64
//! stratified samples plus 32 partly stratified ones).
//!
//! # The direction numbers
//! Dimension 0 is the identity matrix (bit reversal of the index). Dimension 1 comes from
//! the first line of Joe and Kuo's `new-joe-kuo-6.21201` table (S. Joe and F. Y. Kuo,
//! "Constructing Sobol sequences with better two-dimensional projections", SIAM J. Sci.
//! Comput. 30, 2008): `d = 2, s = 1, a = 0, m_1 = 1` (the primitive polynomial `x + 1`),
//! expanded here to 32 direction numbers by the recurrence of their paper, eq. (3). Only
//! these two dimensions are used (every draw is padded), so the table has one line. That
//! matrix is Pascal's triangle mod 2 (column `k` has a 1 in row `j` when `j ⊆ k` bitwise,
//! Lucas's theorem), so the sampler computes it without the table: row `j` of the product
//! is the XOR of the index bits at the supersets of `j`, five shift-and-XOR steps
//! ([`sobol_1_reversed`]); a test checks it against the table for every column.
//!
//! # Cost
//! Each draw costs one 64-bit hash, and per coordinate two or three bit reversals and a
//! four-multiply scramble (no loops, no tables). The first measurement used a loop over
//! the index bits for dimension 1 and full bit reversals at every step; on a 64×64
//! Cornell box it took 1.7x the independent sampler's time per sample (see docs/integrators.md,
//! *Samplers*), which is what this form is for.

/// One line of Joe and Kuo's table: degree `s`, coefficients `a`, initial `m_1 … m_s`.
#[cfg(test)]
const JOE_KUO_DIM_2: (u32, u32, [u32; 1]) = (1, 0, [1]);

/// The 32 direction numbers `v_k = m_k · 2^(32−k)` of one Sobol dimension from its line of
/// Joe and Kuo's table: `m_k = 2 a_1 m_{k−1} ⊕ 4 a_2 m_{k−2} ⊕ … ⊕ 2^s m_{k−s} ⊕ m_{k−s}`
/// for `k > s`, with `a_j` the bits of `a` (most significant first, `s − 1` of them).
#[cfg(test)]
const fn direction_numbers(s: u32, a: u32, m_init: &[u32]) -> [u32; 32] {
    let mut m = [0u32; 32];
    let mut k = 0;
    while k < 32 {
        if k < s as usize {
            m[k] = m_init[k];
        } else {
            let s = s as usize;
            let mut v = m[k - s] ^ (m[k - s] << s);
            let mut j = 1;
            while j < s {
                let a_j = (a >> (s - 1 - j)) & 1;
                if a_j == 1 {
                    v ^= m[k - j] << j;
                }
                j += 1;
            }
            m[k] = v;
        }
        k += 1;
    }
    let mut out = [0u32; 32];
    let mut k = 0;
    while k < 32 {
        out[k] = m[k] << (31 - k);
        k += 1;
    }
    out
}

/// Sobol dimension 1's generator matrix, one column per index bit.
#[cfg(test)]
const DIM_1: [u32; 32] = direction_numbers(JOE_KUO_DIM_2.0, JOE_KUO_DIM_2.1, &JOE_KUO_DIM_2.2);

/// Sobol dimension 0 of point `i`, as a 32-bit fraction: the van der Corput sequence
/// (the definition, for tests).
#[cfg(test)]
pub fn sobol_0(i: u32) -> u32 {
    i.reverse_bits()
}

/// Sobol dimension 1 of point `i`, as a 32-bit fraction, from the table (the definition,
/// for tests; the sampler uses [`sobol_1_reversed`]).
#[cfg(test)]
pub fn sobol_1(mut i: u32) -> u32 {
    let mut x = 0;
    let mut k = 0;
    while i != 0 {
        if i & 1 == 1 {
            x ^= DIM_1[k];
        }
        i >>= 1;
        k += 1;
    }
    x
}

/// Sobol dimension 1 of point `i` with its bits reversed (bit `j` = the digit `2^-(j+1)`):
/// digit `j` is the XOR of the bits `i_k` with `k ⊇ j` (Pascal's matrix mod 2), a superset
/// transform over the five bits of the position, one shift-and-XOR per bit.
#[inline]
pub fn sobol_1_reversed(mut i: u32) -> u32 {
    i ^= (i >> 1) & 0x5555_5555;
    i ^= (i >> 2) & 0x3333_3333;
    i ^= (i >> 4) & 0x0f0f_0f0f;
    i ^= (i >> 8) & 0x00ff_00ff;
    i ^= (i >> 16) & 0x0000_ffff;
    i
}

/// A nested uniform scramble of the bits of `x` from the least significant up: bit `k`
/// flips by a hash of `seed` and the bits below it (a bijection). Additions and
/// multiplications carry only upwards, so each step keeps that structure; the constants
/// are Burley's (2020, listing 3) after Laine and Karras (2011).
#[inline]
fn scramble_upwards(mut x: u32, seed: u32) -> u32 {
    x = x.wrapping_add(seed);
    x ^= x.wrapping_mul(0x6c50_b47c);
    x ^= x.wrapping_mul(0xb82f_1e52);
    x ^= x.wrapping_mul(0xc7af_e638);
    x ^= x.wrapping_mul(0x8d22_f6e6);
    x
}

/// Owen scrambling of a 32-bit fraction: bit `k` below the binary point flips by a hash of
/// `seed` and the bits above it (the definition, for tests; the point functions inline it).
#[cfg(test)]
pub fn owen_scramble(x: u32, seed: u32) -> u32 {
    scramble_upwards(x.reverse_bits(), seed).reverse_bits()
}

/// The shuffled index: a permutation of the sample indices that maps every aligned block
/// of `2^m` indices onto an aligned block of `2^m` indices (bit `k` flips by a hash of
/// `seed` and the bits above it: the same nested scramble as `owen_scramble`; the
/// definition, for tests).
#[cfg(test)]
pub fn shuffle(index: u32, seed: u32) -> u32 {
    owen_scramble(index, seed)
}

/// A 32-bit fraction as a float in [0, 1): its top 24 bits, exactly representable.
#[inline]
pub fn to_unit(x: u32) -> f32 {
    (x >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// Point `index` of a 1D draw seeded by `h`: shuffled, then scrambled van der Corput,
/// `owen(sobol_0(shuffle(index)))`, given `index_reversed = index.reverse_bits()`
/// (reversals that cancel are left out).
#[inline]
pub fn point_1d(index_reversed: u32, h: u64) -> u32 {
    let s = scramble_upwards(index_reversed, h as u32).reverse_bits();
    scramble_upwards(s, (h >> 32) as u32).reverse_bits()
}

/// Point `index` of a 2D draw seeded by `h` (index shuffle, first coordinate) and `h2`
/// (second coordinate): shuffled, then scrambled Sobol dimensions 0 and 1, given
/// `index_reversed = index.reverse_bits()`.
#[inline]
pub fn point_2d(index_reversed: u32, h: u64, h2: u32) -> (u32, u32) {
    let s = scramble_upwards(index_reversed, h as u32).reverse_bits();
    let x = scramble_upwards(s, (h >> 32) as u32).reverse_bits();
    let y = scramble_upwards(sobol_1_reversed(s), h2).reverse_bits();
    (x, y)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Joe and Kuo's dimension 2 (polynomial x + 1) is the Pascal matrix mod 2: column k
    /// holds the binomial coefficients C(k, j) mod 2, i.e. `v_k = v_{k-1} ^ (v_{k-1} >> 1)`.
    #[test]
    fn dimension_1_is_pascals_triangle_mod_2() {
        let mut v = 1u32 << 31;
        for (k, &column) in DIM_1.iter().enumerate() {
            assert_eq!(column, v, "column {k}");
            v ^= v >> 1;
        }
        // The first points of the (unscrambled) sequence, as in every Sobol table.
        let first: Vec<(f64, f64)> =
            (0..4).map(|i| (sobol_0(i) as f64 / 2f64.powi(32), sobol_1(i) as f64 / 2f64.powi(32))).collect();
        assert_eq!(first, vec![(0.0, 0.0), (0.5, 0.5), (0.25, 0.75), (0.75, 0.25)]);
    }

    /// A degree-3 line of the same table (d = 4: s = 3, a = 1, m = 1 3 1) expands to the
    /// direction numbers one computes by hand from m_k = 2 a_2 m_{k−1}... ⊕ 8 m_{k−3} ⊕ m_{k−3}
    /// with a = 1 (a_1 = 0, a_2 = 1): m_4 = 4·3 ⊕ 8·1 ⊕ 1 = 5, m_5 = 4·1 ⊕ 8·3 ⊕ 3 = 31.
    /// The fast forms equal the definitions: dimension 1 against the table on single bits
    /// (every column) and random indices, and the point functions against
    /// `owen(sobol_d(shuffle(i)))` written out.
    #[test]
    fn fast_forms_equal_the_definitions() {
        for (k, &column) in DIM_1.iter().enumerate() {
            assert_eq!(sobol_1_reversed(1 << k).reverse_bits(), column, "column {k}");
        }
        let mut x = 0x1234_5678u64;
        for _ in 0..10_000 {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            let (i, h, h2) = ((x >> 32) as u32, x.rotate_left(17), (x >> 7) as u32);
            assert_eq!(sobol_1_reversed(i).reverse_bits(), sobol_1(i));
            let s = shuffle(i, h as u32);
            let want = (owen_scramble(sobol_0(s), (h >> 32) as u32), owen_scramble(sobol_1(s), h2));
            assert_eq!(point_2d(i.reverse_bits(), h, h2), want);
            assert_eq!(point_1d(i.reverse_bits(), h), want.0);
        }
    }

    #[test]
    fn the_recurrence_matches_a_hand_expansion() {
        let v = direction_numbers(3, 1, &[1, 3, 1]);
        let m: Vec<u32> = (0..5).map(|k| v[k] >> (31 - k)).collect();
        assert_eq!(m, vec![1, 3, 1, 5, 31]);
    }

    /// The scramble is a bijection with the nested structure: two inputs that agree on
    /// their top `k` bits agree there after scrambling too; so the shuffle maps the indices
    /// `0..2^m` onto one aligned block of `2^m`.
    #[test]
    fn scrambles_are_nested() {
        for seed in [0u32, 1, 0xdead_beef, 0x1234_5678] {
            for x in [0u32, 7, 0x8000_0001, 0xffff_fff0, 0x0f0f_0f0f] {
                for k in 1..32 {
                    let mask_high = !(u32::MAX >> k);
                    let z = x ^ (0x5555_5555 & !mask_high);
                    assert_eq!(owen_scramble(x, seed) & mask_high, owen_scramble(z, seed) & mask_high);
                }
            }
            for m in [1u32, 5, 12] {
                let mut block: Vec<u32> = (0..1u32 << m).map(|i| shuffle(i, seed)).collect();
                block.sort_unstable();
                assert!(block[0].is_multiple_of(1 << m) && block.windows(2).all(|w| w[1] == w[0] + 1), "m {m}");
            }
        }
        // Injective on a sample of 2^16 inputs.
        let mut seen: Vec<u32> = (0..1u32 << 16).map(|i| owen_scramble(i << 16, 99)).collect();
        seen.sort_unstable();
        seen.dedup();
        assert_eq!(seen.len(), 1 << 16);
    }
}
