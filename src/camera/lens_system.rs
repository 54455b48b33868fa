//! Lens systems: a real lens prescription in pbrt's lens-file format, traced
//! surface by surface (pbrt-v4's `RealisticCamera`, read, not copied), and
//! its paraxial properties found by tracing rays near the axis.
//!
//! # The lens file
//! One row per surface, from the scene side (front) to the film side (rear),
//! four numbers separated by spaces or tabs, in millimetres, and an optional
//! fifth column naming the glass after the surface; `#` starts a comment,
//! blank lines are skipped:
//!
//! | column | meaning |
//! |---|---|
//! | radius | the surface's radius of curvature, positive when its centre lies on the film side; 0 for the aperture stop (a flat opening) |
//! | thickness | the distance along the axis to the next surface (from the last: to the film, which focusing sets) |
//! | index | the index of refraction of what follows the surface, towards the film (0 or 1: air) |
//! | aperture | the surface's clear aperture, a diameter |
//! | glass (optional) | what follows the surface disperses: a named glass (`N-BK7`, `F2`, any of [`NAMED_GLASSES`]: its Sellmeier index, which must agree with the index column within 0.005), or an Abbe number `V_d` (Cauchy's `n = A + B/λ²` through the index column at the d line, 587.56 nm, with `n_F − n_C = (n_d − 1) / V_d` between 486.13 and 656.27 nm) |
//!
//! ```text
//! # radius  thickness  index  aperture  glass
//! 51.68     4          1.5168 25        N-BK7
//! -51.68    0          1      25
//! ```
//!
//! Without a glass column a surface's index is the same at every wavelength
//! (pbrt's lens files, one index per element). With one, each wavelength
//! refracts with its own index, and the lens's focal length depends on the
//! wavelength: longitudinal chromatic aberration.
//!
//! Every mistake is an error naming the file, the line and the column: a
//! missing or extra column, a number that does not parse or is not finite, a
//! negative or zero aperture, a negative thickness, an index below 1 (other
//! than 0), a stop in glass, a surface whose radius is smaller than its
//! aperture's, two surfaces that cross inside their apertures, an unknown
//! glass, an Abbe number that is not positive, a glass after air, and a named
//! glass whose index at the d line is not the index column's.
//!
//! # Coordinates
//! Lens space is right-handed with `z` along the optical axis, increasing
//! from the scene towards the film; the front surface's vertex is at `z = 0`
//! and surface `i`'s at the sum of the thicknesses before it. Lengths are in
//! millimetres and computed in `f64` (paraxial properties need the precision).
//!
//! # Paraxial properties
//! A ray parallel to the axis at a small height `h` from the scene leaves
//! the last surface towards the rear focal point, where it crosses the axis;
//! the rear principal plane is where the extension of the incoming ray meets
//! the extension of the outgoing one. The effective focal length is the
//! distance from that plane to the focal point, the back focal distance the
//! distance from the last surface's vertex (pbrt-v4's thick-lens
//! approximation, `ComputeCardinalPoints`, traces rays the same way).

use std::path::Path;

use glam::DVec3;

use crate::bxdf::{Ior, NAMED_GLASSES, named_glass};
use crate::error::{Error, Result};

/// The d line (helium, nm), where the index column holds.
pub const D_LINE_NM: f32 = 587.56;
/// The F and C lines (hydrogen, nm), between which an Abbe number's dispersion is measured.
const F_LINE_NM: f64 = 486.13;
const C_LINE_NM: f64 = 656.27;

/// One surface of a lens system, in millimetres.
#[derive(Clone, Debug, PartialEq)]
pub struct LensSurface {
    /// Radius of curvature (positive: centre on the film side); 0 for the aperture stop.
    pub radius: f64,
    /// Distance along the axis to the next surface (from the last: to the film).
    pub thickness: f64,
    /// Index of refraction of the medium after the surface, towards the film (1 for air).
    pub index: f64,
    /// Half the clear aperture.
    pub aperture_radius: f64,
    /// The dispersive glass after the surface (`None`: `index` at every wavelength).
    pub glass: Option<Ior>,
}

impl LensSurface {
    /// True for the aperture stop (a flat opening, no refraction).
    #[inline]
    pub fn is_stop(&self) -> bool {
        self.radius == 0.0
    }

