//! Colour (stub).
