//! Sampling: the deterministic per-sample number source ([`Sampler`]), the fixed
//! layout of its dimensions ([`Dim`]), and the warps from uniform numbers to
//! directions and points ([`warp`]).
//!
//! Sample `k` of pixel `p` takes its numbers from a sampler keyed by
//! `(seed, p, k)`, `k` being the pass index: a sample's numbers do not depend
//! on which thread rendered it, on the tile order, or on how many passes ran
//! before in this process. That is what makes renders bit-identical across
//! thread counts, and resume and merge exact. Two samplers, a closed set
//! (`--sampler`, the `render` block's `sampler:`; [`SamplerKind`]):
//!
//! - **`independent`**: a PCG32 stream whose state and increment are hashes of
//!   `(seed, p, k)`. It ignores [`Dim`] and hands out numbers in the order the
//!   integrator asks for them, exactly as before the layout existed, so its
//!   images are byte-identical to those of rust-v before the `sobol` sampler.
//! - **`sobol`**: Owen-scrambled, shuffled Sobol points ([`sobol`]), index `k`,
//!   one padded 1D or 2D point set per [`Dim`], seeded by `(seed, p, dim)`.
//!   Stratified over the samples of a pixel in every draw; any spp works.
//!   BDPT's light subpath draws from one sequence over the whole film instead,
//!   index `pass · pixels + pixel` (its splats land anywhere: see [`Sobol`]).
//!
//! # The dimension layout
//! Integrators ask for numbers by purpose and bounce, never in stream order,
//! so a data-dependent number of draws (a packet split, a collapse, a path
//! that ends early, BDPT's light subpath) never shifts another draw's
//! dimension. `depth` counts the surface vertices of a subpath before this one
//! (0 at the camera ray's first hit).
//!
//! | draw | 1D/2D | who |
//! |---|---|---|
//! | [`Dim::FILM`] | 2D | the position in the pixel |
//! | [`Dim::wavelength`]`(i)`, `i < 8` | 1D | packet wavelengths (`spectral`), BDPT's `u_λ` (`i = 0`) |
//! | [`Dim::light_choice`]`(depth)` | 1D | next-event estimation: which light |
//! | [`Dim::light_sample`]`(depth)` | 2D | next-event estimation: the point on it |
//! | [`Dim::bsdf`]`(depth)` | 2D | BSDF sample direction |
//! | [`Dim::lobe`]`(depth)` | 1D | BSDF lobe choice |
//! | [`Dim::roulette`]`(depth)` | 1D | Russian roulette |
//! | [`Dim::collapse`]`(depth)` | 1D | `auto`: reflect or collapse at dispersive glass |
//! | [`Dim::collapse_bins`]`(depth)` | 1D | `auto`: the rotation of the drawn bins |
//! | [`Dim::EMIT_CHOICE`], [`Dim::EMIT_POSITION`], [`Dim::EMIT_DIRECTION`] | 1D, 2D, 2D | BDPT's light subpath: the light, a point and a direction leaving it |
//! | [`Dim::LENS`] | 2D | the point on a thin lens of the camera ray (drawn only when the camera has a lens) |
//! | [`Dim::lens_from_light`]`(i)` | 2D | BDPT's `t = 1` with a thin lens: the lens point light vertex `y_i` connects to (the [`Dim::light_sample`] slot of the light subpath's block: it has no next-event estimation) |
//! | `d.`[`on_light_path`](Dim::on_light_path)`()` | as `d` | a per-bounce draw on BDPT's light subpath (its own block) |
//!
//! The fixed draws take ids 0 to 12 ([`Dim::FILM`] 0, the wavelengths 1 to 8, the
//! light subpath's start 9 to 11, [`Dim::LENS`] 12); 13 to 15 are free.
//!
//! A bounce's block has 8 slots and uses 7; **slot 7 is kept for a
//! participating medium's distance draw** (1D) at that depth. A vertex
//! scatters once, at a surface or in a medium, so a medium vertex takes its
//! phase-function direction from the [`Dim::bsdf`] slot of its depth and its
//! light sample from the same next-event slots as a surface vertex (pbrt-v4's
//! `volpath` shares its sampler dimensions the same way). Media need no other
//! room, and adding them changes no existing draw.
//!
//! The walks a packet splits into at a dispersive surface continue with the
//! same per-bounce draws (their numbers are shared, as a hero packet shares
//! its directions; each walk's estimate stays unbiased, and so does their sum).
//! Per-bounce draws of depth [`TABLE_BOUNCES`] and more are off the table: the
//! `sobol` sampler gives them hashed random numbers of `(seed, p, k, dim)`,
//! deterministic like everything else.

