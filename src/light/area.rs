//! Area emission on flat-faced shapes: quads, cuboids (their six faces) and
//! triangle meshes, as a set of flat patches (parallelograms and triangles)
//! sampled uniformly by area: a patch is chosen in proportion to its area,
//! then a point uniformly on it, so the pdf per unit area is `1 / A` over
//! the whole emitter and per solid angle `d² / (|cos θ_l| A)`. A quad or
//! cuboid whose emission is a texture is sampled by the texture's brightness
//! instead (`super::texgrid`): the pdf per unit area is then `p_A(x)`, per
//! solid angle `d² p_A(x) / |cos θ_l|`; a textured mesh stays uniform by area.
//! A patch emits to the side its normal points to (a quad's
//! `edge_u × edge_v`, a cuboid's outward faces, a triangle's
//! counter-clockwise front) unless the object is `two_sided: true`.
//!
//! ```ron
//! objects: [
//!     (shape: Quad(origin: (-0.25, 1.98, -0.25), edge_u: (0.5, 0, 0), edge_v: (0, 0, 0.5)), emission: Scaled(15, D65)),
//!     (shape: Mesh(path: "lamp.obj"), emission: Blackbody(3000), two_sided: true),
//! ],
//! ```

use glam::{Vec2, Vec3};
use std::f32::consts::PI;

use super::EmissionSample;
use super::emit::{surface_pdf_dir, surface_ray};
use super::texgrid::{Face, TextureGrid};
use super::{EmissionTexture, LightSample, mean_radiance, sides};
use crate::color::Spectrum;
use crate::shape::{Cuboid, Mesh, Quad};

/// One flat piece of an emitter.
#[derive(Clone, Copy, Debug)]
enum Patch {
    /// `origin + a u + b v`, `a, b` in [0, 1].
    Parallelogram { origin: Vec3, u: Vec3, v: Vec3, n: Vec3 },
    /// `p0 + b1 e1 + b2 e2`, `b1, b2 >= 0`, `b1 + b2 <= 1`; triangle `prim`
    /// of its mesh (for its texture coordinates).
    Triangle { p0: Vec3, e1: Vec3, e2: Vec3, n: Vec3, prim: u32 },
}

impl Patch {
    fn area(&self) -> f32 {
        match self {
            Patch::Parallelogram { u, v, .. } => u.cross(*v).length(),
            Patch::Triangle { e1, e2, .. } => 0.5 * e1.cross(*e2).length(),
        }
    }

    /// A point uniformly on the patch, the patch's normal, and the point's
    /// coordinates on the patch (`(a, b)` on a parallelogram, the
    /// barycentrics `(b1, b2)` on a triangle).
    #[inline]
    fn sample(&self, u: Vec2) -> (Vec3, Vec3, Vec2) {
        match *self {
            Patch::Parallelogram { origin, u: eu, v: ev, n } => (origin + eu * u.x + ev * u.y, n, u),
            Patch::Triangle { p0, e1, e2, n, .. } => {
                // Uniform barycentrics (pbrt-v4 §6.5.4's square-root warp).
                let s = u.x.sqrt();
                let (b1, b2) = (1.0 - s, u.y * s);
                (p0 + e1 * b1 + e2 * b2, n, Vec2::new(b1, b2))
            }
        }
    }
}

/// A quad, cuboid or mesh emitting `radiance` uniformly, or a texture of radiance.
#[derive(Clone, Debug)]
pub struct AreaLight {
    patches: Vec<Patch>,
    /// Cumulative patch areas divided by the total.
    cdf: Vec<f32>,
    area: f32,
    /// Emitted radiance per wavelength (with a texture, its per-bin peak).
    pub radiance: Spectrum,
    /// Emits from both sides.
    pub two_sided: bool,
    /// The radiance over the surface's (u, v), when it varies.
    pub texture: Option<Box<EmissionTexture>>,
    /// With a texture on a mesh, each patch's texture coordinates at its three
    /// corners (`p0`, `p0 + e1`, `p0 + e2`); else empty.
    uvs: Vec<[Vec2; 3]>,
    /// With a texture on a quad or cuboid, the cells its points are drawn
    /// from by brightness (else `None`: uniform by area).
    grid: Option<Box<TextureGrid>>,
}

impl AreaLight {
    fn new(patches: Vec<Patch>, radiance: Spectrum, two_sided: bool) -> Option<AreaLight> {
        let patches: Vec<Patch> = patches.into_iter().filter(|p| p.area() > 0.0 && p.area().is_finite()).collect();
        let mut acc = 0.0f64;
        let mut cdf: Vec<f32> = patches
            .iter()
            .map(|p| {
                acc += p.area() as f64;
                acc as f32
            })
            .collect();
        let area = acc as f32;
        if !(area > 0.0 && area.is_finite()) {
            return None;
        }
        for c in &mut cdf {
            *c /= area;
        }
        Some(AreaLight { patches, cdf, area, radiance, two_sided, texture: None, uvs: Vec::new(), grid: None })
    }

