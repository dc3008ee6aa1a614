#![doc = include_str!("../README.md")]

pub mod alloc_count;
pub mod bspline;
#[cfg(feature = "cases")]
pub mod cases;
pub mod diagnostics;
pub mod geometry;
pub mod input;
pub mod integrate;
pub mod lie;
pub mod linalg;
pub mod par;
pub mod scalar;
pub mod scene;
pub mod solver;
pub mod surface;

pub use glam;

/// The code blocks of the workspace README, compiled and run as doc tests.
#[doc = include_str!("../../../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
