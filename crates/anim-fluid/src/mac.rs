//! The MAC-grid solver: incompressible Navier-Stokes with smoke, 2D and 3D in one code base.
//!
//! The stable-fluids splitting (Stam 1999) `w0 -(force)-> w1 -(advect)-> w2 -(diffuse)-> w3 -(project)-> w4`
//! on a staggered (MAC, Harlow and Welch 1965) grid: `u` on the x faces, `v` on the y faces, `w`
//! on the z faces, density `rho` and temperature `T` at cell centres, cell size `h`. One step:
//!
//! 1. **forces**: buoyancy `f = (-alpha rho + beta (T - T_amb)) e_y` (Fedkiw, Stam and Jensen
//!    2001) and **vorticity confinement** `f = eps h (N x omega)`, `N = grad|omega| / |grad|omega||`;
//!    then the **sources** (inflow boxes) set density, temperature and velocity inside them;
//! 2. **advection** of velocity and scalars by the velocity at the start of the step, with one
//!    of the [`Advection`] schemes;
//! 3. **viscosity** (when `nu > 0`): backward Euler `(I - nu dt Lap) u = u*` per component,
//!    solved by Jacobi-preconditioned conjugate gradients, no-slip walls through ghost values
//!    `u_ghost = 2 u_wall - u`;
//! 4. **projection** with a [`PressureSolver`] (Jacobi, red-black
//!    Gauss-Seidel, CG or MGPCG) over cells labelled fluid, solid (obstacles) or air (open
//!    sides), after which the discrete divergence of every fluid cell is within the solver's
//!    tolerance.
//!
//! With [`Splitting::Reflection`] (Zehnder, Narain and Thomaszewski 2018) each half step of
//! `dt/2` applies half the forces, advects, diffuses and projects; the second half advects the
//! reflection `2 u' - u~` of the first half's advected velocity `u~` about its projection `u'`,
//! and the scalars are advected once over `dt` by `u'`.
//!
//! Walls ([`Wall`]) are no-slip (with a velocity: a moving lid), free-slip or open (`p = 0`,
//! zero-gradient velocity); obstacles are solid cells ([`MacFluid::set_solid`],
//! [`MacFluid::set_solid_cells`]); inflow is a [`Source`] box or a [`RegionSource`] of any
//! shape ([`MacFluid::add_region_source`]). Everything is `f64`: the accuracy cases (Taylor-Green decay, Ghia's cavity)
//! and the tight pressure tolerances of the work-precision study need it.
//!
//! 2D grids have `nz = 1` and no `w`; every loop is written once for both, the z terms guarded
//! by the dimension. Each stage is parallel over grid lines with rayon and reads only the
//! previous stage's arrays, so results are bitwise identical for any thread count; every
//! buffer is allocated by [`MacFluid::new`].
//!
//! This module holds the solver, its settings and state, and the step sequence. Each stage is a
//! module of its own that works on the grid and the fields it is handed, and knows nothing of
//! the solver: the grid's layout and walls (`mac/grid.rs`, [`Wall`]), advection
//! (`mac/advect.rs`), forces and sources (`mac/forces.rs`, [`Source`]), the viscosity solve
//! (`mac/viscosity.rs`) and the projection (`mac/projection.rs`).

mod advect;
mod forces;
mod grid;
mod projection;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod timing;
mod viscosity;

pub use forces::{RegionSource, Source};
pub use grid::Wall;

use crate::advection::{Advection, Lattice, Splitting};
use crate::error::{self, FluidError};
use crate::pressure::{CellLabel, Poisson, PressureMethod, PressureSolver, SolveInfo};
use advect::Transport;
use anim_core::solver::{Solver, StepReport};
use forces::Confinement;
use grid::{MacGrid, idx};
use projection::Projection;
use rayon::prelude::*;
use viscosity::ImplicitViscosity;

