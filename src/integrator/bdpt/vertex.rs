//! Subpath vertices, the sample's collapsed wavelength, and the densities and
//! material queries a vertex answers.

use std::sync::LazyLock;

use glam::{Vec2, Vec3};

use crate::bxdf::{Bxdf, Outside};
use crate::color::{N_BINS, Spectrum};
use crate::geometry::Frame;
use crate::scene::Scene;
use crate::spectral::{BinDistribution, Lambdas, Readout, bin_importance, continuous_wavelength};

use crate::integrator::Shading;

/// What a subpath vertex is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Kind {
    /// The eye.
    Camera,
    /// A point on light `index`.
    Light(u32),
    /// A surface point of object `index`.
    Surface(u32),
    /// A scattering event in the medium filling object `index`'s inside.
    Medium(u32),
}

/// A subpath vertex.
#[derive(Clone, Copy, Debug)]
pub(super) struct Vertex {
    pub(super) kind: Kind,
    /// Position, geometric normal, shading frame and the local direction
    /// back along the subpath (`wo`).
    pub(super) sh: Shading,
    /// Throughput of the subpath up to and including this vertex's arrival.
    pub(super) beta: Spectrum,
    /// The scattering sampled here was a delta lobe.
    pub(super) delta: bool,
    /// The surface here is glossy ([`crate::bxdf::Bxdf::is_glossy`]).
    pub(super) glossy: bool,
    /// The subpath collapsed to one wavelength before reaching this vertex.
    pub(super) collapsed: bool,
    /// Area density of this vertex as its own walk generated it.
    pub(super) pdf_fwd: f32,
    /// Area density of this vertex as a walk from the other end would.
    pub(super) pdf_rev: f32,
    /// The factor that turns a density per solid angle here towards the
    /// previous vertex into an area density there: `|cos| / d²` at the
    /// previous vertex (no cosine at the eye or a point light; 0 at a
    /// subpath's first vertex). Kept so connections need not recompute it.
    pub(super) g_prev: f32,
    /// At a dielectric's surface, the material of the medium on its outside
    /// (`None`: vacuum, or not a dielectric).
    pub(super) outside: Option<u32>,
    /// The surface coordinates, where the material is textured or a `Mix`
    /// (else zero).
    pub(super) uv: Vec2,
    /// At a surface vertex, its material: the object's, or what a `Mix`
    /// chose at this point ([`Scene::material_at`], resolved once when the
    /// vertex is made, so every strategy sees the same); 0 elsewhere.
    pub(super) material: u32,
}

impl Vertex {
    pub(super) fn at_point(kind: Kind, p: Vec3, n: Vec3, beta: Spectrum, pdf_fwd: f32) -> Vertex {
        let frame = Frame::from_z(if n == Vec3::ZERO { Vec3::Z } else { n });
        let sh = Shading { p, n, frame, wo: Vec3::Z, wo_n: 0.0 };
        Vertex {
            kind,
            sh,
            beta,
            delta: false,
            glossy: false,
            collapsed: false,
            pdf_fwd,
            pdf_rev: 0.0,
            g_prev: 0.0,
            outside: None,
            uv: Vec2::ZERO,
            material: 0,
        }
    }

    #[inline]
    pub(super) fn p(&self) -> Vec3 {
        self.sh.p
    }

    /// True for a vertex on the environment (at infinity: its `p` is a point
    /// far beyond the scene in its direction, its densities per solid angle).
    #[inline]
    pub(super) fn is_infinite(&self, scene: &Scene) -> bool {
        matches!(self.kind, Kind::Light(i) if scene.light(i).is_infinite())
    }

    /// True when densities arriving at this vertex carry its cosine (area
    /// measure on a surface): surfaces and area lights, not the eye or a
    /// point, spot, distant or beam light.
    #[inline]
    pub(super) fn on_surface(&self, scene: &Scene) -> bool {
        match self.kind {
            Kind::Surface(_) => true,
            Kind::Light(i) => !scene.light(i).is_delta(),
            Kind::Camera | Kind::Medium(_) => false,
        }
    }
}

/// The one wavelength a sample collapses to, drawn lazily from `u_λ`.
pub(super) struct Wavelength {
    pub(super) u: f32,
    /// Continuous wavelengths (colour output); bin centres for spectral output.
    pub(super) continuous: bool,
    pub(super) drawn: Option<Single>,
}

/// The collapsed wavelength: the slot of a throughput that holds its value,
/// and the packet of one wavelength (with the weight `1/p`) that evaluates
/// materials at it and reads its value out as colour.
#[derive(Clone, Copy, Debug)]
pub(super) struct Single {
    pub(super) slot: usize,
    pub(super) lambdas: Lambdas<1>,
}

