//! `Mix`: one of two materials, chosen at each hit (pbrt-v4's `mix`).
//!
//! A Mix is not a lobe ([`crate::bxdf`] stays the pure reflection models): at
//! a hit on an object whose material is a Mix, [`crate::scene::Scene`]
//! resolves it to one of its two materials before anything else (the texture
//! step, the BSDF), in `choose`. The choice is a deterministic function of
//! the hit (its point's `f32` bits, its object, the Mix's own index), so every
//! evaluation at one path vertex (BSDF sampling, next-event estimation, BDPT's
//! connections and MIS weights, light tracing) sees the same material, and no
//! sampler dimension is drawn (a scene without a Mix renders as before).
//!
//! Convention (pbrt's): with `u` the hit's hash in [0, 1) and `a` the amount
//! at the hit, the Mix is its second material when `u < a`, else its first:
//! amount 0 is exactly the first, amount 1 exactly the second, and over the
//! surface the second's share is `a`. A nested Mix hashes with its own index,
//! so its choice is independent of its parent's.
//!
//! Scene-level questions (is the object a volume boundary, dispersive, what
//! is its glass's index) read [`crate::scene::Scene::materials`] at the Mix's
//! index, which holds a stand-in: its one `Dielectric` leaf (a Mix with glass
//! bounds the volume that glass does: a path entering where the glass is
//! chosen and leaving where another material is stays consistent with the
//! volume stack), or `Black`. So a Mix holds at most one distinct Dielectric
//! and no `Interface`, and takes no `interior:` medium (the loader refuses it).

use std::collections::BTreeMap;

use glam::{Vec2, Vec3};

use crate::bxdf::Bxdf;
use crate::error::Result;
use crate::scene::check::Check;
use crate::scene::desc::{MaterialDesc, ScalarDesc};
use crate::texture::{self, ScalarTexture};

/// A Mix, built at load: two material indices and the amount.
#[derive(Clone, Debug)]
pub struct Mix {
    /// The two materials (indices into [`crate::scene::Scene::materials`]).
    pub materials: [u32; 2],
    /// The second material's share.
    pub amount: Amount,
    /// Every non-Mix material a hit may resolve to, ascending, once each.
    pub leaves: Vec<u32>,
}

/// A Mix's amount: a number or a texture of numbers, each in [0, 1].
#[derive(Clone, Debug)]
pub enum Amount {
    /// The same share everywhere.
    Value(f32),
    /// A share that varies over the surface's (u, v).
    Texture(ScalarTexture),
}

impl Mix {
    /// The material this Mix (index `own`) is at the hit of object `object`
    /// at point `p`, surface coordinates `uv`: one of its two (maybe a Mix).
    #[inline]
    fn pick(&self, own: u32, object: u32, p: Vec3, uv: Vec2) -> u32 {
        let amount = match &self.amount {
            Amount::Value(a) => *a,
            Amount::Texture(t) => t.eval(uv),
        };
        self.materials[(unit_hash(p, object, own) < amount) as usize]
    }
}

/// The material a hit on object `object` (material `m`) at point `p`,
/// surface coordinates `uv`, resolves to: `m` itself unless it is a Mix, else
/// the leaf its choices lead to (`mixes` is indexed by material; acyclic).
#[inline(never)]
pub(crate) fn choose(mixes: &[Option<Mix>], mut m: u32, object: u32, p: Vec3, uv: Vec2) -> u32 {
    while let Some(Some(mix)) = mixes.get(m as usize) {
        m = mix.pick(m, object, p, uv);
    }
    m
}