/// Settings of [`MacFluid`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MacParams {
    /// Kinematic viscosity `nu`. Default 0 (inviscid; no viscosity solve).
    pub viscosity: f64,
    /// Advection scheme. Default [`Advection::MacCormack`].
    pub advection: Advection,
    /// How a step splits advection from projection. Default [`Splitting::AdvectProject`] (Stam's
    /// order); [`Splitting::Reflection`] is second order in `dt` for two projections.
    pub splitting: Splitting,
    /// Pressure solver. Default [`PressureMethod::Mgpcg`].
    pub pressure: PressureMethod,
    /// Relative residual tolerance of the pressure solve. Default 1e-6.
    pub pressure_tolerance: f64,
    /// Iteration cap of the pressure solve. Default 1000.
    pub pressure_max_iterations: usize,
    /// Whether a pressure solve that misses its tolerance is an error. Default true.
    pub require_convergence: bool,
    /// Buoyancy weight of density `alpha`. Default 0.
    pub buoyancy_density: f64,
    /// Buoyancy weight of temperature `beta`. Default 0.
    pub buoyancy_temperature: f64,
    /// Ambient temperature. Default 0.
    pub ambient_temperature: f64,
    /// Vorticity confinement strength `eps`. Default 0.
    pub vorticity_confinement: f64,
    /// Walls: `walls[axis][0]` at the low side, `[1]` at the high side. Default no-slip at rest.
    pub walls: [[Wall; 2]; 3],
    /// Inflow boxes. Default none.
    pub sources: Vec<Source>,
}

impl Default for MacParams {
    fn default() -> Self {
        Self {
            viscosity: 0.0,
            advection: Advection::MacCormack,
            splitting: Splitting::AdvectProject,
            pressure: PressureMethod::Mgpcg,
            pressure_tolerance: 1e-6,
            pressure_max_iterations: 1000,
            require_convergence: true,
            buoyancy_density: 0.0,
            buoyancy_temperature: 0.0,
            ambient_temperature: 0.0,
            vorticity_confinement: 0.0,
            walls: [[Wall::NoSlip([0.0; 3]); 2]; 3],
            sources: Vec::new(),
        }
    }
}

/// The integrated state: face velocities and cell scalars.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MacState {
    /// Velocity components on their faces: `vel[a]` has `dims` with `dims[a] + 1` (empty `w` in
    /// 2D), x fastest.
    pub vel: [Vec<f64>; 3],
    /// Density per cell.
    pub density: Vec<f64>,
    /// Temperature per cell.
    pub temperature: Vec<f64>,
    /// Simulated time.
    pub time: f64,
    /// Steps taken.
    pub steps: u64,
}

/// Per-step extras beyond [`StepReport`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MacStepInfo {
    /// The pressure solve.
    pub pressure: SolveInfo,
    /// CG iterations of the viscosity solves (all components).
    pub viscosity_iterations: usize,
    /// `max |div u|` over fluid cells after projection (1/s).
    pub divergence: f64,
}

/// The MAC-grid solver: grid, settings, obstacle labels, pressure solver and scratch.
#[derive(Debug, Clone)]
pub struct MacFluid {
    /// Cell extents and size, walls and obstacle cells.
    grid: MacGrid,
    params: MacParams,
    /// The pressure solver and the warm-start pressure.
    projection: Projection,
    // the stages' scratch
    transport: Transport,
    confinement: Confinement,
    viscosity: ImplicitViscosity,
    /// The advected, unprojected velocity of the first half step (advection-reflection only;
    /// empty otherwise).
    reflect: [Vec<f64>; 3],
    backup: MacState,
    /// The warm-start pressure before the current step, restored when the step fails.
    pressure_backup: Vec<f64>,
    last: MacStepInfo,
    /// Sources of any shape, applied after the boxes of the settings.
    regions: Vec<forces::CoveredRegion>,
}

