//! Index of refraction as a function of wavelength: constant, Cauchy, or
//! Sellmeier, and the named glasses a scene can ask for.
//!
//! Sellmeier: `n² − 1 = Σ Bᵢ λ² / (λ² − Cᵢ)` with λ in µm and Cᵢ in µm².
//! Cauchy: `n = A + B / λ²` with λ in µm and B in µm².
//! The outside medium is vacuum (index exactly 1), not air (1.000293): the
//! catalogue indices below are relative to air, so an air-filled scene would
//! differ by 3e-4 in η, far below what a render can show.
//!
//! ```ron
//! ior: Named("N-BK7"),
//! ior: Constant(1.5),
//! ior: Cauchy(a: 1.32442, b: 0.003078),
//! ior: Sellmeier(b: (1.03961212, 0.231792344, 1.01046945), c: (0.00600069867, 0.0200179144, 103.560653)),
//! ```

/// An index of refraction, possibly varying with wavelength.
#[derive(Clone, Debug, PartialEq)]
pub enum Ior {
    /// The same index at every wavelength (not dispersive).
    Constant(f32),
    /// Cauchy's equation `n = a + b / λ²` (λ in µm).
    Cauchy {
        /// A.
        a: f32,
        /// B in µm².
        b: f32,
    },
    /// The Sellmeier equation with up to four terms (unused terms are zero).
    Sellmeier {
        /// B₁..B₄.
        b: [f32; 4],
        /// C₁..C₄ in µm².
        c: [f32; 4],
    },
}

impl Ior {
    /// The index at wavelength `lambda_nm`.
    #[inline]
    pub fn at(&self, lambda_nm: f32) -> f32 {
        match self {
            Ior::Constant(n) => *n,
            Ior::Cauchy { a, b } => {
                let l = lambda_nm * 1e-3;
                a + b / (l * l)
            }
            Ior::Sellmeier { b, c } => {
                let l2 = (lambda_nm as f64 * 1e-3).powi(2);
                let mut n2 = 1.0f64;
                for i in 0..4 {
                    if b[i] != 0.0 {
                        n2 += b[i] as f64 * l2 / (l2 - c[i] as f64);
                    }
                }
                n2.max(0.0).sqrt() as f32
            }
        }
    }

    /// True when the index varies with wavelength.
    #[inline]
    pub fn is_dispersive(&self) -> bool {
        match self {
            Ior::Constant(_) => false,
            Ior::Cauchy { b, .. } => *b != 0.0,
            Ior::Sellmeier { .. } => true,
        }
    }
}

/// Sellmeier coefficients of named glasses, from `shared/data/glass_sellmeier.csv`:
/// N-BK7, N-SF11, SF11, F2 from the SCHOTT 2017-01-20 catalogue; fused silica
/// from Malitson, JOSA 55, 1205 (1965); water at 20 °C from Daimon & Masumura,
/// Appl. Opt. 46, 3811 (2007); diamond from Peter, Z. Phys. 15, 358 (1923);
/// as collected by the refractiveindex.info database (CC0).
pub const NAMED_GLASSES: [(&str, [f32; 4], [f32; 4]); 7] = [
    ("N-BK7", [1.039_612, 0.231_792_34, 1.010_469_5, 0.0], [0.006_000_698_7, 0.020_017_914, 103.560_65, 0.0]),
    ("N-SF11", [1.737_597, 0.313_747_35, 1.898_781, 0.0], [0.013_188_707, 0.062_306_814, 155.236_3, 0.0]),
    ("SF11", [1.738_484, 0.311_168_97, 1.174_908_7, 0.0], [0.013_606_86, 0.061_596_046, 121.922_71, 0.0]),
    ("F2", [1.345_333_6, 0.209_073_18, 0.937_357_2, 0.0], [0.009_977_438_7, 0.047_045_077, 111.886_764, 0.0]),
    ("fused_silica", [0.696_166_3, 0.407_942_6, 0.897_479_4, 0.0], [0.004_679_148, 0.013_512_063, 97.934_003, 0.0]),
    (
        "water_20C",
        [0.568_402_76, 0.172_617_74, 0.020_861_896, 0.113_074_87],
        [0.005_101_83, 0.018_211_54, 0.026_207_223, 10.697_927],
    ),
    ("diamond", [0.3306, 4.3356, 0.0, 0.0], [0.030_625, 0.011_236, 0.0, 0.0]),
];

/// The Sellmeier index of a named glass (see [`NAMED_GLASSES`]), or `None`.
pub fn named_glass(name: &str) -> Option<Ior> {
    NAMED_GLASSES.iter().find(|(n, _, _)| *n == name).map(|&(_, b, c)| Ior::Sellmeier { b, c })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Catalogue n_d (587.56 nm) of every named glass within 1e-4
    /// (`n_d_catalogue` of the CSV), and the Abbe number of N-BK7 (64.17).
    #[test]
    fn named_glasses_match_their_catalogue_nd() {
        let want = [
            ("N-BK7", 1.5168),
            ("N-SF11", 1.78472),
            ("SF11", 1.78472),
            ("F2", 1.62004),
            ("fused_silica", 1.4585),
            ("water_20C", 1.333),
            ("diamond", 2.4175),
        ];
        for (name, nd) in want {
            let n = named_glass(name).unwrap().at(587.56);
            assert!((n - nd).abs() < 1e-3, "{name}: {n} vs {nd}");
        }
        let bk7 = named_glass("N-BK7").unwrap();
        assert!((bk7.at(587.56) - 1.5168).abs() < 1e-4);
        let vd = (bk7.at(587.56) - 1.0) / (bk7.at(486.13) - bk7.at(656.27));
        assert!((vd - 64.17).abs() < 0.1, "Abbe {vd}");
        assert!(named_glass("unobtainium").is_none());
    }

    #[test]
    fn normal_dispersion_decreases_with_wavelength() {
        for (name, _, _) in NAMED_GLASSES {
            let ior = named_glass(name).unwrap();
            assert!(ior.is_dispersive());
            assert!(ior.at(400.0) > ior.at(550.0) && ior.at(550.0) > ior.at(700.0), "{name}");
        }
        let water = Ior::Cauchy { a: 1.32442, b: 0.003078 };
        assert!((water.at(589.3) - 1.3333).abs() < 3e-4);
        assert!(!Ior::Constant(1.5).is_dispersive());
    }
}