    /// The index after the surface at wavelength `lambda_nm`.
    #[inline]
    pub fn index_at(&self, lambda_nm: f32) -> f64 {
        match &self.glass {
            Some(g) => g.at(lambda_nm) as f64,
            None => self.index,
        }
    }
}

/// A lens system: its surfaces from the front (scene side) to the rear.
#[derive(Clone, Debug, PartialEq)]
pub struct LensSystem {
    /// The surfaces, front to rear.
    pub surfaces: Vec<LensSurface>,
}

/// A ray in lens space (millimetres; `dir` need not be unit).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LensRay {
    /// The origin.
    pub origin: DVec3,
    /// The direction.
    pub dir: DVec3,
}

/// The four numeric columns of a row, for error messages.
const COLUMNS: [&str; 4] = ["radius", "thickness", "index", "aperture"];
/// What a row holds, for error messages.
const ROW: &str = "4 or 5 columns (radius, thickness, index, aperture diameter in mm; a glass)";

impl LensSystem {
    /// Reads the lens file at `path` (see the module doc for the format).
    pub fn load(path: &Path) -> Result<LensSystem> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        LensSystem::parse(&text, path)
    }

    /// Parses a lens file's text; `path` names it in errors.
    pub fn parse(text: &str, path: &Path) -> Result<LensSystem> {
        let err = |line: usize, col: usize, message: String| Error::Scene {
            path: path.to_path_buf(),
            position: Some((line, col)),
            field: String::new(),
            message,
        };
        let mut surfaces = Vec::new();
        // Each surface's line and the column of its thickness, for the overlap check.
        let mut rows: Vec<(usize, usize)> = Vec::new();
        for (n, raw) in text.lines().enumerate() {
            let line = n + 1;
            let content = raw.split('#').next().unwrap_or("");
            let mut fields = Vec::new();
            let mut start = None;
            for (i, c) in content.char_indices().chain(std::iter::once((content.len(), ' '))) {
                match (c.is_whitespace(), start) {
                    (false, None) => start = Some(i),
                    (true, Some(s)) => {
                        fields.push((content[..s].chars().count() + 1, &content[s..i]));
                        start = None;
                    }
                    _ => {}
                }
            }
            if fields.is_empty() {
                continue;
            }
            if fields.len() < 4 {
                let col = content.trim_end().chars().count() + 1;
                return Err(err(
                    line,
                    col,
                    format!("expected {ROW}, found {}: the {} is missing", fields.len(), COLUMNS[fields.len()]),
                ));
            }
            if fields.len() > 5 {
                return Err(err(line, fields[5].0, format!("expected {ROW}, found {}", fields.len())));
            }
            let mut v = [0.0f64; 4];
            for (k, &(col, s)) in fields.iter().take(4).enumerate() {
                v[k] = match s.parse::<f64>() {
                    Ok(x) if x.is_finite() && x.abs() <= 1e9 => x,
                    _ => {
                        return Err(err(
                            line,
                            col,
                            format!("the {}: expected a finite number of mm up to 1e9, found `{s}`", COLUMNS[k]),
                        ));
                    }
                };
            }
            let [radius, thickness, index, aperture] = v;
            let col = |k: usize| fields[k].0;
            if thickness < 0.0 {
                return Err(err(line, col(1), format!("the thickness must not be negative, found {thickness}")));
            }
            if !(index == 0.0 || index >= 1.0) {
                return Err(err(line, col(2), format!("the index must be 1 or more (0 or 1: air), found {index}")));
            }
            if aperture <= 0.0 {
                return Err(err(line, col(3), format!("the aperture diameter must be positive, found {aperture}")));
            }
            if radius == 0.0 && index > 1.0 {
                return Err(err(
                    line,
                    col(2),
                    format!("the aperture stop (radius 0) must be followed by air (index 0 or 1), found {index}"),
                ));
            }
            if radius != 0.0 && radius.abs() < aperture / 2.0 {
                return Err(err(
                    line,
                    col(0),
                    format!("a sphere of radius {} cannot span the aperture diameter {aperture}", radius.abs()),
                ));
            }
            let glass = match fields.get(4) {
                None => None,
                Some(&(col, name)) => Some(glass(name, index).map_err(|m| err(line, col, m))?),
            };
            surfaces.push(LensSurface {
                radius,
                thickness,
                index: if index == 0.0 { 1.0 } else { index },
                aperture_radius: aperture / 2.0,
                glass,
            });
            rows.push((line, col(1)));
        }
        if surfaces.is_empty() {
            return Err(err(1, 1, "expected at least one surface row (radius, thickness, index, aperture)".into()));
        }
        // Neighbouring surfaces must not cross inside their common aperture.
        for i in 0..surfaces.len() - 1 {
            let (a, b) = (&surfaces[i], &surfaces[i + 1]);
            let h = a.aperture_radius.min(b.aperture_radius);
            let gap = a.thickness + sag(b.radius, h) - sag(a.radius, h);
            if gap < -1e-9 {
                let (line, col) = rows[i];
                return Err(err(
                    line,
                    col,
                    format!(
                        "this surface and the next (line {}) cross inside their apertures: {:.4} mm apart at the axis, {gap:.4} at height {h} mm",
                        rows[i + 1].0,
                        a.thickness
                    ),
                ));
            }
        }
        Ok(LensSystem { surfaces })
    }

    /// The `z` of each surface's vertex (the front one at 0).
    pub fn vertices(&self) -> Vec<f64> {
        let mut z = 0.0;
        self.surfaces
            .iter()
            .map(|s| {
                let at = z;
                z += s.thickness;
                at
            })
            .collect()
    }

    /// Traces `ray` of wavelength `lambda_nm` (from the scene side, going
    /// towards +z) through every surface, front to rear. `None` when it
    /// misses a surface or the stop inside its aperture, or is totally
    /// reflected. The ray returned starts on the last surface, in the medium
    /// after it.
    pub fn trace_from_scene(&self, ray: LensRay, lambda_nm: f32) -> Option<LensRay> {
        let z = self.vertices();
        let mut r = LensRay { origin: ray.origin, dir: ray.dir.normalize() };
        let mut eta_before = 1.0;
        for (s, &zv) in self.surfaces.iter().zip(&z) {
            let (p, n) = intersect(s, zv, &r)?;
            if p.x * p.x + p.y * p.y > s.aperture_radius * s.aperture_radius {
                return None;
            }
            let eta = s.index_at(lambda_nm);
            let dir = if s.is_stop() { r.dir } else { refract(r.dir, n, eta_before / eta)? };
            r = LensRay { origin: p, dir };
            eta_before = eta;
        }
        Some(r)
    }

    /// Traces `ray` of wavelength `lambda_nm` (from the film side, going
    /// towards −z) through every surface, rear to front; `None` as for
    /// [`LensSystem::trace_from_scene`]. The ray returned starts on the front
    /// surface, in air.
    pub fn trace_from_film(&self, ray: LensRay, lambda_nm: f32) -> Option<LensRay> {
        let z = self.vertices();
        let mut r = LensRay { origin: ray.origin, dir: ray.dir.normalize() };
        for i in (0..self.surfaces.len()).rev() {
            let s = &self.surfaces[i];
            let (p, n) = intersect(s, z[i], &r)?;
            if p.x * p.x + p.y * p.y > s.aperture_radius * s.aperture_radius {
                return None;
            }
            let eta_after = if i > 0 { self.surfaces[i - 1].index_at(lambda_nm) } else { 1.0 };
            let dir = if s.is_stop() { r.dir } else { refract(r.dir, n, s.index_at(lambda_nm) / eta_after)? };
            r = LensRay { origin: p, dir };
        }
        Some(r)
    }

    /// True when some glass of the lens disperses (a glass column).
    pub fn is_dispersive(&self) -> bool {
        self.surfaces.iter().any(|s| s.glass.as_ref().is_some_and(Ior::is_dispersive))
    }

    /// The rear cardinal points at wavelength `lambda_nm` from a ray parallel
    /// to the axis at height `h` (mm) from the scene: `(principal plane z,
    /// focal point z)`; `None` if the ray does not pass or leaves parallel to
    /// the axis.
    pub fn rear_cardinal_points(&self, h: f64, lambda_nm: f32) -> Option<(f64, f64)> {
        let r = self.trace_from_scene(LensRay { origin: DVec3::new(h, 0.0, -1.0), dir: DVec3::Z }, lambda_nm)?;
        // Where the outgoing ray crosses the axis, and where it is at height h.
        if r.dir.x == 0.0 || r.dir.z <= 0.0 {
            return None;
        }
        let focus = r.origin.z - r.origin.x * r.dir.z / r.dir.x;
        let principal = r.origin.z + (h - r.origin.x) * r.dir.z / r.dir.x;
        Some((principal, focus))
    }

    /// The front cardinal points at wavelength `lambda_nm` from a ray
    /// parallel to the axis at height `h` (mm) from the film side: `(principal
    /// plane z, focal point z)`; `None` as for [`LensSystem::rear_cardinal_points`].
    pub fn front_cardinal_points(&self, h: f64, lambda_nm: f32) -> Option<(f64, f64)> {
        let behind = self.vertices().last()? + self.surfaces.last()?.thickness + 1.0;
        let r = self.trace_from_film(LensRay { origin: DVec3::new(h, 0.0, behind), dir: DVec3::NEG_Z }, lambda_nm)?;
        if r.dir.x == 0.0 || r.dir.z >= 0.0 {
            return None;
        }
        let focus = r.origin.z - r.origin.x * r.dir.z / r.dir.x;
        let principal = r.origin.z + (h - r.origin.x) * r.dir.z / r.dir.x;
        Some((principal, focus))
    }

    /// This lens with its film placed so that the plane `distance` mm in
    /// front of the film is in focus at the d line: the last surface's
    /// thickness becomes the distance to the film. pbrt-v4's
    /// `FocusThickLens`, solved exactly for the thick-lens approximation: with
    /// the principal planes `P` (front) and `P'` (rear) and the focal length
    /// `f`, an object `s` in front of `P` images `s'` behind `P'` with
    /// `1/s + 1/s' = 1/f`, and `s + s' = L`, the conjugates' distance less the
    /// principal planes' separation, gives `s' = (L − √(L² − 4fL)) / 2` (the
    /// image near the focal plane). An error message when the plane in focus
    /// would lie inside the lens, nearer than the lens can focus (`L < 4f`),
    /// or with the film inside the lens.
    pub fn focused(&self, distance: f64) -> std::result::Result<LensSystem, String> {
        let h = self.paraxial_height();
        let rear = self.rear_cardinal_points(h, D_LINE_NM);
        let front = self.front_cardinal_points(h, D_LINE_NM);
        let (Some((p_rear, f_rear)), Some((p_front, _))) = (rear, front) else {
            return Err(
                "the lens does not form an image: a ray near the axis does not pass it or leaves it parallel".into()
            );
        };
        let f = f_rear - p_rear;
        if f.is_nan() || f <= 0.0 {
            return Err(format!("the lens diverges (focal length {f:.4} mm): it cannot focus on a film"));
        }
        let l = distance - (p_rear - p_front);
        if l < 4.0 * f {
            return Err(format!(
                "{distance} mm from the film is nearer than this lens can focus: at least {:.4} mm (object and image 4f apart, f {f:.4} mm)",
                4.0 * f + (p_rear - p_front)
            ));
        }
        let film = p_rear + 0.5 * (l - (l * l - 4.0 * f * l).sqrt());
        let z = self.vertices();
        let last = self.surfaces.last().expect("a lens has surfaces");
        let rear_edge = z[z.len() - 1] + sag(last.radius, last.aperture_radius).max(0.0);
        if film <= rear_edge {
            return Err(format!("focusing at {distance} mm puts the film inside the lens"));
        }
        if film - distance >= 0.0 {
            return Err(format!(
                "the plane in focus, {distance} mm from the film, is inside the lens ({:.4} mm from its front to the film)",
                film
            ));
        }
        let mut lens = self.clone();
        lens.surfaces.last_mut().expect("a lens has surfaces").thickness = film - z[z.len() - 1];
        Ok(lens)
    }

    /// The film's `z` (the last vertex plus the last thickness).
    pub fn film_z(&self) -> f64 {
        self.vertices().last().copied().unwrap_or(0.0) + self.surfaces.last().map_or(0.0, |s| s.thickness)
    }

    /// The paraxial effective focal length (mm) at wavelength `lambda_nm`:
    /// from the rear principal plane to the rear focal point, by a ray at a
    /// small height (10⁻⁴ of the front aperture's radius, where the exact
    /// trace is paraxial to about 10⁻⁸).
    pub fn effective_focal_length(&self, lambda_nm: f32) -> Option<f64> {
        let (principal, focus) = self.rear_cardinal_points(self.paraxial_height(), lambda_nm)?;
        Some(focus - principal)
    }

    /// The paraxial back focal distance (mm) at wavelength `lambda_nm`: from
    /// the last surface's vertex to the rear focal point (see
    /// [`LensSystem::effective_focal_length`]). Its change with the
    /// wavelength is the longitudinal chromatic aberration.
    pub fn back_focal_distance(&self, lambda_nm: f32) -> Option<f64> {
        let (_, focus) = self.rear_cardinal_points(self.paraxial_height(), lambda_nm)?;
        let last = *self.vertices().last()?;
        Some(focus - last)
    }

    fn paraxial_height(&self) -> f64 {
        self.surfaces[0].aperture_radius * 1e-4
    }
}