impl MacFluid {
    /// A fluid of `dims` cells (`nz = 1` for `dim = 2`) of size `h`, at rest.
    ///
    /// # Errors
    /// [`FluidError::BadGrid`] for an extent below 2 (or `nz != 1` in 2D, `dim` not 2 or 3),
    /// [`FluidError::BadParameter`] for non-positive `h`, negative viscosity, a bad tolerance,
    /// non-finite forces, or a moving no-slip wall with a normal velocity.
    pub fn new(
        dims: [usize; 3],
        dim: usize,
        h: f64,
        params: MacParams,
    ) -> Result<(Self, MacState), FluidError> {
        if dim != 2 && dim != 3 {
            return Err(FluidError::BadParameter {
                name: "dim",
                requirement: "must be 2 or 3",
                value: dim.to_string(),
            });
        }
        for (a, what) in ["nx", "ny", "nz"].into_iter().enumerate().take(dim) {
            if dims[a] < 2 {
                return Err(FluidError::BadGrid { what, min: 2, got: dims[a] });
            }
        }
        if dim == 2 && dims[2] != 1 {
            return Err(FluidError::BadGrid { what: "nz (must be 1 in 2D)", min: 1, got: dims[2] });
        }
        error::positive("h", h)?;
        Self::validate(&params)?;
        let cells = dims[0] * dims[1] * dims[2];
        let grid = MacGrid { dims, dim, h, walls: params.walls, solid: vec![false; cells] };
        let solver = projection::pressure_solver(
            &grid,
            vec![CellLabel::Fluid; cells],
            params.pressure,
            params.pressure_tolerance,
            params.pressure_max_iterations,
        )?;
        let state = MacState {
            vel: std::array::from_fn(|a| vec![0.0; grid.face_len(a)]),
            density: vec![0.0; cells],
            temperature: vec![params.ambient_temperature; cells],
            time: 0.0,
            steps: 0,
        };
        let mut fluid = Self {
            projection: Projection::new(&grid, solver),
            transport: Transport::new(&grid),
            confinement: Confinement::new(cells),
            viscosity: ImplicitViscosity::new(&grid),
            reflect: Default::default(),
            backup: state.clone(),
            pressure_backup: vec![0.0; cells],
            last: MacStepInfo::default(),
            regions: Vec::new(),
            grid,
            params,
        };
        fluid.size_reflect_buffer();
        Ok((fluid, state))
    }

    fn validate(p: &MacParams) -> Result<(), FluidError> {
        error::non_negative("viscosity", p.viscosity)?;
        error::positive("pressure_tolerance", p.pressure_tolerance)?;
        error::finite("buoyancy_density", p.buoyancy_density)?;
        error::finite("buoyancy_temperature", p.buoyancy_temperature)?;
        error::finite("ambient_temperature", p.ambient_temperature)?;
        error::non_negative("vorticity_confinement", p.vorticity_confinement)?;
        if p.pressure_max_iterations == 0 {
            return Err(FluidError::BadParameter {
                name: "pressure_max_iterations",
                requirement: "must be at least 1",
                value: "0".into(),
            });
        }
        for (a, sides) in p.walls.iter().enumerate() {
            for wall in sides {
                if let Wall::NoSlip(v) = wall
                    && (v.iter().any(|x| !x.is_finite()) || v[a] != 0.0)
                {
                    return Err(FluidError::BadParameter {
                        name: "walls",
                        requirement: "no-slip wall velocity must be finite and tangential",
                        value: format!("{v:?} on axis {a}"),
                    });
                }
            }
        }
        for s in &p.sources {
            let scalars = [s.density, s.temperature];
            if s.min.iter().chain(&s.max).chain(&scalars).any(|x| !x.is_finite())
                || s.velocity.is_some_and(|v| v.iter().any(|x| !x.is_finite()))
            {
                return Err(FluidError::BadParameter {
                    name: "sources",
                    requirement: "must be finite",
                    value: format!("{s:?}"),
                });
            }
        }
        Ok(())
    }

    /// Cell extents.
    #[must_use]
    pub fn dims(&self) -> [usize; 3] {
        self.grid.dims
    }

    /// 2 or 3.
    #[must_use]
    pub fn dim(&self) -> usize {
        self.grid.dim
    }

    /// Cell size.
    #[must_use]
    pub fn h(&self) -> f64 {
        self.grid.h
    }

    /// The settings.
    #[must_use]
    pub fn params(&self) -> &MacParams {
        &self.params
    }

    /// The last step's solver details.
    #[must_use]
    pub fn last_step(&self) -> MacStepInfo {
        self.last
    }

