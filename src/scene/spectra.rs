//! Spectra and indices of refraction in a scene file, checked: the
//! `SpectrumDesc` forms (`Constant`, `Samples`, `Table`, `File`, `Rgb`,
//! named spectra, `Blackbody`, `Luminance`, `Scaled`) become 36-bin
//! [`Spectrum`]s, and `IorDesc` becomes an [`Ior`]. Part of the scene loader's [`Check`], split out to keep each file about one thing.

use std::path::PathBuf;

use super::check::{Check, MAX_MAGNITUDE};
use super::desc::{IorDesc, SpectrumDesc};
use crate::bxdf::{Ior, NAMED_GLASSES, named_glass};
use crate::color::{self, N_BINS, Spectrum};
use crate::error::{Error, Result, show_path};
use crate::io::parse_spectrum_rows;

/// What a spectrum describes: it decides what `Rgb(r, g, b)` means.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Role {
    /// A reflectance: the uplifted colour itself, within [0, 1].
    Reflectance,
    /// An emission or intensity: the uplifted colour times D65.
    Emission,
}

impl Role {
    /// The largest value allowed.
    fn limit(self) -> f32 {
        match self {
            Role::Reflectance => 1.0,
            Role::Emission => MAX_MAGNITUDE,
        }
    }

    /// What is wrong with value `v` and the range that applies.
    fn out_of_range(self, v: f32) -> String {
        match self {
            Role::Reflectance => format!("a reflectance must lie in [0, 1], found {v}"),
            Role::Emission => format!("expected a finite, non-negative value up to {MAX_MAGNITUDE:e}, found {v}"),
        }
    }
}