    /// This light with its radiance given by `texture` at each point's (u, v)
    /// (the quad's or cuboid face's `(a, b)`, the mesh's texture coordinates
    /// as [`crate::shape::Shape::uv`] gives them: `mesh` is the emitting mesh).
    pub fn with_texture(mut self, texture: Option<Box<EmissionTexture>>, mesh: Option<&Mesh>) -> AreaLight {
        if texture.is_some()
            && let Some(m) = mesh
        {
            self.uvs = self
                .patches
                .iter()
                .map(|p| match *p {
                    Patch::Triangle { prim, .. } => {
                        [m.uv(prim, 0.0, 0.0), m.uv(prim, 1.0, 0.0), m.uv(prim, 0.0, 1.0)].map(Vec2::from)
                    }
                    Patch::Parallelogram { .. } => [Vec2::ZERO, Vec2::X, Vec2::Y],
                })
                .collect();
        }
        // A quad's or cuboid's (u, v) is each face's (a, b): its cells follow the texture.
        let faces: Option<Vec<Face>> = self
            .patches
            .iter()
            .map(|p| match *p {
                Patch::Parallelogram { origin, u, v, n } => Some(Face { origin, u, v, n }),
                Patch::Triangle { .. } => None,
            })
            .collect();
        self.grid = match (&texture, faces) {
            (Some(t), Some(faces)) if mesh.is_none() => TextureGrid::new(&faces, &t.texture).map(Box::new),
            _ => None,
        };
        self.texture = texture;
        self
    }

    /// The (u, v) of the point at coordinates `b` on patch `k` (see [`Patch::sample`]).
    #[inline(never)]
    fn uv(&self, k: usize, b: Vec2) -> Vec2 {
        match self.patches[k] {
            Patch::Parallelogram { .. } => b,
            Patch::Triangle { .. } => match self.uvs.get(k) {
                Some([t0, t1, t2]) => *t0 * (1.0 - b.x - b.y) + *t1 * b.x + *t2 * b.y,
                None => Vec2::ZERO,
            },
        }
    }

    /// A quad emitting to the side of `edge_u × edge_v`.
    pub fn quad(q: &Quad, radiance: Spectrum, two_sided: bool) -> Option<AreaLight> {
        let p = Patch::Parallelogram { origin: q.origin, u: q.edge_u, v: q.edge_v, n: q.normal() };
        AreaLight::new(vec![p], radiance, two_sided)
    }

    /// The six faces of a cuboid, emitting outward.
    pub fn cuboid(c: &Cuboid, radiance: Spectrum, two_sided: bool) -> Option<AreaLight> {
        let d = c.max - c.min;
        let mut patches = Vec::with_capacity(6);
        for axis in 0..3 {
            let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
            let u = Vec3::AXES[a] * d[a];
            let v = Vec3::AXES[b] * d[b];
            let n = Vec3::AXES[axis];
            // The face at min has the inward normal +axis; flip it outward.
            patches.push(Patch::Parallelogram { origin: c.min, u, v, n: -n });
            patches.push(Patch::Parallelogram { origin: c.min + n * d[axis], u, v, n });
        }
        AreaLight::new(patches, radiance, two_sided)
    }

    /// Every triangle of a mesh, emitting from its front (counter-clockwise) side.
    pub fn mesh(m: &Mesh, radiance: Spectrum, two_sided: bool) -> Option<AreaLight> {
        let patches = (0..m.triangle_count() as u32)
            .map(|k| {
                let [p0, p1, p2] = m.triangle(k);
                let (e1, e2) = (p1 - p0, p2 - p0);
                Patch::Triangle { p0, e1, e2, n: e1.cross(e2).normalize_or_zero(), prim: k }
            })
            .collect();
        AreaLight::new(patches, radiance, two_sided)
    }

    /// Total power up to the spectrum's shape: `π A` times the mean radiance
    /// per side (a texture's mean, [`EmissionTexture::mean`]).
    pub fn power(&self) -> f32 {
        sides(self.two_sided) * PI * self.area * mean_radiance(&self.radiance, &self.texture)
    }

    /// The cosine at the light of a direction `wi` arriving at a patch of
    /// normal `n`; not positive from the back of a one-sided emitter.
    #[inline]
    fn cos_emit(&self, wi: Vec3, n: Vec3) -> f32 {
        if self.two_sided { wi.dot(n).abs() } else { -wi.dot(n) }
    }

