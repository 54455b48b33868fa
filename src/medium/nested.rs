//! Nested dielectrics: the stack of volumes a path carries, so that a surface
//! between water and glass refracts with `n_water / n_glass` and not as if
//! each met vacuum (after the idea of Schmidt and Budge 2002, "Simple nested
//! dielectrics in ray traced images"; written for rust-v, neither pbrt-v4 nor
//! Mitsuba 3 has it).
//!
//! Every object whose material is a [`crate::bxdf::Dielectric`] (smooth or rough,
//! dispersive or not) bounds a *volume*: its inside (the side opposite its
//! geometric normal) holds its index and its medium (an absorbing
//! [`super::Medium`] or nothing). A path keeps the
//! volumes it is inside in a [`VolumeStack`]: a fixed array of
//! [`VOLUME_STACK_DEPTH`] entries (object, priority, material), no
//! allocation. Vacuum (index 1) is the bottom and is not stored.
//!
//! - The **current volume** is the entry of highest `priority`; among equal
//!   priorities the one entered last (so glass and water of equal priority
//!   nest the natural way: the water, entered after the glass, is inside it).
//!   Segments are absorbed by the current volume's `absorption:`.
//! - At a hit on a volume's surface, entering or leaving is decided by the
//!   geometric normal. The surface is a real interface when its object would
//!   be the current volume on its inside; its **outside** is the current
//!   medium of the stack without this object, and the relative index is
//!   `n_object / n_outside` per wavelength.
//! - Otherwise the hit is a **false intersection** (a lower-priority object
//!   inside a higher-priority medium, or leaving an object that an
//!   equal-priority medium entered later overrides): the path goes straight
//!   on, with no scattering, no bounce counted and no light sample, and only
//!   the stack changes.
//!
//! Overlapping volumes therefore resolve by priority: `priority` is a field
//! of the *object* (default 0, higher wins where volumes overlap):
//!
//! ```ron
//! materials: { "glass": Dielectric(ior: Constant(1.5)), "water": Dielectric(ior: Constant(1.33)) },
//! objects: [
//!     (shape: Cuboid(min: (-0.25, 0, -0.25), max: (0.25, 0.7, 0.25)), material: "glass", priority: 1),
//!     // The water carves its volume out of the glass: where both overlap, water wins.
//!     (shape: Cuboid(min: (-0.22, 0.05, -0.22), max: (0.22, 0.45, 0.22)), material: "water", priority: 3),
//! ],
//! ```
//!
//! **Inconsistent geometry** never panics: leaving an object that is not on
//! the stack (an open mesh, a path that started inside glass the camera
//! probe did not find) refracts into the current volume and leaves the stack
//! as it is; entering an object already on the stack does not record it
//! twice. **Overflow**: a path inside more than [`VOLUME_STACK_DEPTH`]
//! media at once does not record the innermost ones (entering them
//! refracts as usual, but the stack keeps its 8 outer entries, so surfaces
//! inside them take the 8th as their outside).

/// How many media a path can be inside at once (vacuum not counted).
pub const VOLUME_STACK_DEPTH: usize = 8;

/// One medium a path is inside: the object whose volume it is, its
/// priority, and its material (a dielectric, by index into the scene's
/// materials).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Volume {
    /// The object's index in the scene.
    pub object: u32,
    /// Its priority (higher wins where volumes overlap).
    pub priority: u32,
    /// Its material's index (a dielectric).
    pub material: u32,
}

/// What a path meets at a volume's surface.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Crossing {
    /// A real interface: scatter with the relative index `n_object /
    /// n_outside`, where `outside` is the material of the medium on the
    /// other side of the surface from the object (`None`: vacuum).
    Interface {
        /// The outside medium's material, or `None` for vacuum.
        outside: Option<u32>,
    },
    /// A false intersection: continue straight through, no scattering.
    Pass,
}

/// The media a path is inside, innermost last (fixed size, `Copy`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct VolumeStack {
    entries: [Volume; VOLUME_STACK_DEPTH],
    len: u8,
}

impl Default for VolumeStack {
    fn default() -> Self {
        VolumeStack::VACUUM
    }
}

impl VolumeStack {
    /// Vacuum: no medium.
    pub const VACUUM: VolumeStack =
        VolumeStack { entries: [Volume { object: 0, priority: 0, material: 0 }; VOLUME_STACK_DEPTH], len: 0 };

    /// The recorded media, outermost first.
    #[inline]
    pub fn entries(&self) -> &[Volume] {
        &self.entries[..self.len as usize]
    }

    /// True in vacuum.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The position of the current volume among the entries other than
    /// `object`'s: highest priority, the last entered among equals.
    #[inline]
    fn current_index(&self, except: Option<u32>) -> Option<usize> {
        let mut best: Option<usize> = None;
        for (i, m) in self.entries().iter().enumerate() {
            if Some(m.object) != except && best.is_none_or(|b| m.priority >= self.entries[b].priority) {
                best = Some(i);
            }
        }
        best
    }

    /// The medium the path is in now (`None`: vacuum).
    #[inline]
    pub fn current(&self) -> Option<Volume> {
        if self.len == 0 {
            return None;
        }
        self.current_index(None).map(|i| self.entries[i])
    }

