//! Camera sensors: three spectral response curves that turn radiance into the film's three
//! channels, and the colour-correction matrix from those channels to linear sRGB.
//!
//! Every integrator reduces a sample to three numbers before the film (`crate::film`): the
//! projection of its radiance on three curves. The default sensor, `cie1931`, is the CIE 1931
//! colour matching functions, so the film holds CIE XYZ ([`super::color_weights`],
//! [`super::cmf_at`]). A sensor file (`--sensor FILE.csv`) gives three other curves, a camera's,
//! and the film holds *camera RGB*: `c = ∫ s_c(λ) · L(λ) dλ` for `c` in r, g, b. The projection is
//! data: the same 36 tent weights and 1 nm table as the CMFs, from other numbers, so the default
//! render does exactly what it did before.
//!
//! # The file
//! Four numbers a line, `wavelength_nm,r,g,b`, in the format of a spectrum file
//! (`crate::io::parse_table`): an optional header line, `#` comments, commas, semicolons, tabs or
//! spaces; wavelengths strictly increasing; responses finite and not negative; each curve
//! positive somewhere in 360-830 nm. The curves are linear between rows and zero outside the
//! file's range. Any error names the file, line and column.
//!
//! # Resampling and normalisation
//! The curves are evaluated at every nm from 360 to 830 (linear interpolation of the rows):
//! from there on they are handled exactly as the 1 nm CMF table is, the 36 exact tent weights
//! (`S_b = ∫ s · φ_b`, [`super::tent_weights`]) and the 1 nm table for continuous wavelengths,
//! all divided by `∫ s_g` over 360-830 nm. So a spectrally flat radiance of 1 gives G = 1, as it
//! gives Y = 1 with the CMFs, and the CMFs given as a file reproduce the default film up to the
//! resampling of the file's rows (a 5 nm table linearly interpolated is not the 1 nm table).
//!
//! # The colour-correction matrix
//! A 3x3 matrix `M` takes camera RGB to linear sRGB (Rec. 709 primaries, D65 white). It is fitted
//! on the 24 ColorChecker patches ([`super::color_checker`], BabelColor average) under D65: for
//! patch `i`, camera RGB `c_i = Σ_b S_b · (R_i · D65)_b` and the target `t_i` the linear sRGB of
//! the patch's CIE XYZ (the default film's colour of the same radiance), both divided by the Y of
//! D65 (a perfect white reflector has Y = 1). `M` minimises `Σ_i |M c_i − t_i|²` (least squares,
//! the normal equations in f64) subject to `M c_w = t_w` for the perfect white reflector `w`
//! under D65 (a Lagrange multiplier: one 4x4 system per output channel). The constraint is the
//! normalisation: a white or grey surface lit by D65 comes out exactly as with the default
//! sensor, neither tinted nor brighter or darker, whatever the curves' scale. The fit's RMS
//! residual over the 72 values (24 patches x 3 channels, linear sRGB relative to that white) is
//! printed with the matrix; it is 0 only for curves that are a linear mix of the CMFs.
//!
//! The film keeps camera RGB. Output converts each pixel's mean with `M` where the default film
//! converts XYZ to linear sRGB; EXR output in another space goes through the XYZ of that sRGB;
//! `--color-space camera` writes the raw camera RGB.

use std::path::Path;
use std::sync::{Arc, LazyLock};

use super::cie::{cmf_table, curve_at, normalised_curves, tent_weights};
use super::rgb::Xyz;
use super::spectrum::{N_BINS, Spectrum};
use super::{COLOR_CHECKER_NAMES, color_checker, color_weights, color_weights_f64, d65, xyz_to_linear_srgb_f64};
use crate::error::{Error, Result};
use crate::io::parse_table;

/// A 3x3 matrix, row-major.
pub type Matrix3 = [[f64; 3]; 3];

/// The name of the default sensor (the CIE 1931 colour matching functions).
pub const CIE1931: &str = "cie1931";

