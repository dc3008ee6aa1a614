//! # anim-cli
//!
//! The library behind the `anim` command: scene files ([`scene`]: TOML naming a registered scene
//! kind and its parameters, checked by the crate that implements it; the built-in scenes are the
//! registered presets of `anim::CRATES`), the method picked for a stated accuracy ([`tolerance`]:
//! the report's measured cheapest-method table, embedded), and how a run is drawn and written
//! ([`view`]: frame files and previews from a scene's `Context` and `Frame`s). The binary adds
//! the command line, the run loop, the writer thread and the checkpoint files. No crate is named
//! here: every scene runs as an `anim_core::scene::DynScene`.
//!
//! Particle and mesh scenes are written as VTK unstructured grids, PLY, OBJ or CSV and drawn in
//! 3-D; image scenes (the grid fluids) are a [`view::Geometry::Grid`]: their fields go to VTK
//! image data (`.vti` with a `.pvd` series) and the preview shows the density as a picture;
//! systems of a few unknowns are drawn in the plane and written as a CSV table.
//!
//! ```
//! use anim_cli::scene;
//! let file = scene::builtin("kepler").expect("a built-in scene");
//! assert!(file.run.dt > 0.0);
//! let mut scene = scene::build(&file, std::path::Path::new("kepler"), None)?;
//! scene.step(file.run.dt)?;
//! assert!(scene.time() > 0.0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod output;
pub mod run;
pub mod scene;
pub mod tolerance;
pub mod view;
