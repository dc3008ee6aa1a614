//! Ready-to-run scenes for the command line, examples and benchmarks.
//!
//! | scene | what | solver | why |
//! | --- | --- | --- | --- |
//! | [`smoke_box_2d`] | the seed's interactive-style demo: a smoke source at the bottom of a closed box pushes density up, its sideways force flipping every 25 steps | [`seed`](crate::seed) mode, `f32`, 20 Gauss-Seidel sweeps | the seed's routines exactly, as Stam's demo runs them |
//! | [`smoke_plume_3d`] | hot smoke rises from a vent around a sphere into an open-topped box | MAC 3D, MacCormack, MGPCG, buoyancy + vorticity confinement | the 3D solver with an obstacle, inflow and an open boundary |
//! | [`lid_driven_cavity`] | the unit square, top wall sliding at 1, Re = 100 | MAC 2D, MacCormack, MGPCG, implicit viscosity | the classic steady benchmark (Ghia, Ghia and Shin 1982) |
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

use crate::advection::Advection;
use crate::error::FluidError;
use crate::mac::{MacFluid, MacParams, MacState, Source, Wall};
use crate::pressure::PressureMethod;
use crate::seed::{SeedFluid, SeedParams, ix};
use anim_core::solver::{Solver, StepReport};

/// The built-in scene names.
pub const NAMES: [&str; 3] = ["smoke-box-2d", "smoke-plume-3d", "lid-driven-cavity"];

/// The simulation behind a scene.
#[derive(Debug, Clone)]
#[allow(clippy::large_enum_variant)]
pub enum FluidSim {
    /// The seed's solver with its source pattern.
    Seed(SeedFluid),
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
}

impl FluidScene {
    /// Number of steps of `dt` covering `duration`.
    #[must_use]
    pub fn steps(&self) -> usize {
        (self.duration / self.dt).round().max(1.0) as usize
    }

    /// Advances one step of `dt` (the seed scene first applies its source pattern).
    ///
    /// # Errors
    /// The solver's [`FluidError`].
    pub fn step(&mut self) -> Result<StepReport, FluidError> {
        match &mut self.sim {
            FluidSim::Seed(f) => {
                f.apply_source_pattern();
                f.step()?;
                Ok(StepReport::at_time(f.steps() as f64 * f64::from(f.params().dt)))
            }
            FluidSim::Mac(f, s) => f.step(s, self.dt),
        }
    }

    /// Interior cell counts `[nx, ny, nz]` (`nz = 1` in 2D).
    #[must_use]
    pub fn dims(&self) -> [usize; 3] {
        match &self.sim {
            FluidSim::Seed(f) => [f.n(), f.n(), 1],
            FluidSim::Mac(f, _) => f.dims(),
        }
    }

    /// Density per interior cell (x fastest, then y, then z) and the dimensions.
    #[must_use]
    pub fn density(&self) -> (Vec<f64>, [usize; 3]) {
        let dims = self.dims();
        match &self.sim {
            FluidSim::Seed(f) => {
                let n = f.n();
                let d = f.density();
                let v = (1..=n).flat_map(|j| (1..=n).map(move |i| f64::from(d[ix(n, i, j)]))).collect();
                (v, dims)
            }
            FluidSim::Mac(_, s) => (s.density.clone(), dims),
        }
    }

    /// Velocity at the cell centres (x fastest), 3 components (z = 0 in 2D), and the dimensions.
    #[must_use]
    pub fn velocity(&self) -> (Vec<[f64; 3]>, [usize; 3]) {
        let dims = self.dims();
        match &self.sim {
            FluidSim::Seed(f) => {
                let n = f.n();
                let (u, v) = f.velocity();
                let out = (1..=n)
                    .flat_map(|j| {
                        (1..=n).map(move |i| [f64::from(u[ix(n, i, j)]), f64::from(v[ix(n, i, j)]), 0.0])
                    })
                    .collect();
                (out, dims)
            }
            FluidSim::Mac(f, s) => {
                let mut out = Vec::with_capacity(dims[0] * dims[1] * dims[2]);
                for k in 0..dims[2] {
                    for j in 0..dims[1] {
                        for i in 0..dims[0] {
                            out.push(f.velocity_at_point(s, f.cell_centre(i, j, k)));
                        }
                    }
                }
                (out, dims)
            }
        }
    }
}

