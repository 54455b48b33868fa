//! The scene file format: serde structures that *are* the RON format.
//!
//! Every struct denies unknown fields, so a misspelt field is an error with
//! its line:column, never silently ignored. [`super::load_scene`] turns a
//! [`SceneDesc`] into a [`super::Scene`], checking names and sizes.
//!
//! A complete example (`scenes/cornell.ron` is the full one):
//! ```ron
//! (
//!     camera: (eye: (0, 1, 3.5), look_at: (0, 1, 0), up: (0, 1, 0), fov_deg: 45),
//!     render: (width: 256, height: 256, spp: 64, seed: 0, max_bounces: 8, integrator: path),
//!     materials: {
//!         "white": OrenNayar(reflectance: ColorChecker("white 9.5 (.05 D)"), sigma_deg: 20),
//!         "glass": Dielectric(ior: Named("N-BK7")),
//!     },
//!     objects: [
//!         (shape: Quad(origin: (-1, 0, 1), edge_u: (2, 0, 0), edge_v: (0, 0, -2)), material: "white"),
//!         (shape: Sphere(center: (0.3, 0.35, -0.2), radius: 0.35), material: "glass"),
//!         (shape: Sphere(center: (-0.6, 1.7, -0.4), radius: 0.2), emission: Scaled(10, EqualEnergy)),
//!     ],
//!     lights: [ Point(position: (0, 1.9, 0), intensity: Constant(1)) ],
//! )
//! ```

use std::collections::BTreeSet;

use serde::{Deserialize, Serialize};

use crate::settings::SettingsPatch;

mod camera;
mod surroundings;

pub use camera::{CameraDesc, LensDesc};
pub use surroundings::{EnvMapping, EnvironmentDesc, MediumDesc, PhaseDesc};

/// A 3-vector in the file: `(x, y, z)`.
pub type V3 = [f32; 3];

/// The whole scene file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneDesc {
    /// The camera.
    pub camera: CameraDesc,
    /// Render settings; each can be overridden on the command line.
    #[serde(default)]
    pub render: SettingsPatch,
    /// Named materials, referred to by objects (a name may appear once).
    #[serde(default)]
    pub materials: Materials,
    /// The objects (shapes with a material or an emission).
    pub objects: Vec<ObjectDesc>,
    /// Named groups of objects in their own space, placed any number of times by
    /// `Instance(group: "tree")` objects without copying their meshes:
    /// `groups: { "tree": [ (shape: Mesh(path: "tree.ply"), material: "bark") ] }`.
    /// Members are meshes (`Mesh`, `Triangles`) with a material; no emission, `interior`
    /// or `exterior`.
    #[serde(default)]
    pub groups: NamedMap<Vec<ObjectDesc>>,
    /// Lights that are not objects (point lights).
    #[serde(default)]
    pub lights: Vec<LightDesc>,
    /// Named participating media, referred to by objects' `interior:`
    /// (`crate::medium`): `media: { "milk": Homogeneous(sigma_a: ..., sigma_s: ..., phase: HenyeyGreenstein(g: 0.7)) }`.
    #[serde(default)]
    pub media: NamedMap<MediumDesc>,
    /// Radiance from infinitely far away, seen by every ray that escapes
    /// (`crate::light::EnvironmentLight`); none by default (escaping rays see black).
    #[serde(default)]
    pub environment: Option<EnvironmentDesc>,
}

pub(super) fn one() -> f32 {
    1.0
}

fn is_zero(v: &u32) -> bool {
    *v == 0
}

pub(super) fn is_zero_f32(v: &f32) -> bool {
    *v == 0.0
}

/// A map from names to descriptions in file order (`materials`, `media`); a
/// name given twice is an error (`duplicate material "white"`), where a plain
/// map would keep the last.
#[derive(Debug)]
pub struct NamedMap<T>(pub Vec<(String, T)>);

impl<T: Serialize> Serialize for NamedMap<T> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut map = s.serialize_map(Some(self.0.len()))?;
        for (name, m) in &self.0 {
            map.serialize_entry(name, m)?;
        }
        map.end()
    }
}

