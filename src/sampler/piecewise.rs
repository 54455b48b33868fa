//! Piecewise-constant distributions in one and two dimensions (pbrt-v4
//! §A.1 and §A.5.2): the importance sampling of an environment map.
//!
//! A [`Piecewise1D`] over `[0, 1)` has `n` equal cells with non-negative
//! weights `f_i`; its density is `p(x) = f_i / (Σ f / n)` in cell `i`, and
//! [`Piecewise1D::sample`] inverts its CDF. A [`Piecewise2D`] over `[0, 1)²`
//! is a marginal over rows (`v`, weight: the row's sum) and one conditional
//! per row over columns (`u`); its density is the product. The CDFs are
//! summed in `f64`, so a row 65536 cells wide keeps its smallest cells.

use glam::Vec2;

/// A piecewise-constant density over `[0, 1)` with equal cells.
#[derive(Clone, Debug)]
pub struct Piecewise1D {
    /// Each cell's density `f_i / (Σ f / n)`, rounded to `f32` once at
    /// construction (what `sample` and `pdf` return: no division per call).
    density: Vec<f32>,
    /// `cdf[i]` = the probability of the cells before `i` (`cdf[n]` = 1).
    cdf: Vec<f64>,
    /// `Σ f / n`, the integral of the weights over `[0, 1)`.
    integral: f64,
    /// The number of cells `n`, as `f64`.
    n: f64,
    /// `1 / n` where `n` is a power of two, else 0: dividing by a power of
    /// two and multiplying by its (exact) inverse round the same real number,
    /// so both give the same bits, and a product does not wait for a divider.
    inv_n: f64,
    /// A guide table over the buckets of `g(x) = min(⌊x · n⌋, n − 1)` (the
    /// product rounded in `f64`, as [`Piecewise1D::bucket_of`] computes it):
    /// `guide[k]` = how many CDF entries have `g(c) < k` (`k` in `0..=n`).
    /// `g` is monotone, so every entry below `guide[g(u)]` is below `u` and
    /// every entry from `guide[g(u) + 1]` on is above it: the inversion of `u`
    /// searches that stretch only (the same answer as a search of the whole
    /// CDF, a few entries instead of `log2 n` unpredictable steps, and no
    /// division).
    guide: Vec<u32>,
}

impl Piecewise1D {
    /// The distribution of `func` (non-negative, finite); `None` when every
    /// weight is zero (nothing to sample) or `func` is empty.
    pub fn new(func: Vec<f32>) -> Option<Piecewise1D> {
        let n = func.len();
        if n == 0 || func.iter().any(|f| !(f.is_finite() && *f >= 0.0)) {
            return None;
        }
        let mut cdf = Vec::with_capacity(n + 1);
        let mut acc = 0.0f64;
        cdf.push(0.0);
        for &f in &func {
            acc += f as f64;
            cdf.push(acc);
        }
        if acc <= 0.0 {
            return None;
        }
        for c in &mut cdf {
            *c /= acc;
        }
        cdf[n] = 1.0;
        let integral = acc / n as f64;
        let density = func.iter().map(|&f| (f as f64 / integral) as f32).collect();
        let inv_n = if n.is_power_of_two() { 1.0 / n as f64 } else { 0.0 };
        let mut d = Piecewise1D { density, cdf, integral, n: n as f64, inv_n, guide: Vec::new() };
        // guide[k] = #{j : g(cdf[j]) < k}: a histogram of g over the CDF, summed.
        let mut guide = vec![0u32; n + 1];
        for &c in &d.cdf {
            guide[d.bucket_of(c) + 1] += 1;
        }
        for k in 1..=n {
            guide[k] += guide[k - 1];
        }
        d.guide = guide;
        Some(d)
    }

    /// `g(x) = min(⌊x · n⌋, n − 1)`, with `x · n` rounded in `f64` (0 for a
    /// negative or NaN `x`): monotone in `x`, which is all the guide table needs.
    #[inline]
    fn bucket_of(&self, x: f64) -> usize {
        ((x * self.n) as usize).min(self.density.len() - 1)
    }

