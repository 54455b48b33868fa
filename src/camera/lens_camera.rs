//! A camera that looks through a lens system (pbrt-v4's `RealisticCamera`,
//! read, not copied): a physical film behind a [`LensSystem`], camera rays
//! from a film point through a point of the rear element's exit pupil,
//! traced surface by surface to the scene.
//!
//! The film is a rectangle of the image's aspect with the given diagonal (in
//! mm), centred on the axis at the focused film position
//! ([`LensSystem::focused`]). The lens inverts the image, so the film point of
//! pixel `(px, py)` is mirrored through the axis: the picture comes out
//! upright. Lens space (mm, `z` towards the film) maps to the scene with the
//! front vertex at the eye, `x` to the camera's right, `y` to its up and `−z`
//! to its view direction, 1 mm to 0.001 scene units (scene units are metres,
//! as in pbrt).
//!
//! **Exit pupil.** For 64 rings of film radius, the bounds of the points on
//! the rear vertex's plane through which rays from the ring pass the whole
//! lens are found at load (a 96x96 grid over the rear aperture's square,
//! traced from four radii of each ring, grown by one grid step). A camera ray
//! samples its ring's bounds uniformly, rotated to its film point's angle;
//! rays the lens blocks (vignetting) carry nothing.
//!
//! **Weight.** The irradiance on the film is `∫ L cos⁴θ / z² dA` over the
//! exit pupil (`z` the film-to-rear-vertex distance), so a camera ray carries
//! `cos⁴θ A_bounds / z²`, divided by the same integral at the film's centre
//! for a uniform radiance (computed at load on a 512x512 grid): the centre
//! of the film sees a uniform radiance `L` as `L` whatever the aperture; the
//! corners fall off with `cos⁴θ` and the lens's vignetting, as in a photograph.
//!
//! **Wavelengths.** Without a glass column the lens refracts every
//! wavelength alike and one ray (traced at the d line) serves the whole
//! spectrum. With one, each wavelength takes its own path through the lens:
//! the integrators trace one wavelength per camera sample then (see
//! `crate::integrator`).

use glam::{DVec2, DVec3, Vec2, Vec3};

use super::lens_system::{D_LINE_NM, LensRay, LensSystem};

/// Rings of film radius with their own exit-pupil bounds.
const PUPIL_RINGS: usize = 64;
/// The grid over the rear aperture's square that finds each ring's bounds.
const PUPIL_GRID: usize = 96;

/// A lens system with its film and exit pupils.
#[derive(Clone, Debug)]
pub struct LensCamera {
    lens: LensSystem,
    /// The film's width and height, mm.
    film_size: DVec2,
    /// Image size in pixels.
    pixels: DVec2,
    /// The film's and the rear vertex's `z`, mm.
    film_z: f64,
    rear_z: f64,
    /// Per ring: the exit pupil's bounds `(min, max)` on the rear vertex's
    /// plane, for a film point on the +x axis; empty bounds when nothing passes.
    pupils: Vec<(DVec2, DVec2)>,
    /// The weight integral at the film's centre (see the module doc).
    norm: f64,
    dispersive: bool,
}

/// A camera ray through a lens system, in lens space scaled to scene units,
/// relative to the eye: its origin and unit direction in the camera's
/// `(right, up, forward)` frame, and its weight.
#[derive(Clone, Copy, Debug)]
pub struct LensSample {
    /// Origin, camera frame, scene units.
    pub origin: Vec3,
    /// Unit direction, camera frame.
    pub dir: Vec3,
    /// The ray's weight (1 at the film's centre for a uniform radiance, on average).
    pub weight: f32,
}

impl LensCamera {
    /// The lens `lens` (mm) with its aperture stop opened to
    /// `aperture_diameter` mm, focused on the plane `focus_distance` mm in
    /// front of the film, and a film of diagonal `film_diagonal` mm and the
    /// image's aspect. An error message (for the caller to place) when the
    /// lens has no stop, the aperture is wider than the stop's own, the lens
    /// cannot focus there, or no light reaches the film's centre.
    pub fn new(
        lens: &LensSystem,
        aperture_diameter: f64,
        focus_distance: f64,
        film_diagonal: f64,
        width: u32,
        height: u32,
    ) -> Result<LensCamera, String> {
        let mut lens = lens.clone();
        let Some(stop) = lens.surfaces.iter_mut().find(|s| s.is_stop()) else {
            return Err("the lens file has no aperture stop (a row of radius 0)".into());
        };
        // (A relative 1e-6 lets an f32 diameter equal to the stop's pass.)
        if aperture_diameter > 2.0 * stop.aperture_radius * (1.0 + 1e-6) {
            return Err(format!(
                "an aperture of {} mm is wider than the lens's stop, {} mm",
                aperture_diameter as f32,
                2.0 * stop.aperture_radius
            ));
        }
        stop.aperture_radius = stop.aperture_radius.min(aperture_diameter / 2.0);
        let lens = lens.focused(focus_distance)?;
        let (w, h) = (width as f64, height as f64);
        let film_size = DVec2::new(w, h) * (film_diagonal / w.hypot(h));
        let film_z = lens.film_z();
        let rear_z = *lens.vertices().last().expect("a lens has surfaces");
        let dispersive = lens.is_dispersive();
        let mut camera = LensCamera {
            lens,
            film_size,
            pixels: DVec2::new(w, h),
            film_z,
            rear_z,
            pupils: Vec::new(),
            norm: 1.0,
            dispersive,
        };
        camera.pupils = (0..PUPIL_RINGS).map(|ring| camera.pupil_bounds(ring, film_diagonal / 2.0)).collect();
        camera.norm = camera.centre_integral();
        if camera.norm.is_nan() || camera.norm <= 0.0 {
            return Err("no light passes the lens to the film's centre".into());
        }
        Ok(camera)
    }