/// The glass column `name` of a row whose index column is `index`: a named
/// glass agreeing with the index at the d line, or an Abbe number; an error
/// message otherwise.
fn glass(name: &str, index: f64) -> std::result::Result<Ior, String> {
    if index <= 1.0 {
        return Err(format!("a glass (`{name}`) after air: the index column is {index}, expected more than 1"));
    }
    if let Some(g) = named_glass(name) {
        let n_d = g.at(D_LINE_NM) as f64;
        if (n_d - index).abs() > 5e-3 {
            return Err(format!("{name}'s index at the d line is {n_d:.4}, but the index column says {index}"));
        }
        return Ok(g);
    }
    match name.parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => {
            // n_F − n_C = (n_d − 1) / V_d, and Cauchy through n_d.
            let b = (index - 1.0) / v / (1.0 / (F_LINE_NM * 1e-3).powi(2) - 1.0 / (C_LINE_NM * 1e-3).powi(2));
            let a = index - b / (D_LINE_NM as f64 * 1e-3).powi(2);
            Ok(Ior::Cauchy { a: a as f32, b: b as f32 })
        }
        Ok(v) => Err(format!("an Abbe number must be positive, found {v}")),
        Err(_) => {
            let names: Vec<&str> = NAMED_GLASSES.iter().map(|g| g.0).collect();
            Err(format!("expected a glass name ({}) or an Abbe number, found `{name}`", names.join(", ")))
        }
    }
}

