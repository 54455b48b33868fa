//! pbrt-v4's shapes, placed in world space; PLY files read after parsing, in parallel.

use super::*;

impl Parser<'_> {
    // ----------------------------------------------------------------------------------
    // Shapes.

    /// A `Shape` placed by `instance · rec.ctm` (then the mirror `M`).
    pub(crate) fn shape(&mut self, rec: &ShapeRec, instance: DMat4) -> Result<()> {
        self.place(rec, Some(instance))
    }

    /// The `Shape` `rec` placed by `instance · rec.ctm` then the mirror `M` as an object,
    /// or with `instance` None by `rec.ctm` alone as a member of the last group.
    fn place(&mut self, rec: &ShapeRec, instance: Option<DMat4>) -> Result<()> {
        let ps = &rec.params;
        let at = rec.loc;
        let x = match instance {
            Some(i) => self.built.mirror * i * rec.ctm,
            None => rec.ctm,
        };
        let lin = DMat3::from_mat4(x);
        // pbrt's own `reverseOrientation ^ transformSwapsHandedness` (without the mirror `M`),
        // which flips the normal of its quadrics at intersections.
        let quadric_flip =
            rec.reverse ^ (DMat3::from_mat4(instance.unwrap_or(DMat4::IDENTITY) * rec.ctm).determinant() < 0.0);
        let what = format!("Shape \"{}\"", rec.ty);
        let mut mesh_file = None;
        let mut pending = None;
        let (shape, area) = match rec.ty.as_str() {
            "sphere" | "disk" => {
                let s = self.uniform_scale(lin, at, &rec.ty)?;
                let radius = self.float(ps, "radius", 1.0)?;
                let cuts: &[(&str, Option<f64>)] = if rec.ty == "sphere" {
                    &[("zmin", None), ("zmax", None), ("phimax", Some(360.0))]
                } else {
                    &[("phimax", Some(360.0)), ("innerradius", Some(0.0))]
                };
                for &(p, full) in cuts {
                    if let Some(q) = self.param(ps, p) {
                        let v = self.nums_of(q, &["float"])?[0];
                        let partial = match (p, full) {
                            (_, Some(f)) => v != f,
                            ("zmin", _) => v > -radius,
                            _ => v < radius,
                        };
                        if partial {
                            let loc = q.loc;
                            self.warn(
                                loc,
                                format!("partial {} (\"{p}\") is not supported: the whole shape is rendered", rec.ty),
                            )?;
                        }
                    }
                }
                let r = radius * s;
                if rec.ty == "sphere" {
                    if quadric_flip && rec.area.is_some() {
                        self.warn(at, "an emitting sphere that pbrt turns inside out (ReverseOrientation, or a mirroring transform): rust-v's sphere emits outwards")?;
                    }
                    let center = x.transform_point3(DVec3::ZERO);
                    (ShapeDesc::Sphere { center: f3(center), radius: r as f32 }, 4.0 * std::f64::consts::PI * r * r)
                } else {
                    let h = self.float(ps, "height", 0.0)?;
                    let center = x.transform_point3(DVec3::new(0.0, 0.0, h));
                    let mut n = (lin.inverse().transpose() * DVec3::Z).normalize();
                    if quadric_flip {
                        n = -n;
                    }
                    (
                        ShapeDesc::Disk { center: f3(center), normal: f3(n), radius: r as f32 },
                        std::f64::consts::PI * r * r,
                    )
                }
            }
            "plymesh" => {
                let Some((file, floc)) = self.string(ps, "filename")? else {
                    return Err(self.err(at, "Shape \"plymesh\": expected a \"string filename\""));
                };
                if let Some(p) = self.param(ps, "displacement") {
                    let loc = p.loc;
                    self.warn(loc, "plymesh \"displacement\" is not supported (ignored)")?;
                }
                self.param(ps, "edgelength");
                // Read and placed after parsing, all files at once on the thread pool
                // (`resolve_plys`); the object keeps its place in the list.
                pending = Some((file.clone(), floc));
                mesh_file = Some(file);
                (ShapeDesc::Triangles { positions: Vec::new(), indices: Vec::new(), normals: None, uvs: None }, 0.0)
            }
            "trianglemesh" | "bilinearmesh" | "loopsubdiv" => {
                let (positions, tris, normals, uvs) = self.inline_mesh(&rec.ty, ps, at)?;
                let placed = place_mesh(x, rec.reverse, &positions, tris, normals.as_deref(), uvs)
                    .map_err(|m| self.err(at, format!("{what}: {m}")))?;
                self.count_triangles(&placed.0, at)?;
                placed
            }
            other => {
                self.warn(at, format!("Shape \"{other}\" is not supported (left out)"))?;
                for p in &ps.0 {
                    p.used.set(true);
                }
                return Ok(());
            }
        };
        for p in ["alpha", "emissionfilename"] {
            if let Some(p) = self.param(ps, p) {
                let loc = p.loc;
                self.warn(loc, format!("shape \"{}\" is not supported (ignored)", p.name))?;
            }
        }
        self.check_used(ps, &what)?;
        let material = match &rec.material {
            MatRef::Name(n) => Some(n.clone()),
            MatRef::Default => Some(self.default_material()),
            MatRef::Interface if rec.area.is_some() => None,
            // A boundary between two media (vacuum inside: a clear volume).
            MatRef::Interface if rec.inside != rec.outside => Some(self.interface_material()),
            MatRef::Interface => {
                self.warn(at, "a shape with the interface material and the same medium on both sides is left out")?;
                return Ok(());
            }
        };
        let bounds_volume = material.as_ref().is_some_and(|n| {
            self.built
                .materials
                .iter()
                .any(|(k, m)| k == n && matches!(m, MaterialDesc::Dielectric { .. } | MaterialDesc::Interface))
        });
        // pbrt's inside is the side its normal points away from: a sphere that pbrt turns
        // inside out has its "inside" medium around it (rust-v's spheres face outwards).
        let inside_out = rec.ty == "sphere" && quadric_flip && (!rec.inside.is_empty() || !rec.outside.is_empty());
        let (interior, exterior) = if inside_out {
            self.note(at, "MediumInterface on a sphere that pbrt turns inside out (ReverseOrientation, or a mirroring transform): its \"inside\" medium is around it and its \"outside\" medium within it");
            let swapped = ShapeRec { inside: rec.outside.clone(), outside: rec.inside.clone(), ..rec.clone() };
            self.media_of(&swapped, bounds_volume)
        } else {
            self.media_of(rec, bounds_volume)
        };
        let emission = rec.area.as_ref().map(|a| a.emission(area));
        let two_sided = rec.area.as_ref().is_some_and(|a| a.two_sided);
        let slot = match instance {
            Some(_) => Slot::Object(self.built.objects.len()),
            None => {
                let g = self.built.groups.len() - 1;
                Slot::Member(g, self.built.groups[g].1.len())
            }
        };
        if let Some((file, floc)) = pending {
            self.built.pending.push(PendingPly {
                slot,
                file,
                floc,
                loc: at,
                x,
                reverse: rec.reverse,
                area: rec.area.clone(),
            });
        }
        if let Some(name) = interior {
            self.built.interiors.push((self.built.objects.len(), name, at));
        }
        if let Some(name) = exterior {
            self.built.exteriors.push((self.built.objects.len(), name, at));
        }
        let o = ObjectDesc {
            shape,
            material,
            emission,
            two_sided,
            priority: 0,
            transform: None,
            interior: None,
            exterior: None,
        };
        match slot {
            Slot::Object(_) => {
                self.built.objects.push(o);
                self.built.mesh_files.push(mesh_file);
                self.built.object_locs.push(at);
            }
            Slot::Member(g, _) => {
                self.built.groups[g].1.push(o);
                self.built.group_files[g].push(mesh_file);
                self.built.group_locs[g].push(at);
            }
        }
        Ok(())
    }

    /// The group of the `ObjectBegin` `name` with shapes `shapes`, built at its first
    /// instance: its meshes in object space (placed by their CTMs). `None` when its
    /// instances are copies instead: a shape emits, has a `MediumInterface` or is not a
    /// mesh (pbrt-v4 refuses area lights in instances; rust-v's groups hold meshes
    /// without media), or every shape was left out.
    pub(crate) fn native_group(&mut self, name: &str, shapes: &[ShapeRec]) -> Result<Option<usize>> {
        if let Some(g) = self.built.group_index.get(name) {
            return Ok(*g);
        }
        let mesh = |s: &ShapeRec| matches!(s.ty.as_str(), "plymesh" | "trianglemesh" | "bilinearmesh" | "loopsubdiv");
        let native = !shapes.is_empty()
            && shapes.iter().all(|s| {
                mesh(s)
                    && s.area.is_none()
                    && s.inside.is_empty()
                    && s.outside.is_empty()
                    && !matches!(s.material, MatRef::Interface)
            });
        let mut group = None;
        if native {
            let g = self.built.groups.len();
            let mut unique = name.to_string();
            let mut k = 2;
            while self.built.groups.iter().any(|(n, _)| *n == unique) {
                unique = format!("{name} ({k})");
                k += 1;
            }
            self.built.groups.push((unique, Vec::new()));
            self.built.group_files.push(Vec::new());
            self.built.group_locs.push(Vec::new());
            for s in shapes {
                self.place(s, None)?;
            }
            if self.built.groups[g].1.is_empty() {
                self.built.groups.pop();
                self.built.group_files.pop();
                self.built.group_locs.pop();
            } else {
                group = Some(g);
            }
        }
        self.built.group_index.insert(name.to_string(), group);
        Ok(group)
    }

    /// An `ObjectInstance` of group `g` under the CTM `ctm`: an `Instance` object placed
    /// by the matrix `M · ctm` (the mirror included).
    pub(crate) fn instance(&mut self, g: usize, ctm: DMat4, at: Loc) -> Result<()> {
        self.built.instanced += self.built.groups[g].1.len();
        if self.built.instanced > MAX_INSTANCED {
            return Err(self.err(
                at,
                format!("the instances place more than {MAX_INSTANCED} objects: expected fewer ObjectInstances"),
            ));
        }
        let x = self.built.mirror * ctm;
        let transform = (x != DMat4::IDENTITY).then(|| {
            let row = |r: usize| {
                let v = x.row(r);
                [v.x as f32 + 0.0, v.y as f32 + 0.0, v.z as f32 + 0.0, v.w as f32 + 0.0]
            };
            TransformDesc { matrix: Some([row(0), row(1), row(2)]), ..TransformDesc::default() }
        });
        self.built.objects.push(ObjectDesc {
            shape: ShapeDesc::Instance { group: self.built.groups[g].0.clone() },
            material: None,
            emission: None,
            two_sided: false,
            priority: 0,
            transform,
            interior: None,
            exterior: None,
        });
        self.built.mesh_files.push(None);
        self.built.object_locs.push(at);
        Ok(())
    }

    /// Adds a placed mesh's triangles to the count, refusing more than [`MAX_TRIANGLES`].
    pub(super) fn count_triangles(&mut self, shape: &ShapeDesc, at: Loc) -> Result<()> {
        if let ShapeDesc::Triangles { indices, .. } = shape {
            self.built.triangles += indices.len();
        }
        if self.built.triangles > MAX_TRIANGLES {
            return Err(self.err(
                at,
                format!(
                    "the scene expands to more than {MAX_TRIANGLES} triangles (instances are copies): expected fewer"
                ),
            ));
        }
        Ok(())
    }

    /// Reads every PLY file the `plymesh` shapes name, each once, in parallel, records
    /// them as inputs in order of first use, and places each shape's triangles (in
    /// parallel too). Errors are those of the first failing file or shape in file order.
    pub(crate) fn resolve_plys(&mut self) -> Result<()> {
        let pending = std::mem::take(&mut self.built.pending);
        let mut files: Vec<(String, Loc)> = Vec::new();
        for p in &pending {
            if !files.iter().any(|(f, _)| *f == p.file) {
                files.push((p.file.clone(), p.floc));
            }
        }
        let dir = self.ctx.dir.clone();
        let loaded: Vec<Result<(PathBuf, u64, MeshData)>> = files
            .par_iter()
            .map(|(f, _)| {
                let path = dir.join(f);
                let bytes = read_input(&path)?;
                let hash = fnv1a(&bytes);
                Ok((path.clone(), hash, parse_mesh(bytes, &path)?))
            })
            .collect();
        let mut data = HashMap::new();
        for ((f, loc), r) in files.iter().zip(loaded) {
            let (path, hash, mesh) = r.map_err(|e| self.err(*loc, format!("plymesh: {e}")))?;
            self.ctx.record_input(f, path, hash);
            data.insert(f.clone(), mesh);
        }
        let placed: Vec<std::result::Result<(ShapeDesc, f64), String>> = pending
            .par_iter()
            .map(|p| {
                let d = &data[&p.file];
                let positions: Vec<DVec3> = d.positions.iter().map(|v| v.as_dvec3()).collect();
                let normals: Option<Vec<DVec3>> = d.normals.as_ref().map(|n| n.iter().map(|v| v.as_dvec3()).collect());
                place_mesh(p.x, p.reverse, &positions, d.triangles.clone(), normals.as_deref(), d.uvs.clone())
            })
            .collect();
        for (p, r) in pending.iter().zip(placed) {
            let (shape, area) = r.map_err(|m| self.err(p.loc, format!("Shape \"plymesh\" \"{}\": {m}", p.file)))?;
            self.count_triangles(&shape, p.loc)?;
            let o = match p.slot {
                Slot::Object(i) => &mut self.built.objects[i],
                Slot::Member(g, j) => &mut self.built.groups[g].1[j],
            };
            o.shape = shape;
            if let Some(a) = &p.area {
                o.emission = Some(a.emission(area));
            }
        }
        Ok(())
    }

    /// The index-matched boundary of a medium (pbrt's `interface` material).
    pub(super) fn interface_material(&mut self) -> String {
        let name = "pbrt-interface".to_string();
        if !self.built.materials.iter().any(|(k, _)| *k == name) {
            self.built.materials.push((name.clone(), MaterialDesc::Interface));
        }
        name
    }

    pub(super) fn default_material(&mut self) -> String {
        let name = "pbrt-default-diffuse".to_string();
        if !self.built.materials.iter().any(|(k, _)| *k == name) {
            self.built
                .materials
                .push((name.clone(), MaterialDesc::Lambertian { reflectance: SpectrumDesc::Constant(0.5) }));
        }
        name
    }

    /// The uniform scale of a sphere's or disk's transform (a warning and the mean if it is not uniform).
    pub(super) fn uniform_scale(&mut self, lin: DMat3, at: Loc, ty: &str) -> Result<f64> {
        let s = [lin.x_axis.length(), lin.y_axis.length(), lin.z_axis.length()];
        let mean = (s[0] + s[1] + s[2]) / 3.0;
        let sheared = lin.x_axis.dot(lin.y_axis).abs() > 1e-6 * s[0] * s[1]
            || lin.x_axis.dot(lin.z_axis).abs() > 1e-6 * s[0] * s[2]
            || lin.y_axis.dot(lin.z_axis).abs() > 1e-6 * s[1] * s[2];
        if sheared || s.iter().any(|v| (v - mean).abs() > 1e-6 * mean) {
            self.warn(
                at,
                format!(
                    "a {ty} under a non-uniform scale or shear is not supported: scaled uniformly by the mean ({mean})"
                ),
            )?;
        }
        Ok(mean)
    }

    /// `trianglemesh`, `bilinearmesh` and `loopsubdiv` in object space:
    /// positions, triangles, normals and uvs.
    #[allow(clippy::type_complexity)]
    pub(super) fn inline_mesh(
        &mut self,
        ty: &str,
        ps: &Params,
        at: Loc,
    ) -> Result<(Vec<DVec3>, Vec<[u32; 3]>, Option<Vec<DVec3>>, Option<Vec<[f32; 2]>>)> {
        let points = |p: &Self, name: &str, types: &[&str], n: usize| -> Result<Option<Vec<f64>>> {
            match p.param(ps, name) {
                None => Ok(None),
                Some(q) => {
                    let v = p.nums_of(q, types)?;
                    if v.len() % n != 0 {
                        return Err(p.err(
                            q.loc,
                            format!("\"{} {name}\": expected a multiple of {n} values, found {}", q.ty, v.len()),
                        ));
                    }
                    Ok(Some(v.to_vec()))
                }
            }
        };
        let Some(p) = points(self, "P", &["point3"], 3)? else {
            return Err(self.err(at, format!("Shape \"{ty}\": expected \"point3 P\" (the vertices)")));
        };
        let positions: Vec<DVec3> = p.chunks(3).map(|c| DVec3::new(c[0], c[1], c[2])).collect();
        let nv = positions.len();
        let normals = points(self, "N", &["normal3"], 3)?
            .map(|n| n.chunks(3).map(|c| DVec3::new(c[0], c[1], c[2])).collect::<Vec<_>>());
        let uvs = match points(self, "uv", &["point2", "float"], 2)? {
            Some(v) => Some(v.chunks(2).map(|c| [c[0] as f32, c[1] as f32]).collect::<Vec<_>>()),
            None => points(self, "st", &["point2", "float"], 2)?
                .map(|v| v.chunks(2).map(|c| [c[0] as f32, c[1] as f32]).collect()),
        };
        for (name, len) in [("N", normals.as_ref().map(Vec::len)), ("uv", uvs.as_ref().map(Vec::len))] {
            if let Some(len) = len
                && len != nv
            {
                return Err(
                    self.err(at, format!("Shape \"{ty}\" \"{name}\": expected one per vertex ({nv}), found {len}"))
                );
            }
        }
        let corners = if ty == "bilinearmesh" { 4 } else { 3 };
        let indices: Vec<u32> = match self.param(ps, "indices") {
            Some(q) => {
                let v = self.nums_of(q, &["integer"])?;
                if v.len() % corners != 0 {
                    return Err(self.err(
                        q.loc,
                        format!("\"integer indices\": expected a multiple of {corners} values, found {}", v.len()),
                    ));
                }
                if let Some(bad) = v.iter().find(|&&i| i < 0.0 || i as usize >= nv || i.fract() != 0.0) {
                    return Err(self.err(
                        q.loc,
                        format!(
                            "\"integer indices\": vertex index {bad} out of range: expected 0 to {}",
                            nv as i64 - 1
                        ),
                    ));
                }
                v.iter().map(|&i| i as u32).collect()
            }
            None if nv == corners => (0..corners as u32).collect(),
            None => {
                return Err(
                    self.err(at, format!("Shape \"{ty}\": expected \"integer indices\" (there are {nv} vertices)"))
                );
            }
        };
        for p in ["S", "faceIndices"] {
            if let Some(q) = self.param(ps, p) {
                let loc = q.loc;
                self.warn(loc, format!("Shape \"{ty}\" \"{p}\" is not supported (ignored)"))?;
            }
        }
        let tris: Vec<[u32; 3]> = if corners == 4 {
            indices.chunks(4).flat_map(|q| [[q[0], q[1], q[2]], [q[2], q[1], q[3]]]).collect()
        } else {
            indices.chunks(3).map(|t| [t[0], t[1], t[2]]).collect()
        };
        if ty == "loopsubdiv" {
            let levels = self.int(ps, "levels", 3, 0, 16)?;
            let after = tris.len().saturating_mul(1 << (2 * levels));
            if after > MAX_TRIANGLES {
                return Err(self.err(
                    at,
                    format!("loopsubdiv: {} triangles at {levels} levels make {after}, more than {MAX_TRIANGLES}: expected fewer levels", tris.len()),
                ));
            }
            let (p, t, n) = super::super::loop_subdiv::subdivide(positions, tris, levels as u32);
            let n = n.iter().all(|v| *v != DVec3::ZERO).then_some(n);
            return Ok((p, t, n, None));
        }
        Ok((positions, tris, normals, uvs))
    }
}