pub mod piecewise;
pub mod sobol;
pub mod warp;

use glam::Vec2;
use rand::Rng;
use rand_pcg::Pcg32;

pub use crate::settings::SamplerKind;

/// Per-bounce draws beyond this depth get hashed random numbers (`sobol`).
pub const TABLE_BOUNCES: u32 = 16;

/// Per-bounce slots: the stride of a bounce's block in the dimension ids.
const SLOTS: u64 = 8;
/// Where the per-bounce blocks start.
const BOUNCES_AT: u64 = 16;
/// Added to a per-bounce id on BDPT's light subpath.
const LIGHT_PATH: u64 = 1 << 40;
/// Ids from here on are off the table (wavelength draws beyond 8: no packet has them).
const OFF_TABLE: u64 = 1 << 41;

/// One draw's place in the fixed dimension layout (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Dim(u64);

impl Dim {
    /// The film position within the pixel (2D).
    pub const FILM: Dim = Dim(0);
    /// BDPT: which light the light subpath starts on (1D).
    pub const EMIT_CHOICE: Dim = Dim(9);
    /// BDPT: the point on the light (2D).
    pub const EMIT_POSITION: Dim = Dim(10);
    /// BDPT: the direction leaving the light (2D).
    pub const EMIT_DIRECTION: Dim = Dim(11);
    /// The camera ray's point on a thin lens (2D; not drawn for a pinhole,
    /// so that pinhole images stay what they were with either sampler).
    pub const LENS: Dim = Dim(12);

    /// Wavelength draw `i` of a packet (1D; `i < 8` is on the table).
    #[inline]
    pub fn wavelength(i: usize) -> Dim {
        Dim(if i < 8 { 1 + i as u64 } else { OFF_TABLE + i as u64 })
    }

    #[inline]
    fn bounce(depth: u32, slot: u64) -> Dim {
        Dim(BOUNCES_AT + SLOTS * depth as u64 + slot)
    }

    /// Next-event estimation at depth `depth`: which light (1D).
    #[inline]
    pub fn light_choice(depth: u32) -> Dim {
        Dim::bounce(depth, 0)
    }

    /// Next-event estimation at depth `depth`: the point on the light (2D).
    #[inline]
    pub fn light_sample(depth: u32) -> Dim {
        Dim::bounce(depth, 1)
    }

    /// The BSDF sample's direction at depth `depth` (2D).
    #[inline]
    pub fn bsdf(depth: u32) -> Dim {
        Dim::bounce(depth, 2)
    }

    /// The BSDF sample's lobe choice at depth `depth` (1D).
    #[inline]
    pub fn lobe(depth: u32) -> Dim {
        Dim::bounce(depth, 3)
    }

    /// Russian roulette after the bounce at depth `depth` (1D).
    #[inline]
    pub fn roulette(depth: u32) -> Dim {
        Dim::bounce(depth, 4)
    }

    /// A scattering medium at depth `depth`: where the path scatters (1D; slot 7).
    #[inline]
    pub fn medium_distance(depth: u32) -> Dim {
        Dim::bounce(depth, 7)
    }

    /// `auto` at dispersive glass at depth `depth`: reflect, or collapse (1D).
    #[inline]
    pub fn collapse(depth: u32) -> Dim {
        Dim::bounce(depth, 5)
    }

    /// `auto` at dispersive glass at depth `depth`: the drawn bins' rotation (1D).
    #[inline]
    pub fn collapse_bins(depth: u32) -> Dim {
        Dim::bounce(depth, 6)
    }

    /// BDPT's connection of light vertex `y_i` to a thin lens (`t = 1`): the
    /// lens point (2D). The light subpath's [`Dim::light_sample`] slot of
    /// depth `i`, unused there (a light subpath makes no next-event estimate).
    #[inline]
    pub fn lens_from_light(i: u32) -> Dim {
        Dim::light_sample(i).on_light_path()
    }

    /// This per-bounce draw on BDPT's light subpath (a block of its own).
    #[inline]
    pub fn on_light_path(self) -> Dim {
        Dim(self.0 | LIGHT_PATH)
    }

    /// [`Dim::on_light_path`] when `light` is set, else `self`.
    #[inline]
    pub fn on_light_path_if(self, light: bool) -> Dim {
        if light { self.on_light_path() } else { self }
    }