/// The sag of a spherical surface of radius `r` (0: flat) at height `h`: how
/// far its point at that height lies from its vertex along +z.
fn sag(r: f64, h: f64) -> f64 {
    if r == 0.0 {
        return 0.0;
    }
    r - r.signum() * (r * r - h * h).max(0.0).sqrt()
}

/// The ray's hit on surface `s` whose vertex is at `z`, and the surface's
/// unit normal there facing the ray (against its direction).
fn intersect(s: &LensSurface, z: f64, r: &LensRay) -> Option<(DVec3, DVec3)> {
    if s.is_stop() {
        if r.dir.z == 0.0 {
            return None;
        }
        let t = (z - r.origin.z) / r.dir.z;
        if t <= 0.0 {
            return None;
        }
        return Some((r.origin + r.dir * t, DVec3::new(0.0, 0.0, -r.dir.z.signum())));
    }
    let centre = DVec3::new(0.0, 0.0, z + s.radius);
    let o = r.origin - centre;
    let (a, b, c) = (r.dir.length_squared(), 2.0 * r.dir.dot(o), o.length_squared() - s.radius * s.radius);
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return None;
    }
    let root = disc.sqrt();
    // A numerically stable pair of roots.
    let q = if b < 0.0 { -0.5 * (b - root) } else { -0.5 * (b + root) };
    let (t0, t1) = (q / a, c / q);
    let (t0, t1) = (t0.min(t1), t0.max(t1));
    // The vertex's side of the sphere: the nearer hit when the ray travels
    // towards the centre from the vertex's side, else the farther.
    let towards_centre = (r.dir.z > 0.0) == (s.radius > 0.0);
    let t = if towards_centre { t0 } else { t1 };
    if t.is_nan() || t <= 0.0 {
        return None;
    }
    let p = r.origin + r.dir * t;
    let mut n = (p - centre) / s.radius.abs();
    if n.dot(r.dir) > 0.0 {
        n = -n;
    }
    Some((p, n))
}

/// Snell's law: the unit direction refracted from unit `d` at a surface of
/// unit normal `n` facing against `d`, with `eta` the ratio of the indices
/// (incident over transmitted); `None` on total internal reflection.
fn refract(d: DVec3, n: DVec3, eta: f64) -> Option<DVec3> {
    let cos_i = -d.dot(n);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i).max(0.0);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((d * eta + n * (eta * cos_i - cos_t)).normalize())
}

#[cfg(test)]
mod tests;