/// Triangles in object space placed by `x` (the mirror included) as pbrt-v4 orients
/// them: the winding flipped by `reverse` and by a transform that swaps handedness, or,
/// with shading normals, turned towards them (pbrt's `FaceForward`); normals transformed
/// and flipped by `reverse`. Returns the shape and its area in world space.
pub(super) fn place_mesh(
    x: DMat4,
    reverse: bool,
    positions: &[DVec3],
    mut tris: Vec<[u32; 3]>,
    normals: Option<&[DVec3]>,
    uvs: Option<Vec<[f32; 2]>>,
) -> std::result::Result<(ShapeDesc, f64), String> {
    let nv = positions.len();
    if let Some(k) = tris.iter().position(|t| t.iter().any(|&i| i as usize >= nv)) {
        return Err(format!("triangle {k} has a vertex index out of range (there are {nv} vertices)"));
    }
    let lin = DMat3::from_mat4(x);
    let world: Vec<DVec3> = positions.iter().map(|p| x.transform_point3(*p)).collect();
    let area: f64 = tris
        .iter()
        .map(|t| {
            0.5 * (world[t[1] as usize] - world[t[0] as usize])
                .cross(world[t[2] as usize] - world[t[0] as usize])
                .length()
        })
        .sum();
    if reverse ^ (lin.determinant() < 0.0) {
        for t in &mut tris {
            t.swap(1, 2);
        }
    }
    let nt = lin.inverse().transpose();
    let normals: Option<Vec<V3>> = normals.map(|ns| {
        ns.iter()
            .map(|n| {
                let w = (nt * *n).normalize_or_zero();
                f3(if reverse { -w } else { w })
            })
            .collect()
    });
    if let Some(ns) = &normals {
        for t in &mut tris {
            let [a, b, c] = t.map(|i| world[i as usize]);
            let s: DVec3 = t.iter().map(|&i| DVec3::from(ns[i as usize].map(f64::from))).sum();
            if (b - a).cross(c - a).dot(s) < 0.0 {
                t.swap(1, 2);
            }
        }
    }
    let positions = world.iter().map(|p| f3(*p)).collect();
    Ok((ShapeDesc::Triangles { positions, indices: tris, normals, uvs }, area))
}
