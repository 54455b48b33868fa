//! Geometry (stub; the geometry work replaces this file).
pub mod frame;
