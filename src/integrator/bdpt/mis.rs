//! Multiple importance sampling over every strategy that could make a path.

use crate::scene::Scene;

use super::vertex::{Kind, Vertex};

/// The densities a strategy changes at the connection: `pt_rev` at
/// `x_{t-1}`, `ptm_rev` at `x_{t-2}`, `qs_rev` at `y_{s-1}`, `qsm_rev` at
/// `y_{s-2}`.
#[derive(Clone, Copy, Debug)]
pub(super) struct Overrides {
    pub(super) pt_rev: f32,
    pub(super) ptm_rev: f32,
    pub(super) qs_rev: f32,
    pub(super) qsm_rev: f32,
}

/// The power-heuristic weight of strategy `(s, t)` for the path made of
/// `camera[..t]` and `light[..s]`: `1 / (1 + Σ_i (p_i / p_s)²)` over the
/// other strategies, each ratio a product of `pdf_rev / pdf_fwd` along the
/// path (zero densities, of delta vertices, count as 1; strategies that
/// would need a connection at a delta vertex are skipped).
pub(super) fn mis_weight(scene: &Scene, camera: &[Vertex], t: usize, light: &[Vertex], s: usize, o: Overrides) -> f32 {
    let remap = |p: f32| if p > 0.0 { p } else { 1.0 };
    let mut sum = 0.0f32;
    // Camera side: x_{t-1} … x_1 generated from the light instead.
    let cam_rev = |i: usize| {
        if i + 1 == t {
            o.pt_rev
        } else if i + 2 == t {
            o.ptm_rev
        } else {
            camera[i].pdf_rev
        }
    };
    let cam_delta = |i: usize| i + 1 != t && camera[i].delta;
    let mut ri = 1.0f32;
    for i in (1..t).rev() {
        ri *= remap(cam_rev(i)) / remap(camera[i].pdf_fwd);
        if !cam_delta(i) && !cam_delta(i - 1) {
            sum += ri * ri;
        }
    }
    // Light side: y_{s-1} … y_0 generated from the camera instead.
    let light_rev = |i: usize| {
        if i + 1 == s {
            o.qs_rev
        } else if i + 2 == s {
            o.qsm_rev
        } else {
            light[i].pdf_rev
        }
    };
    let light_delta = |i: usize| i + 1 != s && light[i].delta;
    let delta_light = match light.first().map(|v| v.kind) {
        Some(Kind::Light(i)) => scene.light(i).is_delta(),
        _ => false,
    };
    let mut ri = 1.0f32;
    for i in (0..s).rev() {
        ri *= remap(light_rev(i)) / remap(light[i].pdf_fwd);
        let delta_before = if i > 0 { light_delta(i - 1) } else { delta_light };
        if !light_delta(i) && !delta_before {
            sum += ri * ri;
        }
    }
    1.0 / (1.0 + sum)
}