/// The three response curves that project a sample's radiance onto the film's channels, and
/// (for a sensor file) the matrix from those channels to linear sRGB. See the module doc.
#[derive(Clone, Debug, PartialEq)]
pub struct Sensor {
    /// `cie1931`, or the file as it was given.
    name: String,
    /// The file's text (`None` for `cie1931`): checkpoints store it, so that a resume or merge
    /// uses exactly the sensor that made the film.
    csv: Option<String>,
    /// Per-bin weights: the channels of a 36-bin spectrum are `Σ_b weights[b] · L_b`.
    weights: [[f32; 3]; N_BINS],
    /// The curves at 1 nm from 360 to 830 nm, per nm (for continuous wavelengths).
    curves: Vec<[f32; 3]>,
    /// The fitted camera RGB -> linear sRGB matrix, and its inverse in f32 (the RGB mode's
    /// values, linear sRGB, go back to camera RGB); `None` for `cie1931`.
    fit: Option<Fit>,
}

/// A sensor file's colour correction.
#[derive(Clone, Debug, PartialEq)]
struct Fit {
    /// Camera RGB -> linear sRGB.
    to_srgb: Matrix3,
    /// Camera RGB -> the XYZ whose linear sRGB is `to_srgb · c` (what the film's output takes).
    to_xyz: Matrix3,
    /// Linear sRGB -> camera RGB, in f32.
    from_srgb: [[f32; 3]; 3],
    /// The RMS residual of the fit over the ColorChecker (linear sRGB, white Y = 1).
    residual: f64,
}