impl Check<'_> {
    /// A text file the scene refers to (a spectrum table), read through
    /// [`Check::read_input`] like every input: the resolved path and the text.
    pub(crate) fn read_text_input(&self, field: &str, rel: &str) -> Result<(PathBuf, String)> {
        let (path, bytes) = self.read_input(field, rel)?;
        let text = String::from_utf8(bytes).map_err(|e| {
            let at = e.utf8_error().valid_up_to();
            self.err(field, format!("{}: byte {at} is not UTF-8; expected a UTF-8 text file", show_path(&path)))
        })?;
        Ok((path, text))
    }

    /// Checks a table's points (finite, wavelengths strictly increasing, at least one).
    pub(crate) fn table(&self, field: &str, points: &[(f32, f32)]) -> Result<Spectrum> {
        if points.is_empty() {
            return Err(self.err(field, "expected at least one (nm, value) pair"));
        }
        for (k, w) in points.iter().enumerate() {
            if !(w.0.is_finite() && w.1.is_finite() && w.0 > 0.0) {
                return Err(self.err(
                    format!("{field}[{k}]"),
                    format!("expected a positive wavelength in nm and a finite value, found {w:?}"),
                ));
            }
            if k > 0 && w.0 <= points[k - 1].0 {
                return Err(self.err(
                    format!("{field}[{k}]"),
                    format!("wavelengths must increase: {} nm follows {} nm", w.0, points[k - 1].0),
                ));
            }
        }
        Ok(Spectrum::from_table(points))
    }

    /// A spectrum for emission or intensity (any non-negative values).
    pub(crate) fn spectrum(&self, field: &str, s: &SpectrumDesc) -> Result<Spectrum> {
        self.spectrum_as(field, s, Role::Emission)
    }

    /// A spectrum in a role; the role decides what `Rgb` means and which values are allowed.
    fn spectrum_as(&self, field: &str, s: &SpectrumDesc, role: Role) -> Result<Spectrum> {
        self.spectrum_in(field, s, role, true)
    }

    /// [`Check::spectrum_as`]; `direct` when the values are used as they stand (not
    /// under `Scaled` or `Luminance`), so a file's rows can be checked one by one.
    fn spectrum_in(&self, field: &str, s: &SpectrumDesc, role: Role, direct: bool) -> Result<Spectrum> {
        let out = match s {
            SpectrumDesc::Constant(v) => Spectrum::splat(*v),
            SpectrumDesc::Samples(v) => {
                if v.len() != N_BINS {
                    return Err(
                        self.err(field, format!("expected 36 samples (380 to 730 nm every 10 nm), found {}", v.len()))
                    );
                }
                Spectrum::from_fn(|i| v[i])
            }
            SpectrumDesc::ColorChecker(name) => color::color_checker(name).ok_or_else(|| {
                self.err(
                    field,
                    format!(
                        "unknown ColorChecker patch \"{name}\"; expected one of: {}",
                        color::COLOR_CHECKER_NAMES.join(", ")
                    ),
                )
            })?,
            SpectrumDesc::Image { .. } | SpectrumDesc::Checkerboard { .. } => {
                return Err(self.err(
                    field,
                    "a texture (Image, Checkerboard) can stand only for a material's reflectance or an object's emission \
                     (not inside another texture); expected a spectrum",
                ));
            }
            SpectrumDesc::Rayleigh(s) => {
                if !(s.is_finite() && *s >= 0.0) {
                    return Err(self.err(field, format!("expected a non-negative scale, found {s}")));
                }
                Spectrum::from_fn(|b| s * (550.0 / color::bin_lambda_nm(b)).powi(4))
            }
            SpectrumDesc::D65 => color::d65(),
            SpectrumDesc::EqualEnergy => color::equal_energy(),
            SpectrumDesc::Blackbody(t) => color::blackbody(*t)
                .ok_or_else(|| self.err(field, format!("expected a positive temperature in kelvin, found {t}")))?,
            SpectrumDesc::Scaled(k, inner) => self.spectrum_in(field, inner, role, false)? * *k,
            SpectrumDesc::Table(points) => self.table(field, points)?,
            SpectrumDesc::File(rel) => {
                let (path, text) = self.read_text_input(field, rel)?;
                // Errors in the data name the data file, the row's line and column, and the field.
                let at = |(line, col), message| Error::Scene {
                    path: path.clone(),
                    position: Some((line, col)),
                    field: field.to_string(),
                    message,
                };
                let rows = parse_spectrum_rows(&text).map_err(|e| at((e.line, e.col), e.message))?;
                for r in &rows {
                    if r.nm <= 0.0 {
                        return Err(at((r.line, 1), format!("expected a positive wavelength in nm, found {}", r.nm)));
                    }
                    // Values used as they stand must lie in the role's range (a scaled file is
                    // checked after scaling, below).
                    if direct && !(0.0..=role.limit()).contains(&r.value) {
                        return Err(at((r.line, r.value_col), role.out_of_range(r.value)));
                    }
                }
                let points: Vec<(f32, f32)> = rows.iter().map(|r| (r.nm, r.value)).collect();
                Spectrum::from_table(&points)
            }
            SpectrumDesc::Rgb(r, g, b) => {
                let rgb = [*r, *g, *b];
                let limit = if role == Role::Reflectance { 1.0 } else { MAX_MAGNITUDE };
                if !rgb.iter().all(|v| v.is_finite() && (0.0..=limit).contains(v)) {
                    return Err(
                        self.err(field, format!("expected linear sRGB components in [0, {limit}], found {rgb:?}"))
                    );
                }
                match role {
                    Role::Reflectance => color::rgb_reflectance(rgb),
                    Role::Emission => color::rgb_emission(rgb),
                }
            }
            SpectrumDesc::Luminance(y, inner) => {
                let s = self.spectrum_in(field, inner, role, false)?;
                let have = s.to_xyz().y;
                if !(y.is_finite() && *y >= 0.0 && *y <= MAX_MAGNITUDE) {
                    return Err(self.err(field, format!("expected a luminance in [0, {MAX_MAGNITUDE:e}], found {y}")));
                }
                if !(have > 0.0 && have.is_finite()) {
                    return Err(self.err(field, format!("cannot scale a spectrum of luminance {have} to {y}")));
                }
                s * (*y / have)
            }
        };
        if out.has_nan_or_inf() {
            return Err(self.err(field, role.out_of_range(f32::NAN)));
        }
        if out.min_value() < 0.0 {
            return Err(self.err(field, role.out_of_range(out.min_value())));
        }
        if out.max_value() > role.limit() {
            return Err(self.err(field, role.out_of_range(out.max_value())));
        }
        Ok(out)
    }

    pub(crate) fn reflectance(&self, field: &str, s: &SpectrumDesc) -> Result<Spectrum> {
        let r = self.spectrum_as(field, s, Role::Reflectance)?;
        if r.max_value() > 1.0 {
            return Err(self.err(field, format!("a reflectance must lie in [0, 1], found {}", r.max_value())));
        }
        Ok(r)
    }

    pub(crate) fn ior(&self, field: &str, d: &IorDesc) -> Result<Ior> {
        let ior = match d {
            IorDesc::Constant(n) => Ior::Constant(*n),
            IorDesc::Cauchy { a, b } => Ior::Cauchy { a: *a, b: *b },
            IorDesc::Sellmeier { b, c } => Ior::Sellmeier { b: [b[0], b[1], b[2], 0.0], c: [c[0], c[1], c[2], 0.0] },
            IorDesc::Named(name) => named_glass(name).ok_or_else(|| {
                let names: Vec<&str> = NAMED_GLASSES.iter().map(|g| g.0).collect();
                self.err(field, format!("unknown glass \"{name}\"; expected one of: {}", names.join(", ")))
            })?,
        };
        // Paths after a dispersive split carry any wavelength of the colour integral's range
        // (360-830 nm), so the index must be finite and positive on all of it: no Sellmeier pole
        // inside, and positive at every nm (and between, by continuity).
        let (lo, hi) = color::INTEGRAL_RANGE_NM;
        if let Ior::Sellmeier { b, c } = &ior
            && let Some(i) =
                (0..4).find(|&i| b[i] != 0.0 && c[i] > 0.0 && (lo..=hi).contains(&(c[i].sqrt() as f64 * 1e3)))
        {
            return Err(self.err(
                field,
                format!(
                    "a Sellmeier term (C = {}) has its pole at {:.1} nm, inside 360-830 nm; expected poles outside the visible range",
                    c[i],
                    c[i].sqrt() * 1e3
                ),
            ));
        }
        for step in 0..=(hi - lo) as usize {
            let lambda = (lo + step as f64) as f32;
            let n = ior.at(lambda);
            if !(n.is_finite() && n > 0.0) {
                return Err(self
                    .err(field, format!("the index of refraction at {lambda} nm is {n}; expected a positive number")));
            }
        }
        Ok(ior)
    }
}
