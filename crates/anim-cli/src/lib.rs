//! # anim-cli
//!
//! The library behind the `anim` command: scene files ([`scene`]: TOML with every field checked,
//! the built-in scenes), the method picked for a stated accuracy ([`tolerance`]: the report's
//! measured cheapest-method table, embedded), their runnable form ([`runner`]: one [`runner::Runner`] per crate, with
//! checkpoint save and restore), and how a run is drawn and written ([`view`]). The binary adds
//! the command line, the writer thread and the checkpoint files.
//!
//! Particle and mesh scenes are written as VTK unstructured grids, PLY, OBJ or CSV and drawn in
//! 3-D; the grid fluids of anim-fluid (`smoke-box-2d`, `smoke-plume-3d`, `lid-driven-cavity`)
//! are a [`view::Geometry::Grid`]: their density and velocity fields go to VTK image data
//! (`.vti` with a `.pvd` series) and the preview shows the density as a picture. The particle
//! fluids of anim-flip (`dam-break-2d`, `dam-break-3d`, `drop-2d`, `drop-3d`, `sloshing-tank`)
//! are particle scenes: each frame is the point cloud of the particles, turned z up like the other
//! scenes (the sloshing tank's in the world frame, the tank's displacement added).
//!
//! ```
//! use anim_cli::scene;
//! let text = scene::builtin("kepler").expect("a built-in scene");
//! let file = scene::parse(text, std::path::Path::new("kepler"))?;
//! assert!(file.run.dt > 0.0);
//! let mut runner = anim_cli::runner::build(&file.scene, std::path::Path::new("kepler"), None)?;
//! runner.step(file.run.dt)?;
//! assert!(runner.state().t > 0.0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod runner;
pub mod scene;
pub mod tolerance;
pub mod view;