/// The `materials` map.
pub type Materials = NamedMap<MaterialDesc>;

impl<T> Default for NamedMap<T> {
    fn default() -> Self {
        NamedMap(Vec::new())
    }
}

/// What a [`NamedMap`]'s entries are called in errors.
pub trait Noun {
    /// `material`, `medium`.
    const NOUN: &'static str;
}

impl Noun for MaterialDesc {
    const NOUN: &'static str = "material";
}

impl Noun for MediumDesc {
    const NOUN: &'static str = "medium";
}

impl Noun for Vec<ObjectDesc> {
    const NOUN: &'static str = "group";
}

impl<'de, T: Deserialize<'de> + Noun> Deserialize<'de> for NamedMap<T> {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visit<T>(std::marker::PhantomData<T>);
        impl<'de, T: Deserialize<'de> + Noun> serde::de::Visitor<'de> for Visit<T> {
            type Value = NamedMap<T>;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                write!(f, "a map from {} names to descriptions", T::NOUN)
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<NamedMap<T>, A::Error> {
                let mut seen = BTreeSet::new();
                let mut out = Vec::new();
                while let Some(name) = map.next_key::<String>()? {
                    if !seen.insert(name.clone()) {
                        return Err(serde::de::Error::custom(format!("duplicate {} \"{name}\"", T::NOUN)));
                    }
                    out.push((name, map.next_value()?));
                }
                Ok(NamedMap(out))
            }
        }
        d.deserialize_map(Visit(std::marker::PhantomData))
    }
}

/// A spectrum in the scene file.
#[derive(Clone, Debug, Deserialize, Serialize)]
pub enum SpectrumDesc {
    /// The same value at every wavelength: `Constant(0.5)`.
    Constant(f32),
    /// 36 values at 380, 390, ..., 730 nm: `Samples([0.1, 0.1, ...])`.
    Samples(Vec<f32>),
    /// A ColorChecker patch by its BabelColor name: `ColorChecker("red")`.
    ColorChecker(String),
    /// CIE illuminant D65, normalised to 1 at 560 nm.
    D65,
    /// The equal-energy illuminant: 1 everywhere.
    EqualEnergy,
    /// Planck's law at a temperature in kelvin, normalised to peak 1: `Blackbody(3000)`.
    Blackbody(f32),
    /// A spectrum times a factor: `Scaled(10, D65)`.
    Scaled(f32, Box<SpectrumDesc>),
    /// `(nm, value)` pairs at any wavelengths in increasing order, linear between them and flat
    /// beyond the ends, sampled at the 36 bin centres: `Table([(400, 0.1), (550, 0.8), (700, 0.3)])`.
    Table(Vec<(f32, f32)>),
    /// A two-column CSV file (`nm,value` per line, relative to the scene file; a header line,
    /// blank lines and `#` comments are allowed), read like `Table`: `File("data/led.csv")`.
    File(String),
    /// Scattering that falls as λ⁻⁴ (Rayleigh): `s · (550 nm / λ)⁴`: `Rayleigh(0.5)`.
    Rayleigh(f32),
    /// Linear sRGB, uplifted to a smooth spectrum (Jakob and Hanika 2019): as a reflectance
    /// (components in [0, 1]) its colour under D65; as an emission the colour times D65, so the
    /// emitter seen directly renders `(r, g, b)`: `Rgb(0.8, 0.2, 0.1)`.
    Rgb(f32, f32, f32),
    /// An image texture (a material's reflectance or an object's emission; see `crate::texture`):
    /// `Image(path: "wood.png", uv_scale: (2, 2), uv_offset: (0, 0), wrap: Repeat, scale: 1)`.
    Image {
        /// A PNG (sRGB) or EXR (linear) file, relative to the scene file.
        path: String,
        /// Multiplies (u, v) before the lookup (default `(1, 1)`).
        #[serde(default = "ones2")]
        uv_scale: [f32; 2],
        /// Added to (u, v) after `uv_scale` (default `(0, 0)`).
        #[serde(default)]
        uv_offset: [f32; 2],
        /// Outside [0, 1]: `Repeat` (default) or `Clamp`.
        #[serde(default)]
        wrap: Wrap,
        /// A factor on every texel (default 1); for a reflectance the product is clamped to [0, 1].
        #[serde(default = "one")]
        scale: f32,
    },
    /// A checkerboard over (u, v) (a material's reflectance or an object's emission):
    /// `Checkerboard(even: Constant(0.8), odd: Rgb(0.1, 0.1, 0.3), scale: 8)`.
    Checkerboard {
        /// The squares where `⌊N u⌋ + ⌊N v⌋` is even.
        even: Box<SpectrumDesc>,
        /// The other squares.
        odd: Box<SpectrumDesc>,
        /// `N`, squares per unit of u and of v.
        scale: f32,
    },
    /// A spectrum scaled to the given luminance Y (a flat spectrum of 1 has Y = 1):
    /// `Luminance(5, Blackbody(3000))` is a 3000 K emitter as bright as `Constant(5)`.
    Luminance(f32, Box<SpectrumDesc>),
}