/// A number in [0, 1) from a hit: its point's bits, its object and the Mix's
/// material index, through splitmix64's finaliser (24 bits: every value an
/// exact `f32`).
#[inline]
pub fn unit_hash(p: Vec3, object: u32, mix: u32) -> f32 {
    let a = u64::from(p.x.to_bits()) | (u64::from(p.y.to_bits()) << 32);
    let b = u64::from(p.z.to_bits()) | (u64::from(object) << 32);
    let h = splitmix(splitmix(a ^ u64::from(mix).wrapping_mul(0xd6e8_feb8_6659_fd93)) ^ b);
    (h >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
}

/// splitmix64's step: an add and the finaliser.
#[inline]
fn splitmix(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Builds every Mix among `descs` (the scene's materials in file order; the
/// material of `descs[i]` is index `i + 1` in `materials`, whose entries for
/// Mixes are placeholders, replaced here by their stand-ins): resolves the
/// children's names, checks the amounts, refuses cycles, Interface leaves
/// and two distinct Dielectric leaves. The answer is indexed by material;
/// empty when the scene has no Mix.
pub(crate) fn build(
    check: &Check,
    descs: &[(String, MaterialDesc)],
    by_name: &BTreeMap<&str, u32>,
    materials: &mut [Bxdf],
) -> Result<Vec<Option<Mix>>> {
    if !descs.iter().any(|(_, d)| matches!(d, MaterialDesc::Mix { .. })) {
        return Ok(Vec::new());
    }
    let field = |name: &str| format!("materials.\"{name}\"");
    let mut mixes: Vec<Option<Mix>> = vec![None; materials.len()];
    for (i, (name, d)) in descs.iter().enumerate() {
        let MaterialDesc::Mix { materials: (a, b), amount } = d else { continue };
        let f = field(name);
        let mut children = [0; 2];
        for (k, child) in [a, b].into_iter().enumerate() {
            children[k] = *by_name.get(child.as_str()).ok_or_else(|| {
                let known: Vec<&str> = by_name.keys().copied().collect();
                check.err(
                    format!("{f}.materials[{k}]"),
                    format!("unknown material \"{child}\"; defined: {}", known.join(", ")),
                )
            })?;
        }
        let amount = match amount {
            ScalarDesc::Value(v) if v.is_finite() && (0.0..=1.0).contains(v) => Amount::Value(*v),
            ScalarDesc::Value(v) => {
                return Err(check.err(
                    format!("{f}.amount"),
                    format!("expected the second material's share, a number in [0, 1], found {v}"),
                ));
            }
            ScalarDesc::Texture(t) => Amount::Texture(texture::scalar_from_desc(
                check,
                &format!("{f}.amount"),
                t,
                (0.0, 1.0),
                "the second material's share",
            )?),
        };
        mixes[i + 1] = Some(Mix { materials: children, amount, leaves: Vec::new() });
    }
    let names: Vec<&str> = std::iter::once("").chain(descs.iter().map(|(n, _)| n.as_str())).collect();
    for m in 0..mixes.len() {
        if mixes[m].is_none() {
            continue;
        }
        let mut leaves = Vec::new();
        let mut trail = vec![m as u32];
        walk(&mixes, &mut trail, &mut leaves).map_err(|cycle| {
            let chain: Vec<String> = cycle.iter().map(|&c| format!("\"{}\"", names[c as usize])).collect();
            check.err(
                format!("{}.materials", field(names[m])),
                format!("a cycle of Mix materials: {}; a Mix cannot contain itself", chain.join(" → ")),
            )
        })?;
        leaves.sort_unstable();
        leaves.dedup();
        let f = field(names[m]);
        if let Some(&l) = leaves.iter().find(|&&l| materials[l as usize].is_interface()) {
            return Err(check.err(
                format!("{f}.materials"),
                format!("\"{}\" is an Interface (no surface): a Mix chooses between surfaces", names[l as usize]),
            ));
        }
        let glass: Vec<u32> = leaves.iter().copied().filter(|&l| materials[l as usize].bounds_volume()).collect();
        if glass.len() > 1 {
            return Err(check.err(
                format!("{f}.materials"),
                format!(
                    "holds two Dielectrics (\"{}\" and \"{}\"); a Mix may hold one, which bounds its object's volume",
                    names[glass[0] as usize], names[glass[1] as usize]
                ),
            ));
        }
        materials[m] = glass.first().map_or(Bxdf::Black, |&g| materials[g as usize].clone());
        if let Some(mix) = &mut mixes[m] {
            mix.leaves = leaves;
        }
    }
    Ok(mixes)
}

/// Collects the leaves under the Mix at the end of `trail` into `leaves`;
/// `Err` with the materials of a cycle when one is found.
fn walk(mixes: &[Option<Mix>], trail: &mut Vec<u32>, leaves: &mut Vec<u32>) -> std::result::Result<(), Vec<u32>> {
    let m = *trail.last().expect("the walk starts at a Mix");
    let Some(mix) = &mixes[m as usize] else {
        leaves.push(m);
        return Ok(());
    };
    for c in mix.materials {
        if let Some(at) = trail.iter().position(|&t| t == c) {
            let mut cycle = trail[at..].to_vec();
            cycle.push(c);
            return Err(cycle);
        }
        trail.push(c);
        walk(mixes, trail, leaves)?;
        trail.pop();
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The hash is uniform on [0, 1): over a grid of points the share below
    /// `a` is `a` within a binomial's 5 σ, and it changes with the object
    /// and the Mix's index.
    #[test]
    fn the_hash_is_uniform_and_keyed() {
        let n = 200;
        let mut below = [0u32; 3];
        let mut differs = 0;
        for i in 0..n {
            for j in 0..n {
                let p = Vec3::new(i as f32 * 0.013 - 1.0, 0.5, j as f32 * 0.007);
                let u = unit_hash(p, 3, 7);
                assert!((0.0..1.0).contains(&u));
                for (k, a) in [0.1, 0.5, 0.9].into_iter().enumerate() {
                    below[k] += (u < a) as u32;
                }
                differs += (unit_hash(p, 4, 7) != u && unit_hash(p, 3, 8) != u) as u32;
            }
        }
        let total = (n * n) as f32;
        for (k, a) in [0.1f32, 0.5, 0.9].into_iter().enumerate() {
            let sigma = (a * (1.0 - a) / total).sqrt();
            let share = below[k] as f32 / total;
            assert!((share - a).abs() < 5.0 * sigma, "share below {a}: {share}");
        }
        assert!(differs as f32 > 0.99 * total, "{differs}");
    }
}
