// The README, with its links into `scene` resolved: to the module with feature `serde`, else
// to the features table that says how to get it.
#![cfg_attr(feature = "serde", doc = concat!(include_str!("../README.md"), "\n[`scene`]: scene\n[`Checkpoint`]: scene::Checkpoint\n[`View`]: scene::View\n[`DynScene`]: scene::DynScene\n[`SceneKind`]: scene::SceneKind\n[`Preset`]: scene::Preset\n[`Placement`]: scene::Placement\n[`PinSpec`]: scene::PinSpec\n"))]
#![cfg_attr(not(feature = "serde"), doc = concat!(include_str!("../README.md"), "\n[`scene`]: #features\n[`Checkpoint`]: #features\n[`View`]: #features\n[`DynScene`]: #features\n[`SceneKind`]: #features\n[`Preset`]: #features\n[`Placement`]: #features\n[`PinSpec`]: #features\n"))]

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
pub mod mesh;
pub mod par;
pub mod scalar;
#[cfg(feature = "serde")]
pub mod scene;
pub mod solver;
pub mod surface;

pub use glam;

/// The code blocks of the workspace README, compiled and run as doc tests.
#[doc = include_str!("../../../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
