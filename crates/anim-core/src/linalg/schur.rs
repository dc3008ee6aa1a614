//! Schur complement (stub).
