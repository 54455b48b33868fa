//! The directives: what each does to the graphics state, the transforms and
//! the blocks, and `Include`/`Import`.

use super::*;

impl Parser<'_> {
    /// Parses every directive of the main file and what it includes.
    pub(crate) fn run(&mut self) -> Result<()> {
        while let Some((t, f)) = self.next()? {
            let loc = Self::loc(&t, f);
            let Tok::Word(word) = t.tok else {
                return Err(self.err(
                    loc,
                    format!(
                        "expected a directive (such as Shape, AttributeBegin or WorldBegin), found {}",
                        t.tok.describe()
                    ),
                ));
            };
            self.directive(&word, loc)?;
        }
        if let Some((_, _, loc)) = self.saved.last() {
            return Err(self.err(*loc, "this AttributeBegin has no AttributeEnd before the end of the file"));
        }
        if let Some((name, _, loc)) = &self.object {
            return Err(self.err(*loc, format!("ObjectBegin \"{name}\" has no ObjectEnd before the end of the file")));
        }
        if !self.world {
            return Err(Error::Scene {
                path: self.files[0].clone(),
                position: None,
                field: String::new(),
                message: "the file has no WorldBegin: expected the camera and options, WorldBegin, then the scene"
                    .into(),
            });
        }
        Ok(())
    }

    fn apply(&mut self, t: DMat4) {
        self.state.ctm *= t;
    }

    fn need_world(&self, loc: Loc, directive: &str, inside: bool) -> Result<()> {
        if self.world != inside {
            let msg = if inside {
                format!("{directive} before WorldBegin: expected it after WorldBegin")
            } else {
                format!("{directive} after WorldBegin: expected it before WorldBegin (with the camera and film)")
            };
            return Err(self.err(loc, msg));
        }
        Ok(())
    }

    fn directive(&mut self, word: &str, loc: Loc) -> Result<()> {
        match word {
            "Identity" => self.state.ctm = DMat4::IDENTITY,
            "Translate" => {
                let v = self.numbers(loc, 3, "Translate x y z")?;
                self.apply(DMat4::from_translation(DVec3::new(v[0], v[1], v[2])));
            }
            "Scale" => {
                let v = self.numbers(loc, 3, "Scale x y z")?;
                self.apply(DMat4::from_scale(DVec3::new(v[0], v[1], v[2])));
            }
            "Rotate" => {
                let v = self.numbers(loc, 4, "Rotate angle x y z")?;
                let axis = DVec3::new(v[1], v[2], v[3]);
                let Some(axis) = axis.try_normalize() else {
                    return Err(self.err(loc, "Rotate: expected a non-zero axis x y z"));
                };
                self.apply(DMat4::from_axis_angle(axis, v[0].to_radians()));
            }
            "LookAt" => {
                let v = self.numbers(loc, 9, "LookAt eye, look, up")?;
                let t = look_at(&v).ok_or_else(|| {
                    self.err(loc, "LookAt: expected an eye different from the look point and an up not along the view")
                })?;
                self.apply(t);
            }
            "Transform" | "ConcatTransform" => {
                let v = self.numbers(loc, 16, word)?;
                let m = DMat4::from_cols_array(&v.try_into().unwrap_or([0.0; 16]));
                if m.determinant() == 0.0 || !m.is_finite() {
                    return Err(self.err(loc, format!("{word}: expected an invertible matrix")));
                }
                if word == "Transform" {
                    self.state.ctm = m;
                } else {
                    self.apply(m);
                }
            }
            "CoordinateSystem" => {
                let (name, _) = self.string_arg(loc, "a coordinate system's name")?;
                self.named_cs.insert(name, self.state.ctm);
            }
            "CoordSysTransform" => {
                let (name, at) = self.string_arg(loc, "a coordinate system's name")?;
                match self.named_cs.get(&name) {
                    Some(m) => self.state.ctm = *m,
                    None => {
                        let mut known: Vec<&str> = self.named_cs.keys().map(String::as_str).collect();
                        known.sort();
                        return Err(self
                            .err(at, format!("unknown coordinate system \"{name}\"; defined: {}", known.join(", "))));
                    }
                }
            }
            "ActiveTransform" => {
                let (t, at) = self.need(loc, "StartTime, EndTime or All")?;
                match t.tok {
                    Tok::Word(w) if w == "All" => {}
                    Tok::Word(w) if w == "StartTime" || w == "EndTime" => {
                        self.warn(
                            at,
                            "ActiveTransform StartTime/EndTime: motion blur is not supported; one transform is used",
                        )?;
                    }
                    other => {
                        return Err(
                            self.err(at, format!("expected StartTime, EndTime or All, found {}", other.describe()))
                        );
                    }
                }
            }
            "TransformTimes" => {
                self.numbers(loc, 2, "TransformTimes start end")?;
                self.warn(loc, "TransformTimes: motion blur is not supported (ignored)")?;
            }
            "ReverseOrientation" => self.state.reverse = !self.state.reverse,
            "AttributeBegin" | "TransformBegin" => {
                if word == "TransformBegin" {
                    self.warn(
                        loc,
                        "TransformBegin is deprecated in pbrt-v4: read as AttributeBegin for the transform",
                    )?;
                }
                self.saved.push((self.state.clone(), word == "TransformBegin", loc));
            }
            "AttributeEnd" | "TransformEnd" => match self.saved.pop() {
                Some((s, only_ctm, _)) => {
                    if only_ctm {
                        self.state.ctm = s.ctm;
                    } else {
                        self.state = s;
                    }
                }
                None => return Err(self.err(loc, format!("{word} without a matching AttributeBegin"))),
            },
            "Attribute" => {
                let (target, _) =
                    self.string_arg(loc, "\"shape\", \"light\", \"material\", \"medium\" or \"texture\"")?;
                self.params()?;
                self.warn(loc, format!("Attribute \"{target}\": default parameters are not supported (ignored)"))?;
            }
            "WorldBegin" => {
                if self.world {
                    return Err(self.err(loc, "a second WorldBegin: expected one"));
                }
                self.world = true;
                self.begin_world(loc)?;
                self.named_cs.insert("world".into(), DMat4::IDENTITY);
                self.state.ctm = DMat4::IDENTITY;
            }
            "WorldEnd" => self.warn(loc, "WorldEnd is pbrt-v3 syntax (ignored)")?,
            "Include" | "Import" => {
                let (rel, at) = self.string_arg(loc, "a file name")?;
                self.include(&rel, at)?;
            }
            "Option" => {
                let ps = self.params()?;
                for p in &ps.0 {
                    self.note(p.loc, format!("Option \"{}\" is ignored (rust-v has its own settings)", p.name));
                }
            }
            "ColorSpace" => {
                let (name, at) = self.string_arg(loc, "a colour space name")?;
                if name != "srgb" {
                    self.warn(
                        at,
                        format!("ColorSpace \"{name}\": only srgb is supported; RGB values are read as sRGB"),
                    )?;
                }
            }
            "Camera" | "Film" | "Sampler" | "Integrator" | "PixelFilter" | "Accelerator" => {
                self.need_world(loc, word, false)?;
                let (ty, at) = self.string_arg(loc, &format!("the {word}'s type"))?;
                let ps = self.params()?;
                match word {
                    "Camera" => {
                        self.named_cs.insert("camera".into(), self.state.ctm.inverse());
                        // pbrt-v4: the camera sits in the outside medium of the current MediumInterface.
                        self.built.camera_medium = Some((self.state.outside.clone(), at));
                        self.camera(&ty, at, &ps, self.state.ctm)?;
                    }
                    "Film" => self.film(&ty, at, &ps)?,
                    "Sampler" => self.sampler(&ty, at, &ps)?,
                    "Integrator" => self.integrator(&ty, at, &ps)?,
                    "PixelFilter" => self.filter(&ty, at, &ps)?,
                    _ => {
                        for p in &ps.0 {
                            p.used.set(true);
                        }
                        self.note(at, "Accelerator is ignored (rust-v builds its own BVH)");
                    }
                }
                self.check_used(&ps, &format!("{word} \"{ty}\""))?;
            }
            "MakeNamedMedium" => {
                let (name, at) = self.string_arg(loc, "a medium's name")?;
                let ps = self.params()?;
                self.make_medium(name, at, &ps)?;
            }
            "MediumInterface" => {
                let (inside, at) = self.string_arg(loc, "a medium's name")?;
                // pbrt-v4: one name is both the inside and the outside.
                let outside = match self.peek()? {
                    Some(Tok::Str(_)) => self.string_arg(at, "a medium's name")?.0,
                    _ => inside.clone(),
                };
                self.state.inside = inside;
                self.state.outside = outside;
            }
            "Shape" | "Material" | "MakeNamedMaterial" | "NamedMaterial" | "Texture" | "LightSource"
            | "AreaLightSource" | "ObjectBegin" | "ObjectEnd" | "ObjectInstance" => {
                self.need_world(loc, word, true)?;
                self.world_directive(word, loc)?;
            }
            other => {
                return Err(self.err(
                    loc,
                    format!(
                        "unknown directive `{}`: expected a pbrt-v4 directive (Shape, Material, LightSource, AttributeBegin, Translate, ...)",
                        other.chars().take(40).collect::<String>()
                    ),
                ));
            }
        }
        Ok(())
    }

    fn world_directive(&mut self, word: &str, loc: Loc) -> Result<()> {
        match word {
            "Shape" => {
                let (ty, at) = self.string_arg(loc, "the shape's type")?;
                let params = self.params()?;
                let rec = ShapeRec {
                    ty,
                    params,
                    ctm: self.state.ctm,
                    reverse: self.state.reverse,
                    material: self.state.material.clone(),
                    area: self.state.area.clone(),
                    inside: self.state.inside.clone(),
                    outside: self.state.outside.clone(),
                    loc: at,
                };
                match &mut self.object {
                    Some((_, shapes, _)) => shapes.push(rec),
                    None => self.shape(&rec, DMat4::IDENTITY)?,
                }
            }
            "Material" => {
                let (ty, at) = self.string_arg(loc, "the material's type")?;
                let ps = self.params()?;
                self.state.material = self.material(None, &ty, at, &ps)?;
            }
            "MakeNamedMaterial" => {
                let (name, at) = self.string_arg(loc, "the material's name")?;
                let ps = self.params()?;
                let ty = match ps.0.iter().find(|p| p.name == "type") {
                    Some(Param { value: Value::Strs(s), .. }) => {
                        if let Some(p) = ps.0.iter().find(|p| p.name == "type") {
                            p.used.set(true);
                        }
                        ps.1.borrow_mut().push("type".into());
                        s[0].clone()
                    }
                    _ => {
                        return Err(
                            self.err(at, format!("MakeNamedMaterial \"{name}\": expected a \"string type\" parameter"))
                        );
                    }
                };
                let m = self.material(Some(&name), &ty, at, &ps)?;
                self.built.named_materials.insert(name, m);
            }
            "NamedMaterial" => {
                let (name, at) = self.string_arg(loc, "a material's name")?;
                match self.built.named_materials.get(&name) {
                    Some(m) => self.state.material = m.clone(),
                    None => {
                        let mut known: Vec<&str> = self.built.named_materials.keys().map(String::as_str).collect();
                        known.sort();
                        return Err(self.err(at, format!("unknown material \"{name}\"; defined: {}", known.join(", "))));
                    }
                }
            }
            "Texture" => {
                let (name, at) = self.string_arg(loc, "the texture's name")?;
                let (kind, _) = self.string_arg(at, "the texture's kind: \"spectrum\" or \"float\"")?;
                let (class, cat) = self.string_arg(at, "the texture's class (imagemap, checkerboard, ...)")?;
                let ps = self.params()?;
                self.texture(name, &kind, &class, cat, &ps)?;
            }
            "LightSource" => {
                let (ty, at) = self.string_arg(loc, "the light's type")?;
                let ps = self.params()?;
                self.light(&ty, at, &ps, self.state.ctm)?;
                self.check_used(&ps, &format!("LightSource \"{ty}\""))?;
            }
            "AreaLightSource" => {
                let (ty, at) = self.string_arg(loc, "the area light's type")?;
                let ps = self.params()?;
                self.state.area = self.area_light(&ty, at, &ps)?;
                self.check_used(&ps, &format!("AreaLightSource \"{ty}\""))?;
            }
            "ObjectBegin" => {
                let (name, at) = self.string_arg(loc, "the object's name")?;
                if self.object.is_some() {
                    return Err(self.err(at, "ObjectBegin inside ObjectBegin: expected ObjectEnd first"));
                }
                self.saved.push((self.state.clone(), false, loc));
                self.object = Some((name, Vec::new(), at));
            }
            "ObjectEnd" => match self.object.take() {
                Some((name, shapes, _)) => {
                    // A redefined object is a new group at its next instance.
                    self.built.group_index.remove(&name);
                    self.objects.insert(name, shapes);
                    if let Some((s, _, _)) = self.saved.pop() {
                        self.state = s;
                    }
                }
                None => return Err(self.err(loc, "ObjectEnd without ObjectBegin")),
            },
            "ObjectInstance" => {
                let (name, at) = self.string_arg(loc, "an object's name")?;
                if self.object.is_some() {
                    return Err(
                        self.err(at, "ObjectInstance inside ObjectBegin: expected it outside object definitions")
                    );
                }
                let Some(shapes) = self.objects.get(&name).cloned() else {
                    let mut known: Vec<&str> = self.objects.keys().map(String::as_str).collect();
                    known.sort();
                    return Err(self.err(at, format!("unknown object \"{name}\"; defined: {}", known.join(", "))));
                };
                let ctm = self.state.ctm;
                match self.native_group(&name, &shapes)? {
                    Some(g) => self.instance(g, ctm, at)?,
                    None => {
                        self.note(
                            at,
                            "ObjectInstance: an object with an emitting shape, a MediumInterface or a shape other than a mesh is placed as copies of its shapes",
                        );
                        for s in &shapes {
                            self.shape(s, ctm)?;
                        }
                    }
                }
            }
            _ => unreachable!("world directives are listed in `directive`"),
        }
        Ok(())
    }

    /// Warns about every parameter of `ps` that nothing read: `what` names the entity.
    pub(crate) fn check_used(&mut self, ps: &Params, what: &str) -> Result<()> {
        let mut known: Vec<String> = ps.1.borrow().clone();
        known.sort();
        known.dedup();
        let known = if known.is_empty() { "none".to_string() } else { known.join(", ") };
        for p in &ps.0 {
            if !p.used.get() {
                self.warn(
                    p.loc,
                    format!("{what}: parameter \"{} {}\" is not supported (ignored); read here: {known}", p.ty, p.name),
                )?;
            }
        }
        Ok(())
    }

    fn include(&mut self, rel: &str, at: Loc) -> Result<()> {
        if self.stack.len() >= MAX_INCLUDE_DEPTH {
            return Err(
                self.err(at, format!("Include nested more than {MAX_INCLUDE_DEPTH} deep: expected fewer levels"))
            );
        }
        let path = self.ctx.dir.join(rel);
        let canonical = std::fs::canonicalize(&path).ok();
        if canonical.is_some() {
            for open in &self.stack {
                if std::fs::canonicalize(&self.files[open.file]).ok() == canonical {
                    return Err(self.err(at, format!("Include \"{rel}\" is a cycle: the file is already being read")));
                }
            }
        }
        let bytes = read_input(&path).map_err(|e| self.err(at, format!("Include \"{rel}\": {e}")))?;
        // pbrt-v4 reads gzipped scene files (`geometry.pbrt.gz`) too.
        let plain = if rel.to_ascii_lowercase().ends_with(".gz") {
            let mut out = Vec::new();
            std::io::Read::read_to_end(&mut flate2::read::MultiGzDecoder::new(bytes.as_slice()), &mut out)
                .map_err(|e| self.err(at, format!("Include \"{rel}\": gzip decompression failed: {e}")))?;
            out
        } else {
            bytes.clone()
        };
        let text = String::from_utf8(plain).map_err(|e| {
            self.err(
                at,
                format!("Include \"{rel}\": byte {} is not UTF-8; expected UTF-8 text", e.utf8_error().valid_up_to()),
            )
        })?;
        self.ctx.record_input(rel, path.clone(), fnv1a(&bytes));
        let file = self.files.len();
        self.files.push(path);
        self.stack.push(Open { lexer: Lexer::new(text), file });
        Ok(())
    }
}

/// pbrt's `LookAt`: camera-from-world for an eye, a look point and an up
/// vector (`v` = eye x y z, look x y z, up x y z); `None` if degenerate.
pub(crate) fn look_at(v: &[f64]) -> Option<DMat4> {
    let pos = DVec3::new(v[0], v[1], v[2]);
    let look = DVec3::new(v[3], v[4], v[5]);
    let up = DVec3::new(v[6], v[7], v[8]).try_normalize()?;
    let dir = (look - pos).try_normalize()?;
    let right = up.cross(dir).try_normalize()?;
    let new_up = dir.cross(right);
    let world_from_camera = DMat4::from_cols(right.extend(0.0), new_up.extend(0.0), dir.extend(0.0), pos.extend(1.0));
    Some(world_from_camera.inverse())
}
