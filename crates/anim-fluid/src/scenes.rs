//! Ready-to-run scenes for the command line, examples and benchmarks.
//!
//! | scene | what | solver | why |
//! | --- | --- | --- | --- |
//! | [`smoke_box_2d`] | an interactive-style demo: a smoke source at the bottom of a closed box pushes density up, its sideways force flipping every 25 steps | [Stam's solver](crate::stam), `f32`, 20 Gauss-Seidel sweeps | Stam's routines (GDC 2003) exactly, as his demo runs them |
//! | [`smoke_plume_3d`] | hot smoke rises from a vent around a sphere into an open-topped box | MAC 3D, MacCormack, MGPCG, buoyancy + vorticity confinement | the 3D solver with an obstacle, inflow and an open boundary |
//! | [`taylor_green_decay`] | the Taylor-Green vortex in the unit square with free-slip walls, decaying for a given time | MAC 2D, any advection, pressure to 1e-10 | the analytic decay `exp(-2 nu pi^2 t)` checks advection, projection and viscosity together |
//! | [`lid_driven_cavity`] | the unit square, top wall sliding at 1, Re = 100, bands of passive dye | MAC 2D, MacCormack, MGPCG, implicit viscosity | the classic steady benchmark (Ghia, Ghia and Shin 1982) |
//!
//! ```
//! use anim_fluid::scenes;
//!
//! let mut scene = scenes::by_name("lid-driven-cavity", Some(16)).expect("a known scene")?;
//! let report = scene.step()?;
//! assert!(report.constraint_violation.is_some_and(|d| d < 1e-3));
//! let (density, dims) = scene.density();
//! assert_eq!(density.len(), dims[0] * dims[1] * dims[2]);
//! # Ok::<(), anim_fluid::FluidError>(())
//! ```

use crate::advection::{Advection, Splitting};
use crate::error::FluidError;
use crate::mac::{MacFluid, MacParams, MacState, Source, Wall};
use crate::pressure::PressureMethod;
use crate::stam::{StamFluid, StamParams, ix};
use anim_core::geometry::Shape;
use anim_core::solver::{Solver, StepReport};
use serde::Deserialize as _;

/// The built-in scene names.
pub const NAMES: [&str; 3] = ["smoke-box-2d", "smoke-plume-3d", "lid-driven-cavity"];

/// The simulation behind a scene.
#[derive(Debug, Clone)]
#[allow(clippy::large_enum_variant)]
pub enum FluidSim {
    /// Stam's solver (GDC 2003) with its source pattern.
    Stam(StamFluid),
    /// The MAC solver and its state.
    Mac(MacFluid, MacState),
}

/// A scene: a simulation, its time step and duration.
#[derive(Debug, Clone)]
pub struct FluidScene {
    /// Short name.
    pub name: &'static str,
    /// One-line description.
    pub description: &'static str,
    /// The simulation.
    pub sim: FluidSim,
    /// Time step (s).
    pub dt: f64,
    /// Suggested duration (s).
    pub duration: f64,
    /// Obstacle shapes drawn with the scene (a smoke scene's shape obstacles; the plume's
    /// sphere is drawn by the scene's name).
    pub shapes: Vec<Shape>,
}

impl FluidScene {
    /// Number of steps of `dt` covering `duration`.
    #[must_use]
    pub fn steps(&self) -> usize {
        (self.duration / self.dt).round().max(1.0) as usize
    }

    /// Advances one step of the scene's `dt` (the Stam scene first applies its source pattern).
    ///
    /// # Errors
    /// The solver's [`FluidError`]; the simulation is then as before the step.
    pub fn step(&mut self) -> Result<StepReport, FluidError> {
        self.step_by(self.dt)
    }

    /// Advances one step of `dt` (the Stam scene first applies its source pattern; its solver
    /// takes the step in `f32`, so `dt` is rounded to `f32` there).
    ///
    /// # Errors
    /// [`FluidError::BadParameter`] for a non-positive or non-finite `dt`; the solver's
    /// [`FluidError`]. The fields (the Stam scene's sources included), step count and time are
    /// then as before the step.
    pub fn step_by(&mut self, dt: f64) -> Result<StepReport, FluidError> {
        crate::error::positive("dt", dt)?;
        match &mut self.sim {
            FluidSim::Stam(f) => {
                let (dt32, before) = (dt as f32, f.params().dt);
                if dt32 != before {
                    f.set_dt(dt32)?;
                }
                if let Err(e) = f.step_with_source_pattern() {
                    // The step the fluid kept before (positive, so accepted again).
                    f.set_dt(before)?;
                    return Err(e);
                }
                Ok(StepReport::at_time(f.time()))
            }
            FluidSim::Mac(f, s) => f.step(s, dt),
        }
    }