impl Wavelength {
    /// The sample's wavelength (drawn on first use).
    pub(super) fn single(&mut self) -> Single {
        static DIST: LazyLock<BinDistribution> = LazyLock::new(|| {
            let importance = bin_importance();
            BinDistribution::new(|b| importance[b]).expect("visual importance is positive")
        });
        let (u, continuous) = (self.u, self.continuous);
        *self.drawn.get_or_insert_with(|| {
            if continuous {
                let (lambdas, _) = continuous_wavelength(&DIST, u);
                Single { slot: (lambdas.pos[0].round().max(0.0) as usize).min(N_BINS - 1), lambdas }
            } else {
                let (b, p) = DIST.sample(u);
                Single { slot: b, lambdas: Lambdas { pos: [b as f32], weight: 1.0 / p, readout: Readout::Spectral } }
            }
        })
    }

    /// The value of throughput `v` at the sample's wavelength: the slot that
    /// holds it once its subpath has collapsed, else its interpolation there.
    pub(super) fn at(&mut self, v: &Spectrum, collapsed: bool) -> f32 {
        let one = self.single();
        if collapsed { v[one.slot] } else { one.lambdas.sample(v)[0] }
    }
}

/// A strategy's contribution: the full spectrum, or one value at the
/// sample's collapsed wavelength.
#[derive(Clone, Copy, Debug)]
pub(super) enum Contrib {
    Full(Spectrum),
    Single(f32),
}

/// Veach's correction of the adjoint BSDF for shading normals: the factor
/// by which importance transport differs from radiance transport where the
/// shading normal is not the geometric one (1 on flat geometry).
#[inline]
pub(super) fn shading_correction(sh: &Shading, wi: Vec3, wi_local: Vec3) -> f32 {
    let den = sh.wo_n.abs() * wi_local.z.abs();
    let c = sh.wo.z.abs() * wi.dot(sh.n).abs() / den;
    if c.is_finite() { c } else { 0.0 }
}

/// The material of surface vertex `v`, untextured: for what no texture
/// changes (delta, dispersive, black).
#[inline]
pub(super) fn material<'s>(scene: &'s Scene, v: &Vertex) -> &'s Bxdf {
    &scene.materials[v.material as usize]
}

/// The BSDF at surface vertex `v` (its material, a `Mix` already resolved,
/// with its texture evaluated at the vertex's (u, v), built in `slot`).
#[inline(always)]
pub(super) fn bsdf_at<'s>(scene: &'s Scene, v: &Vertex, slot: &'s mut Option<Bxdf>) -> &'s Bxdf {
    scene.bsdf_of(v.material, v.uv, slot)
}

/// True when a connection can end at `v`: a surface whose material has a
/// non-delta part (a plastic whose walk sampled its mirror coat still has
/// its diffuse base), or a light. Not the sampled lobe's `delta` flag,
/// which only says how the walk continued.
#[inline]
pub(super) fn connectible(scene: &Scene, v: &Vertex) -> bool {
    match v.kind {
        Kind::Surface(_) => !material(scene, v).is_delta(),
        Kind::Light(_) | Kind::Camera | Kind::Medium(_) => true,
    }
}

/// True when vertex `v` lies on a dispersive surface (its glass or the
/// medium outside it disperses).
#[inline]
pub(super) fn is_dispersive(scene: &Scene, v: &Vertex) -> bool {
    matches!(v.kind, Kind::Surface(_) if material(scene, v).dispersion_within(outside(scene, v.outside)).is_some())
}

/// The medium outside a dielectric vertex, from its material index.
#[inline]
pub(super) fn outside(scene: &Scene, material: Option<u32>) -> Outside<'_> {
    scene.outside(material)
}

/// Converts a density per solid angle at `from` towards `to` into a density
/// per unit area at `to`.
#[inline]
pub(super) fn to_area(scene: &Scene, pdf_dir: f32, from: &Vertex, to: &Vertex) -> f32 {
    if to.is_infinite(scene) {
        // A vertex on the environment is a direction: its density stays per solid angle.
        return pdf_dir;
    }
    let d = to.p() - from.p();
    let d2 = d.length_squared();
    if d2.is_nan() || d2 <= 0.0 {
        return 0.0;
    }
    let mut pdf = pdf_dir / d2;
    if to.on_surface(scene) {
        pdf *= (d.dot(to.sh.n) / d2.sqrt()).abs();
    }
    pdf
}

/// The BSDF density at surface vertex `v` for local directions `wo`, `wi`
/// (0 for delta lobes).
#[inline]
pub(super) fn pdf_at(scene: &Scene, v: &Vertex, wo: Vec3, wi: Vec3) -> f32 {
    match v.kind {
        Kind::Surface(_) => {
            let mut slot = None;
            bsdf_at(scene, v, &mut slot).pdf_within(wo, wi, &Lambdas::full(), outside(scene, v.outside))
        }
        Kind::Medium(o) => scene.interior(o).map_or(0.0, |m| m.phase().eval(wo, wi)),
        _ => 0.0,
    }
}