    /// True for the draws of BDPT's light subpath (its start and its bounces).
    #[inline]
    pub fn is_light_path(self) -> bool {
        self.0 & LIGHT_PATH != 0 || matches!(self, Dim::EMIT_CHOICE | Dim::EMIT_POSITION | Dim::EMIT_DIRECTION)
    }

    /// True when the `sobol` sampler has a point set for this draw.
    #[inline]
    fn on_table(self) -> bool {
        self.0 < OFF_TABLE && (self.0 & (LIGHT_PATH - 1)) < BOUNCES_AT + SLOTS * TABLE_BOUNCES as u64
    }
}

/// The number source of one camera sample (see the module doc).
#[derive(Clone, Debug)]
pub enum Sampler {
    /// Independent uniform numbers in request order (dimensions ignored).
    Independent(Pcg32),
    /// Padded, Owen-scrambled Sobol points, one set per dimension.
    Sobol(Sobol),
}

/// The `sobol` sampler's state: its key (a hash of seed and pixel) and the sample index.
///
/// BDPT's light subpaths draw from one point set for the whole film instead
/// ([`Dim::is_light_path`]): key a hash of the seed alone, index
/// `pass · pixels + pixel`. A light subpath's splats land anywhere, so what
/// matters for them is how the light subpaths of a pass spread over the light
/// and its directions together, not per pixel: with a power-of-two pixel
/// count each pass's light subpaths are a stratified set in every light draw.
/// Past 2^32 light subpaths the index wraps and the key changes (a fresh
/// scramble), so no subpath's numbers repeat.
/// Each sample's numbers stay uniform and independent across draws (each
/// draw's set is scrambled with its own hash), so every estimate stays
/// unbiased, and the index is still a function of `(pixel, pass)`, so merge
/// and resume stay exact.
#[derive(Clone, Copy, Debug)]
pub struct Sobol {
    key: u64,
    index: u32,
    /// `index` with its bits reversed (every draw starts from it).
    index_reversed: u32,
    /// The key of the light subpath's draws (a hash of the seed).
    light_key: u64,
    /// The light subpath's index, `pass · pixels + pixel`.
    light_index: u32,
    /// `light_index` with its bits reversed.
    light_index_reversed: u32,
}

/// SplitMix64's finaliser: a bijective 64-bit mix (Steele et al. 2014).
#[inline]
fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The top 24 bits of `x` as a float in [0, 1) (exactly representable, < 1).
#[inline]
fn unit_24(x: u64) -> f32 {
    (x >> 40) as f32 * (1.0 / (1u32 << 24) as f32)
}

impl Sampler {
    /// The `independent` stream of sample `pass` of pixel `pixel` (row-major index) for `seed`.
    #[inline]
    pub fn new(seed: u64, pixel: u64, pass: u64) -> Self {
        let a = mix64(seed ^ 0x9e37_79b9_7f4a_7c15);
        let b = mix64(a ^ pixel.wrapping_mul(0xd1b5_4a32_d192_ed03));
        let state = mix64(b ^ pass.wrapping_mul(0x8cb9_2ba7_2f3d_8dd7));
        let stream = mix64(state ^ 0x5851_f42d_4c95_7f2d);
        Sampler::Independent(Pcg32::new(state, stream))
    }

    /// The sampler `kind` for sample `pass` of pixel `pixel` (row-major index) of a film
    /// of `pixels` pixels, for `seed`. The `sobol` sampler's index is the pass (modulo
    /// 2^32); on BDPT's light subpath it is `pass · pixels + pixel` (see [`Sobol`]).
    #[inline]
    pub fn of_kind(kind: SamplerKind, seed: u64, pixel: u64, pass: u64, pixels: u64) -> Self {
        match kind {
            SamplerKind::Independent => Sampler::new(seed, pixel, pass),
            SamplerKind::Sobol => {
                let a = mix64(seed ^ 0x2545_f491_4f6c_dd1d);
                let key = mix64(a ^ pixel.wrapping_mul(0x9e37_79b9_7f4a_7c15));
                let index = pass as u32;
                // The film's sequence index; every 2^32 of them (e.g. past 512
                // passes of a 4096x2048 film) take a fresh scramble, so no index repeats.
                let global = pass.wrapping_mul(pixels).wrapping_add(pixel);
                let light_key = mix64(a ^ 0x6a09_e667_f3bc_c909 ^ (global >> 32).wrapping_mul(0x9e37_79b9_7f4a_7c15));
                let light_index = global as u32;
                Sampler::Sobol(Sobol {
                    key,
                    index,
                    index_reversed: index.reverse_bits(),
                    light_key,
                    light_index,
                    light_index_reversed: light_index.reverse_bits(),
                })
            }
        }
    }