impl Sensor {
    /// The default sensor: the CIE 1931 colour matching functions, the film holds XYZ.
    pub fn cie1931() -> &'static Arc<Sensor> {
        static S: LazyLock<Arc<Sensor>> = LazyLock::new(|| {
            Arc::new(Sensor {
                name: CIE1931.into(),
                csv: None,
                weights: *color_weights(),
                curves: cmf_table().to_vec(),
                fit: None,
            })
        });
        &S
    }

    /// The sensor `--sensor` names: `cie1931`, or a CSV file read from `path`.
    pub fn from_arg(arg: &Path) -> Result<Arc<Sensor>> {
        if arg.as_os_str() == CIE1931 {
            return Ok(Sensor::cie1931().clone());
        }
        let bytes = crate::io::read_input(arg).map_err(|e| match e {
            Error::Io { source, .. } => Error::Settings(format!(
                "--sensor {}: {source}; expected `cie1931` or a CSV of `wavelength_nm,r,g,b` rows",
                crate::error::show_path(arg)
            )),
            e => Error::Settings(format!("--sensor: {e}")),
        })?;
        let text = String::from_utf8(bytes).map_err(|e| Error::Scene {
            path: arg.to_path_buf(),
            position: None,
            field: String::new(),
            message: format!(
                "not UTF-8 text (byte {}): expected a CSV of `wavelength_nm,r,g,b` rows",
                e.utf8_error().valid_up_to()
            ),
        })?;
        Ok(Arc::new(Sensor::from_csv(&arg.display().to_string(), &text, arg)?))
    }

    /// A sensor from a CSV's text; `name` is what it is called (the file as given), `path`
    /// what errors name.
    pub fn from_csv(name: &str, text: &str, path: &Path) -> Result<Sensor> {
        let at = |position: Option<(usize, usize)>, message: String| Error::Scene {
            path: path.to_path_buf(),
            position,
            field: String::new(),
            message,
        };
        let rows = parse_table::<4>(text, "four numbers `wavelength_nm,r,g,b`", "`wavelength_nm,r,g,b`")
            .map_err(|e| at(Some((e.line, e.col)), e.message))?;
        const CHANNELS: [&str; 3] = ["r", "g", "b"];
        for r in &rows {
            if r.values[0] <= 0.0 {
                return Err(at(
                    Some((r.line, r.cols[0])),
                    format!("expected a positive wavelength in nm, found {}", r.values[0]),
                ));
            }
            for (c, name) in CHANNELS.iter().enumerate() {
                if r.values[c + 1] < 0.0 {
                    return Err(at(
                        Some((r.line, r.cols[c + 1])),
                        format!(
                            "the {name} response is {}: expected a response of 0 or more (a sensor cannot give negative light)",
                            r.values[c + 1]
                        ),
                    ));
                }
            }
        }
        // Every nm from 360 to 830: the rows linearly interpolated, zero outside them.
        let (lo, hi) = crate::color::INTEGRAL_RANGE_NM;
        let table: Vec<(f64, [f64; 3])> = (lo as u32..=hi as u32)
            .map(|nm| {
                let x = nm as f64;
                let k = rows.partition_point(|r| (r.values[0] as f64) < x);
                let v = if k < rows.len() && rows[k].values[0] as f64 == x {
                    std::array::from_fn(|c| rows[k].values[c + 1] as f64)
                } else if k == 0 || k == rows.len() {
                    [0.0; 3]
                } else {
                    let (a, b) = (&rows[k - 1], &rows[k]);
                    let f = (x - a.values[0] as f64) / (b.values[0] as f64 - a.values[0] as f64);
                    std::array::from_fn(|c| a.values[c + 1] as f64 * (1.0 - f) + b.values[c + 1] as f64 * f)
                };
                (x, v)
            })
            .collect();
        let first = &rows[0];
        for (c, name) in CHANNELS.iter().enumerate() {
            if table.iter().all(|r| r.1[c] == 0.0) {
                return Err(at(
                    Some((first.line, first.cols[c + 1])),
                    format!(
                        "the {name} curve is zero at every wavelength from {lo} to {hi} nm: expected a channel that responds to some light"
                    ),
                ));
            }
        }
        let weights64 = tent_weights(&table);
        let weights = weights64.map(|r| r.map(|v| v as f32));
        let curves = normalised_curves(&table);
        let (to_srgb, residual) = fit_matrix(&weights.map(|r| r.map(f64::from))).ok_or_else(|| {
            at(
                None,
                "the three curves are not independent (one is a mix of the others): no colour-correction matrix can be fitted"
                    .into(),
            )
        })?;
        let to_xyz = mat_mul(&invert(&srgb_matrix()).unwrap_or(IDENTITY), &to_srgb);
        let from_srgb = invert(&to_srgb)
            .ok_or_else(|| at(None, "the fitted colour-correction matrix is singular".into()))?
            .map(|r| r.map(|v| v as f32));
        Ok(Sensor {
            name: name.into(),
            csv: Some(text.into()),
            weights,
            curves,
            fit: Some(Fit { to_srgb, to_xyz, from_srgb, residual }),
        })
    }

    /// `cie1931`, or the file as it was given.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The file's text (`None` for `cie1931`).
    pub fn csv(&self) -> Option<&str> {
        self.csv.as_deref()
    }

    /// Whether this is the default sensor (the film holds CIE XYZ).
    pub fn is_cie1931(&self) -> bool {
        self.fit.is_none()
    }

    /// The per-bin weights of the three channels.
    #[inline]
    pub fn weights(&self) -> &[[f32; 3]; N_BINS] {
        &self.weights
    }

    /// The three curves at `lambda_nm`, per nm, normalised like the weights; zero outside
    /// 360-830 nm. For `cie1931`, exactly [`super::cmf_at`].
    #[inline]
    pub fn at(&self, lambda_nm: f32) -> [f32; 3] {
        curve_at(&self.curves, lambda_nm)
    }

    /// The three channels of a 36-bin spectrum (for `cie1931`, exactly [`Spectrum::to_xyz`]).
    pub fn project(&self, s: &Spectrum) -> Xyz {
        let (mut x, mut y, mut z) = (0.0f32, 0.0f32, 0.0f32);
        for (&v, w) in s.0.iter().zip(self.weights.iter()) {
            x += v * w[0];
            y += v * w[1];
            z += v * w[2];
        }
        Xyz::new(x, y, z)
    }

    /// The colour-correction matrix camera RGB -> linear sRGB (`None` for `cie1931`).
    pub fn to_srgb(&self) -> Option<Matrix3> {
        self.fit.as_ref().map(|f| f.to_srgb)
    }

    /// Camera RGB -> the XYZ whose linear sRGB is the corrected colour (`None` for `cie1931`,
    /// whose film holds XYZ).
    pub fn to_xyz(&self) -> Option<Matrix3> {
        self.fit.as_ref().map(|f| f.to_xyz)
    }

    /// Linear sRGB -> camera RGB in f32 (`None` for `cie1931`): the RGB mode's values.
    #[inline]
    pub fn from_srgb(&self) -> Option<&[[f32; 3]; 3]> {
        self.fit.as_ref().map(|f| &f.from_srgb)
    }

    /// The fit's RMS residual over the ColorChecker under D65 (`None` for `cie1931`).
    pub fn residual(&self) -> Option<f64> {
        self.fit.as_ref().map(|f| f.residual)
    }

    /// One line for the render log: the sensor, its matrix and the fit's residual.
    pub fn describe(&self) -> String {
        match &self.fit {
            None => format!("sensor {CIE1931}: the film holds CIE 1931 XYZ"),
            Some(f) => {
                let m = f.to_srgb.map(|r| format!("[{:.6}, {:.6}, {:.6}]", r[0], r[1], r[2])).join(", ");
                format!(
                    "sensor {}: camera RGB -> linear sRGB [{m}], fitted on the ColorChecker under D65 (white exact): RMS residual {:.6}",
                    crate::error::show_path(Path::new(&self.name)),
                    f.residual
                )
            }
        }
    }
}