    /// A point (uniformly by area, or by a texture's brightness), its
    /// geometric normal, its (u, v) when the light has a texture (else zero),
    /// and its density per unit area.
    #[inline]
    pub(super) fn sample_point(&self, u: Vec2) -> (Vec3, Vec3, Vec2, f32) {
        if let Some(g) = &self.grid {
            return g.sample(u);
        }
        // Choose a patch with u.x, then reuse u.x's position within its interval.
        let k = self.cdf.partition_point(|&c| c <= u.x).min(self.patches.len() - 1);
        let lo = if k == 0 { 0.0 } else { self.cdf[k - 1] };
        let ux = ((u.x - lo) / (self.cdf[k] - lo)).clamp(0.0, 1.0 - f32::EPSILON);
        let (point, n, b) = self.patches[k].sample(Vec2::new(ux, u.y));
        let uv = if self.texture.is_some() { self.uv(k, b) } else { Vec2::ZERO };
        (point, n, uv, 1.0 / self.area)
    }

    /// The density per unit area with which the light draws `point`, a point
    /// of its surface, for [`Self::sample_li`] and emitted rays (`1 / A`
    /// unless a texture steers it).
    #[inline]
    pub fn pdf_area(&self, point: Vec3) -> f32 {
        match &self.grid {
            Some(g) => g.density(point),
            None => 1.0 / self.area,
        }
    }

    /// The total area of the emitting surface.
    #[inline]
    pub(super) fn area(&self) -> f32 {
        self.area
    }

    /// Samples a point uniformly by area; the pdf is per solid angle from `p`.
    #[inline]
    pub fn sample_li(&self, p: Vec3, u: Vec2) -> Option<LightSample> {
        self.sample_li_uv(p, u).map(|(s, _)| s)
    }

    /// [`AreaLight::sample_li`], and the sampled point's (u, v) when the light
    /// has a texture (else zero).
    #[inline]
    pub fn sample_li_uv(&self, p: Vec3, u: Vec2) -> Option<(LightSample, Vec2)> {
        let (point, n, uv, pdf_area) = self.sample_point(u);
        let d = point - p;
        let d2 = d.length_squared();
        if d2 == 0.0 {
            return None;
        }
        let wi = d / d2.sqrt();
        let cos_l = self.cos_emit(wi, n);
        if cos_l <= 0.0 {
            return None;
        }
        let pdf = if self.grid.is_some() { d2 * pdf_area / cos_l } else { d2 / (cos_l * self.area) };
        Some((LightSample { wi, point, n, pdf, scale: 1.0, is_delta: false }, uv))
    }

    /// The pdf per solid angle of [`AreaLight::sample_li`] from `p` for `wi`
    /// hitting the light at `point`, whose geometric normal is `n`.
    #[inline]
    pub fn pdf_li(&self, p: Vec3, wi: Vec3, point: Vec3, n: Vec3) -> f32 {
        let cos_l = self.cos_emit(wi, n);
        if cos_l <= 0.0 {
            return 0.0;
        }
        if self.grid.is_some() {
            return (point - p).length_squared() * self.pdf_area(point) / cos_l;
        }
        (point - p).length_squared() / (cos_l * self.area)
    }
}

/// Emission sampling: rays leaving the light (BDPT's light subpaths, light tracing).
impl AreaLight {
    /// A cosine-distributed ray from a point drawn as [`Self::sample_point`] draws it.
    #[inline]
    pub(super) fn sample_le(&self, u_pos: Vec2, u_dir: Vec2) -> Option<EmissionSample> {
        let (point, n, uv, pdf_area) = self.sample_point(u_pos);
        let e = surface_ray(point, n, uv, self.area(), self.two_sided, u_dir)?;
        Some(if self.grid.is_some() { EmissionSample { pdf_pos: pdf_area, ..e } } else { e })
    }

    /// The densities `(pdf_pos, pdf_dir)` of [`Self::sample_le`] for a ray
    /// leaving `point` (geometric normal `n`) along `dir`.
    #[inline]
    pub(super) fn pdf_le(&self, point: Vec3, n: Vec3, dir: Vec3) -> (f32, f32) {
        let pdf_pos = if self.grid.is_some() { self.pdf_area(point) } else { 1.0 / self.area() };
        (pdf_pos, surface_pdf_dir(n, dir, self.two_sided))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::Light;
    use crate::light::tests::pdf_integral;
    use crate::sampler::Sampler;
    use crate::shape::Shape;

    /// Irradiance at distance `c` below the centre of an `a` x `b` rectangle
    /// of radiance `l` facing it: four corner form factors (the point-to-
    /// rectangle formula, e.g. Howell's catalogue, case B-3).
    fn rectangle_irradiance(a: f64, b: f64, c: f64, l: f64) -> f64 {
        let (x, y) = (a / 2.0 / c, b / 2.0 / c);
        let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
        let f = (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * std::f64::consts::PI);
        4.0 * std::f64::consts::PI * l * f
    }

    fn square() -> Quad {
        Quad::new(Vec3::new(-0.5, 1.0, -0.5), Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 1.0))
    }