    /// One uniform number in [0, 1) for draw `dim` (24 bits: exactly representable and < 1).
    #[inline]
    pub fn get_1d(&mut self, dim: Dim) -> f32 {
        match self {
            Sampler::Independent(rng) => (rng.next_u32() >> 8) as f32 * (1.0 / (1u32 << 24) as f32),
            Sampler::Sobol(s) => s.get_1d(dim),
        }
    }

    /// Two uniform numbers in [0, 1)² for draw `dim`.
    #[inline]
    pub fn get_2d(&mut self, dim: Dim) -> Vec2 {
        match self {
            Sampler::Independent(_) => {
                let x = self.get_1d(dim);
                Vec2::new(x, self.get_1d(dim))
            }
            Sampler::Sobol(s) => s.get_2d(dim),
        }
    }

    /// [`Sampler::get_1d`] for a draw whose value is read only when `used` (a
    /// light choice among one light, a lobe choice at a one-lobe BSDF, roulette
    /// that cannot cut). `sobol` skips an unread draw: each [`Dim`] is its own
    /// point set, so no other draw moves and the image is the same, minus the
    /// hashing (about a third of a Cornell-box sample's draws). An `independent`
    /// stream always draws, so that its order, and its images, stay as they were.
    #[inline]
    pub fn get_1d_if(&mut self, used: bool, dim: Dim) -> f32 {
        match self {
            Sampler::Sobol(_) if !used => 0.5,
            _ => self.get_1d(dim),
        }
    }

    /// [`Sampler::get_2d`] for a draw whose value is read only when `used` (see
    /// [`Sampler::get_1d_if`]).
    #[inline]
    pub fn get_2d_if(&mut self, used: bool, dim: Dim) -> Vec2 {
        match self {
            Sampler::Sobol(_) if !used => Vec2::splat(0.5),
            _ => self.get_2d(dim),
        }
    }

    /// The next number of an `independent` stream, for the tests of other modules
    /// that want a plain stream ([`Sampler::new`]); dimensions do not matter there.
    #[cfg(test)]
    pub fn next_1d(&mut self) -> f32 {
        debug_assert!(matches!(self, Sampler::Independent(_)));
        self.get_1d(Dim::FILM)
    }

    /// The next two numbers of an `independent` stream (see [`Sampler::next_1d`]).
    #[cfg(test)]
    pub fn next_2d(&mut self) -> Vec2 {
        debug_assert!(matches!(self, Sampler::Independent(_)));
        self.get_2d(Dim::FILM)
    }
}

impl Sobol {
    /// The hash that seeds draw `dim`, its sample index and that index reversed:
    /// this pixel's, or the film's for a light subpath's draw.
    #[inline]
    fn draw(&self, dim: Dim) -> (u64, u32, u32) {
        let (key, index, reversed) = if dim.is_light_path() {
            (self.light_key, self.light_index, self.light_index_reversed)
        } else {
            (self.key, self.index, self.index_reversed)
        };
        (mix64(key ^ dim.0.wrapping_mul(0xd6e8_feb8_6659_fd93)), index, reversed)
    }

    /// Off the table: a hash of (key, dim, index).
    #[inline]
    fn fallback(h: u64, index: u32) -> u64 {
        mix64(h ^ (index as u64 + 1).wrapping_mul(0x8cb9_2ba7_2f3d_8dd7))
    }

    #[inline]
    fn get_1d(&self, dim: Dim) -> f32 {
        let (h, index, reversed) = self.draw(dim);
        if !dim.on_table() {
            return unit_24(Sobol::fallback(h, index));
        }
        sobol::to_unit(sobol::point_1d(reversed, h))
    }

    #[inline]
    fn get_2d(&self, dim: Dim) -> Vec2 {
        let (h, index, reversed) = self.draw(dim);
        if !dim.on_table() {
            let r = Sobol::fallback(h, index);
            return Vec2::new(unit_24(r), unit_24(r << 24));
        }
        // The second coordinate's seed: 32 more bits from the hash (a multiply spreads them).
        let h2 = ((h ^ (h >> 29)).wrapping_mul(0xbf58_476d_1ce4_e5b9) >> 32) as u32;
        let (x, y) = sobol::point_2d(reversed, h, h2);
        Vec2::new(sobol::to_unit(x), sobol::to_unit(y))
    }
}

#[cfg(test)]
mod tests;