    /// Steps taken.
    #[must_use]
    pub fn steps_taken(&self) -> u64 {
        match &self.sim {
            FluidSim::Stam(f) => f.steps(),
            FluidSim::Mac(_, s) => s.steps,
        }
    }

    /// Simulated time.
    #[must_use]
    pub fn time(&self) -> f64 {
        match &self.sim {
            FluidSim::Stam(f) => f.time(),
            FluidSim::Mac(_, s) => s.time,
        }
    }

    /// 2 or 3.
    #[must_use]
    pub fn dim(&self) -> usize {
        match &self.sim {
            FluidSim::Stam(_) => 2,
            FluidSim::Mac(f, _) => f.dim(),
        }
    }

    /// Cell size (world units; the domain's corner is at the origin).
    #[must_use]
    pub fn cell_size(&self) -> f64 {
        match &self.sim {
            FluidSim::Stam(f) => 1.0 / f.n() as f64,
            FluidSim::Mac(f, _) => f.h(),
        }
    }

    /// Interior cell counts `[nx, ny, nz]` (`nz = 1` in 2D).
    #[must_use]
    pub fn dims(&self) -> [usize; 3] {
        match &self.sim {
            FluidSim::Stam(f) => [f.n(), f.n(), 1],
            FluidSim::Mac(f, _) => f.dims(),
        }
    }

    /// Density per interior cell (x fastest, then y, then z) and the dimensions.
    #[must_use]
    pub fn density(&self) -> (Vec<f64>, [usize; 3]) {
        let mut out = Vec::new();
        self.density_into(&mut out);
        (out, self.dims())
    }

    /// [`FluidScene::density`] into `out` (resized; no allocation once it has the capacity).
    pub fn density_into(&self, out: &mut Vec<f64>) {
        out.clear();
        match &self.sim {
            FluidSim::Stam(f) => {
                let n = f.n();
                let d = f.density();
                out.extend((1..=n).flat_map(|j| (1..=n).map(move |i| f64::from(d[ix(n, i, j)]))));
            }
            FluidSim::Mac(_, s) => out.extend_from_slice(&s.density),
        }
    }

    /// Velocity at the cell centres (x fastest), 3 components (z = 0 in 2D), and the dimensions.
    #[must_use]
    pub fn velocity(&self) -> (Vec<[f64; 3]>, [usize; 3]) {
        let mut flat = Vec::new();
        self.velocity_into(&mut flat);
        (flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(), self.dims())
    }

    /// [`FluidScene::velocity`] flattened (`[u0, v0, w0, u1, ...]`) into `out` (resized; no
    /// allocation once it has the capacity).
    pub fn velocity_into(&self, out: &mut Vec<f64>) {
        out.clear();
        let dims = self.dims();
        match &self.sim {
            FluidSim::Stam(f) => {
                let n = f.n();
                let (u, v) = f.velocity();
                for j in 1..=n {
                    for i in 1..=n {
                        out.extend([f64::from(u[ix(n, i, j)]), f64::from(v[ix(n, i, j)]), 0.0]);
                    }
                }
            }
            FluidSim::Mac(f, s) => {
                for k in 0..dims[2] {
                    for j in 0..dims[1] {
                        for i in 0..dims[0] {
                            out.extend(f.velocity_at_point(s, f.cell_centre(i, j, k)));
                        }
                    }
                }
            }
        }
    }

    /// Everything the scene's simulation carries from one step to the next, for checkpoints:
    /// Stam's solver's six arrays, step count and time ([`StamFluid::memory`]), or the MAC
    /// solver's [`MacState`] (velocities, density, temperature, step count, time) and its
    /// warm-start pressure ([`MacFluid::memory`]). A scene built by the same call and given this
    /// by [`FluidScene::restore_memory`] continues bit for bit.
    #[must_use]
    pub fn memory(&self) -> serde_json::Value {
        match &self.sim {
            FluidSim::Stam(f) => serde_json::json!({ "solver": "stam", "stam": f.memory() }),
            FluidSim::Mac(f, s) => {
                serde_json::json!({ "solver": "mac", "state": s, "simulation": f.memory() })
            }
        }
    }