/// A medium vertex at `p` in the medium filling object `object`, reached
/// travelling along `dir`: its frame's z is `−dir`, so its local `wo` is +z
/// (the phase function depends only on the angle, so any frame serves); no
/// normal (no cosine, no ray offset).
pub(super) fn medium_vertex(object: u32, p: Vec3, dir: Vec3, beta: Spectrum, collapsed: bool) -> Vertex {
    let sh = Shading { p, n: Vec3::ZERO, frame: Frame::from_z(-dir), wo: Vec3::Z, wo_n: 0.0 };
    Vertex {
        kind: Kind::Medium(object),
        sh,
        beta,
        delta: false,
        glossy: false,
        collapsed,
        pdf_fwd: 0.0,
        pdf_rev: 0.0,
        g_prev: 0.0,
        outside: None,
        uv: Vec2::ZERO,
        material: 0,
    }
}

/// How a scattering vertex scatters: its BSDF (texture evaluated) and the
/// medium outside a dielectric, or its phase function. Built once per
/// vertex and connection, so a connection evaluates each end's model once.
#[derive(Clone, Copy)]
pub(super) enum Scatter<'a> {
    Surface(&'a Bxdf, Outside<'a>),
    Medium(&'a crate::medium::HenyeyGreenstein),
}

impl Scatter<'_> {
    /// The model's value between local directions `wo` and `wi`.
    #[inline]
    pub(super) fn eval<const N: usize>(&self, wo: Vec3, wi: Vec3, lambdas: &Lambdas<N>) -> crate::color::Sampled<N> {
        match self {
            Scatter::Surface(b, out) => b.eval_within(wo, wi, lambdas, *out),
            Scatter::Medium(p) => crate::color::Sampled::splat(p.eval(wo, wi)),
        }
    }

    /// Its density for `wi` given `wo` (the full spectrum's, as the walks sample).
    #[inline]
    pub(super) fn pdf(&self, wo: Vec3, wi: Vec3, full: &Lambdas<N_BINS>) -> f32 {
        match self {
            Scatter::Surface(b, out) => b.pdf_within(wo, wi, full, *out),
            Scatter::Medium(p) => p.eval(wo, wi),
        }
    }
}

/// The [`Scatter`] of surface or medium vertex `v` (a textured BSDF is built in `slot`).
#[inline]
pub(super) fn scatter<'s>(scene: &'s Scene, v: &Vertex, slot: &'s mut Option<Bxdf>) -> Option<Scatter<'s>> {
    match v.kind {
        Kind::Surface(_) => Some(Scatter::Surface(bsdf_at(scene, v, slot), outside(scene, v.outside))),
        Kind::Medium(o) => scene.interior(o).map(|m| Scatter::Medium(m.phase())),
        _ => None,
    }
}

/// The cosine a scattering vertex contributes for local direction `wi`:
/// `|cos θ|` on a surface, 1 in a medium.
#[inline]
pub(super) fn cos_at(v: &Vertex, wi: Vec3) -> f32 {
    if matches!(v.kind, Kind::Medium(_)) { 1.0 } else { wi.z.abs() }
}

/// `|w · n|` at vertex `v` when densities arriving there carry its cosine
/// (a surface), else 1 (a medium point).
#[inline]
pub(super) fn cos_normal(v: &Vertex, w: Vec3) -> f32 {
    if matches!(v.kind, Kind::Medium(_)) { 1.0 } else { w.dot(v.sh.n).abs() }
}

/// Whether world direction `w` (local `wi`) leaves vertex `v` on the side its
/// shading frame claims ([`Shading::consistent`] on a surface; always in a medium).
#[inline]
pub(super) fn consistent_at(v: &Vertex, w: Vec3, wi: Vec3) -> bool {
    matches!(v.kind, Kind::Medium(_)) || v.sh.consistent(w, wi)
}

/// The area density at `next` of the ray `sample_le` would start from light
/// vertex `y` towards it.
#[inline]
pub(super) fn pdf_light(scene: &Scene, y: &Vertex, next: &Vertex) -> f32 {
    let Kind::Light(i) = y.kind else {
        return 0.0;
    };
    let light = scene.light(i);
    let w = (next.p() - y.p()).normalize_or_zero();
    let (pdf_pos, pdf_dir) = light.pdf_le(y.p(), y.sh.n, w);
    if light.is_delta_direction() || light.is_infinite() {
        // Parallel rays: the disk's density projected onto `next`.
        let cos = if next.on_surface(scene) { w.dot(next.sh.n).abs() } else { 1.0 };
        return pdf_pos * cos;
    }
    to_area(scene, pdf_dir, y, next)
}