/// The 24 ColorChecker patches and the perfect white reflector under D65, each as camera RGB
/// (through per-bin weights `w`) and target linear sRGB (through the CIE colour weights), divided
/// by the Y of D65. The white is last.
pub fn color_checker_pairs(w: &[[f64; 3]; N_BINS]) -> Vec<([f64; 3], [f64; 3])> {
    let light = d65();
    let cie = color_weights_f64();
    let project = |s: &Spectrum, w: &[[f64; 3]; N_BINS]| -> [f64; 3] {
        let mut acc = [0.0f64; 3];
        for (b, wb) in w.iter().enumerate() {
            for c in 0..3 {
                acc[c] += wb[c] * s.0[b] as f64;
            }
        }
        acc
    };
    let white_y = project(&light, cie)[1];
    let mut spectra: Vec<Spectrum> =
        COLOR_CHECKER_NAMES.iter().filter_map(|n| color_checker(n)).map(|r| r * light).collect();
    spectra.push(light);
    spectra
        .iter()
        .map(|s| {
            let cam = project(s, w).map(|v| v / white_y);
            let xyz = project(s, cie).map(|v| v / white_y);
            (cam, xyz_to_linear_srgb_f64(xyz))
        })
        .collect()
}

/// The white-preserving least-squares matrix (module doc) for per-bin weights `w`, and the RMS
/// residual over the 24 patches' 72 values; `None` when the system is singular.
fn fit_matrix(w: &[[f64; 3]; N_BINS]) -> Option<(Matrix3, f64)> {
    let pairs = color_checker_pairs(w);
    let (white, patches) = pairs.split_last()?;
    // Normal equations A m = b with A = Σ c cᵀ, bordered by the white's constraint.
    let mut a = [[0.0f64; 3]; 3];
    for (c, _) in patches {
        for i in 0..3 {
            for j in 0..3 {
                a[i][j] += c[i] * c[j];
            }
        }
    }
    let mut m = [[0.0f64; 3]; 3];
    for (k, row) in m.iter_mut().enumerate() {
        let mut sys = [[0.0f64; 5]; 4];
        for i in 0..3 {
            sys[i][..3].copy_from_slice(&a[i]);
            sys[i][3] = white.0[i];
            sys[i][4] = patches.iter().map(|(c, t)| c[i] * t[k]).sum();
        }
        sys[3][..3].copy_from_slice(&white.0);
        sys[3][4] = white.1[k];
        let x = solve4(sys)?;
        row.copy_from_slice(&x[..3]);
    }
    let sq: f64 = patches.iter().map(|(c, t)| (0..3).map(|k| (dot(&m[k], c) - t[k]).powi(2)).sum::<f64>()).sum();
    let residual = (sq / (3 * patches.len()) as f64).sqrt();
    m.iter().flatten().all(|v| v.is_finite()).then_some((m, residual))
}

fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Solves a 4x4 system (augmented, 5 columns) by Gaussian elimination with partial pivoting;
/// `None` when it is singular (relative to its largest entry).
fn solve4(mut s: [[f64; 5]; 4]) -> Option<[f64; 4]> {
    let scale = s.iter().flat_map(|r| r[..4].iter()).fold(0.0f64, |m, v| m.max(v.abs()));
    if !(scale > 0.0 && scale.is_finite()) {
        return None;
    }
    for col in 0..4 {
        let p = (col..4).max_by(|&i, &j| s[i][col].abs().total_cmp(&s[j][col].abs()))?;
        if s[p][col].abs() <= 1e-12 * scale {
            return None;
        }
        s.swap(col, p);
        for r in 0..4 {
            if r != col {
                let f = s[r][col] / s[col][col];
                let pivot = s[col];
                for (v, p) in s[r][col..].iter_mut().zip(&pivot[col..]) {
                    *v -= f * p;
                }
            }
        }
    }
    Some(std::array::from_fn(|i| s[i][4] / s[i][i]))
}

