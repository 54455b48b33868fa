//! Which light-transport method a render uses, and the line saying why:
//! [`with_estimator`] calls the render loop with the estimator the settings
//! ask for, picked once outside the tile loop; [`describe`] gives the reason
//! `rust-v render` prints. `auto` decides in one place ([`auto_pick`]), which
//! both read.

use super::{
    Bdpt, Caustics, Estimator, FullSpectrum, Packets, PathTracer, RgbWavelengths, Transport, Whitted, caustics,
};
use crate::scene::Scene;
use crate::settings::{IntegratorKind, WavelengthsKind};
use crate::spectral::WavelengthSampling;

/// Calls `f` with the estimator the settings ask for: the one place where the
/// integrator is chosen, outside the tile loop.
pub(crate) fn with_estimator<R>(scene: &Scene, f: impl EstimatorFn<R>) -> R {
    let settings = &scene.settings;
    let bdpt = |light_only| Bdpt { max_bounces: settings.max_bounces, light_only };
    let whitted = Transport::Whitted(Whitted { max_bounces: settings.max_bounces });
    let path = |disperse| {
        Transport::Path(PathTracer {
            max_bounces: settings.max_bounces,
            disperse,
            collapse_to: settings.packet_size,
            light_caustics: false,
        })
    };
    match settings.integrator {
        IntegratorKind::Auto => match auto_pick(scene) {
            Auto::Caustics(c, _) => f.call(&c),
            Auto::Bdpt(_) => f.call(&bdpt(false)),
            Auto::Path => f.call(&FullSpectrum(path(true))),
        },
        IntegratorKind::Bdpt => f.call(&bdpt(false)),
        IntegratorKind::LightTrace => f.call(&bdpt(true)),
        IntegratorKind::Caustics => match Caustics::new(scene, settings.max_bounces, settings.packet_size) {
            Some(c) => f.call(&c),
            None => f.call(&FullSpectrum(path(true))),
        },
        IntegratorKind::Whitted => f.call(&FullSpectrum(whitted)),
        IntegratorKind::Path => f.call(&FullSpectrum(path(false))),
        IntegratorKind::Spectral => {
            let (how, always) = match settings.wavelengths {
                WavelengthsKind::Rgb => return f.call(&RgbWavelengths(path(true))),
                WavelengthsKind::Hero => (WavelengthSampling::Hero, false),
                WavelengthsKind::Random => (WavelengthSampling::Random, false),
                WavelengthsKind::Continuous => (WavelengthSampling::Hero, true),
            };
            match settings.packet_size {
                1 => f.call(&Packets::<1>(path(true), how, always)),
                2 => f.call(&Packets::<2>(path(true), how, always)),
                8 => f.call(&Packets::<8>(path(true), how, always)),
                _ => f.call(&Packets::<4>(path(true), how, always)),
            }
        }
    }
}