    /// True when the lens's glass disperses: each wavelength needs its own ray.
    #[inline]
    pub fn is_dispersive(&self) -> bool {
        self.dispersive
    }

    /// The focused lens system.
    pub fn lens(&self) -> &LensSystem {
        &self.lens
    }

    /// The film's width and height in mm.
    pub fn film_size(&self) -> (f64, f64) {
        (self.film_size.x, self.film_size.y)
    }

    /// The film point (mm, lens space) of film position `film` (pixels): mirrored through the axis.
    #[inline]
    pub fn film_point(&self, film: Vec2) -> DVec2 {
        let f = DVec2::new(film.x as f64, film.y as f64) / self.pixels;
        DVec2::new(-(f.x - 0.5) * self.film_size.x, (f.y - 0.5) * self.film_size.y)
    }

    /// The half-width of the rear aperture's square the pupil search covers.
    fn rear_extent(&self) -> f64 {
        self.lens.surfaces.last().expect("a lens has surfaces").aperture_radius * 1.5
    }

    /// True when the ray from film point `p` (mm) through the rear-plane
    /// point `q` passes the lens at the d line.
    fn passes(&self, p: DVec2, q: DVec2) -> bool {
        let origin = DVec3::new(p.x, p.y, self.film_z);
        let dir = DVec3::new(q.x, q.y, self.rear_z) - origin;
        self.lens.trace_from_film(LensRay { origin, dir }, D_LINE_NM).is_some()
    }

    /// Ring `ring`'s exit-pupil bounds, from four film radii across it.
    fn pupil_bounds(&self, ring: usize, max_radius: f64) -> (DVec2, DVec2) {
        let extent = self.rear_extent();
        let step = 2.0 * extent / PUPIL_GRID as f64;
        let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        for k in 0..4 {
            let r = (ring as f64 + k as f64 / 3.0) / PUPIL_RINGS as f64 * max_radius;
            for i in 0..PUPIL_GRID {
                for j in 0..PUPIL_GRID {
                    let q = DVec2::new(-extent + (i as f64 + 0.5) * step, -extent + (j as f64 + 0.5) * step);
                    if self.passes(DVec2::new(r, 0.0), q) {
                        lo = lo.min(q);
                        hi = hi.max(q);
                    }
                }
            }
        }
        if lo.x > hi.x {
            return (DVec2::ZERO, DVec2::ZERO);
        }
        (lo - DVec2::splat(step), hi + DVec2::splat(step))
    }

    /// `∫ cos⁴θ / z² dA` over the rays from the film's centre that pass the
    /// lens (a midpoint sum on a 512x512 grid over the centre's pupil bounds).
    fn centre_integral(&self) -> f64 {
        let (lo, hi) = self.pupils[0];
        let n = 512;
        let cell = (hi - lo) / n as f64;
        let z = self.film_z - self.rear_z;
        let mut sum = 0.0;
        for i in 0..n {
            for j in 0..n {
                let q = lo + cell * DVec2::new(i as f64 + 0.5, j as f64 + 0.5);
                if self.passes(DVec2::ZERO, q) {
                    let cos2 = z * z / (z * z + q.length_squared());
                    sum += cos2 * cos2 / (z * z);
                }
            }
        }
        sum * cell.x * cell.y
    }

    /// The camera ray through film position `film` (pixels) and exit-pupil
    /// sample `u`, at wavelength `lambda_nm`; `None` when the lens blocks it.
    pub fn ray(&self, film: Vec2, u: Vec2, lambda_nm: f32) -> Option<LensSample> {
        let p = self.film_point(film);
        let r = p.length();
        let max_radius = 0.5 * self.film_size.length();
        let ring = ((r / max_radius * PUPIL_RINGS as f64) as usize).min(PUPIL_RINGS - 1);
        let (lo, hi) = self.pupils[ring];
        let area = (hi.x - lo.x) * (hi.y - lo.y);
        if area <= 0.0 {
            return None;
        }
        let q = lo + (hi - lo) * DVec2::new(u.x as f64, u.y as f64);
        // The bounds are for a film point on +x: rotate to this one's angle.
        let (sin, cos) = if r > 0.0 { (p.y / r, p.x / r) } else { (0.0, 1.0) };
        let q = DVec2::new(cos * q.x - sin * q.y, sin * q.x + cos * q.y);
        let origin = DVec3::new(p.x, p.y, self.film_z);
        let dir = (DVec3::new(q.x, q.y, self.rear_z) - origin).normalize();
        let out = self.lens.trace_from_film(LensRay { origin, dir }, lambda_nm)?;
        let cos = -dir.z;
        let z = self.film_z - self.rear_z;
        let weight = cos.powi(4) * area / (z * z) / self.norm;
        let d = out.dir.normalize();
        Some(LensSample {
            origin: Vec3::new(out.origin.x as f32, out.origin.y as f32, -out.origin.z as f32) * 1e-3,
            dir: Vec3::new(d.x as f32, d.y as f32, -d.z as f32),
            weight: weight as f32,
        })
    }
}