/// How an image texture continues outside [0, 1].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
pub enum Wrap {
    /// Periodically (the default).
    #[default]
    Repeat,
    /// The edge texels extend outwards.
    Clamp,
}

fn ones2() -> [f32; 2] {
    [1.0, 1.0]
}

/// A `Mix`'s default amount: each material half the time.
fn half() -> ScalarDesc {
    ScalarDesc::Value(0.5)
}

/// An index of refraction in the scene file.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub enum IorDesc {
    /// Constant over wavelength: `Constant(1.5)`.
    Constant(f32),
    /// `n = a + b / λ²`, λ in µm: `Cauchy(a: 1.5, b: 0.0042)`.
    Cauchy {
        /// A.
        a: f32,
        /// B in µm².
        b: f32,
    },
    /// `n² − 1 = Σ Bᵢ λ² / (λ² − Cᵢ)`, λ in µm, three terms.
    Sellmeier {
        /// B₁, B₂, B₃.
        b: V3,
        /// C₁, C₂, C₃ in µm².
        c: V3,
    },
    /// A named glass: `Named("N-BK7")` (N-BK7, N-SF11, SF11, F2, fused_silica, water_20C, diamond).
    Named(String),
}

/// A material.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub enum MaterialDesc {
    /// Ideal diffuse.
    Lambertian {
        /// Reflectance.
        reflectance: SpectrumDesc,
    },
    /// Rough diffuse; σ in degrees (0 = Lambertian).
    OrenNayar {
        /// Reflectance.
        reflectance: SpectrumDesc,
        /// Roughness σ in degrees.
        sigma_deg: f32,
    },
    /// A perfect mirror.
    Mirror {
        /// Reflectance.
        reflectance: SpectrumDesc,
    },
    /// Glass: `Dielectric(ior: Named("N-BK7"))`, optionally rough
    /// (`roughness: A`, GGX α) and absorbing (`absorption: SPECTRUM`, per unit length).
    Dielectric {
        /// Index of refraction of the inside.
        ior: IorDesc,
        /// GGX α in [0, 1] (default 0: smooth), or a texture of α.
        #[serde(default)]
        roughness: ScalarDesc,
        /// Absorption coefficient inside, per scene unit (default: clear).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        absorption: Option<SpectrumDesc>,
        /// A thin film on the outside (on every microfacet of rough glass): `coating: ThinFilm(thickness_nm: 100, ior: Constant(1.38))`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        coating: Option<CoatingDesc>,
    },
    /// A metal: `Conductor(metal: "Au")` (Au, Ag, Cu, Al, Cr, CuZn) or
    /// `Conductor(eta: SPECTRUM, k: SPECTRUM)`, optionally `roughness: A`
    /// (GGX α as Mitsuba's `alpha`; 0, the default, is a smooth metal).
    Conductor {
        /// A named metal (exclusive with `eta` and `k`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        metal: Option<String>,
        /// The real part of the complex index, per wavelength.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        eta: Option<SpectrumDesc>,
        /// The extinction coefficient (imaginary part), per wavelength.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        k: Option<SpectrumDesc>,
        /// GGX α in [0, 1] (default 0: smooth), or a texture of α.
        #[serde(default)]
        roughness: ScalarDesc,
        /// A thin film on the metal: `coating: ThinFilm(thickness_nm: 300, ior: Constant(1.45))`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        coating: Option<CoatingDesc>,
    },
    /// Coated diffuse: a dielectric coat (index `ior`, GGX `roughness`,
    /// default 0: smooth) over a Lambertian base of `reflectance`.
    Plastic {
        /// The base's diffuse reflectance.
        reflectance: SpectrumDesc,
        /// The coat's index of refraction.
        ior: IorDesc,
        /// GGX α of the coat in [0, 1] (default 0: smooth), or a texture of α.
        #[serde(default)]
        roughness: ScalarDesc,
    },
    /// An index-matched boundary (`Interface`): light passes straight through; it
    /// bounds the volume its object's `interior:` medium fills.
    Interface,
    /// A free-standing thin film (soap film): `ThinSheet(thickness_nm: 400, ior: Constant(1.33))`.
    ThinSheet {
        /// Thickness in nm, or a texture of thicknesses.
        thickness_nm: ScalarDesc,
        /// The film's index of refraction.
        ior: IorDesc,
    },
    /// Absorbs everything.
    Black,
    /// One of two other materials, chosen at each hit (pbrt-v4's `mix`):
    /// `Mix(materials: ("paint", "metal"), amount: 0.3)` is the second with
    /// probability `amount` (a number in [0, 1] or a texture of numbers), the
    /// first otherwise; the choice is a hash of the hit point, so every
    /// strategy sees the same one (`crate::material::mix`).
    Mix {
        /// The names of the two materials (either may be a Mix itself).
        materials: (String, String),
        /// The second material's share in [0, 1], or a texture of shares
        /// (default ½, as pbrt's).
        #[serde(default = "half")]
        amount: ScalarDesc,
    },
}