/// What `auto` picks, with the reason where it leaves path tracing.
enum Auto {
    /// `caustics`.
    Caustics(Caustics, &'static str),
    /// `bdpt`.
    Bdpt(&'static str),
    /// `auto`'s path tracing.
    Path,
}

/// `auto`'s choice: path tracing, except in the scenes [`needs_bdpt`] names
/// (without a lens system, which light subpaths cannot reach the camera
/// through): there `caustics` where it covers the reason (delta lights or the
/// sun meeting a specular surface, every delta light one that `caustics`
/// aims: no beam; no scattering medium, which `caustics` refuses), else
/// `bdpt`. Measured (docs/integrators.md): `caustics` reached a given error
/// 5x (sunset.ron) to 20x (caustic-point.ron) sooner than `bdpt`.
fn auto_pick(scene: &Scene) -> Auto {
    if !needs_bdpt(scene) || scene.camera.lens_system().is_some() {
        return Auto::Path;
    }
    let why = match (scene.has_delta_surface(), scene.has_delta_light()) {
        (true, true) => {
            "a point, spot, distant or beam light meets a specular surface (caustics path tracing cannot find)"
        }
        (true, false) => {
            "the environment's sun (the sky's, or a map's: half its power within 1% of the sphere) meets a specular surface (caustics path tracing cannot find)"
        }
        _ => "a point, spot, distant or beam light meets a scattering medium (light subpaths start in its beam)",
    };
    let s = &scene.settings;
    let aimed = !scene.has_scattering() && caustics::aims_every_delta_light(scene);
    match aimed.then(|| Caustics::new(scene, s.max_bounces, s.packet_size)).flatten() {
        Some(c) => Auto::Caustics(c, why),
        None => Auto::Bdpt(why),
    }
}

/// True when the scene has light that path tracing cannot reach well: a
/// delta light (point, spot, distant, beam) together with a specular
/// surface (smooth glass, mirror, smooth metal, thin sheet), whose caustics
/// no camera path can connect to the light, or together with a scattering
/// medium, where a narrow beam's single scattering reaches a camera path
/// only when its distance sample lands in the beam (light subpaths start in
/// it: on `milky-water.ron` BDPT's error at equal time is a third of path
/// tracing's or less). The sky's sun, half a degree across, counts as a
/// delta light for caustics (a camera path reaches it through smooth glass
/// only by hitting its disk), and so does a map's sun
/// ([`crate::light::EnvironmentLight::has_sun`]). `auto` then leaves path tracing for
/// `caustics` or `bdpt` (`auto_pick`).
pub fn needs_bdpt(scene: &Scene) -> bool {
    let caustics = scene.has_delta_surface() && (scene.has_delta_light() || scene.has_sun());
    caustics || (scene.has_delta_light() && scene.has_scattering())
}

/// One line saying which light-transport model the settings pick for this
/// scene and why (printed once by `rust-v render`).
pub fn describe(scene: &Scene) -> String {
    let line = describe_transport(scene);
    let line = if !scene.has_scattering() {
        line
    } else if scene.settings.integrator == IntegratorKind::Whitted {
        format!("{line}; participating media attenuate only (no in-scattering)")
    } else {
        format!(
            "{line}; participating media: distances by spectral MIS over the wavelengths, scattering events as path vertices"
        )
    };
    match scene.camera.lens_system() {
        Some(lens) if lens.is_dispersive() => match scene.settings.integrator {
            IntegratorKind::Auto => format!(
                "{line}; the camera's lens disperses: one continuous wavelength per camera sample, drawn by visual importance, on its own ray through the lens"
            ),
            IntegratorKind::Spectral => format!(
                "{line}; the camera's lens disperses: each wavelength of a packet on its own ray through the lens"
            ),
            _ => format!("{line}; the camera's lens refracts every wavelength like the d line (587.56 nm)"),
        },
        _ => line,
    }
}

/// The line for `caustics` (also `auto`'s where it picks it).
fn describe_caustics(scene: &Scene, c: &Caustics) -> String {
    format!(
        "auto's path tracing, except caustics of the environment and distant, point and spot lights through specular and glossy surfaces: light subpaths aimed at {} specular or glossy object(s) ({:.0}% of aimed rays reach one; a light subpath for {:.1}% of the samples) connect them to the camera (no MIS: a partition of the paths)",
        c.aim.target_count(),
        100.0 * c.aim.reach(scene),
        100.0 * c.fraction
    )
}

/// [`describe`] without the camera's lens.
fn describe_transport(scene: &Scene) -> String {
    let s = &scene.settings;
    let dispersive = scene.has_dispersion();
    match s.integrator {
        IntegratorKind::Auto => match auto_pick(scene) {
            Auto::Caustics(c, why) => format!("auto: {why}: {}", describe_caustics(scene, &c)),
            Auto::Bdpt(why) => format!(
                "auto: {why}: bidirectional path tracing{}",
                if dispersive { "; the full spectrum until a subpath refracts at dispersive glass, then one wavelength" } else { ", full spectrum" }
            ),
            Auto::Path if dispersive => format!(
                "auto: dispersive material present: full-spectrum path tracing; a path that refracts at dispersive glass continues as {} single continuous wavelengths (bin centres with --spectral) drawn by throughput and visual importance",
                s.packet_size
            ),
            Auto::Path => "auto: no dispersive material: full-spectrum path tracing (all 36 bins on every path, no wavelength sampling)".into(),
        },
        IntegratorKind::Path if dispersive => "path: full spectrum; dispersive glass refracts every wavelength like 589.3 nm (no rainbow)".into(),
        IntegratorKind::Path => "path: full-spectrum path tracing".into(),
        IntegratorKind::Bdpt => "bdpt: bidirectional path tracing, every strategy combined by MIS (power heuristic)".into(),
        IntegratorKind::LightTrace => "lighttrace: light subpaths connected to the camera only (no camera paths)".into(),
        IntegratorKind::Caustics => match Caustics::new(scene, s.max_bounces, s.packet_size) {
            Some(c) => format!("caustics: {}", describe_caustics(scene, &c)),
            None => "caustics: no specular surface with bounds, or no environment, distant, point or spot light, to aim at: auto's full-spectrum path tracing alone".into(),
        },
        IntegratorKind::Whitted => "whitted: specular chains and direct light at the first diffuse hit (no indirect light, no caustics)".into(),
        IntegratorKind::Spectral => match s.wavelengths {
            WavelengthsKind::Rgb => "spectral, rgb: three wavelengths (435.8, 546.1, 700 nm) read out as RGB".into(),
            WavelengthsKind::Continuous => format!(
                "spectral, continuous: hero packets of {} wavelengths anywhere in 360-830 nm, every spectrum interpolated at each",
                s.packet_size
            ),
            w if dispersive => format!(
                "spectral, {w:?} packets of {} continuous wavelengths (dispersive glass; bin centres with --spectral), split at dispersive surfaces",
                s.packet_size
            )
            .to_lowercase(),
            w => format!("spectral, {w:?} packets of {} wavelengths, split at dispersive surfaces", s.packet_size).to_lowercase(),
        },
    }
}

/// A function generic over the estimator type (a closure cannot be generic).
pub(crate) trait EstimatorFn<R> {
    /// Runs with estimator `e`.
    fn call<E: Estimator>(self, e: &E) -> R;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::settings::SettingsPatch;

    /// What `auto` picks, and the reason it prints: `caustics` for a spot and
    /// for the sky's sun on glass (a map's sun: `tests/environment.rs`); BDPT for a beam on glass (not aimed) and a
    /// spot in a scattering medium; path tracing for an index-matched boundary
    /// under a spot, and for a uniform environment over glass.
    #[test]
    fn auto_picks_caustics_or_bdpt_where_path_tracing_cannot_reach_the_light() {
        let scene = |materials: &str, light: &str, media: &str, interior: &str| {
            let text = format!(
                r#"(camera: (eye: (0, 0, 5), look_at: (0, 0, 0), fov_deg: 30),
                media: {{ {media} }},
                materials: {{ "m": {materials}, "floor": Lambertian(reflectance: Constant(0.5)) }},
                objects: [ (shape: Sphere(center: (0, 0, 0), radius: 1), material: "m"{interior}),
                           (shape: Quad(origin: (-3, -1, 3), edge_u: (6, 0, 0), edge_v: (0, 0, -6)), material: "floor") ],
                {light})"#
            );
            crate::scene::load_scene_str(&text, std::path::Path::new("t.ron"), &SettingsPatch::default()).unwrap()
        };
        let spot = "lights: [ Spot(position: (0, 3, 0), look_at: (0, 0, 0), cone_deg: 20, falloff_deg: 5, intensity: Constant(5)) ]";
        let sky = "environment: Sky(sun_elevation_deg: 30, sun_azimuth_deg: 0, turbidity: 3, ground_albedo: 0.3)";
        let milk = r#""milk": Homogeneous(sigma_a: Constant(0.1), sigma_s: Constant(1))"#;
        let beam = "lights: [ Beam(origin: (0, 3, 0), direction: (0, -1, 0), radius: 0.2, irradiance: Constant(5)) ]";
        let glass = "Dielectric(ior: Constant(1.5))";
        // (scene, why and what auto picks: `caustics`' aimed light subpaths, or bdpt)
        let (aimed, bidir) = ("light subpaths aimed", "bidirectional");
        let cases = [
            (scene(glass, spot, "", ""), Some(("specular surface", aimed))),
            (scene(glass, beam, "", ""), Some(("specular surface", bidir))),
            (scene("Interface", spot, milk, r#", interior: "milk""#), Some(("scattering medium", bidir))),
            (scene(glass, sky, "", ""), Some(("the environment's sun", aimed))),
            (scene("Interface", spot, "", ""), None),
            (scene(glass, "environment: Uniform(Constant(1))", "", ""), None),
            (scene("Interface", sky, milk, r#", interior: "milk""#), None),
        ];
        for (i, (s, want)) in cases.iter().enumerate() {
            let line = describe(s);
            assert_eq!(needs_bdpt(s), want.is_some(), "case {i}: {line}");
            if let Some((why, what)) = want {
                assert!(line.contains(why) && line.contains(what), "case {i}: {line}");
                assert_eq!(matches!(auto_pick(s), Auto::Caustics(..)), *what == aimed, "case {i}: {line}");
            }
        }
    }
}