    /// How many CDF entries are at most `u` (`partition_point` of the whole
    /// CDF), through the guide table.
    #[inline]
    fn count_at_most(&self, u: f64) -> usize {
        let k = self.bucket_of(u);
        let (lo, hi) = (self.guide[k] as usize, self.guide[k + 1] as usize);
        lo + self.cdf[lo..hi].partition_point(|&c| c <= u)
    }

    /// `Σ f / n`.
    #[inline]
    pub fn integral(&self) -> f64 {
        self.integral
    }

    /// A point `x` in `[0, 1)`, its density and its cell, by inverting the CDF at `u`.
    #[inline]
    pub fn sample(&self, u: f32) -> (f32, f32, usize) {
        let u = u as f64;
        let n = self.density.len();
        // The last cell whose CDF start is at most u, skipping empty cells.
        let i = (self.count_at_most(u).max(1) - 1).min(n - 1);
        let (lo, hi) = (self.cdf[i], self.cdf[i + 1]);
        let du = if hi > lo { ((u - lo) / (hi - lo)).clamp(0.0, 1.0) } else { 0.5 };
        let (x, lo_edge, hi_edge) = if self.inv_n > 0.0 {
            let inv = self.inv_n as f32;
            ((i as f64 + du) * self.inv_n, i as f32 * inv, (i + 1) as f32 * inv)
        } else {
            ((i as f64 + du) / self.n, i as f32 / n as f32, (i + 1) as f32 / n as f32)
        };
        // Keep x inside its cell in f32 (so pdf(x) answers the same cell).
        let x = (x as f32).clamp(lo_edge, next_below(hi_edge));
        (x, self.density[i], i)
    }

    /// The cell holding `x` (clamped into `[0, 1)`).
    #[inline]
    pub fn cell(&self, x: f32) -> usize {
        let n = self.density.len();
        ((x.max(0.0) * n as f32) as usize).min(n - 1)
    }

    /// The density at `x`.
    #[inline]
    pub fn pdf(&self, x: f32) -> f32 {
        self.density[self.cell(x)]
    }
}

/// The largest `f32` below `x` (for `x` > 0).
#[inline]
fn next_below(x: f32) -> f32 {
    f32::from_bits(x.to_bits() - 1)
}

/// A piecewise-constant density over `[0, 1)²` on a `width` x `height` grid.
#[derive(Clone, Debug)]
pub struct Piecewise2D {
    /// One distribution over `u` per row.
    rows: Vec<Piecewise1D>,
    /// Over `v`: each row's integral. Rows with zero weight are kept (with a
    /// uniform conditional) so that indices match; the marginal never picks them.
    marginal: Piecewise1D,
}

impl Piecewise2D {
    /// The distribution of `func` (row-major, `width` x `height`, non-negative
    /// and finite); `None` when it is all zero or the sizes do not match.
    pub fn new(func: &[f32], width: usize, height: usize) -> Option<Piecewise2D> {
        if width == 0 || height == 0 || func.len() != width * height {
            return None;
        }
        let mut rows = Vec::with_capacity(height);
        let mut row_weights = Vec::with_capacity(height);
        for row in func.chunks_exact(width) {
            match Piecewise1D::new(row.to_vec()) {
                Some(d) => {
                    row_weights.push(d.integral() as f32);
                    rows.push(d);
                }
                None => {
                    if row.iter().any(|f| !(f.is_finite() && *f >= 0.0)) {
                        return None;
                    }
                    row_weights.push(0.0);
                    rows.push(Piecewise1D::new(vec![1.0; width])?);
                }
            }
        }
        let marginal = Piecewise1D::new(row_weights)?;
        Some(Piecewise2D { rows, marginal })
    }

    /// A point `(u, v)` in `[0, 1)²` and its density, from two uniform numbers.
    #[inline]
    pub fn sample(&self, u: Vec2) -> (Vec2, f32) {
        let (v, pdf_v, row) = self.marginal.sample(u.y);
        let (x, pdf_u, _) = self.rows[row].sample(u.x);
        (Vec2::new(x, v), pdf_v * pdf_u)
    }

