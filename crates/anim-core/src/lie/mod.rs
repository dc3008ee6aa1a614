//! Lie groups (stub).
