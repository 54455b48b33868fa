//! pbrt-v4's materials and textures.

use super::*;

impl Parser<'_> {
    // ----------------------------------------------------------------------------------
    // Materials and textures.

    /// Adds a material to the description under `name` (or a new name) and returns its reference.
    /// An anonymous material (`Material "diffuse" ...`) is named `#K TYPE` (`#3 diffuse`),
    /// K counting them: a name a pbrt file would hardly give.
    pub(super) fn add_material(&mut self, name: Option<&str>, ty: &str, m: MaterialDesc, at: Loc) -> Result<MatRef> {
        let name = match name {
            Some(n) => {
                if self.built.materials.iter().any(|(k, _)| k == n) {
                    return Err(self.err(at, format!("material \"{n}\" defined twice: expected each name once")));
                }
                n.to_string()
            }
            None => loop {
                self.built.anonymous += 1;
                let n = format!("#{} {ty}", self.built.anonymous);
                if !self.built.materials.iter().any(|(k, _)| *k == n) {
                    break n;
                }
            },
        };
        self.built.materials.push((name.clone(), m));
        Ok(MatRef::Name(name))
    }

    pub(super) fn reflectance(&mut self, ps: &Params, name: &str, default: f32) -> Result<SpectrumDesc> {
        Ok(self.spectrum(ps, name, Role::Reflectance)?.map_or(SpectrumDesc::Constant(default), |s| s.0))
    }

    pub(super) fn conductor(&mut self, ps: &Params, prefix: &str, at: Loc) -> Result<MaterialDesc> {
        let n = |s: &str| format!("{prefix}{s}");
        let roughness = self.roughness(ps, prefix, at)?;
        if let Some((r, _, loc)) = self.spectrum(ps, &n("reflectance"), Role::Reflectance)? {
            self.warn(
                loc,
                "a conductor given by \"reflectance\" is rendered as a Mirror of that reflectance (roughness dropped)",
            )?;
            return Ok(MaterialDesc::Mirror { reflectance: r });
        }
        let name_of = |p: Option<&Param>, suffix: &str| match p.map(|p| &p.value) {
            Some(Value::Strs(s)) => {
                s[0].strip_prefix("metal-").and_then(|m| m.strip_suffix(suffix)).map(str::to_string)
            }
            _ => None,
        };
        let eta_p = ps.0.iter().find(|p| p.name == n("eta"));
        let k_p = ps.0.iter().find(|p| p.name == n("k"));
        let (eta_m, k_m) = (name_of(eta_p, "-eta"), name_of(k_p, "-k"));
        let metal = match (eta_p, k_p) {
            (None, None) => Some("Cu".to_string()),
            _ if eta_m.is_some() && eta_m == k_m => eta_m.clone(),
            _ => None,
        };
        if let Some(m) = metal {
            self.param(ps, &n("eta"));
            self.param(ps, &n("k"));
            if METALS.contains(&m.as_str()) {
                return Ok(MaterialDesc::Conductor {
                    metal: Some(m),
                    eta: None,
                    k: None,
                    roughness: roughness.into(),
                    coating: None,
                });
            }
            self.warn(
                at,
                format!("metal \"{m}\" is not among rust-v's metals ({}): rendered as Al", METALS.join(", ")),
            )?;
            return Ok(MaterialDesc::Conductor {
                metal: Some("Al".into()),
                eta: None,
                k: None,
                roughness: roughness.into(),
                coating: None,
            });
        }
        if eta_m.is_some() || k_m.is_some() {
            self.warn(at, "a conductor's \"eta\" and \"k\" name different metals: rendered as Cu")?;
            self.param(ps, &n("eta"));
            self.param(ps, &n("k"));
            return Ok(MaterialDesc::Conductor {
                metal: Some("Cu".into()),
                eta: None,
                k: None,
                roughness: roughness.into(),
                coating: None,
            });
        }
        let eta = self.spectrum(ps, &n("eta"), Role::Unbounded)?.map(|s| s.0).unwrap_or(SpectrumDesc::Constant(1.0));
        let k = self.spectrum(ps, &n("k"), Role::Unbounded)?.map(|s| s.0).unwrap_or(SpectrumDesc::Constant(0.0));
        Ok(MaterialDesc::Conductor {
            metal: None,
            eta: Some(eta),
            k: Some(k),
            roughness: roughness.into(),
            coating: None,
        })
    }

    /// `Material` or `MakeNamedMaterial` (then `name` is given).
    pub(crate) fn material(&mut self, name: Option<&str>, ty: &str, at: Loc, ps: &Params) -> Result<MatRef> {
        let what = format!("material \"{ty}\"");
        let m = match ty {
            "" | "none" | "interface" => {
                self.check_used(ps, &what)?;
                return Ok(MatRef::Interface);
            }
            "diffuse" => MaterialDesc::Lambertian { reflectance: self.reflectance(ps, "reflectance", 0.5)? },
            "coateddiffuse" => {
                self.warn(at, "coateddiffuse is rendered as Plastic: a dielectric coat (pbrt's eta and roughness) over a Lambertian base, without the layer's thickness, albedo and inter-reflections that pbrt simulates stochastically")?;
                let reflectance = self.reflectance(ps, "reflectance", 0.5)?;
                let roughness = self.roughness(ps, "", at)?;
                let ior = self.ior(ps, "eta")?;
                for p in ["thickness", "albedo", "g", "maxdepth", "nsamples"] {
                    self.param(ps, p);
                }
                MaterialDesc::Plastic { reflectance, ior, roughness: roughness.into() }
            }
            "conductor" => self.conductor(ps, "", at)?,
            "coatedconductor" => {
                self.warn(at, "coatedconductor is rendered as its conductor alone (the dielectric coat is dropped)")?;
                for p in [
                    "interface.roughness",
                    "interface.uroughness",
                    "interface.vroughness",
                    "interface.eta",
                    "thickness",
                    "albedo",
                    "g",
                    "maxdepth",
                    "nsamples",
                ] {
                    self.param(ps, p);
                }
                self.conductor(ps, "conductor.", at)?
            }
            "dielectric" | "thindielectric" => {
                if ty == "thindielectric" {
                    self.warn(at, "thindielectric is rendered as a dielectric (rays bend; a thin sheet would not)")?;
                }
                let ior = self.ior(ps, "eta")?;
                let roughness = self.roughness(ps, "", at)?;
                MaterialDesc::Dielectric { ior, roughness: roughness.into(), absorption: None, coating: None }
            }
            "diffusetransmission" => {
                self.warn(
                    at,
                    "diffusetransmission is rendered as diffuse reflection only (the transmission is dropped)",
                )?;
                self.param(ps, "transmittance");
                let r = self.reflectance(ps, "reflectance", 0.25)?;
                let s = self.float(ps, "scale", 1.0)?;
                MaterialDesc::Lambertian { reflectance: scaled(r, s) }
            }
            "mix" => {
                // pbrt chooses materials[1] where amount ≥ u (u a hash of the hit in
                // [0, 1)), so an amount outside [0, 1] is the nearer end: clamped.
                let amount = self.float_or_texture(ps, "amount", 0.5)?.clamp(0.0, 1.0) as f32;
                let names = match self.param(ps, "materials") {
                    Some(Param { value: Value::Strs(s), .. }) if s.len() == 2 => s.clone(),
                    _ => {
                        return Err(
                            self.err(at, "material \"mix\": expected \"string materials\" with two material names")
                        );
                    }
                };
                let mut children = Vec::with_capacity(2);
                for n in &names {
                    let child = match self.built.named_materials.get(n).cloned() {
                        Some(MatRef::Name(c)) => c,
                        Some(MatRef::Default) => self.default_material(),
                        Some(MatRef::Interface) => {
                            return Err(self.err(
                                at,
                                format!("material \"mix\": \"{n}\" is an interface (no surface); expected two surface materials"),
                            ));
                        }
                        None => return Err(self.err(at, format!("material \"mix\": unknown material \"{n}\""))),
                    };
                    children.push(child);
                }
                let [a, b]: [String; 2] = children.try_into().expect("two names");
                MaterialDesc::Mix { materials: (a, b), amount: crate::scene::desc::ScalarDesc::Value(amount) }
            }
            other => {
                self.warn(at, format!("material \"{other}\" is not supported: rendered as diffuse 0.5"))?;
                for p in &ps.0 {
                    p.used.set(true);
                }
                MaterialDesc::Lambertian { reflectance: SpectrumDesc::Constant(0.5) }
            }
        };
        for p in ["normalmap", "displacement"] {
            if let Some(p) = self.param(ps, p) {
                let loc = p.loc;
                self.warn(loc, format!("\"{}\" (bump and normal maps) is not supported (ignored)", p.name))?;
            }
        }
        self.check_used(ps, &what)?;
        self.add_material(name, ty, m, at)
    }

    pub(crate) fn texture(&mut self, name: String, kind: &str, class: &str, at: Loc, ps: &Params) -> Result<()> {
        let what = format!("texture \"{class}\"");
        if kind != "spectrum" && kind != "float" && kind != "color" {
            return Err(self.err(
                at,
                format!("texture \"{name}\": expected the kind \"spectrum\" or \"float\", found \"{kind}\""),
            ));
        }
        let float = kind == "float";
        let tex = match class {
            "constant" => {
                if float {
                    Tex::Float(self.float(ps, "value", 1.0)?)
                } else {
                    Tex::Spectrum(self.reflectance(ps, "value", 1.0)?)
                }
            }
            "scale" => {
                let s = self.float_or_texture(ps, "scale", 1.0)?;
                if float {
                    Tex::Float(self.float_or_texture(ps, "tex", 1.0)? * s)
                } else {
                    Tex::Spectrum(scaled(self.reflectance(ps, "tex", 1.0)?, s))
                }
            }
            "imagemap" if !float => {
                let Some((file, _)) = self.string(ps, "filename")? else {
                    return Err(self.err(at, format!("texture \"{name}\": imagemap needs a \"string filename\"")));
                };
                let wrap = match self.string(ps, "wrap")? {
                    None => Wrap::Repeat,
                    Some((w, _)) if w == "repeat" => Wrap::Repeat,
                    Some((w, _)) if w == "clamp" => Wrap::Clamp,
                    Some((w, loc)) => {
                        self.warn(loc, format!("imagemap wrap \"{w}\" is not supported: repeat is used"))?;
                        Wrap::Repeat
                    }
                };
                let scale = self.float(ps, "scale", 1.0)?;
                let uv_scale = [self.float(ps, "uscale", 1.0)? as f32, self.float(ps, "vscale", 1.0)? as f32];
                let uv_offset = [self.float(ps, "udelta", 0.0)? as f32, self.float(ps, "vdelta", 0.0)? as f32];
                if self.boolean(ps, "invert", false)? {
                    self.warn(at, "imagemap \"invert\" is not supported (ignored)")?;
                }
                self.param(ps, "filter");
                self.param(ps, "maxanisotropy");
                if let Some((e, loc)) = self.string(ps, "encoding")?
                    && e != "sRGB"
                    && e != "linear"
                {
                    self.warn(loc, format!("imagemap encoding \"{e}\": PNGs are read as sRGB, EXRs as linear"))?;
                }
                Tex::Spectrum(SpectrumDesc::Image { path: file, uv_scale, uv_offset, wrap, scale: scale as f32 })
            }
            "checkerboard" if !float => {
                let even = self.reflectance(ps, "tex1", 1.0)?;
                let odd = self.reflectance(ps, "tex2", 0.0)?;
                let (u, v) = (self.float(ps, "uscale", 1.0)?, self.float(ps, "vscale", 1.0)?);
                if u != v {
                    self.warn(at, format!("checkerboard uscale {u} and vscale {v} differ: rust-v's checkerboard has one scale; using uscale"))?;
                }
                if self.int(ps, "dimension", 2, 2, 3)? != 2 {
                    self.warn(at, "a 3D checkerboard is not supported: the 2D one is used")?;
                }
                self.param(ps, "udelta");
                self.param(ps, "vdelta");
                Tex::Spectrum(SpectrumDesc::Checkerboard { even: Box::new(even), odd: Box::new(odd), scale: u as f32 })
            }
            other => {
                self.warn(at, format!("{kind} texture \"{other}\" is not supported: a constant 0.5 is used"))?;
                for p in &ps.0 {
                    p.used.set(true);
                }
                if float { Tex::Float(0.5) } else { Tex::Spectrum(SpectrumDesc::Constant(0.5)) }
            }
        };
        if let Some((m, loc)) = self.string(ps, "mapping")?
            && m != "uv"
        {
            self.warn(loc, format!("texture mapping \"{m}\" is not supported: uv is used"))?;
        }
        self.check_used(ps, &what)?;
        self.built.textures.insert(name, tex);
        Ok(())
    }
}