    /// What a hit on the surface of medium `m` is, for a path `entering`
    /// it (arriving against the geometric normal) or leaving it.
    #[inline]
    pub fn crossing(&self, m: Volume, entering: bool) -> Crossing {
        let Some(best) = self.current_index(Some(m.object)) else {
            return Crossing::Interface { outside: None };
        };
        let other = self.entries[best];
        let overridden = if entering {
            other.priority > m.priority
        } else {
            // Leaving: an equal-priority medium entered after this one holds the volume here.
            let at = self.entries().iter().position(|e| e.object == m.object);
            other.priority > m.priority || (other.priority == m.priority && at.is_some_and(|at| best > at))
        };
        if overridden { Crossing::Pass } else { Crossing::Interface { outside: Some(other.material) } }
    }

    /// The path enters `m`: recorded unless already there or the stack is full.
    #[inline]
    pub fn enter(&mut self, m: Volume) {
        let n = self.len as usize;
        if n < VOLUME_STACK_DEPTH && !self.entries().iter().any(|e| e.object == m.object) {
            self.entries[n] = m;
            self.len += 1;
        }
    }

    /// The path leaves the medium of `object` (nothing if it is not recorded).
    #[inline]
    pub fn leave(&mut self, object: u32) {
        let n = self.len as usize;
        if let Some(at) = self.entries().iter().position(|e| e.object == object) {
            self.entries.copy_within(at + 1..n, at);
            self.len -= 1;
        }
    }

    /// The path crosses the surface of `m`, entering or leaving it.
    #[inline]
    pub fn cross(&mut self, m: Volume, entering: bool) {
        if entering { self.enter(m) } else { self.leave(m.object) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn m(object: u32, priority: u32) -> Volume {
        Volume { object, priority, material: 10 + object }
    }

    /// Glass and water of equal priority, water inside: every surface sees
    /// the right outside, and the path ends in vacuum.
    #[test]
    fn equal_priorities_nest_in_entry_order() {
        let (glass, water) = (m(1, 0), m(2, 0));
        let mut s = VolumeStack::VACUUM;
        assert_eq!(s.crossing(glass, true), Crossing::Interface { outside: None });
        s.cross(glass, true);
        assert_eq!(s.current(), Some(glass));
        assert_eq!(s.crossing(water, true), Crossing::Interface { outside: Some(11) });
        s.cross(water, true);
        assert_eq!(s.current(), Some(water));
        assert_eq!(s.crossing(water, false), Crossing::Interface { outside: Some(11) });
        s.cross(water, false);
        assert_eq!(s.crossing(glass, false), Crossing::Interface { outside: None });
        s.cross(glass, false);
        assert!(s.is_empty() && s.current().is_none());
    }

    /// A lower-priority object inside a higher-priority medium is passed
    /// straight through, entering and leaving, and never becomes current.
    #[test]
    fn lower_priority_inside_higher_is_a_false_intersection() {
        let (outer, inner) = (m(1, 5), m(2, 1));
        let mut s = VolumeStack::VACUUM;
        s.cross(outer, true);
        assert_eq!(s.crossing(inner, true), Crossing::Pass);
        s.cross(inner, true);
        assert_eq!(s.current(), Some(outer));
        assert_eq!(s.crossing(inner, false), Crossing::Pass);
        // Leaving the outer medium while still inside the inner one: the inner is the outside.
        assert_eq!(s.crossing(outer, false), Crossing::Interface { outside: Some(12) });
        // Equal priority, the other entered later: leaving the earlier is false.
        let mut t = VolumeStack::VACUUM;
        t.cross(m(1, 0), true);
        t.cross(m(2, 0), true);
        assert_eq!(t.crossing(m(1, 0), false), Crossing::Pass);
    }

    /// Leaving a medium never entered, entering one twice and overflowing
    /// the stack keep it consistent and never panic.
    #[test]
    fn inconsistent_geometry_and_overflow() {
        let mut s = VolumeStack::VACUUM;
        assert_eq!(s.crossing(m(3, 0), false), Crossing::Interface { outside: None });
        s.cross(m(3, 0), false);
        assert!(s.is_empty());
        s.cross(m(1, 0), true);
        s.cross(m(1, 0), true);
        assert_eq!(s.entries().len(), 1);
        for i in 2..20 {
            s.cross(m(i, 0), true);
        }
        assert_eq!(s.entries().len(), VOLUME_STACK_DEPTH);
        assert_eq!(s.current(), Some(m(8, 0)));
        // The unrecorded ninth: leaving it is a real interface into the 8th, and changes nothing.
        assert_eq!(s.crossing(m(9, 0), false), Crossing::Interface { outside: Some(18) });
        s.cross(m(9, 0), false);
        assert_eq!(s.entries().len(), VOLUME_STACK_DEPTH);
        s.cross(m(4, 0), false);
        assert_eq!(s.entries().iter().map(|e| e.object).collect::<Vec<_>>(), [1, 2, 3, 5, 6, 7, 8]);
    }
}