    /// Lattice extents of velocity component `a`.
    #[must_use]
    pub fn face_dims(&self, a: usize) -> [usize; 3] {
        self.grid.face_dims(a)
    }

    /// Changes the pressure method and tolerance (rebuilds the solver's buffers).
    ///
    /// # Errors
    /// [`FluidError::BadParameter`] for a bad tolerance or iteration cap.
    pub fn set_pressure(
        &mut self,
        method: PressureMethod,
        tolerance: f64,
        max_iterations: usize,
    ) -> Result<(), FluidError> {
        error::positive("pressure_tolerance", tolerance)?;
        let op = self.projection.operator().clone();
        self.projection.set_solver(PressureSolver::new(op, method, tolerance, max_iterations)?);
        self.params.pressure = method;
        self.params.pressure_tolerance = tolerance;
        self.params.pressure_max_iterations = max_iterations;
        Ok(())
    }

    /// Changes the advection scheme.
    pub fn set_advection(&mut self, advection: Advection) {
        self.params.advection = advection;
    }

    /// Changes how a step splits advection from projection (allocates the reflection's buffer
    /// the first time [`Splitting::Reflection`] is chosen).
    pub fn set_splitting(&mut self, splitting: Splitting) {
        self.params.splitting = splitting;
        self.size_reflect_buffer();
    }

    fn size_reflect_buffer(&mut self) {
        if self.params.splitting == Splitting::Reflection && self.reflect[0].is_empty() {
            self.reflect = std::array::from_fn(|a| vec![0.0; self.grid.face_len(a)]);
        }
    }

    /// Marks the cells whose centres `inside(x, y, z)` holds as solid obstacles, and rebuilds the
    /// pressure operator.
    ///
    /// # Errors
    /// Only if the pressure operator cannot be rebuilt (never for a valid fluid).
    pub fn set_solid(&mut self, inside: impl Fn([f64; 3]) -> bool) -> Result<(), FluidError> {
        let [nx, ny, nz] = self.grid.dims;
        let solid: Vec<bool> = (0..nz)
            .flat_map(|k| (0..ny).flat_map(move |j| (0..nx).map(move |i| (i, j, k))))
            .map(|(i, j, k)| inside(self.grid.cell_centre(i, j, k)))
            .collect();
        self.set_solid_cells(&solid)
    }

    /// Marks the cells whose entry of `solid` (one per cell, x fastest) is true as solid
    /// obstacles, the others as fluid, and rebuilds the pressure operator.
    ///
    /// # Errors
    /// [`FluidError::BadLength`] when `solid` does not have one entry per cell; otherwise only if
    /// the pressure operator cannot be rebuilt (never for a valid fluid).
    pub fn set_solid_cells(&mut self, solid: &[bool]) -> Result<(), FluidError> {
        let cells = self.grid.solid.len();
        if solid.len() != cells {
            return Err(FluidError::BadLength { name: "solid", got: solid.len(), expected: cells });
        }
        let labels = solid.iter().map(|&s| if s { CellLabel::Solid } else { CellLabel::Fluid }).collect();
        let solver = projection::pressure_solver(
            &self.grid,
            labels,
            self.params.pressure,
            self.params.pressure_tolerance,
            self.params.pressure_max_iterations,
        )?;
        self.grid.solid.copy_from_slice(solid);
        self.projection.set_solver(solver);
        Ok(())
    }

    /// Whether each cell is a solid obstacle (x fastest).
    #[must_use]
    pub fn solid(&self) -> &[bool] {
        &self.grid.solid
    }

    /// Adds a source of any shape, applied every step after the boxes of the settings and the
    /// region sources added before it.
    ///
    /// # Errors
    /// [`FluidError::BadLength`] for a mask without one entry per cell or per face of its
    /// component (none for `w` in 2D), [`FluidError::BadParameter`] for a non-finite density,
    /// temperature or velocity.
    pub fn add_region_source(&mut self, source: RegionSource) -> Result<(), FluidError> {
        source.check(&self.grid)?;
        self.regions.push(forces::CoveredRegion::of(&source));
        Ok(())
    }

