//! pbrt-v4's camera, film, sampler, integrator and filter, and `WorldBegin`.

use super::*;

impl Parser<'_> {
    // ----------------------------------------------------------------------------------
    // Camera and options.

    pub(crate) fn camera(&mut self, ty: &str, at: Loc, ps: &Params, ctm: DMat4) -> Result<()> {
        if ty != "perspective" {
            self.warn(at, format!("Camera \"{ty}\" is not supported: rendered as a perspective camera"))?;
        }
        let fov = self.float(ps, "fov", 90.0)?;
        if !(fov > 0.0 && fov < 180.0) {
            return Err(self.err(at, format!("Camera \"fov\": expected degrees in (0, 180), found {fov}")));
        }
        let lens_radius = self.float(ps, "lensradius", 0.0)?;
        let focal_distance = self.float(ps, "focaldistance", 1e6)?;
        if !(lens_radius >= 0.0 && focal_distance > 0.0) {
            return Err(self.err(at, format!("Camera: expected \"lensradius\" ≥ 0 and \"focaldistance\" > 0, found {lens_radius} and {focal_distance}")));
        }
        if let Some(p) = self.param(ps, "screenwindow") {
            let loc = p.loc;
            self.warn(loc, "Camera \"screenwindow\" is not supported: the full frame is rendered")?;
        }
        if let Some(p) = self.param(ps, "frameaspectratio") {
            let loc = p.loc;
            self.warn(loc, "Camera \"frameaspectratio\" is not supported: the film's aspect ratio is used")?;
        }
        for t in ["shutteropen", "shutterclose"] {
            if let Some(p) = self.param(ps, t) {
                let loc = p.loc;
                self.warn(loc, format!("Camera \"{t}\": motion blur is not supported (ignored)"))?;
            }
        }
        self.built.pending_camera =
            Some(PendingCamera { fov, lens_radius, focal_distance, camera_from_world: ctm, loc: at });
        Ok(())
    }

    pub(crate) fn film(&mut self, ty: &str, at: Loc, ps: &Params) -> Result<()> {
        if ty != "rgb" && ty != "spectral" {
            self.warn(at, format!("Film \"{ty}\" is not supported: rendered as an rgb film"))?;
        }
        let x = self.int(ps, "xresolution", 1280, 1, crate::settings::MAX_SIDE as i64)? as u32;
        let y = self.int(ps, "yresolution", 720, 1, crate::settings::MAX_SIDE as i64)? as u32;
        self.built.resolution = (x, y);
        self.built.render.width = Some(x);
        self.built.render.height = Some(y);
        if let Some((_, loc)) = self.string(ps, "filename")? {
            self.note(
                loc,
                "Film \"filename\" is ignored: the output is rust-v's -o (default: the scene's name with .png)",
            );
        }
        if let Some((s, loc)) = self.string(ps, "sensor")?
            && s != "cie1931"
        {
            self.warn(
                loc,
                format!(
                    "Film \"sensor\" \"{s}\": pbrt's measured camera curves are not shipped with rust-v: rendered with the CIE 1931 observer (give the camera's curves with --sensor FILE.csv, docs/sensors.md)"
                ),
            )?;
        }
        for ignored in ["iso", "exposuretime", "whitebalance", "maxcomponentvalue", "savefp16", "diagonal"] {
            if let Some(p) = self.param(ps, ignored) {
                let loc = p.loc;
                self.warn(loc, format!("Film \"{ignored}\" is not supported (ignored)"))?;
            }
        }
        Ok(())
    }

    pub(crate) fn sampler(&mut self, ty: &str, at: Loc, ps: &Params) -> Result<()> {
        let spp = self.int(ps, "pixelsamples", 16, 1, u32::MAX as i64)?;
        self.built.render.spp = Some(spp as u32);
        let seed = self.int(ps, "seed", 0, 0, i64::MAX)?;
        if ps.0.iter().any(|p| p.name == "seed") {
            self.built.render.seed = Some(seed as u64);
        }
        if !["zsobol", "sobol", "paddedsobol", "halton", "independent", "pmj02bn", "stratified"].contains(&ty) {
            self.warn(at, format!("Sampler \"{ty}\" is unknown: rust-v's own sampler is used"))?;
        }
        for p in ["jitter", "xsamples", "ysamples", "randomization", "dimensions"] {
            self.param(ps, p);
        }
        Ok(())
    }

    pub(crate) fn integrator(&mut self, ty: &str, at: Loc, ps: &Params) -> Result<()> {
        let depth = self.int(ps, "maxdepth", 5, 0, u32::MAX as i64)?;
        self.built.render.max_bounces = Some(depth as u32);
        let kind = match ty {
            "path" | "volpath" => IntegratorKind::Path,
            "bdpt" => IntegratorKind::Bdpt,
            "lightpath" => IntegratorKind::LightTrace,
            other => {
                self.note(at, format!("Integrator \"{other}\" is not available: rust-v's auto method is used"));
                IntegratorKind::Auto
            }
        };
        self.built.render.integrator = Some(kind);
        for p in ["regularize", "lightsampler"] {
            self.param(ps, p);
        }
        Ok(())
    }

    pub(crate) fn filter(&mut self, ty: &str, at: Loc, ps: &Params) -> Result<()> {
        if ty != "box" {
            self.warn(at, format!("PixelFilter \"{ty}\" is not supported: rust-v uses a one-pixel box filter"))?;
        }
        for p in ["xradius", "yradius", "radius", "sigma", "B", "C", "tau", "alpha"] {
            if let Some(p) = self.param(ps, p)
                && ty == "box"
            {
                let loc = p.loc;
                self.warn(loc, "PixelFilter \"box\" radius: rust-v's box is one pixel wide (ignored)")?;
            }
        }
        Ok(())
    }

    /// At `WorldBegin`: the camera, and the mirror `M` that keeps the image the right way round.
    ///
    /// pbrt's camera looks down +z with +x to the image's right and +y up: with a proper
    /// (rotation) camera transform, right = up × forward in world space. rust-v's camera
    /// puts forward × up on the right, the other way. Mirroring the whole world (x → −x)
    /// turns one into the other: for the mirror `M`, `M a × M b = −M (a × b)`, so rust-v's
    /// right in the mirrored world is `M` (pbrt's right). A camera transform that already
    /// mirrors (`Scale -1 1 1` before `LookAt`, as exporters write) needs no mirror.
    pub(crate) fn begin_world(&mut self, loc: Loc) -> Result<()> {
        let cam = self.built.pending_camera.take().unwrap_or(PendingCamera {
            fov: 90.0,
            lens_radius: 0.0,
            focal_distance: 1e6,
            camera_from_world: DMat4::IDENTITY,
            loc,
        });
        let w = cam.camera_from_world.inverse();
        let eye = w.transform_point3(DVec3::ZERO);
        let forward = w.transform_vector3(DVec3::Z);
        let up = w.transform_vector3(DVec3::Y);
        let right = w.transform_vector3(DVec3::X);
        let lens = DMat3::from_cols(right, up, forward);
        let scales = [right.length(), up.length(), forward.length()];
        if (scales[0] - scales[1]).abs() > 1e-6 * scales[0]
            || right.dot(up).abs() > 1e-6 * scales[0] * scales[1]
            || right.dot(forward).abs() > 1e-6 * scales[0] * scales[2]
            || up.dot(forward).abs() > 1e-6 * scales[1] * scales[2]
        {
            self.warn(
                cam.loc,
                "the camera transform scales or shears: rust-v's camera uses its view direction and up only",
            )?;
        }
        let mirror = lens.determinant() > 0.0;
        self.built.mirror = if mirror { DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0)) } else { DMat4::IDENTITY };
        let m = self.built.mirror;
        let (xres, yres) = self.built.resolution;
        // pbrt's fov spans the shorter image side; rust-v's is vertical.
        let fov = if xres >= yres {
            cam.fov
        } else {
            2.0 * ((cam.fov.to_radians() * 0.5).tan() * yres as f64 / xres as f64).atan().to_degrees()
        };
        self.built.camera = Some(CameraDesc {
            eye: f3(m.transform_point3(eye)),
            look_at: f3(m.transform_point3(eye + forward.normalize())),
            up: f3(m.transform_vector3(up.normalize())),
            fov_deg: Some(fov as f32),
            // pbrt's thin lens: a disk of `lensradius` in scene units, focused at
            // `focaldistance` along the view direction.
            aperture_radius: cam.lens_radius as f32,
            focus_distance: (cam.lens_radius > 0.0).then_some(cam.focal_distance as f32),
            lens: None,
            medium: None,
        });
        Ok(())
    }
}
