//! pbrt-v4's light sources and area lights.

use super::*;

impl Parser<'_> {
    // ----------------------------------------------------------------------------------
    // Lights.

    pub(crate) fn area_light(&mut self, ty: &str, at: Loc, ps: &Params) -> Result<Option<AreaLight>> {
        if ty != "diffuse" {
            self.warn(at, format!("AreaLightSource \"{ty}\" is not supported (ignored)"))?;
            for p in &ps.0 {
                p.used.set(true);
            }
            return Ok(None);
        }
        let (spectrum, rgb) = self.light_param(ps, "L")?;
        let scale = self.float(ps, "scale", 1.0)?;
        let two_sided = self.boolean(ps, "twosided", false)?;
        let power = self.float(ps, "power", -1.0)?;
        if let Some((_, loc)) = self.string(ps, "filename")? {
            self.warn(loc, "an area light's image (\"filename\") is not supported: \"L\" is used")?;
        }
        Ok(Some(AreaLight { spectrum, rgb, scale, power: (power > 0.0).then_some(power), two_sided }))
    }

    pub(crate) fn light(&mut self, ty: &str, at: Loc, ps: &Params, ctm: DMat4) -> Result<()> {
        let x = self.built.mirror * ctm;
        let scale = self.float(ps, "scale", 1.0)?;
        match ty {
            "point" | "spot" => {
                let (s, rgb) = self.light_param(ps, "I")?;
                let from = self.point3(ps, "from", DVec3::ZERO)?;
                let power = self.float(ps, "power", -1.0)?;
                let position = f3(x.transform_point3(from));
                if ty == "point" {
                    let k = if power > 0.0 { power / (4.0 * std::f64::consts::PI) } else { 1.0 };
                    self.built
                        .lights
                        .push(LightDesc::Point { position, intensity: light_spectrum(&s, rgb, scale * k) });
                } else {
                    let to = self.point3(ps, "to", DVec3::Z)?;
                    let cone = self.float(ps, "coneangle", 30.0)?;
                    let delta = self.float(ps, "conedeltaangle", 5.0)?;
                    let k = if power > 0.0 {
                        let (end, start) = (cone.to_radians().cos(), (cone - delta).to_radians().cos());
                        power / (2.0 * std::f64::consts::PI * ((1.0 - start) + (start - end) / 2.0))
                    } else {
                        1.0
                    };
                    self.built.lights.push(LightDesc::Spot {
                        position,
                        look_at: f3(x.transform_point3(to)),
                        cone_deg: cone as f32,
                        falloff_deg: delta.min(cone) as f32,
                        intensity: light_spectrum(&s, rgb, scale * k),
                    });
                }
            }
            "distant" => {
                let (s, rgb) = self.light_param(ps, "L")?;
                let from = self.point3(ps, "from", DVec3::ZERO)?;
                let to = self.point3(ps, "to", DVec3::Z)?;
                let e = self.float(ps, "illuminance", -1.0)?;
                let k = if e > 0.0 { e } else { 1.0 };
                let d = x.transform_vector3(to - from);
                self.built
                    .lights
                    .push(LightDesc::Distant { direction: f3(d), irradiance: light_spectrum(&s, rgb, scale * k) });
            }
            "infinite" => {
                if let Some((file, floc)) = self.string(ps, "filename")? {
                    return self.image_light(ps, at, file, floc, scale, x);
                }
                let (s, rgb) = self.light_param(ps, "L")?;
                let e = self.float(ps, "illuminance", -1.0)?;
                let k = if e > 0.0 { e / std::f64::consts::PI } else { 1.0 };
                if let Some(p) = self.param(ps, "portal") {
                    let loc = p.loc;
                    self.warn(loc, "infinite light \"portal\" is not supported (ignored)")?;
                }
                if self.built.environment.is_some() {
                    self.warn(at, "a second infinite light: only the last one is kept")?;
                }
                self.built.environment_loc = Some(at);
                self.built.environment = Some(EnvironmentDesc::Uniform(light_spectrum(&s, rgb, scale * k)));
            }
            other => {
                self.warn(at, format!("LightSource \"{other}\" is not supported (left out)"))?;
                for p in &ps.0 {
                    p.used.set(true);
                }
            }
        }
        Ok(())
    }

    /// pbrt-v4's `ImageInfiniteLight`: an equal-area square image (`mapping: EqualArea`)
    /// turned as pbrt turns it (`x`: world from the light's space, the mirror `M`
    /// included; the map's frame is pbrt's light space with y and z swapped, see
    /// `crate::light::environment`). A frame that mirrors (a transform that swaps
    /// handedness) cannot be a `rotate_deg`: the image is then flipped left to right in
    /// memory (`NAME-envmap.exr`, written beside the RON by `convert`), which mirrors
    /// the map's x axis. `illuminance` scales the map as pbrt-v4 does.
    fn image_light(&mut self, ps: &Params, at: Loc, file: String, floc: Loc, scale: f64, x: DMat4) -> Result<()> {
        if let Some(p) = self.param(ps, "L") {
            let loc = p.loc;
            return Err(
                self.err(loc, "LightSource \"infinite\": \"L\" and \"filename\" exclude each other (as in pbrt-v4)")
            );
        }
        if let Some(p) = self.param(ps, "portal") {
            let loc = p.loc;
            self.warn(loc, "infinite light \"portal\" is not supported (ignored)")?;
        }
        let e = self.float(ps, "illuminance", -1.0)?;
        // The map's frame: pbrt's light space (x, y, z) is the map's (x, z, y).
        let swap = DMat3::from_cols(DVec3::X, DVec3::Z, DVec3::Y);
        let l = DMat3::from_mat4(x);
        let lengths = [l.x_axis.length(), l.y_axis.length(), l.z_axis.length()];
        let q = orthonormal(l);
        let off = (0..3).any(|k| (l.col(k) / lengths[k] - q.col(k)).length() > 1e-6)
            || lengths.iter().any(|v| (v - lengths[0]).abs() > 1e-6 * lengths[0]);
        if off {
            self.warn(at, "the infinite light's transform scales or shears: only its rotation turns the map")?;
        }
        let mut r = q * swap;
        let mirrored = r.determinant() < 0.0;
        if mirrored {
            r *= DMat3::from_diagonal(DVec3::new(-1.0, 1.0, 1.0));
        }
        let mut scale = scale;
        let mut path = file.clone();
        if mirrored || e > 0.0 {
            let full = self.ctx.dir.join(&file);
            let bytes = read_input(&full).map_err(|err| self.err(floc, format!("infinite light \"{file}\": {err}")))?;
            let (w, h, pixels) = crate::io::image::decode_image(&full, &bytes)
                .map_err(|err| self.err(floc, format!("infinite light: {err}")))?;
            let (w, h) = (w as usize, h as usize);
            let rgb = pixels.linear_rgb();
            if e > 0.0 {
                // pbrt-v4's illuminance of the map's upper hemisphere (light-space +z):
                // 2π/(w·h) Σ Y(texel) cos θ over the texels whose centre looks up.
                let mut k = 0.0f64;
                for j in 0..h {
                    for i in 0..w {
                        let u = 2.0 * (i as f64 + 0.5) / w as f64 - 1.0;
                        let v = 2.0 * (j as f64 + 0.5) / h as f64 - 1.0;
                        let signed = 1.0 - (u.abs() + v.abs());
                        let rr = 1.0 - signed.abs();
                        let cos = (1.0 - rr * rr).copysign(signed);
                        if cos > 0.0 {
                            let c = rgb[j * w + i];
                            k += (0.2126 * c[0] as f64 + 0.7152 * c[1] as f64 + 0.0722 * c[2] as f64) * cos;
                        }
                    }
                }
                k *= 2.0 * std::f64::consts::PI / (w * h) as f64;
                if !(k > 0.0 && k.is_finite()) {
                    return Err(self.err(
                        floc,
                        format!(
                            "infinite light \"{file}\": \"illuminance\" needs a map that lights its upper hemisphere"
                        ),
                    ));
                }
                scale *= e / k;
            }
            if mirrored {
                let mut data = Vec::with_capacity(w * h * 3);
                for j in 0..h {
                    for i in (0..w).rev() {
                        data.extend_from_slice(&rgb[j * w + i]);
                    }
                }
                let mut out = std::io::Cursor::new(Vec::new());
                image::Rgb32FImage::from_raw(w as u32, h as u32, data)
                    .ok_or_else(|| self.err(floc, "infinite light: the image's size does not match its pixels"))?
                    .write_to(&mut out, image::ImageFormat::OpenExr)
                    .map_err(|err| self.err(floc, format!("infinite light \"{file}\": {err}")))?;
                let stem = self.files[0].file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
                path = format!("{stem}-envmap.exr");
                self.ctx.provide(&path, out.into_inner());
                self.ctx.record_input(&file, full, fnv1a(&bytes));
                self.note(floc, format!("infinite light \"{file}\": its frame mirrors the map (the transform swaps handedness); rust-v turns maps only, so the map is flipped left to right in memory"));
            }
        }
        if self.built.environment.is_some() {
            self.warn(at, "a second infinite light: only the last one is kept")?;
        }
        self.built.environment_loc = Some(floc);
        self.built.environment = Some(EnvironmentDesc::Image {
            path,
            scale: scale as f32,
            rotate_deg: euler_xyz_deg(r),
            mapping: crate::scene::desc::EnvMapping::EqualArea,
        });
        Ok(())
    }
}

/// The nearest rotation-or-mirror to `l` with orthonormal columns (Gram-Schmidt, x first).
fn orthonormal(l: DMat3) -> DMat3 {
    let x = l.x_axis.normalize();
    let y = (l.y_axis - x * x.dot(l.y_axis)).normalize();
    let z0 = x.cross(y);
    let z = if z0.dot(l.z_axis) < 0.0 { -z0 } else { z0 };
    DMat3::from_cols(x, y, z)
}

/// Angles `(a, b, c)` in degrees with `r = Rz(c) · Ry(b) · Rx(a)` (a rotation), as
/// `rotate_deg` means them.
fn euler_xyz_deg(r: DMat3) -> V3 {
    let at = |row: usize, col: usize| r.col(col)[row];
    let b = (-at(2, 0)).clamp(-1.0, 1.0).asin();
    let (a, c) = if b.cos() > 1e-9 {
        (at(2, 1).atan2(at(2, 2)), at(1, 0).atan2(at(0, 0)))
    } else {
        // Gimbal lock (b = ±90°): only a − c (or a + c) is defined; take c = 0.
        ((-at(1, 2)).atan2(at(1, 1)), 0.0)
    };
    [a, b, c].map(|v| v.to_degrees() as f32 + 0.0)
}