/// Builds a scene by name (see [`NAMES`]) at `resolution` cells across (`None`: the default);
/// `None` for an unknown name.
#[must_use]
pub fn by_name(name: &str, resolution: Option<usize>) -> Option<Result<FluidScene, FluidError>> {
    Some(match name {
        "smoke-box-2d" => smoke_box_2d(resolution.unwrap_or(128)),
        "smoke-plume-3d" => smoke_plume_3d(resolution.unwrap_or(32)),
        "lid-driven-cavity" => lid_driven_cavity(resolution.unwrap_or(64), 100.0, Advection::MacCormack),
        _ => return None,
    })
}

/// The seed's smoke source in a closed `N x N` box ([`crate::seed::source_pattern`]), dt = 0.1,
/// diff = visc = 1e-4, 200 steps.
///
/// # Errors
/// [`FluidError::BadGrid`] for `n < 2`.
pub fn smoke_box_2d(n: usize) -> Result<FluidScene, FluidError> {
    let params = SeedParams::default();
    Ok(FluidScene {
        name: "smoke-box-2d",
        description: "the seed's stable fluids: a smoke source at the bottom of a closed box",
        sim: FluidSim::Seed(SeedFluid::new(n, params)?),
        dt: f64::from(params.dt),
        duration: 20.0,
    })
}

/// Hot smoke rising around a sphere: an `n x 3n/2 x n` box of height 1.5, open at the top,
/// a vent (density 1, temperature 1, upward velocity 0.5) at the bottom centre, a sphere of
/// radius 0.15 above it; buoyancy `alpha = 0.05`, `beta = 1`, vorticity confinement 2;
/// MacCormack, MGPCG (tolerance 1e-5), dt = 1.5 h (CFL about 1 at the plume's speed).
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
    fluid.set_solid(|p| (p[0] - 0.5).powi(2) + (p[1] - 0.45).powi(2) + (p[2] - 0.5).powi(2) < 0.15 * 0.15)?;
    Ok(FluidScene {
        name: "smoke-plume-3d",
        description: "hot smoke rising from a vent around a sphere, open top",
        sim: FluidSim::Mac(fluid, state),
        dt: 1.5 * h,
        duration: 3.0,
    })
}

/// The lid-driven cavity: unit square, `n x n` cells, the top wall moving at `u = 1`, viscosity
/// `1 / re`, implicit viscosity, MGPCG (tolerance 1e-8), dt = h (CFL 1 at the lid), run to
/// t = 20 (steady at Re = 100).
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
    let (fluid, state) = MacFluid::new([n, n, 1], 2, h, params)?;
    Ok(FluidScene {
        name: "lid-driven-cavity",
        description: "lid-driven cavity, Re = 100",
        sim: FluidSim::Mac(fluid, state),
        dt: h,
        duration: 20.0,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_scene_builds_and_steps() {
        for name in NAMES {
            let mut scene = by_name(name, Some(8)).unwrap().unwrap();
            scene.step().unwrap();
            let (d, dims) = scene.density();
            assert_eq!(d.len(), dims.iter().product::<usize>());
            assert_eq!(scene.velocity().0.len(), d.len());
        }
        assert!(by_name("nope", None).is_none());
        assert!(matches!(smoke_box_2d(1), Err(FluidError::BadGrid { .. })));
    }

    #[test]
    fn plume_rises() {
        let mut scene = smoke_plume_3d(10).unwrap();
        for _ in 0..10 {
            scene.step().unwrap();
        }
        let FluidSim::Mac(_, state) = &scene.sim else { panic!("a MAC scene") };
        // Upward flow leaves the vent and smoke has entered the box.
        assert!(state.vel[1].iter().fold(0.0f64, |m, &x| m.max(x)) > 0.1);
        assert!(state.density.iter().sum::<f64>() > 1.0);
    }
}
