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
                if let Some((file, loc)) = self.string(ps, "filename")? {
                    self.warn(loc, format!("LightSource \"infinite\" image \"{file}\": pbrt-v4 maps are equal-area octahedral and rust-v reads equirectangular maps only; the environment is left out (convert the map and use environment: Image(...))"))?;
                    for p in &ps.0 {
                        p.used.set(true);
                    }
                    return Ok(());
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
}