    /// Restores what [`FluidScene::memory`] of the same scene returned. Nothing changes on
    /// error.
    ///
    /// # Errors
    /// [`FluidError::Checkpoint`] (or [`FluidError::BadLength`] for a state array of the wrong
    /// length) naming what does not fit: the solver kind, a missing or mistyped field, the
    /// grid, an array's length or a non-finite value.
    pub fn restore_memory(&mut self, memory: &serde_json::Value) -> Result<(), FluidError> {
        let solver = memory
            .get("solver")
            .and_then(serde_json::Value::as_str)
            .ok_or_else(|| FluidError::Checkpoint("no `solver` (\"stam\" or \"mac\")".into()))?;
        let field = |key: &str| {
            memory.get(key).ok_or_else(|| FluidError::Checkpoint(format!("no `{key}` in a {solver} memory")))
        };
        match &mut self.sim {
            FluidSim::Stam(f) if solver == "stam" => f.restore_memory(field("stam")?),
            FluidSim::Mac(f, s) if solver == "mac" => {
                let state = MacState::deserialize(field("state")?)
                    .map_err(|e| FluidError::Checkpoint(format!("`state`: {e}")))?;
                f.check_state(&state)?;
                // Both checked before anything changes: `restore_memory` validates first.
                f.restore_memory(field("simulation")?)?;
                *s = state;
                Ok(())
            }
            _ => Err(FluidError::Checkpoint(format!(
                "a {solver} memory for a scene run by the {} solver",
                match self.sim {
                    FluidSim::Stam(_) => "stam",
                    FluidSim::Mac(..) => "mac",
                }
            ))),
        }
    }
}

/// Builds a scene by name (see [`NAMES`]) at `resolution` cells across (`None`: the default);
/// `None` for an unknown name.
#[must_use]
pub fn by_name(name: &str, resolution: Option<usize>) -> Option<Result<FluidScene, FluidError>> {
    let n = resolution.or_else(|| resolution_default(name))?;
    Some(match name {
        "smoke-box-2d" => smoke_box_2d(n),
        "smoke-plume-3d" => smoke_plume_3d(n),
        "lid-driven-cavity" => lid_driven_cavity(n, 100.0, Advection::MacCormack),
        _ => return None,
    })
}

/// The cells across a scene when none is given (128 for the smoke box, 32 for the plume, 64
/// for the cavity); `None` for an unknown name.
#[must_use]
pub fn resolution_default(name: &str) -> Option<usize> {
    match name {
        "smoke-box-2d" => Some(128),
        "smoke-plume-3d" => Some(32),
        "lid-driven-cavity" => Some(64),
        _ => None,
    }
}

/// Stam's smoke source in a closed `N x N` box ([`crate::stam::source_pattern`]), dt = 0.1,
/// diff = visc = 1e-4, 200 steps.
///
/// # Errors
/// [`FluidError::BadGrid`] for `n < 2`.
pub fn smoke_box_2d(n: usize) -> Result<FluidScene, FluidError> {
    let params = StamParams::default();
    Ok(FluidScene {
        name: "smoke-box-2d",
        description: "Stam's stable fluids (GDC 2003): a smoke source at the bottom of a closed box",
        sim: FluidSim::Stam(StamFluid::new(n, params)?),
        dt: f64::from(params.dt),
        duration: 20.0,
        shapes: Vec::new(),
    })
}

/// Centre of the sphere of [`smoke_plume_3d`] (grid coordinates, y up), m.
pub const PLUME_SPHERE_CENTRE: [f64; 3] = [0.5, 0.45, 0.5];
/// Radius of the sphere of [`smoke_plume_3d`], m.
pub const PLUME_SPHERE_RADIUS: f64 = 0.15;

/// Hot smoke rising around a sphere: an `n x 3n/2 x n` box of height 1.5, open at the top,
/// a vent (density 1, temperature 1, upward velocity 0.5) at the bottom centre, a sphere of
/// radius 0.15 above it ([`PLUME_SPHERE_CENTRE`], [`PLUME_SPHERE_RADIUS`]); buoyancy
/// `alpha = 0.05`, `beta = 1`, vorticity confinement 2; MacCormack, MGPCG (tolerance 1e-5),
/// dt = 1.5 h (CFL about 1 at the plume's speed).
///
/// # Errors
/// [`FluidError::BadGrid`] for `n < 2`.
pub fn smoke_plume_3d(n: usize) -> Result<FluidScene, FluidError> {
    let h = 1.0 / n.max(1) as f64;
    let ny = (3 * n).div_ceil(2);
    let mut walls = [[Wall::NoSlip([0.0; 3]); 2]; 3];
    walls[1][1] = Wall::Open;
    let params = MacParams {
        advection: Advection::MacCormack,
        pressure: PressureMethod::Mgpcg,
        pressure_tolerance: 1e-5,
        buoyancy_density: 0.05,
        buoyancy_temperature: 1.0,
        vorticity_confinement: 2.0,
        walls,
        sources: vec![Source {
            min: [0.4, 0.0, 0.4],
            max: [0.6, 0.1, 0.6],
            density: 1.0,
            temperature: 1.0,
            velocity: Some([0.0, 0.5, 0.0]),
        }],
        ..MacParams::default()
    };
    let (mut fluid, state) = MacFluid::new([n, ny, n], 3, h, params)?;
    let ([cx, cy, cz], r) = (PLUME_SPHERE_CENTRE, PLUME_SPHERE_RADIUS);
    fluid.set_solid(|p| (p[0] - cx).powi(2) + (p[1] - cy).powi(2) + (p[2] - cz).powi(2) < r * r)?;
    Ok(FluidScene {
        name: "smoke-plume-3d",
        description: "hot smoke rising from a vent around a sphere, open top",
        sim: FluidSim::Mac(fluid, state),
        dt: 1.5 * h,
        duration: 3.0,
        shapes: Vec::new(),
    })
}