    /// World position of the centre of cell `(i, j, k)` (z = 0 in 2D).
    #[must_use]
    pub fn cell_centre(&self, i: usize, j: usize, k: usize) -> [f64; 3] {
        self.grid.cell_centre(i, j, k)
    }

    /// World position of face `(i, j, k)` of component `a`.
    #[must_use]
    pub fn face_centre(&self, a: usize, i: usize, j: usize, k: usize) -> [f64; 3] {
        self.grid.face_centre(a, i, j, k)
    }

    /// Sets every face velocity from `f(position) -> velocity` (component `a` at face `a`).
    pub fn set_velocity(&self, state: &mut MacState, f: impl Fn([f64; 3]) -> [f64; 3]) {
        for a in 0..self.grid.dim {
            let d = self.grid.face_dims(a);
            for k in 0..d[2] {
                for j in 0..d[1] {
                    for i in 0..d[0] {
                        state.vel[a][idx(d, i, j, k)] = f(self.grid.face_centre(a, i, j, k))[a];
                    }
                }
            }
        }
        self.grid.enforce_walls(&mut state.vel);
    }

    /// Velocity of `state` at world position `p` (linear interpolation of each component; no-slip
    /// walls blend the tangential components toward the wall velocity in the last half cell).
    #[must_use]
    pub fn velocity_at_point(&self, state: &MacState, p: [f64; 3]) -> [f64; 3] {
        let mut out = [0.0; 3];
        for a in 0..self.grid.dim {
            let lat = Lattice { values: &state.vel[a], dims: self.grid.face_dims(a), dim: self.grid.dim };
            let g = self.grid.lattice_coords(a, p);
            out[a] = lat.wall_blend(g, lat.linear(g).0, &self.grid.wall_values(a));
        }
        out
    }

    /// The pressure operator (cell labels of the walls' and obstacles' layout).
    #[must_use]
    pub fn pressure_operator(&self) -> &Poisson {
        self.projection.operator()
    }

    /// Net outflow `h div u` of every cell of `state` (0 in solids), the negated right-hand side
    /// of the pressure solve. `out` has one entry per cell.
    ///
    /// # Panics
    /// If `out` does not have one entry per cell.
    #[track_caller]
    pub fn net_outflow(&self, state: &MacState, out: &mut [f64]) {
        assert_eq!(out.len(), self.grid.solid.len(), "net_outflow: one entry per cell");
        projection::outflow(&self.grid, &state.vel, out);
    }

    /// `max |div u|` over fluid cells, 1/s.
    #[must_use]
    pub fn max_divergence(&self, state: &MacState) -> f64 {
        let mut out = vec![0.0; self.grid.solid.len()];
        projection::outflow(&self.grid, &state.vel, &mut out);
        out.iter().fold(0.0f64, |m, x| m.max(x.abs())) / self.grid.h
    }