    /// Monte Carlo irradiance `E = mean(L cos θ / pdf)` at `p` (normal +y),
    /// with 40k light samples: its standard error is below 0.3% here.
    fn irradiance(light: &AreaLight, p: Vec3) -> f64 {
        let mut s = Sampler::new(9, 1, 1);
        let n = 40_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            if let Some(ls) = light.sample_li(p, s.next_2d()) {
                sum += (ls.wi.y.max(0.0) / ls.pdf) as f64;
            }
        }
        sum / n as f64
    }

    #[test]
    fn quad_and_mesh_emitters_give_the_closed_form_irradiance() {
        let q = square();
        assert!(q.normal().y < 0.0, "the test square faces down");
        let want = rectangle_irradiance(1.0, 1.0, 1.0, 1.0);
        let quad = AreaLight::quad(&q, Spectrum::ONE, false).unwrap();
        let got = irradiance(&quad, Vec3::ZERO);
        assert!((got - want).abs() < 0.01 * want, "quad: {got} vs {want}");
        // The same square as two triangles of a mesh (counter-clockwise seen from below).
        let c = [q.origin, q.origin + q.edge_u, q.origin + q.edge_u + q.edge_v, q.origin + q.edge_v];
        let mesh = Mesh::from_triangles(c.to_vec(), vec![[0, 1, 2], [0, 2, 3]], None).unwrap();
        let tri = AreaLight::mesh(&mesh, Spectrum::ONE, false).unwrap();
        let got = irradiance(&tri, Vec3::ZERO);
        assert!((got - want).abs() < 0.01 * want, "mesh: {got} vs {want}");
        // One-sided: nothing from above; two-sided: the same from above.
        assert_eq!(irradiance(&quad, Vec3::new(0.0, 2.0, 0.0)), 0.0);
    }

    /// The pdf of every flat emitter integrates, over the directions that hit
    /// it, to the share of its area that faces the point: 1 for a quad seen
    /// from its front, 1/2 for this cuboid, which shows the point three of its
    /// faces (areas 0.35 + 0.49 + 0.35 of 2.38; samples on the other three
    /// carry no light towards it). 200k directions: about 1% standard error,
    /// so 4%. `pdf_li` equals the sampled pdf.
    #[test]
    fn flat_emitter_pdfs_integrate_to_their_visible_share() {
        let cuboid = Cuboid::new(Vec3::new(-0.3, 0.8, -0.2), Vec3::new(0.4, 1.3, 0.5));
        let q = square();
        let p = Vec3::new(0.9, -0.2, 1.1);
        let cases: Vec<(Light, Shape, f64)> = vec![
            (Light::Area(AreaLight::quad(&q, Spectrum::ONE, false).unwrap()), Shape::Quad(q), 1.0),
            (Light::Area(AreaLight::quad(&q, Spectrum::ONE, true).unwrap()), Shape::Quad(q), 1.0),
            (Light::Area(AreaLight::cuboid(&cuboid, Spectrum::ONE, false).unwrap()), Shape::Cuboid(cuboid), 0.5),
        ];
        for (light, shape, want) in &cases {
            let integral = pdf_integral(light, |r| shape.intersect(r, f32::INFINITY), p, 3, 200_000);
            assert!((integral - want).abs() < 0.04 * want, "{shape:?}: ∫pdf = {integral}, want {want}");
            let mut s = Sampler::new(5, 5, 5);
            for _ in 0..500 {
                let Some(ls) = light.sample_li(p, s.next_2d()) else { continue };
                let hit = shape.intersect(&crate::geometry::Ray::new(p, ls.wi), f32::INFINITY).unwrap();
                assert!((hit.p - ls.point).length() < 1e-3, "the sampled point is on the shape");
                let back = light.pdf_li(p, ls.wi, hit.p, hit.n);
                assert!((back - ls.pdf).abs() <= 1e-3 * ls.pdf, "pdf_li {back} vs {}", ls.pdf);
            }
        }
    }

    #[test]
    fn degenerate_emitters_are_refused() {
        let flat = Quad::new(Vec3::ZERO, Vec3::X, Vec3::X);
        assert!(AreaLight::quad(&flat, Spectrum::ONE, false).is_none());
    }
}