    /// The density at `uv`.
    #[inline]
    pub fn pdf(&self, uv: Vec2) -> f32 {
        let row = self.marginal.cell(uv.y);
        self.marginal.pdf(uv.y) * self.rows[row].pdf(uv.x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::Sampler;

    /// `k / n`, where `u · n` crosses an integer (the guide's bucket edges).
    fn bucket(k: usize, n: usize) -> f64 {
        k as f64 / n as f64
    }

    /// The guide table answers exactly what a search of the whole CDF does,
    /// for distributions with empty stretches and spikes, at random `u`, at
    /// every CDF value and bucket edge `k / n` and their neighbouring floats,
    /// and at 0 and the largest f32 below 1.
    #[test]
    fn the_guide_table_inverts_as_the_whole_search_does() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_pcg::Pcg32::seed_from_u64(3);
        for n in [1usize, 2, 3, 7, 64, 257] {
            for _ in 0..20 {
                let func: Vec<f32> = (0..n)
                    .map(|_| match rng.random::<f32>() {
                        x if x < 0.4 => 0.0,
                        x if x < 0.45 => 1e4 * rng.random::<f32>(),
                        _ => rng.random::<f32>(),
                    })
                    .collect();
                let Some(d) = Piecewise1D::new(func) else { continue };
                let mut us: Vec<f64> = (0..200).map(|_| rng.random::<f32>() as f64).collect();
                for &c in d.cdf.iter().chain((0..=n).map(|k| bucket(k, n)).collect::<Vec<_>>().iter()) {
                    let c32 = (c as f32).clamp(0.0, next_below(1.0));
                    us.extend([
                        c32 as f64,
                        next_below(c32.max(f32::MIN_POSITIVE)) as f64,
                        f32::from_bits(c32.to_bits() + 1).min(next_below(1.0)) as f64,
                    ]);
                }
                us.extend([0.0, next_below(1.0) as f64]);
                for u in us {
                    assert_eq!(d.count_at_most(u), d.cdf.partition_point(|&c| c <= u), "n {n}, u {u}");
                }
            }
        }
    }

    /// `sample` answers, bit for bit, the plain inversion (a search of the
    /// whole CDF, divisions by `n` and by the weights' integral), for sizes that
    /// are powers of two (where it multiplies by `1 / n`) and sizes that are not.
    #[test]
    fn sampling_is_the_plain_inversion_bit_for_bit() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_pcg::Pcg32::seed_from_u64(5);
        for n in [1usize, 2, 3, 4, 7, 8, 64, 100, 128, 257, 1024] {
            let func: Vec<f32> =
                (0..n).map(|_| if rng.random::<f32>() < 0.3 { 0.0 } else { rng.random::<f32>() * 10.0 }).collect();
            let Some(d) = Piecewise1D::new(func.clone()) else { continue };
            let integral = func.iter().map(|&f| f as f64).sum::<f64>() / n as f64;
            let mut us: Vec<f32> = (0..2000).map(|_| rng.random::<f32>()).collect();
            us.extend((0..n).map(|k| (k as f32 / n as f32).clamp(0.0, next_below(1.0))));
            us.extend([0.0, next_below(1.0)]);
            for u in us {
                let uf = u as f64;
                let i = (d.cdf.partition_point(|&c| c <= uf).max(1) - 1).min(n - 1);
                let (lo, hi) = (d.cdf[i], d.cdf[i + 1]);
                let du = if hi > lo { ((uf - lo) / (hi - lo)).clamp(0.0, 1.0) } else { 0.5 };
                let x = (((i as f64 + du) / n as f64) as f32)
                    .clamp(i as f32 / n as f32, next_below((i + 1) as f32 / n as f32));
                let pdf = (func[i] as f64 / integral) as f32;
                let (gx, gpdf, gi) = d.sample(u);
                assert_eq!((gx.to_bits(), gpdf.to_bits(), gi), (x.to_bits(), pdf.to_bits(), i), "n {n}, u {u}");
                assert_eq!(d.pdf(x).to_bits(), pdf.to_bits());
            }
        }
    }