    /// The first non-finite value of `state` (fields in the order u, v, w, density,
    /// temperature), reported with the value `before` held there.
    fn check_finite(&self, state: &MacState, before: &MacState, step: u64) -> Result<(), FluidError> {
        // (name, values after the step, values before it, lattice extents)
        type Field<'a> = (&'static str, &'a [f64], &'a [f64], [usize; 3]);
        let fields: [Field<'_>; 5] = [
            ("u", &state.vel[0], &before.vel[0], self.grid.face_dims(0)),
            ("v", &state.vel[1], &before.vel[1], self.grid.face_dims(1)),
            ("w", &state.vel[2], &before.vel[2], self.grid.face_dims(2)),
            ("density", &state.density, &before.density, self.grid.dims),
            ("temperature", &state.temperature, &before.temperature, self.grid.dims),
        ];
        for (field, values, old, d) in fields {
            if values.par_iter().with_min_len(crate::grain::ENTRIES).any(|x| !x.is_finite()) {
                let at = values.iter().position(|x| !x.is_finite()).unwrap_or(0);
                let last = old.get(at).copied().filter(|x| x.is_finite());
                return Err(FluidError::NonFinite {
                    step,
                    field,
                    i: at % d[0].max(1),
                    j: (at / d[0].max(1)) % d[1].max(1),
                    k: at / (d[0] * d[1]).max(1),
                    value: values[at],
                    last_finite: last,
                });
            }
        }
        Ok(())
    }

    /// Advances `state` by `dt`; on error `state` and the warm-start pressure are exactly as
    /// before the step (both are copied aside first, into buffers sized by [`MacFluid::new`]).
    ///
    /// # Errors
    /// [`FluidError::BadParameter`] for a non-positive or non-finite `dt`,
    /// [`FluidError::NonFinite`] naming the field, the cell (or face), the value and the value
    /// there before the step, [`FluidError::NotConverged`] when a solve misses its tolerance
    /// and `require_convergence` is set.
    ///
    /// # Panics
    /// If `state` does not have this fluid's array lengths (a state of another fluid; see
    /// [`MacFluid::check_state`]).
    #[track_caller]
    pub fn advance(&mut self, state: &mut MacState, dt: f64) -> Result<MacStepInfo, FluidError> {
        error::positive("dt", dt)?;
        let step = state.steps;
        let mut backup = std::mem::take(&mut self.backup);
        copy_state(state, &mut backup);
        self.pressure_backup.copy_from_slice(&self.projection.pressure);
        let result = self.advance_in_place(state, &backup, dt, step);
        if result.is_err() {
            copy_state(&backup, state);
            self.projection.pressure.copy_from_slice(&self.pressure_backup);
        }
        self.backup = backup;
        let info = result?;
        self.last = info;
        Ok(info)
    }

    /// Checks that `state` fits this fluid: array lengths, finite values, finite time.
    ///
    /// # Errors
    /// [`FluidError::BadLength`] naming the array, [`FluidError::Checkpoint`] naming the array
    /// and index of a non-finite value or a non-finite time.
    pub fn check_state(&self, state: &MacState) -> Result<(), FluidError> {
        let cells = self.grid.solid.len();
        let fields: [(&'static str, &[f64], usize); 5] = [
            ("u", &state.vel[0], self.grid.face_dims(0).iter().product()),
            ("v", &state.vel[1], self.grid.face_dims(1).iter().product()),
            ("w", &state.vel[2], self.grid.face_dims(2).iter().product()),
            ("density", &state.density, cells),
            ("temperature", &state.temperature, cells),
        ];
        for (name, values, expected) in fields {
            if values.len() != expected {
                return Err(FluidError::BadLength { name, got: values.len(), expected });
            }
            if let Some(at) = values.iter().position(|x| !x.is_finite()) {
                return Err(FluidError::Checkpoint(format!("`{name}`[{at}] is {}", values[at])));
            }
        }
        if !(state.time.is_finite() && state.time >= 0.0) {
            return Err(FluidError::Checkpoint(format!(
                "time {} is not finite and non-negative",
                state.time
            )));
        }
        Ok(())
    }

    /// What the solver itself carries from one step to the next: the pressure of the last
    /// projection, the next solve's starting guess. With the [`MacState`], it continues a run bit
    /// for bit ([`MacFluid::restore_memory`]).
    #[must_use]
    pub fn memory(&self) -> serde_json::Value {
        serde_json::json!({ "dims": self.grid.dims, "pressure": self.projection.pressure })
    }

    /// Restores what [`MacFluid::memory`] of a fluid of the same grid returned. Nothing changes
    /// on error.
    ///
    /// # Errors
    /// [`FluidError::Checkpoint`] when a field is missing or mistyped, the grid differs, the
    /// pressure has the wrong length or a non-finite value.
    pub fn restore_memory(&mut self, memory: &serde_json::Value) -> Result<(), FluidError> {
        let dims: [usize; 3] = memory
            .get("dims")
            .and_then(|d| serde_json::from_value(d.clone()).ok())
            .ok_or_else(|| FluidError::Checkpoint("no grid `dims` (three cell counts)".into()))?;
        if dims != self.grid.dims {
            return Err(FluidError::Checkpoint(format!(
                "the checkpoint is of a {dims:?} grid, this fluid is {:?}",
                self.grid.dims
            )));
        }
        let pressure: Vec<f64> = memory
            .get("pressure")
            .and_then(|d| serde_json::from_value(d.clone()).ok())
            .ok_or_else(|| FluidError::Checkpoint("no `pressure` (an array of numbers)".into()))?;
        if pressure.len() != self.projection.pressure.len() {
            return Err(FluidError::Checkpoint(format!(
                "`pressure` has {} values, the grid has {} cells",
                pressure.len(),
                self.projection.pressure.len()
            )));
        }
        if let Some(at) = pressure.iter().position(|x| !x.is_finite()) {
            return Err(FluidError::Checkpoint(format!("`pressure`[{at}] is {}", pressure[at])));
        }
        self.projection.pressure.copy_from_slice(&pressure);
        Ok(())
    }

    /// Buoyancy and vorticity confinement: `vel += dt f`.
    fn add_forces(&mut self, state: &mut MacState, dt: f64) {
        let p = &self.params;
        if p.buoyancy_density != 0.0 || p.buoyancy_temperature != 0.0 {
            forces::buoyancy(
                &self.grid,
                p.buoyancy_density,
                p.buoyancy_temperature,
                p.ambient_temperature,
                &mut state.vel[1],
                &state.density,
                &state.temperature,
                dt,
            );
        }
        if p.vorticity_confinement > 0.0 {
            self.confinement.apply(&self.grid, p.vorticity_confinement, &mut state.vel, dt);
        }
    }

    /// Applies the sources: density, temperature and velocity inside each box, then in each
    /// region.
    fn apply_sources(&self, state: &mut MacState) {
        let MacState { vel, density, temperature, .. } = state;
        forces::apply_sources(&self.grid, &self.params.sources, vel, density, temperature);
        forces::apply_region_sources(&self.grid, &self.regions, vel, density, temperature);
    }

    /// Sets wall-normal and obstacle face velocities; open walls copy their inner neighbour.
    fn enforce_walls(&self, vel: &mut [Vec<f64>; 3]) {
        self.grid.enforce_walls(vel);
    }

    /// Copies the velocity aside and advects over `dt` by it: the velocity itself, or `field`
    /// (one array per component, on the velocity's faces) when given.
    fn advect_velocity(&mut self, state: &mut MacState, field: Option<&[Vec<f64>; 3]>, dt: f64) {
        self.transport.velocity(&self.grid, self.params.advection, &mut state.vel, field, dt);
    }

    /// One advection of the velocity by itself over `dt` (the grain measurement times it).
    #[cfg(test)]
    pub(crate) fn advect_for_timing(&mut self, state: &mut MacState, dt: f64) {
        self.advect_velocity(state, None, dt);
    }

    /// Advects density and temperature over `dt` by the velocity the last
    /// [`Self::advect_velocity`] copied aside.
    fn advect_scalars(&mut self, state: &mut MacState, dt: f64) {
        let scheme = self.params.advection;
        self.transport.scalars(&self.grid, scheme, &mut state.density, &mut state.temperature, dt);
    }

    /// Projects `state.vel` onto divergence-free fields.
    fn project(&mut self, state: &mut MacState) -> SolveInfo {
        self.projection.project(&self.grid, &mut state.vel)
    }

    /// The implicit viscosity step over `dt`, if the fluid is viscous; CG iterations taken.
    fn diffuse(&mut self, state: &mut MacState, dt: f64, step: u64) -> Result<usize, FluidError> {
        if self.params.viscosity > 0.0 {
            let (nu, require) = (self.params.viscosity, self.params.require_convergence);
            self.viscosity.solve(&self.grid, nu, require, &mut state.vel, dt, step)
        } else {
            Ok(0)
        }
    }

    /// [`Self::diffuse`]; a solve that fails on a non-finite residual (the velocity overflowed)
    /// is kept in `deferred` and the step goes on, so that the non-finite guard at its end names
    /// the value rather than the solve.
    fn diffuse_or_defer(
        &mut self,
        state: &mut MacState,
        dt: f64,
        step: u64,
        deferred: &mut Option<FluidError>,
    ) -> Result<usize, FluidError> {
        match self.diffuse(state, dt, step) {
            Err(e @ FluidError::NotConverged { residual, .. }) if !residual.is_finite() => {
                deferred.get_or_insert(e);
                Ok(0)
            }
            other => other,
        }
    }

    fn advance_in_place(
        &mut self,
        next: &mut MacState,
        before: &MacState,
        dt: f64,
        step: u64,
    ) -> Result<MacStepInfo, FluidError> {
        // A viscosity solve that failed on a non-finite residual, reported after the
        // non-finite guard has had the chance to name the value that overflowed.
        let mut deferred = None;
        let (pressure, viscosity_iterations) = match self.params.splitting {
            Splitting::AdvectProject => {
                self.add_forces(next, dt);
                self.apply_sources(next);
                self.enforce_walls(&mut next.vel);
                // Velocity advected by itself (frozen at its pre-advection value), then the
                // scalars by the same field.
                self.advect_velocity(next, None, dt);
                self.advect_scalars(next, dt);
                let viscosity = self.diffuse_or_defer(next, dt, step, &mut deferred)?;
                let pressure = self.project(next);
                self.enforce_walls(&mut next.vel);
                (pressure, viscosity)
            }
            Splitting::Reflection => {
                // Zehnder et al. (2018), with the body forces split over the two halves.
                self.add_forces(next, 0.5 * dt);
                self.apply_sources(next);
                self.enforce_walls(&mut next.vel);
                self.advect_velocity(next, None, 0.5 * dt);
                let mut viscosity = self.diffuse_or_defer(next, 0.5 * dt, step, &mut deferred)?;
                let mut reflect = std::mem::take(&mut self.reflect);
                for a in 0..self.grid.dim {
                    reflect[a].copy_from_slice(&next.vel[a]);
                }
                let first = self.project(next);
                self.enforce_walls(&mut next.vel);
                // `next.vel` is the divergence-free midpoint field u': it carries the
                // reflection 2 u' - u~ over the second half, and the scalars over the whole step.
                for a in 0..self.grid.dim {
                    reflect[a]
                        .par_iter_mut()
                        .zip(next.vel[a].par_iter())
                        .with_min_len(crate::grain::ENTRIES)
                        .for_each(|(r, &u)| *r = 2.0 * u - *r);
                }
                self.advect_velocity(next, Some(&reflect), 0.5 * dt);
                self.reflect = reflect;
                self.advect_scalars(next, dt);
                self.add_forces(next, 0.5 * dt);
                self.enforce_walls(&mut next.vel);
                viscosity += self.diffuse_or_defer(next, 0.5 * dt, step, &mut deferred)?;
                let mut pressure = self.project(next);
                self.enforce_walls(&mut next.vel);
                pressure.iterations += first.iterations;
                pressure.converged &= first.converged;
                pressure.residual = pressure.residual.max(first.residual);
                (pressure, viscosity)
            }
        };
        self.check_finite(next, before, step)?;
        if let Some(e) = deferred {
            return Err(e);
        }
        if !pressure.converged && self.params.require_convergence {
            return Err(FluidError::NotConverged {
                step,
                solve: "pressure",
                iterations: pressure.iterations,
                residual: pressure.residual,
                tolerance: self.params.pressure_tolerance,
            });
        }
        let divergence = self.projection.max_divergence(&self.grid, &next.vel);
        next.time += dt;
        next.steps += 1;
        Ok(MacStepInfo { pressure, viscosity_iterations, divergence })
    }
}

/// Copies every array of `from` into `to` (same sizes; no allocation).
fn copy_state(from: &MacState, to: &mut MacState) {
    for a in 0..3 {
        to.vel[a].copy_from_slice(&from.vel[a]);
    }
    to.density.copy_from_slice(&from.density);
    to.temperature.copy_from_slice(&from.temperature);
    to.time = from.time;
    to.steps = from.steps;
}

impl Solver for MacFluid {
    type State = MacState;
    type Error = FluidError;

    fn step(&mut self, state: &mut MacState, dt: f64) -> Result<StepReport, FluidError> {
        let info = self.advance(state, dt)?;
        let mut report = StepReport::at_time(state.time);
        report.iterations = info.pressure.iterations;
        report.residual = Some(info.pressure.residual);
        report.constraint_violation = Some(info.divergence);
        Ok(report)
    }
}