/// A scalar material parameter (`roughness`, `thickness_nm`): a number, as
/// always (`roughness: 0.2`), or a texture of numbers over the surface's
/// (u, v) (`roughness: Image(path: "rough.png", scale: 0.5)`,
/// `roughness: Checkerboard(even: 0.1, odd: 0.4, scale: 8)`; see
/// `crate::texture::ScalarTexture`).
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum ScalarDesc {
    /// The same value everywhere.
    Value(f32),
    /// A texture of values.
    Texture(ScalarTextureDesc),
}

impl Default for ScalarDesc {
    fn default() -> Self {
        ScalarDesc::Value(0.0)
    }
}

impl From<f32> for ScalarDesc {
    fn from(v: f32) -> Self {
        ScalarDesc::Value(v)
    }
}

/// What [`ScalarDesc`] accepts, for its error message.
const SCALAR_EXPECTED: &str = "expected a number (`roughness: 0.2`), \
    `Image(path: \"...\", uv_scale: (1, 1), uv_offset: (0, 0), wrap: Repeat, scale: 1)` \
    or `Checkerboard(even: 0.1, odd: 0.4, scale: 8)` (numbers, not spectra)";

impl<'de> Deserialize<'de> for ScalarDesc {
    /// A number or a texture (serde's untagged choice, which RON supports);
    /// anything else is one error listing the three forms at the value's
    /// position (the untagged choice alone says only "did not match any variant").
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Raw {
            Value(f32),
            Texture(ScalarTextureDesc),
        }
        match Raw::deserialize(d) {
            Ok(Raw::Value(v)) => Ok(ScalarDesc::Value(v)),
            Ok(Raw::Texture(t)) => Ok(ScalarDesc::Texture(t)),
            Err(_) => Err(serde::de::Error::custom(SCALAR_EXPECTED)),
        }
    }
}