/// The lid-driven cavity: unit square, `n x n` cells, the top wall moving at `u = 1`, viscosity
/// `1 / re`, implicit viscosity, MGPCG (tolerance 1e-8), dt = h (CFL 1 at the lid), run to
/// t = 20 (steady at Re = 100). The density is a passive dye (no buoyancy) in eight
/// horizontal bands, 1 and 0 alternating, that shows the flow in pictures and leaves the
/// velocity untouched.
///
/// # Errors
/// [`FluidError::BadGrid`] for `n < 2`, [`FluidError::BadParameter`] for `re <= 0`.
pub fn lid_driven_cavity(n: usize, re: f64, advection: Advection) -> Result<FluidScene, FluidError> {
    crate::error::positive("re", re)?;
    let h = 1.0 / n.max(1) as f64;
    let mut walls = [[Wall::NoSlip([0.0; 3]); 2]; 3];
    walls[1][1] = Wall::NoSlip([1.0, 0.0, 0.0]);
    let params = MacParams {
        viscosity: 1.0 / re,
        advection,
        pressure: PressureMethod::Mgpcg,
        pressure_tolerance: 1e-8,
        walls,
        ..MacParams::default()
    };
    let (fluid, mut state) = MacFluid::new([n, n, 1], 2, h, params)?;
    for (c, d) in state.density.iter_mut().enumerate() {
        let j = c / n;
        *d = if (8 * j / n).is_multiple_of(2) { 1.0 } else { 0.0 };
    }
    Ok(FluidScene {
        name: "lid-driven-cavity",
        description: "lid-driven cavity, Re = 100",
        sim: FluidSim::Mac(fluid, state),
        dt: h,
        duration: 20.0,
        shapes: Vec::new(),
    })
}

/// Measured and analytic amplitude of a decayed Taylor-Green vortex, and the steps taken.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TaylorGreenDecay {
    /// Amplitude of the initial mode in the final `u` (least-squares projection on the mode).
    pub amplitude: f64,
    /// The analytic amplitude `exp(-2 nu pi^2 t_end)`.
    pub exact: f64,
    /// Steps taken (`dt = t_end / steps`, the largest step with `dt <= cfl h`).
    pub steps: usize,
}

/// Runs the Taylor-Green vortex `u = sin(pi x) cos(pi y)`, `v = -cos(pi x) sin(pi y)` on an
/// `n x n` MAC grid of the unit square with free-slip walls, viscosity `nu`, the given advection
/// and splitting and the pressure solved to 1e-10, for `t_end` at the CFL number `cfl` (of the unit velocity
/// scale), and measures the mode's decay.
///
/// # Errors
/// The grid and parameter errors of [`MacFluid::new`] and the step errors of the solver.
pub fn taylor_green_decay(
    n: usize,
    advection: Advection,
    splitting: Splitting,
    nu: f64,
    t_end: f64,
    cfl: f64,
) -> Result<TaylorGreenDecay, FluidError> {
    use std::f64::consts::PI;
    let params = MacParams {
        viscosity: nu,
        advection,
        splitting,
        pressure_tolerance: 1e-10,
        walls: [[Wall::FreeSlip; 2]; 3],
        ..MacParams::default()
    };
    let h = 1.0 / n as f64;
    let (mut fluid, mut state) = MacFluid::new([n, n, 1], 2, h, params)?;
    let mode =
        |p: [f64; 3]| [(PI * p[0]).sin() * (PI * p[1]).cos(), -(PI * p[0]).cos() * (PI * p[1]).sin(), 0.0];
    fluid.set_velocity(&mut state, mode);
    let steps = (t_end / (cfl * h)).ceil() as usize;
    let dt = t_end / steps as f64;
    for _ in 0..steps {
        fluid.advance(&mut state, dt)?;
    }
    let d = fluid.face_dims(0);
    let (mut num, mut den) = (0.0, 0.0);
    for j in 0..d[1] {
        for i in 0..d[0] {
            let m = mode(fluid.face_centre(0, i, j, 0))[0];
            num += m * state.vel[0][i + d[0] * j];
            den += m * m;
        }
    }
    Ok(TaylorGreenDecay { amplitude: num / den, exact: (-2.0 * nu * PI * PI * t_end).exp(), steps })
}

#[cfg(test)]
mod reference_runs;
#[cfg(test)]
mod tests;