const IDENTITY: Matrix3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// The XYZ -> linear sRGB matrix the film's output uses, read off [`xyz_to_linear_srgb_f64`].
fn srgb_matrix() -> Matrix3 {
    let cols = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]].map(xyz_to_linear_srgb_f64);
    std::array::from_fn(|i| std::array::from_fn(|j| cols[j][i]))
}

fn mat_mul(a: &Matrix3, b: &Matrix3) -> Matrix3 {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

/// The inverse of a 3x3 matrix (`None` when singular).
fn invert(m: &Matrix3) -> Option<Matrix3> {
    let c = |i: usize, j: usize| {
        let (r0, r1) = ((i + 1) % 3, (i + 2) % 3);
        let (c0, c1) = ((j + 1) % 3, (j + 2) % 3);
        m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]
    };
    let det = m[0][0] * c(0, 0) + m[0][1] * c(0, 1) + m[0][2] * c(0, 2);
    let size = m.iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()));
    (det.abs() > 1e-12 * size.powi(3)).then(|| std::array::from_fn(|i| std::array::from_fn(|j| c(j, i) / det)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sensor(text: &str) -> Result<Sensor> {
        Sensor::from_csv("t.csv", text, Path::new("t.csv"))
    }

    /// The CMFs as a sensor (from their own 1 nm table, so no resampling) give back the colour
    /// weights to f32 rounding and an exact fit: the matrix is the film's XYZ -> sRGB and the
    /// residual is f64 rounding.
    #[test]
    fn cmfs_as_a_sensor_fit_exactly() {
        let mut text = String::from("wavelength_nm,r,g,b\n");
        for &(nm, c) in crate::color::cie::cmf_1nm() {
            text += &format!("{nm},{},{},{}\n", c[0], c[1], c[2]);
        }
        let s = sensor(&text).unwrap();
        for (a, b) in s.weights().iter().zip(color_weights()) {
            for c in 0..3 {
                assert!((a[c] - b[c]).abs() <= 2e-6 * b[c].abs().max(1e-3), "{a:?} vs {b:?}");
            }
        }
        let m = s.to_srgb().unwrap();
        let want = srgb_matrix();
        for i in 0..3 {
            for j in 0..3 {
                assert!((m[i][j] - want[i][j]).abs() < 1e-4, "{m:?}");
            }
        }
        assert!(s.residual().unwrap() < 1e-5, "{}", s.residual().unwrap());
    }

    #[test]
    fn the_default_is_the_cmf_table() {
        let s = Sensor::cie1931();
        assert!(s.is_cie1931() && s.to_xyz().is_none());
        for nm in [359.5f32, 360.0, 412.3, 555.0, 829.9, 830.0, 831.0] {
            assert_eq!(s.at(nm), crate::color::cmf_at(nm));
        }
        let sp = Spectrum::from_fn(|i| 0.1 + (i as f32 * 0.3).sin().abs());
        assert_eq!(s.project(&sp), sp.to_xyz());
    }

    #[test]
    fn bad_files_name_line_and_column() {
        let e = |t: &str| sensor(t).unwrap_err().to_string();
        let msg = e("wavelength_nm,r,g,b\n400,1,1,1\n410,1,1\n");
        assert!(msg.starts_with("t.csv:3:1: expected four numbers"), "{msg}");
        let msg = e("wavelength_nm,r,g,b\n400,1,1,1\n410,1,NaN,1\n");
        assert!(msg.starts_with("t.csv:3:7: expected a finite number"), "{msg}");
        let msg = e("400,1,1,1\n410,1,1,-0.5\n");
        assert!(msg.starts_with("t.csv:2:9: the b response is -0.5"), "{msg}");
        let msg = e("400,1,0,1\n410,1,0,1\n");
        assert!(msg.starts_with("t.csv:1:7: the g curve is zero"), "{msg}");
        let msg = e("400,1,1,1\n390,1,1,1\n");
        assert!(msg.starts_with("t.csv:2:1: wavelengths must increase"), "{msg}");
        let msg = e("400,1,1,1\n500,1,1,1\n");
        assert!(msg.contains("not independent"), "{msg}");
        let msg = e("# nothing\n");
        assert!(msg.starts_with("t.csv:1:1: expected at least one"), "{msg}");
    }
}