/// A texture of numbers (a [`ScalarDesc`] that varies).
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub enum ScalarTextureDesc {
    /// An image's luminance (`0.2126 R + 0.7152 G + 0.0722 B` of its linear
    /// sRGB, the grey itself where R = G = B) times `scale`, looked up as a
    /// reflectance image is:
    /// `Image(path: "rough.png", uv_scale: (1, 1), uv_offset: (0, 0), wrap: Repeat, scale: 0.5)`.
    Image {
        /// A PNG (sRGB) or EXR (linear) file, relative to the scene file.
        path: String,
        /// Multiplies (u, v) before the lookup (default `(1, 1)`).
        #[serde(default = "ones2")]
        uv_scale: [f32; 2],
        /// Added to (u, v) after `uv_scale` (default `(0, 0)`).
        #[serde(default)]
        uv_offset: [f32; 2],
        /// Outside [0, 1]: `Repeat` (default) or `Clamp`.
        #[serde(default)]
        wrap: Wrap,
        /// A factor on every texel's luminance (default 1).
        #[serde(default = "one")]
        scale: f32,
    },
    /// Two numbers in a checkerboard over (u, v):
    /// `Checkerboard(even: 0.1, odd: 0.4, scale: 8)`.
    Checkerboard {
        /// The value on the squares where `⌊N u⌋ + ⌊N v⌋` is even.
        even: f32,
        /// The value on the other squares.
        odd: f32,
        /// `N`, squares per unit of u and of v.
        scale: f32,
    },
}

/// A coating on a surface.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub enum CoatingDesc {
    /// A thin film of `thickness_nm` and index `ior` (interference per wavelength).
    ThinFilm {
        /// Thickness in nm, or a texture of thicknesses.
        thickness_nm: ScalarDesc,
        /// The film's index of refraction.
        ior: IorDesc,
    },
}

/// A shape.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub enum ShapeDesc {
    /// A sphere.
    Sphere {
        /// Centre.
        center: V3,
        /// Radius.
        radius: f32,
    },
    /// A thin spherical shell between two concentric spheres.
    Bubble {
        /// Centre.
        center: V3,
        /// Outer radius.
        outer_radius: f32,
        /// Inner radius (less than the outer).
        inner_radius: f32,
    },
    /// An infinite plane through `point` with normal `normal`.
    Plane {
        /// A point on the plane.
        point: V3,
        /// The normal (need not be unit).
        normal: V3,
    },
    /// A disk.
    Disk {
        /// Centre.
        center: V3,
        /// The normal (the emitting side for a light).
        normal: V3,
        /// Radius.
        radius: f32,
    },
    /// An axis-aligned box as a solid.
    Cuboid {
        /// The minimum corner.
        min: V3,
        /// The maximum corner.
        max: V3,
    },
    /// A parallelogram `origin + a·edge_u + b·edge_v`, a, b in [0, 1]; normal `edge_u × edge_v`.
    Quad {
        /// A corner.
        origin: V3,
        /// First edge.
        edge_u: V3,
        /// Second edge.
        edge_v: V3,
    },
    /// A triangle mesh given inline, built like a mesh file's contents:
    /// `Triangles(positions: [(0, 0, 0), (1, 0, 0), (1, 1, 0)], indices: [(0, 1, 2)])`.
    Triangles {
        /// Vertex positions.
        positions: Vec<V3>,
        /// Triangles as indices into `positions`, counter-clockwise seen from the front.
        indices: Vec<[u32; 3]>,
        /// Per-vertex shading normals, one per position (default: flat triangles).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        normals: Option<Vec<V3>>,
        /// Per-vertex texture coordinates `(u, v)`, one per position (kept for textures,
        /// issue 35; default: none).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        uvs: Option<Vec<[f32; 2]>>,
    },
    /// A triangle mesh from an OBJ or PLY file (optionally .gz), relative to the scene file.
    Mesh {
        /// The mesh file.
        path: String,
        /// Uniform or per-axis scale (default 1).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        scale: Option<ScaleDesc>,
        /// Rotation in degrees about x, then y, then z (default none).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        rotate_deg: Option<V3>,
        /// Translation (default none).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        translate: Option<V3>,
    },
    /// The objects of a group in `groups`, placed by this object's `transform:` (which
    /// may be a general `matrix:`); each member keeps its own material, so the object
    /// takes no `material:`: `Instance(group: "tree")`.
    Instance {
        /// The group's name.
        group: String,
    },
}