    /// The 1D density integrates to 1 (a sum over the cells), samples land in
    /// cells with zero weight never, and `pdf` at a sample answers the
    /// density `sample` returned.
    #[test]
    fn one_dimension_inverts_its_cdf() {
        let d = Piecewise1D::new(vec![0.0, 1.0, 3.0, 0.0, 4.0]).unwrap();
        let total: f32 = (0..5).map(|i| d.pdf((i as f32 + 0.5) / 5.0) / 5.0).sum();
        assert!((total - 1.0).abs() < 1e-6);
        let mut s = Sampler::new(1, 0, 0);
        let mut counts = [0usize; 5];
        let n = 80_000;
        for _ in 0..n {
            let (x, pdf, i) = d.sample(s.next_1d());
            assert!((0.0..1.0).contains(&x));
            assert_eq!(d.cell(x), i);
            assert_eq!(d.pdf(x), pdf);
            counts[i] += 1;
        }
        assert_eq!(counts[0] + counts[3], 0, "empty cells are never sampled");
        // Expected fractions 1/8, 3/8, 4/8; binomial std. error < 0.2%, so 1%.
        for (i, want) in [(1, 0.125), (2, 0.375), (4, 0.5)] {
            let got = counts[i] as f64 / n as f64;
            assert!((got - want).abs() < 0.01, "cell {i}: {got} vs {want}");
        }
        // The ends of [0, 1) stay inside.
        assert!(d.sample(0.0).0 >= 0.0 && d.sample(1.0 - f32::EPSILON / 2.0).0 < 1.0);
        assert!(Piecewise1D::new(vec![0.0, 0.0]).is_none());
        assert!(Piecewise1D::new(vec![1.0, f32::NAN]).is_none());
        assert!(Piecewise1D::new(vec![]).is_none());
    }

    /// A 2D grid with a few bright cells and empty rows: the density sums to 1
    /// over the grid and a chi-square test of 200k samples against the cell
    /// probabilities passes (27 cells with non-zero weight, all with expected
    /// counts ≥ 5; the 0.1% critical value of χ² with 26 degrees of freedom is 54.05).
    #[test]
    fn two_dimensions_match_their_density() {
        let (w, h) = (8usize, 6usize);
        let mut f = vec![0.0f32; w * h];
        for (i, v) in f.iter_mut().enumerate() {
            *v = if i / w == 2 { 0.0 } else { 0.05 * (i % 3) as f32 };
        }
        f[w + 3] = 40.0;
        f[4 * w + 7] = 25.0;
        f[5 * w] = 10.0;
        let d = Piecewise2D::new(&f, w, h).unwrap();
        let cell_area = 1.0 / (w * h) as f32;
        let total: f32 = (0..w * h)
            .map(|i| d.pdf(Vec2::new(((i % w) as f32 + 0.5) / w as f32, ((i / w) as f32 + 0.5) / h as f32)) * cell_area)
            .sum();
        assert!((total - 1.0).abs() < 1e-5, "{total}");
        let n = 200_000;
        let mut counts = vec![0usize; w * h];
        let mut s = Sampler::new(2, 0, 0);
        for _ in 0..n {
            let (uv, pdf) = d.sample(s.next_2d());
            assert!(pdf > 0.0 && (pdf - d.pdf(uv)).abs() <= 1e-6 * pdf, "pdf {pdf} vs {}", d.pdf(uv));
            let (i, j) = ((uv.x * w as f32) as usize, (uv.y * h as f32) as usize);
            counts[j * w + i] += 1;
        }
        let sum: f32 = f.iter().sum();
        let mut chi2 = 0.0f64;
        let mut cells = 0;
        for (i, &c) in counts.iter().enumerate() {
            let expected = n as f64 * f[i] as f64 / sum as f64;
            if f[i] == 0.0 {
                assert_eq!(c, 0, "cell {i} has no weight");
                continue;
            }
            if expected >= 5.0 {
                chi2 += (c as f64 - expected).powi(2) / expected;
                cells += 1;
            }
        }
        assert_eq!(cells, 27);
        assert!(chi2 < 54.05, "χ² = {chi2}");
    }
}
