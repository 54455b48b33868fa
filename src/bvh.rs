//! BVH (stub).