/// A scale: one number or three.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(untagged)]
pub enum ScaleDesc {
    /// The same along every axis.
    Uniform(f32),
    /// Per axis.
    PerAxis(V3),
}

/// An object: a shape with a material, an emission, or both.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectDesc {
    /// The shape.
    pub shape: ShapeDesc,
    /// The name of a material in `materials` (default: black, for lights).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<String>,
    /// Emitted radiance, making the object an area light (spheres, disks,
    /// quads, cuboids and meshes); a spectrum, or a texture (`Image`,
    /// `Checkerboard`) over the surface's (u, v).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub emission: Option<SpectrumDesc>,
    /// Whether the emission leaves both sides of the surface (default false:
    /// only the side the normal points to, outward for a sphere).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub two_sided: bool,
    /// For a dielectric object: which medium wins where its volume overlaps
    /// another's (default 0; higher wins; nested dielectrics, see
    /// [`crate::medium::nested`]; ignored for other materials): `priority: 2`.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub priority: u32,
    /// Where to place the shape: `transform: (scale: 2, rotate_deg: (0, 45, 0), translate: (1, 0, 0))`
    /// (default: as given). See [`TransformDesc`] for what each shape accepts.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transform: Option<TransformDesc>,
    /// The name of a medium in `media` filling the object's inside (its
    /// material must be a `Dielectric` or an `Interface`): `interior: "milk"`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub interior: Option<String>,
    /// The name of the medium just outside the object's surface, as a check:
    /// rust-v finds the outside from the volumes around the object (nesting
    /// and `priority`), and the scene is refused when they disagree:
    /// `exterior: "haze"`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub exterior: Option<String>,
}

/// An object's placement, applied to its shape: scale, then rotate about x, then y,
/// then z (degrees), then translate, each optional; the same meaning and order as a
/// `Mesh`'s own `scale`, `rotate_deg` and `translate`, which apply first.
///
/// Spheres, bubbles and disks take only a uniform scale (a scaled sphere would be an
/// ellipsoid, a scaled disk an ellipse); planes and quads take any scale; a cuboid
/// with a rotation becomes a closed mesh of 12 triangles (still a solid for nested
/// dielectrics), without one it stays an axis-aligned box.
#[derive(Clone, Debug, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct TransformDesc {
    /// Uniform or per-axis scale, positive (default 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<ScaleDesc>,
    /// Rotation in degrees about x, then y, then z (default none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotate_deg: Option<V3>,
    /// Translation (default none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub translate: Option<V3>,
    /// A general affine map instead of the three above, as three rows of four
    /// (`x' = m[0][0] x + m[0][1] y + m[0][2] z + m[0][3]`, ...): shears and mirrors.
    /// Only for an `Instance`, a `Mesh` and `Triangles`; invertible and finite:
    /// `matrix: ((1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0))`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub matrix: Option<[[f32; 4]; 3]>,
}

/// A light that is not an object.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub enum LightDesc {
    /// A point light.
    Point {
        /// Position.
        position: V3,
        /// Radiant intensity.
        intensity: SpectrumDesc,
    },
    /// A point light limited to a cone with a smooth falloff at its edge.
    Spot {
        /// Position.
        position: V3,
        /// The point the cone's axis goes through.
        look_at: V3,
        /// The cone's half-angle in degrees (0 to 90).
        cone_deg: f32,
        /// The width of the smooth edge inside the cone, in degrees (0 to `cone_deg`).
        falloff_deg: f32,
        /// Radiant intensity on the axis.
        intensity: SpectrumDesc,
    },
    /// Parallel light from one direction everywhere (the sun).
    Distant {
        /// The direction the light travels in.
        direction: V3,
        /// Irradiance on a surface facing it.
        irradiance: SpectrumDesc,
    },
    /// A collimated beam of parallel light from a disk.
    Beam {
        /// The centre of the emitting disk.
        origin: V3,
        /// The direction the light travels in (the disk faces it).
        direction: V3,
        /// The beam's radius.
        radius: f32,
        /// Irradiance across the beam.
        irradiance: SpectrumDesc,
    },
}
