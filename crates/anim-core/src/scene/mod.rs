//! The contracts through which the command line, `cargo xtask` and the Python bindings drive
//! every solver crate the same way, without knowing any of them.
//!
//! A solver crate implements three traits on its simulation type:
//!
//! - [`Solver`](crate::solver::Solver): advance a separate state by `dt`;
//! - [`Checkpoint`]: save and restore everything a step reads (the state, the simulated time,
//!   an integrator's memory, warm starts, step counters), versioned, so that a resumed run
//!   continues bit for bit;
//! - [`View`]: what the scene looks like: its static [`Context`] once (topology, ground, pins,
//!   colliders, tank walls, the region the motion stays in) and a [`Frame`] per output time
//!   (points, or the cells of an image grid, with named fields), y up whatever the solver's
//!   own frame ([`turn_z_up`] turns a z-up solver's).
//!
//! Every type that implements the three, paired with its state in a [`Simulated`], is a
//! [`DynScene`]: an object-safe scene the run loop can step, checkpoint and draw behind a
//! `Box<dyn DynScene>`. A crate registers its scenes as one [`SceneKind`]: the `kind` a scene
//! file names, the crate's [`Preset`]s (name, description, default step and frame counts, the
//! scene-file parameters), and a builder from those parameters, which are the crate's own serde
//! types read with `deny_unknown_fields`. A kind whose scenes a study of the report measured
//! also gives a [`study::Tolerance`]: what each measured method means on its scenes, for
//! `anim run SCENE --tolerance TOL`.
//!
//! ```
//! use anim_core::scene::{DynScene, Frame};
//! use anim_core::scene::systems::KINDS;
//!
//! // The oscillator preset of anim-core, built from its own parameters and stepped.
//! let kind = KINDS.iter().find(|k| k.kind == "harmonic-oscillator").expect("registered");
//! let preset = &(kind.presets)()[0];
//! let mut scene = (kind.build)(&preset.params, &Default::default())?;
//! for _ in 0..10 {
//!     scene.step(preset.run.dt)?;
//! }
//! let mut frame = Frame::default();
//! scene.frame(&mut frame);
//! assert_eq!(frame.points.len(), 1);
//! assert!((frame.time - 10.0 * preset.run.dt).abs() < 1e-12);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! A builder estimates the memory its scene will take from the parameters before allocating
//! any of it ([`MemoryNeed`]: grids, particles, matrix nonzeros and factor fill) and refuses a
//! size the machine cannot hold with [`BuildError::Memory`], which names the field, the
//! estimate and the memory available.
//!
//! What the module is not: a renderer or a file writer. A [`Frame`] is plain arrays; the `anim`
//! command turns frames into VTK, PLY, OBJ or CSV files and preview images.

mod checkpoint;
mod dynamic;
mod looped;
mod memory;
mod pin;
mod placement;
mod preset;
pub mod study;
pub mod systems;
mod turn;
mod view;

pub use checkpoint::{
    Checkpoint, CheckpointError, restore_state_and_memory, save_state_and_memory, saved_field, saved_state,
};
pub use dynamic::{DynScene, Simulated, StepError};
pub use looped::Looped;
pub use memory::{
    FRAME_CELL_BYTES, FRAME_POINT_BYTES, MemoryNeed, UNKNOWN_LIMIT, WRITTEN_CELL_BYTES, WRITTEN_POINT_BYTES,
    available_memory, check_memory, cholesky_factor_blocks, format_bytes, free_memory,
};
pub use pin::{PinBox, PinError, PinSpec};
pub use placement::{ObstacleMesh, Placement, is_unit_scale, unit_scale};
pub use preset::{BuildContext, BuildError, BuildFn, Preset, RunDefaults, SceneKind, is_default, params};
pub use turn::turn_z_up;
pub use view::{Context, Field, Frame, ImageGrid, MeshProp, Prop, Up, View, frame_box, ground_height};
