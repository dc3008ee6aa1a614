//! The MAC-grid solver: incompressible Navier-Stokes with smoke, 2D and 3D in one code base.
//!
//! Seed section 6.1's splitting `w0 -(force)-> w1 -(advect)-> w2 -(diffuse)-> w3 -(project)-> w4`
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
//! Walls ([`Wall`]) are no-slip (with a velocity: a moving lid), free-slip or open (`p = 0`,
//! zero-gradient velocity); obstacles are solid cells ([`MacFluid::set_solid`]); inflow is a
//! [`Source`] box. Everything is `f64`: the accuracy cases (Taylor-Green decay, Ghia's cavity)
//! and the tight pressure tolerances of the work-precision study need it.
//!
//! 2D grids have `nz = 1` and no `w`; every loop is written once for both, the z terms guarded
//! by the dimension. Each stage is parallel over grid lines with rayon and reads only the
//! previous stage's arrays, so results are bitwise identical for any thread count; every
//! buffer is allocated by [`MacFluid::new`].

use crate::advection::{Advection, Lattice, Splitting, WallValues};
use crate::error::{self, FluidError};
use crate::pressure::{CellLabel, Poisson, PressureMethod, PressureSolver, SolveInfo};
use anim_core::solver::{Solver, StepReport};
use rayon::prelude::*;

/// A domain wall.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Wall {
    /// No-slip, moving with this velocity (its normal component must be 0).
    NoSlip([f64; 3]),
    /// Free-slip (zero normal velocity, zero tangential stress).
    FreeSlip,
    /// Open: pressure 0 outside, velocity and scalars extrapolated.
    Open,
}

/// An inflow box: every step, inside it the density and temperature are set to these values and
/// the velocity to `velocity`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Source {
    /// Lower corner (world units).
    pub min: [f64; 3],
    /// Upper corner.
    pub max: [f64; 3],
    /// Density set inside.
    pub density: f64,
    /// Temperature set inside.
    pub temperature: f64,
    /// Velocity set on the faces inside, or `None` to leave it.
    pub velocity: Option<[f64; 3]>,
}

/// Settings of [`MacFluid`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MacParams {
    /// Kinematic viscosity `nu`. Default 0 (inviscid; no viscosity solve).
    pub viscosity: f64,
    /// Advection scheme. Default [`Advection::MacCormack`].
    pub advection: Advection,
    /// How a step splits advection from projection. Default [`Splitting::AdvectProject`] (the
    /// seed's order); [`Splitting::Reflection`] is second order in `dt` for two projections.
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
    dims: [usize; 3],
    dim: usize,
    h: f64,
    params: MacParams,
    solid: Vec<bool>,
    pressure: PressureSolver,
    // scratch
    old_vel: [Vec<f64>; 3],
    advect_tmp: [Vec<f64>; 3],
    scalar_old: Vec<f64>,
    /// The advected, unprojected velocity of the first half step (advection-reflection only;
    /// empty otherwise).
    reflect: [Vec<f64>; 3],
    backup: MacState,
    /// The warm-start pressure before the current step, restored when the step fails.
    s_backup: Vec<f64>,
    partials: Vec<f64>,
    rhs: Vec<f64>,
    s: Vec<f64>,
    cell_vec: [Vec<f64>; 3],
    cell_mag: Vec<f64>,
    cell_force: [Vec<f64>; 3],
    cg: [Vec<f64>; 5],
    last: MacStepInfo,
}

/// Index of `(i, j, k)` in a lattice of `d`.
#[inline]
fn idx(d: [usize; 3], i: usize, j: usize, k: usize) -> usize {
    i + d[0] * (j + d[1] * k)
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
        let face_len = |a: usize| if a < dim { cells / dims[a] * (dims[a] + 1) } else { 0 };
        let max_len = (0..3).map(face_len).max().unwrap_or(0).max(cells);
        let open = Self::open_sides(&params);
        let op = Poisson::new(dims, dim, vec![CellLabel::Fluid; cells], open)?;
        let pressure = PressureSolver::new(
            op,
            params.pressure,
            params.pressure_tolerance,
            params.pressure_max_iterations,
        )?;
        let state = MacState {
            vel: [vec![0.0; face_len(0)], vec![0.0; face_len(1)], vec![0.0; face_len(2)]],
            density: vec![0.0; cells],
            temperature: vec![params.ambient_temperature; cells],
            time: 0.0,
            steps: 0,
        };
        let mut fluid = Self {
            dims,
            dim,
            h,
            params,
            solid: vec![false; cells],
            pressure,
            old_vel: [vec![0.0; face_len(0)], vec![0.0; face_len(1)], vec![0.0; face_len(2)]],
            advect_tmp: [vec![0.0; max_len], vec![0.0; max_len], vec![0.0; max_len]],
            scalar_old: vec![0.0; cells],
            reflect: Default::default(),
            backup: state.clone(),
            s_backup: vec![0.0; cells],
            partials: vec![0.0; max_len.div_ceil(crate::pressure::CHUNK) + 1],
            rhs: vec![0.0; cells],
            s: vec![0.0; cells],
            cell_vec: [vec![0.0; cells], vec![0.0; cells], vec![0.0; cells]],
            cell_mag: vec![0.0; cells],
            cell_force: [vec![0.0; cells], vec![0.0; cells], vec![0.0; cells]],
            cg: [
                vec![0.0; max_len],
                vec![0.0; max_len],
                vec![0.0; max_len],
                vec![0.0; max_len],
                vec![0.0; max_len],
            ],
            last: MacStepInfo::default(),
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

    fn open_sides(p: &MacParams) -> [[bool; 2]; 3] {
        let mut open = [[false; 2]; 3];
        for a in 0..3 {
            for s in 0..2 {
                open[a][s] = p.walls[a][s] == Wall::Open;
            }
        }
        open
    }

    /// Cell extents.
    #[must_use]
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// 2 or 3.
    #[must_use]
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Cell size.
    #[must_use]
    pub fn h(&self) -> f64 {
        self.h
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
        let mut d = self.dims;
        if a < self.dim {
            d[a] += 1;
        } else {
            d = [0, 0, 0];
        }
        d
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
        let op = self.pressure.operator().clone();
        self.pressure = PressureSolver::new(op, method, tolerance, max_iterations)?;
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
            self.reflect = std::array::from_fn(|a| vec![0.0; self.old_vel[a].len()]);
        }
    }

    /// Marks the cells whose centres `inside(x, y, z)` holds as solid obstacles, and rebuilds the
    /// pressure operator.
    ///
    /// # Errors
    /// Only if the pressure operator cannot be rebuilt (never for a valid fluid).
    pub fn set_solid(&mut self, inside: impl Fn([f64; 3]) -> bool) -> Result<(), FluidError> {
        let [nx, ny, nz] = self.dims;
        let mut labels = vec![CellLabel::Fluid; self.solid.len()];
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    let c = idx(self.dims, i, j, k);
                    let p = self.cell_centre(i, j, k);
                    self.solid[c] = inside(p);
                    if self.solid[c] {
                        labels[c] = CellLabel::Solid;
                    }
                }
            }
        }
        let op = Poisson::new(self.dims, self.dim, labels, Self::open_sides(&self.params))?;
        self.pressure = PressureSolver::new(
            op,
            self.params.pressure,
            self.params.pressure_tolerance,
            self.params.pressure_max_iterations,
        )?;
        Ok(())
    }

    /// World position of the centre of cell `(i, j, k)` (z = 0 in 2D).
    #[must_use]
    pub fn cell_centre(&self, i: usize, j: usize, k: usize) -> [f64; 3] {
        let z = if self.dim == 3 { (k as f64 + 0.5) * self.h } else { 0.0 };
        [(i as f64 + 0.5) * self.h, (j as f64 + 0.5) * self.h, z]
    }

    /// World position of face `(i, j, k)` of component `a`.
    #[must_use]
    pub fn face_centre(&self, a: usize, i: usize, j: usize, k: usize) -> [f64; 3] {
        let mut p = self.cell_centre(i, j, k);
        p[a] -= 0.5 * self.h;
        p
    }

    /// Sets every face velocity from `f(position) -> velocity` (component `a` at face `a`).
    pub fn set_velocity(&self, state: &mut MacState, f: impl Fn([f64; 3]) -> [f64; 3]) {
        for a in 0..self.dim {
            let d = self.face_dims(a);
            for k in 0..d[2] {
                for j in 0..d[1] {
                    for i in 0..d[0] {
                        state.vel[a][idx(d, i, j, k)] = f(self.face_centre(a, i, j, k))[a];
                    }
                }
            }
        }
        self.enforce_walls(&mut state.vel);
    }

    /// Whether face `(i, j, k)` of component `a` is fixed by a wall or an obstacle.
    #[inline]
    fn face_fixed(&self, a: usize, i: usize, j: usize, k: usize) -> bool {
        let n = [i, j, k];
        if n[a] == 0 || n[a] == self.dims[a] {
            return self.params.walls[a][usize::from(n[a] != 0)] != Wall::Open;
        }
        let stride = [1, self.dims[0], self.dims[0] * self.dims[1]][a];
        let hi = idx(self.dims, i, j, k);
        self.solid[hi] || self.solid[hi - stride]
    }

    /// Sets wall-normal and obstacle face velocities; open walls copy their inner neighbour.
    fn enforce_walls(&self, vel: &mut [Vec<f64>; 3]) {
        for a in 0..self.dim {
            let d = self.face_dims(a);
            let stride = [1, d[0], d[0] * d[1]][a];
            let field = &mut vel[a];
            for k in 0..d[2] {
                for j in 0..d[1] {
                    for i in 0..d[0] {
                        let n = [i, j, k];
                        let f = idx(d, i, j, k);
                        if n[a] == 0 || n[a] == self.dims[a] {
                            let side = usize::from(n[a] != 0);
                            field[f] = match self.params.walls[a][side] {
                                Wall::Open => {
                                    if side == 0 {
                                        field[f + stride]
                                    } else {
                                        field[f - stride]
                                    }
                                }
                                _ => 0.0,
                            };
                        } else if self.face_fixed(a, i, j, k) {
                            field[f] = 0.0;
                        }
                    }
                }
            }
        }
    }

    /// Tangential wall values for sampling component `a` (no-slip walls only).
    fn wall_values(&self, a: usize) -> WallValues {
        let mut w: WallValues = [[None; 2]; 3];
        for b in 0..self.dim {
            if b == a {
                continue;
            }
            for s in 0..2 {
                if let Wall::NoSlip(v) = self.params.walls[b][s] {
                    w[b][s] = Some(v[a]);
                }
            }
        }
        w
    }

    /// Velocity of `state` at world position `p` (linear interpolation of each component; no-slip
    /// walls blend the tangential components toward the wall velocity in the last half cell).
    #[must_use]
    pub fn velocity_at_point(&self, state: &MacState, p: [f64; 3]) -> [f64; 3] {
        let mut out = [0.0; 3];
        for a in 0..self.dim {
            let lat = Lattice { values: &state.vel[a], dims: self.face_dims(a), dim: self.dim };
            let g = self.lattice_coords(a, p);
            out[a] = lat.wall_blend(g, lat.linear(g).0, &self.wall_values(a));
        }
        out
    }

    /// Velocity at world position `p`, linear interpolation of each component.
    #[inline]
    fn velocity_at(&self, vel: &[Vec<f64>; 3], p: [f64; 3]) -> [f64; 3] {
        let mut out = [0.0; 3];
        for a in 0..self.dim {
            let lat = Lattice { values: &vel[a], dims: self.face_dims(a), dim: self.dim };
            let g = self.lattice_coords(a, p);
            out[a] = lat.linear(g).0;
        }
        out
    }

    /// Index coordinates of world point `p` in the lattice of component `a` (3 = cell centres).
    #[inline]
    fn lattice_coords(&self, a: usize, p: [f64; 3]) -> [f64; 3] {
        let mut g = [0.0; 3];
        for b in 0..self.dim {
            g[b] = p[b] / self.h - if b == a { 0.0 } else { 0.5 };
        }
        g
    }

    /// Midpoint back-trace of `p` through `vel` over `dt` (negative dt traces forward), clamped
    /// to the domain.
    #[inline]
    fn trace(&self, vel: &[Vec<f64>; 3], p: [f64; 3], dt: f64) -> [f64; 3] {
        let clamp = |mut q: [f64; 3]| {
            for b in 0..self.dim {
                q[b] = q[b].clamp(0.0, self.dims[b] as f64 * self.h);
            }
            q
        };
        let u0 = self.velocity_at(vel, p);
        let mut mid = p;
        for b in 0..self.dim {
            mid[b] -= 0.5 * dt * u0[b];
        }
        let um = self.velocity_at(vel, clamp(mid));
        let mut q = p;
        for b in 0..self.dim {
            q[b] -= dt * um[b];
        }
        clamp(q)
    }

    /// One semi-Lagrangian pass: `out[x] = field(trace(x, dt))` on the lattice of component `a`
    /// (3 for cell scalars). With `limit`, also returns nothing but clamps `out` into the range
    /// of `range_of` around the traced point.
    fn sl_pass(
        &self,
        vel: &[Vec<f64>; 3],
        a: usize,
        field: &[f64],
        out: &mut [f64],
        dt: f64,
        cubic: bool,
        clamp_to: Option<&[f64]>,
    ) {
        let d = if a < 3 { self.face_dims(a) } else { self.dims };
        let lat = Lattice { values: field, dims: d, dim: self.dim };
        let walls = if a < 3 { self.wall_values(a) } else { [[None; 2]; 3] };
        let range = clamp_to.map(|v| Lattice { values: v, dims: d, dim: self.dim });
        let offset = |b: usize| if b == a { 0.0 } else { 0.5 };
        out[..field.len()].par_chunks_mut(d[0]).enumerate().for_each(|(line, row)| {
            let (j, k) = (line % d[1], line / d[1]);
            for (i, o) in row.iter_mut().enumerate() {
                let n = [i, j, k];
                let mut p = [0.0; 3];
                for b in 0..self.dim {
                    p[b] = (n[b] as f64 + offset(b)) * self.h;
                }
                let q = self.trace(vel, p, dt);
                let g = self.lattice_coords(a, q);
                let mut v = if cubic { lat.cubic(g) } else { lat.linear(g).0 };
                v = lat.wall_blend(g, v, &walls);
                if let Some(r) = &range {
                    let (_, lo, hi) = r.linear(g);
                    let w = r.wall_blend(g, v, &walls);
                    let (lo, hi) = (lo.min(w), hi.max(w));
                    v = v.clamp(lo, hi);
                }
                *o = v;
            }
        });
    }

    /// Advects `field_in` (lattice of component `a`, 3 for scalars) by `old` (the velocity at the
    /// start of the advection) with the configured scheme into `out`; `tmp` is scratch.
    fn advect_field(
        &self,
        old: &[Vec<f64>; 3],
        a: usize,
        field_in: &[f64],
        out: &mut [f64],
        dt: f64,
        tmp: &mut [Vec<f64>; 3],
    ) {
        let [fwd, back, corrected] = tmp;
        let n = field_in.len();
        match self.params.advection {
            Advection::Linear => self.sl_pass(old, a, field_in, out, dt, false, None),
            Advection::MonotoneCubic => self.sl_pass(old, a, field_in, out, dt, true, None),
            Advection::Bfecc => {
                self.sl_pass(old, a, field_in, fwd, dt, false, None);
                self.sl_pass(old, a, &fwd[..n], back, -dt, false, None);
                corrected[..n]
                    .par_iter_mut()
                    .zip(field_in.par_iter().zip(back[..n].par_iter()))
                    .for_each(|(c, (&f, &b))| *c = f + 0.5 * (f - b));
                self.sl_pass(old, a, &corrected[..n], out, dt, false, Some(field_in));
            }
            Advection::MacCormack => {
                self.sl_pass(old, a, field_in, fwd, dt, false, None);
                self.sl_pass(old, a, &fwd[..n], back, -dt, false, None);
                corrected[..n]
                    .par_iter_mut()
                    .zip(fwd[..n].par_iter().zip(field_in.par_iter().zip(back[..n].par_iter())))
                    .for_each(|(c, (&fw, (&f, &b)))| *c = fw + 0.5 * (f - b));
                // Limiter: clamp into the range of the samples the forward trace used.
                let d = if a < 3 { self.face_dims(a) } else { self.dims };
                let lat = Lattice { values: field_in, dims: d, dim: self.dim };
                let walls = if a < 3 { self.wall_values(a) } else { [[None; 2]; 3] };
                let offset = |b: usize| if b == a { 0.0 } else { 0.5 };
                out[..n].par_chunks_mut(d[0]).zip(corrected[..n].par_chunks(d[0])).enumerate().for_each(
                    |(line, (row, crow))| {
                        let (j, k) = (line % d[1], line / d[1]);
                        for (i, (o, &c)) in row.iter_mut().zip(crow).enumerate() {
                            let nn = [i, j, k];
                            let mut p = [0.0; 3];
                            for b in 0..self.dim {
                                p[b] = (nn[b] as f64 + offset(b)) * self.h;
                            }
                            let g = self.lattice_coords(a, self.trace(old, p, dt));
                            let (v, lo, hi) = lat.linear(g);
                            let w = lat.wall_blend(g, v, &walls);
                            *o = c.clamp(lo.min(w), hi.max(w));
                        }
                    },
                );
            }
        }
    }

    /// Buoyancy and vorticity confinement: `vel += dt f`.
    fn add_forces(&mut self, state: &mut MacState, dt: f64) {
        let p = &self.params;
        let d = self.dims;
        if p.buoyancy_density != 0.0 || p.buoyancy_temperature != 0.0 {
            let fd = self.face_dims(1);
            let (alpha, beta, amb) = (p.buoyancy_density, p.buoyancy_temperature, p.ambient_temperature);
            let (rho, temp) = (&state.density, &state.temperature);
            state.vel[1].par_chunks_mut(fd[0]).enumerate().for_each(|(line, row)| {
                let (j, k) = (line % fd[1], line / fd[1]);
                if j == 0 || j == d[1] {
                    return;
                }
                for (i, v) in row.iter_mut().enumerate() {
                    let (lo, hi) = (idx(d, i, j - 1, k), idx(d, i, j, k));
                    let f = -alpha * 0.5 * (rho[lo] + rho[hi]) + beta * (0.5 * (temp[lo] + temp[hi]) - amb);
                    *v += dt * f;
                }
            });
        }
        if p.vorticity_confinement > 0.0 {
            self.vorticity_confinement(state, dt);
        }
    }

    fn vorticity_confinement(&mut self, state: &mut MacState, dt: f64) {
        let (d, h, dim) = (self.dims, self.h, self.dim);
        let eps = self.params.vorticity_confinement;
        // Cell-centred velocity.
        let vel = &state.vel;
        for a in 0..dim {
            let fd = self.face_dims(a);
            let stride = [1, fd[0], fd[0] * fd[1]][a];
            self.cell_vec[a].par_chunks_mut(d[0]).enumerate().for_each(|(line, row)| {
                let (j, k) = (line % d[1], line / d[1]);
                for (i, c) in row.iter_mut().enumerate() {
                    let f = idx(fd, i, j, k);
                    *c = 0.5 * (vel[a][f] + vel[a][f + stride]);
                }
            });
        }
        // Vorticity (central differences, one-sided at the walls) into cell_force, |omega| into cell_mag.
        let cv = &self.cell_vec;
        let deriv = |field: &[f64], i: usize, j: usize, k: usize, b: usize| -> f64 {
            let n = [i, j, k];
            let (lo, hi) = (n[b].saturating_sub(1), (n[b] + 1).min(d[b] - 1));
            let mut a = n;
            a[b] = lo;
            let mut c = n;
            c[b] = hi;
            (field[idx(d, c[0], c[1], c[2])] - field[idx(d, a[0], a[1], a[2])])
                / ((hi - lo).max(1) as f64 * h)
        };
        {
            let [f0, f1, f2] = &mut self.cell_force;
            let mag = &mut self.cell_mag;
            mag.par_chunks_mut(d[0])
                .zip(f0.par_chunks_mut(d[0]).zip(f1.par_chunks_mut(d[0]).zip(f2.par_chunks_mut(d[0]))))
                .enumerate()
                .for_each(|(line, (m, (o0, (o1, o2))))| {
                    let (j, k) = (line % d[1], line / d[1]);
                    for i in 0..d[0] {
                        let wz = deriv(&cv[1], i, j, k, 0) - deriv(&cv[0], i, j, k, 1);
                        let (wx, wy) = if dim == 3 {
                            (
                                deriv(&cv[2], i, j, k, 1) - deriv(&cv[1], i, j, k, 2),
                                deriv(&cv[0], i, j, k, 2) - deriv(&cv[2], i, j, k, 0),
                            )
                        } else {
                            (0.0, 0.0)
                        };
                        o0[i] = wx;
                        o1[i] = wy;
                        o2[i] = wz;
                        m[i] = (wx * wx + wy * wy + wz * wz).sqrt();
                    }
                });
        }
        // Force per cell: eps h (N x omega), stored in cell_vec (velocities no longer needed).
        let (omega, mag) = (&self.cell_force, &self.cell_mag);
        {
            let [c0, c1, c2] = &mut self.cell_vec;
            c0.par_chunks_mut(d[0])
                .zip(c1.par_chunks_mut(d[0]).zip(c2.par_chunks_mut(d[0])))
                .enumerate()
                .for_each(|(line, (f0, (f1, f2)))| {
                    let (j, k) = (line % d[1], line / d[1]);
                    for i in 0..d[0] {
                        let gx = deriv(mag, i, j, k, 0);
                        let gy = deriv(mag, i, j, k, 1);
                        let gz = if dim == 3 { deriv(mag, i, j, k, 2) } else { 0.0 };
                        let len = (gx * gx + gy * gy + gz * gz).sqrt() + 1e-12 / h;
                        let (nx, ny, nz) = (gx / len, gy / len, gz / len);
                        let c = idx(d, i, j, k);
                        let (ox, oy, oz) = (omega[0][c], omega[1][c], omega[2][c]);
                        f0[i] = eps * h * (ny * oz - nz * oy);
                        f1[i] = eps * h * (nz * ox - nx * oz);
                        f2[i] = eps * h * (nx * oy - ny * ox);
                    }
                });
        }
        for a in 0..dim {
            let fd = self.face_dims(a);
            let cf = &self.cell_vec[a];
            state.vel[a].par_chunks_mut(fd[0]).enumerate().for_each(|(line, row)| {
                let (j, k) = (line % fd[1], line / fd[1]);
                for (i, v) in row.iter_mut().enumerate() {
                    let n = [i, j, k];
                    if n[a] == 0 || n[a] == d[a] {
                        continue;
                    }
                    let mut lo = n;
                    lo[a] -= 1;
                    *v += dt * 0.5 * (cf[idx(d, lo[0], lo[1], lo[2])] + cf[idx(d, i, j, k)]);
                }
            });
        }
    }

    /// Applies the sources: density, temperature and velocity inside each box.
    fn apply_sources(&self, state: &mut MacState) {
        let inside = |s: &Source, p: [f64; 3]| (0..self.dim).all(|b| p[b] >= s.min[b] && p[b] <= s.max[b]);
        let d = self.dims;
        for s in &self.params.sources {
            for k in 0..d[2] {
                for j in 0..d[1] {
                    for i in 0..d[0] {
                        if inside(s, self.cell_centre(i, j, k)) {
                            let c = idx(d, i, j, k);
                            state.density[c] = state.density[c].max(s.density);
                            state.temperature[c] = s.temperature;
                        }
                    }
                }
            }
            if let Some(v) = s.velocity {
                for a in 0..self.dim {
                    let fd = self.face_dims(a);
                    for k in 0..fd[2] {
                        for j in 0..fd[1] {
                            for i in 0..fd[0] {
                                if inside(s, self.face_centre(a, i, j, k)) && !self.face_fixed(a, i, j, k) {
                                    state.vel[a][idx(fd, i, j, k)] = v[a];
                                }
                            }
                        }
                    }
                }
            }
        }
    }

    /// Backward-Euler viscosity `(I - nu dt Lap) u = u*` per component by Jacobi-preconditioned CG.
    fn viscosity(&mut self, state: &mut MacState, dt: f64, step: u64) -> Result<usize, FluidError> {
        let kappa = self.params.viscosity * dt / (self.h * self.h);
        let mut total = 0;
        for a in 0..self.dim {
            let fd = self.face_dims(a);
            let n = state.vel[a].len();
            let [mut r, mut z, mut p, mut q, mut dg] = std::mem::take(&mut self.cg);
            let mut partials = std::mem::take(&mut self.partials);
            // Neighbour classification shared by the operator and the right-hand side.
            let this = &*self;
            let walls = this.wall_values(a);
            // Returns (diag, sum of free neighbours of x, known contribution) for face f.
            let stencil = |x: &[f64], i: usize, j: usize, k: usize| -> (f64, f64, f64) {
                let n3 = [i, j, k];
                let stride = [1, fd[0], fd[0] * fd[1]];
                let f = idx(fd, i, j, k);
                let (mut diag, mut free, mut known) = (1.0, 0.0, 0.0);
                for b in 0..this.dim {
                    for side in 0..2 {
                        let outside = if side == 0 { n3[b] == 0 } else { n3[b] + 1 == fd[b] };
                        if outside {
                            // Only tangential axes reach here (normal boundary faces are fixed or open).
                            if let Some(w) = walls[b][side] {
                                diag += 2.0 * kappa;
                                known += 2.0 * kappa * w;
                            }
                            continue;
                        }
                        let g = if side == 0 { f - stride[b] } else { f + stride[b] };
                        let mut m = n3;
                        if side == 0 {
                            m[b] -= 1;
                        } else {
                            m[b] += 1;
                        }
                        diag += kappa;
                        if this.face_fixed(a, m[0], m[1], m[2]) || (m[a] == 0 || m[a] == this.dims[a]) {
                            known += kappa * x[g];
                        } else {
                            free += kappa * x[g];
                        }
                    }
                }
                (diag, free, known)
            };
            let is_unknown = |i: usize, j: usize, k: usize| {
                let n3 = [i, j, k];
                !(this.face_fixed(a, i, j, k) || n3[a] == 0 || n3[a] == this.dims[a])
            };
            let u = &state.vel[a];
            // r = b - A u with b = u* + known, starting from x = u*.
            r[..n]
                .par_chunks_mut(fd[0])
                .zip(z[..n].par_chunks_mut(fd[0]).zip(dg[..n].par_chunks_mut(fd[0])))
                .enumerate()
                .for_each(|(line, (rr, (zz, dd)))| {
                    let (j, k) = (line % fd[1], line / fd[1]);
                    for i in 0..fd[0] {
                        if is_unknown(i, j, k) {
                            let f = idx(fd, i, j, k);
                            let (diag, free, known) = stencil(u, i, j, k);
                            rr[i] = u[f] + known;
                            zz[i] = diag * u[f] - free;
                            dd[i] = diag;
                        } else {
                            rr[i] = 0.0;
                            zz[i] = 0.0;
                            dd[i] = 0.0;
                        }
                    }
                });
            let bnorm = crate::pressure::max_abs(&r[..n], &mut partials);
            if bnorm == 0.0 {
                self.cg = [r, z, p, q, dg];
                self.partials = partials;
                continue;
            }
            r[..n].par_iter_mut().zip(z[..n].par_iter_mut()).zip(q[..n].par_iter()).for_each(
                |((rr, zz), _)| {
                    *rr -= *zz;
                    *zz = 0.0;
                },
            );
            z[..n].par_iter_mut().zip(r[..n].par_iter().zip(dg[..n].par_iter())).for_each(
                |(zz, (&rr, &d))| {
                    *zz = if d > 0.0 { rr / d } else { 0.0 };
                },
            );
            let mut dotp = |x: &[f64], y: &[f64]| crate::pressure::dot(x, y, &mut partials);
            p[..n].copy_from_slice(&z[..n]);
            let mut rz = dotp(&r[..n], &z[..n]);
            let mut x = std::mem::take(&mut state.vel[a]);
            let mut it = 0;
            let tol = 1e-10;
            let mut res = r[..n].iter().fold(0.0f64, |m, v| m.max(v.abs())) / bnorm;
            while res > tol && it < 500 {
                q[..n].par_chunks_mut(fd[0]).enumerate().for_each(|(line, qq)| {
                    let (j, k) = (line % fd[1], line / fd[1]);
                    for i in 0..fd[0] {
                        let f = idx(fd, i, j, k);
                        qq[i] = if dg[f] > 0.0 {
                            let (diag, free, _) = stencil(&p, i, j, k);
                            diag * p[f] - free
                        } else {
                            0.0
                        };
                    }
                });
                let pq = dotp(&p[..n], &q[..n]);
                if !(pq > 0.0) {
                    break;
                }
                let alpha = rz / pq;
                x.par_iter_mut().zip(p[..n].par_iter()).for_each(|(x, &p)| *x += alpha * p);
                r[..n].par_iter_mut().zip(q[..n].par_iter()).for_each(|(r, &q)| *r -= alpha * q);
                it += 1;
                res = r[..n].iter().fold(0.0f64, |m, v| m.max(v.abs())) / bnorm;
                z[..n].par_iter_mut().zip(r[..n].par_iter().zip(dg[..n].par_iter())).for_each(
                    |(zz, (&rr, &d))| {
                        *zz = if d > 0.0 { rr / d } else { 0.0 };
                    },
                );
                let rz_new = dotp(&r[..n], &z[..n]);
                let beta = rz_new / rz;
                rz = rz_new;
                p[..n].par_iter_mut().zip(z[..n].par_iter()).for_each(|(p, &z)| *p = z + beta * *p);
            }
            state.vel[a] = x;
            self.partials = partials;
            self.cg = [r, z, p, q, dg];
            total += it;
            if res > tol && self.params.require_convergence {
                return Err(FluidError::NotConverged {
                    step,
                    solve: "viscosity",
                    iterations: it,
                    residual: res,
                    tolerance: tol,
                });
            }
        }
        Ok(total)
    }

    /// Net outflow of every fluid cell, `sum (u_+ - u_-)` (= h div u), into `out`.
    fn outflow(&self, vel: &[Vec<f64>; 3], out: &mut [f64]) {
        let d = self.dims;
        let dim = self.dim;
        let fds: [[usize; 3]; 3] = std::array::from_fn(|a| self.face_dims(a));
        let solid = &self.solid;
        out.par_chunks_mut(d[0]).enumerate().for_each(|(line, row)| {
            let (j, k) = (line % d[1], line / d[1]);
            for (i, o) in row.iter_mut().enumerate() {
                if solid[idx(d, i, j, k)] {
                    *o = 0.0;
                    continue;
                }
                let mut s = 0.0;
                for a in 0..dim {
                    let fd = fds[a];
                    let stride = [1, fd[0], fd[0] * fd[1]][a];
                    let f = idx(fd, i, j, k);
                    s += vel[a][f + stride] - vel[a][f];
                }
                *o = s;
            }
        });
    }

    /// The pressure operator (cell labels of the walls' and obstacles' layout).
    #[must_use]
    pub fn pressure_operator(&self) -> &Poisson {
        self.pressure.operator()
    }

    /// Net outflow `h div u` of every cell of `state` (0 in solids), the negated right-hand side
    /// of the pressure solve. `out` has one entry per cell.
    ///
    /// # Panics
    /// If `out` does not have one entry per cell.
    #[track_caller]
    pub fn net_outflow(&self, state: &MacState, out: &mut [f64]) {
        assert_eq!(out.len(), self.solid.len(), "net_outflow: one entry per cell");
        self.outflow(&state.vel, out);
    }

    /// `max |div u|` over fluid cells, 1/s.
    #[must_use]
    pub fn max_divergence(&self, state: &MacState) -> f64 {
        let mut out = vec![0.0; self.solid.len()];
        self.outflow(&state.vel, &mut out);
        out.iter().fold(0.0f64, |m, x| m.max(x.abs())) / self.h
    }

    /// Projects `state.vel` onto divergence-free fields.
    fn project(&mut self, state: &mut MacState) -> SolveInfo {
        let mut rhs = std::mem::take(&mut self.rhs);
        self.outflow(&state.vel, &mut rhs);
        rhs.par_iter_mut().for_each(|x| *x = -*x);
        let mut s = std::mem::take(&mut self.s);
        let info = self.pressure.solve(&rhs, &mut s);
        let d = self.dims;
        let labels = self.pressure.operator().labels();
        let walls = self.params.walls;
        for a in 0..self.dim {
            let fd = self.face_dims(a);
            state.vel[a].par_chunks_mut(fd[0]).enumerate().for_each(|(line, row)| {
                let (j, k) = (line % fd[1], line / fd[1]);
                for (i, v) in row.iter_mut().enumerate() {
                    let n = [i, j, k];
                    let value = |c: Option<usize>| match c {
                        Some(c) => match labels[c] {
                            CellLabel::Fluid => Some(s[c]),
                            CellLabel::Air => Some(0.0),
                            CellLabel::Solid => None,
                        },
                        None => None,
                    };
                    let lo = if n[a] == 0 {
                        if walls[a][0] == Wall::Open { Some(0.0) } else { None }
                    } else {
                        let mut m = n;
                        m[a] -= 1;
                        value(Some(idx(d, m[0], m[1], m[2])))
                    };
                    let hi = if n[a] == d[a] {
                        if walls[a][1] == Wall::Open { Some(0.0) } else { None }
                    } else {
                        value(Some(idx(d, i, j, k)))
                    };
                    if let (Some(lo), Some(hi)) = (lo, hi) {
                        *v -= hi - lo;
                    }
                }
            });
        }
        self.rhs = rhs;
        self.s = s;
        info
    }

    /// The first non-finite value of `state` (fields in the order u, v, w, density,
    /// temperature), reported with the value `before` held there.
    fn check_finite(&self, state: &MacState, before: &MacState, step: u64) -> Result<(), FluidError> {
        // (name, values after the step, values before it, lattice extents)
        type Field<'a> = (&'static str, &'a [f64], &'a [f64], [usize; 3]);
        let fields: [Field<'_>; 5] = [
            ("u", &state.vel[0], &before.vel[0], self.face_dims(0)),
            ("v", &state.vel[1], &before.vel[1], self.face_dims(1)),
            ("w", &state.vel[2], &before.vel[2], self.face_dims(2)),
            ("density", &state.density, &before.density, self.dims),
            ("temperature", &state.temperature, &before.temperature, self.dims),
        ];
        for (field, values, old, d) in fields {
            if values.par_iter().any(|x| !x.is_finite()) {
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
        self.s_backup.copy_from_slice(&self.s);
        let result = self.advance_in_place(state, &backup, dt, step);
        if result.is_err() {
            copy_state(&backup, state);
            self.s.copy_from_slice(&self.s_backup);
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
        let cells = self.solid.len();
        let fields: [(&'static str, &[f64], usize); 5] = [
            ("u", &state.vel[0], self.face_dims(0).iter().product()),
            ("v", &state.vel[1], self.face_dims(1).iter().product()),
            ("w", &state.vel[2], self.face_dims(2).iter().product()),
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
        serde_json::json!({ "dims": self.dims, "pressure": self.s })
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
        if dims != self.dims {
            return Err(FluidError::Checkpoint(format!(
                "the checkpoint is of a {dims:?} grid, this fluid is {:?}",
                self.dims
            )));
        }
        let pressure: Vec<f64> = memory
            .get("pressure")
            .and_then(|d| serde_json::from_value(d.clone()).ok())
            .ok_or_else(|| FluidError::Checkpoint("no `pressure` (an array of numbers)".into()))?;
        if pressure.len() != self.s.len() {
            return Err(FluidError::Checkpoint(format!(
                "`pressure` has {} values, the grid has {} cells",
                pressure.len(),
                self.s.len()
            )));
        }
        if let Some(at) = pressure.iter().position(|x| !x.is_finite()) {
            return Err(FluidError::Checkpoint(format!("`pressure`[{at}] is {}", pressure[at])));
        }
        self.s.copy_from_slice(&pressure);
        Ok(())
    }

    /// Copies the velocity aside and advects over `dt` by it: the velocity itself, or `field`
    /// (one array per component, on the velocity's faces) when given.
    fn advect_velocity(&mut self, state: &mut MacState, field: Option<&[Vec<f64>; 3]>, dt: f64) {
        let mut old = std::mem::take(&mut self.old_vel);
        let mut tmp = std::mem::take(&mut self.advect_tmp);
        for a in 0..self.dim {
            old[a].copy_from_slice(&state.vel[a]);
        }
        for a in 0..self.dim {
            let input = field.map_or(&old[a], |f| &f[a]);
            self.advect_field(&old, a, input, &mut state.vel[a], dt, &mut tmp);
        }
        self.old_vel = old;
        self.advect_tmp = tmp;
        self.enforce_walls(&mut state.vel);
    }

    /// Advects density and temperature over `dt` by the velocity the last
    /// [`Self::advect_velocity`] copied aside.
    fn advect_scalars(&mut self, state: &mut MacState, dt: f64) {
        let old = std::mem::take(&mut self.old_vel);
        let mut tmp = std::mem::take(&mut self.advect_tmp);
        let mut scalar_old = std::mem::take(&mut self.scalar_old);
        for target in [&mut state.density, &mut state.temperature] {
            scalar_old.copy_from_slice(target);
            self.advect_field(&old, 3, &scalar_old, target, dt, &mut tmp);
        }
        self.old_vel = old;
        self.advect_tmp = tmp;
        self.scalar_old = scalar_old;
    }

    /// The implicit viscosity step over `dt`, if the fluid is viscous; CG iterations taken.
    fn diffuse(&mut self, state: &mut MacState, dt: f64, step: u64) -> Result<usize, FluidError> {
        if self.params.viscosity > 0.0 { self.viscosity(state, dt, step) } else { Ok(0) }
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
                for a in 0..self.dim {
                    reflect[a].copy_from_slice(&next.vel[a]);
                }
                let first = self.project(next);
                self.enforce_walls(&mut next.vel);
                // `next.vel` is the divergence-free midpoint field u': it carries the
                // reflection 2 u' - u~ over the second half, and the scalars over the whole step.
                for a in 0..self.dim {
                    reflect[a]
                        .par_iter_mut()
                        .zip(next.vel[a].par_iter())
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
        let mut out = std::mem::take(&mut self.rhs);
        self.outflow(&next.vel, &mut out);
        let divergence = crate::pressure::max_abs(&out, &mut self.partials) / self.h;
        self.rhs = out;
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Taylor-Green vortex in the unit box with free-slip walls: `u = sin(pi x) cos(pi y)`,
    /// `v = -cos(pi x) sin(pi y)` decays as `exp(-2 nu pi^2 t)`.
    pub(super) fn taylor_green(n: usize, advection: Advection, nu: f64, t_end: f64) -> (f64, f64) {
        let r = crate::scenes::taylor_green_decay(n, advection, Splitting::AdvectProject, nu, t_end, 0.5)
            .unwrap();
        (r.amplitude, r.exact)
    }

    #[test]
    fn taylor_green_decay_matches_analytic_at_low_resolution() {
        let (a, exact) = taylor_green(32, Advection::MacCormack, 0.05, 0.5);
        assert!((a / exact - 1.0).abs() < 0.02, "{a} vs {exact}");
    }

    /// A box of smoke (density and temperature 1) near the floor.
    fn smoke_source() -> Source {
        Source { min: [0.3, 0.0, 0.3], max: [0.6, 0.2, 0.6], density: 1.0, temperature: 1.0, velocity: None }
    }

    /// The Taylor-Green vortex is a steady Euler flow whose advection term is a gradient: the
    /// splitting error of advect-then-project (first order, about `2 dt` of the amplitude at
    /// `t = 1`) is the whole error of MacCormack at N = 32, CFL 2 (dt = 1/16). Advection-
    /// reflection's error is of second order in `dt`; halving the step of advect-then-project
    /// (what two half steps without the reflection would give) would still leave about 3%.
    #[test]
    fn reflection_removes_the_first_order_splitting_error() {
        let run = |splitting| {
            let r = crate::scenes::taylor_green_decay(32, Advection::MacCormack, splitting, 0.01, 1.0, 2.0)
                .unwrap();
            (r.amplitude / r.exact - 1.0).abs()
        };
        let (chorin, reflection) = (run(Splitting::AdvectProject), run(Splitting::Reflection));
        assert!(chorin > 0.05, "advect-project {chorin}");
        assert!(reflection < 0.005, "reflection {reflection}");
    }

    /// Advection-reflection projects twice: the step still ends divergence-free to the solver's
    /// tolerance, with smoke carried by the midpoint field, 2D and 3D, on 1 and 2 threads alike.
    #[test]
    fn reflection_ends_divergence_free_and_is_thread_count_independent() {
        for (dims, dim) in [([16, 12, 1], 2), ([8, 8, 8], 3)] {
            let run = |threads: usize| {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
                pool.install(|| {
                    let params = MacParams {
                        splitting: Splitting::Reflection,
                        pressure_tolerance: 1e-8,
                        viscosity: 0.01,
                        buoyancy_temperature: 1.0,
                        sources: vec![smoke_source()],
                        ..MacParams::default()
                    };
                    let (mut f, mut s) = MacFluid::new(dims, dim, 1.0 / 16.0, params).unwrap();
                    f.set_velocity(&mut s, |p| [(3.0 * p[1]).sin(), (2.0 * p[0]).cos(), 0.5 * p[1]]);
                    let before = f.max_divergence(&s);
                    let mut worst: f64 = 0.0;
                    for _ in 0..5 {
                        let info = f.advance(&mut s, 0.05).unwrap();
                        assert!(info.pressure.converged);
                        worst = worst.max(info.divergence / before.max(1.0));
                    }
                    (s, worst)
                })
            };
            let (one, worst) = run(1);
            let (two, _) = run(2);
            assert!(worst < 1e-6, "{dim}D relative divergence {worst}");
            assert!(one.density.iter().sum::<f64>() > 0.5, "smoke entered");
            assert_eq!(serde_json::to_string(&one).unwrap(), serde_json::to_string(&two).unwrap());
        }
    }

    /// Finite but huge densities overflow the buoyancy force (`-alpha (rho_a + rho_b) / 2` is
    /// infinite): the step fails naming the step, field, face, value and the face's value
    /// before the step, and leaves the state and the warm-start pressure bitwise as they were.
    #[test]
    fn overflow_is_reported_and_the_step_undone() {
        for (dims, dim) in [([8, 8, 1], 2), ([6, 6, 6], 3)] {
            let params = MacParams { buoyancy_density: 10.0, ..MacParams::default() };
            let (mut fluid, mut state) = MacFluid::new(dims, dim, 0.125, params).unwrap();
            fluid.set_velocity(&mut state, |p| [(3.0 * p[1]).sin() + 1.0, (2.0 * p[0]).cos(), p[0]]);
            for _ in 0..2 {
                fluid.advance(&mut state, 0.05).unwrap();
            }
            let c = idx(dims, 3, 2, dims[2] / 2);
            state.density[c] = 1e308;
            state.density[c + dims[0]] = 1e308;
            let before = state.clone();
            let memory = serde_json::to_string(&fluid.memory()).unwrap();
            assert!(fluid.memory()["pressure"].as_array().unwrap().iter().any(|p| p.as_f64() != Some(0.0)));
            let err = fluid.advance(&mut state, 0.05).unwrap_err();
            let FluidError::NonFinite { step, field, i, j, k, value, last_finite } = err.clone() else {
                panic!("{err}")
            };
            assert_eq!(step, 2);
            assert!(!value.is_finite());
            let (old, d) = match field {
                "u" => (&before.vel[0], fluid.face_dims(0)),
                "v" => (&before.vel[1], fluid.face_dims(1)),
                "w" => (&before.vel[2], fluid.face_dims(2)),
                "density" => (&before.density, dims),
                "temperature" => (&before.temperature, dims),
                other => panic!("field {other}"),
            };
            assert!(i < d[0] && j < d[1] && k < d[2], "{err}");
            let last = old[idx(d, i, j, k)];
            assert_eq!(last_finite, Some(last));
            let msg = err.to_string();
            assert!(msg.starts_with("anim-fluid: step 2: non-finite "), "{msg}");
            assert!(msg.contains(&format!("{field} {value} at cell ({i}, {j}, {k})")), "{msg}");
            assert!(msg.contains(&format!("last finite value there {last}")), "{msg}");
            let bits = |s: &MacState| {
                s.vel
                    .iter()
                    .chain([&s.density, &s.temperature])
                    .flatten()
                    .map(|x| x.to_bits())
                    .collect::<Vec<_>>()
            };
            assert_eq!(bits(&state), bits(&before));
            assert_eq!((state.steps, state.time.to_bits()), (before.steps, before.time.to_bits()));
            assert_eq!(serde_json::to_string(&fluid.memory()).unwrap(), memory, "warm start changed");
        }
    }

    /// Every pressure method and advection scheme, 2D and 3D: the state and the solver's memory
    /// continue a run bit for bit.
    #[test]
    fn state_and_memory_continue_bit_for_bit() {
        for (k, method) in PressureMethod::ALL.into_iter().enumerate() {
            for (dims, dim) in [([10, 8, 1], 2), ([6, 5, 4], 3)] {
                let params = MacParams {
                    pressure: method,
                    pressure_tolerance: 1e-6,
                    pressure_max_iterations: 100_000,
                    viscosity: 0.01,
                    advection: Advection::ALL[k % 4],
                    splitting: Splitting::ALL[(k / 2) % 2],
                    buoyancy_temperature: 1.0,
                    vorticity_confinement: 1.0,
                    sources: vec![smoke_source()],
                    ..MacParams::default()
                };
                let build = || {
                    let (mut f, mut s) = MacFluid::new(dims, dim, 0.1, params.clone()).unwrap();
                    f.set_solid(|p| (p[0] - 0.7).powi(2) + (p[1] - 0.5).powi(2) < 0.01).unwrap();
                    f.set_velocity(&mut s, |p| [(3.0 * p[1]).sin(), (2.0 * p[0]).cos(), 0.5 * p[1]]);
                    (f, s)
                };
                let (mut f, mut s) = build();
                for _ in 0..2 {
                    f.advance(&mut s, 0.05).unwrap();
                }
                let saved = serde_json::to_string(&(&s, f.memory())).unwrap();
                for _ in 0..3 {
                    f.advance(&mut s, 0.05).unwrap();
                }
                let (mut g, _) = build();
                let (mut r, memory): (MacState, serde_json::Value) = serde_json::from_str(&saved).unwrap();
                g.check_state(&r).unwrap();
                g.restore_memory(&memory).unwrap();
                for _ in 0..3 {
                    g.advance(&mut r, 0.05).unwrap();
                }
                let text = |s: &MacState, f: &MacFluid| serde_json::to_string(&(s, f.memory())).unwrap();
                assert_eq!(text(&s, &f), text(&r, &g), "{method:?} {dim}D");
            }
        }
    }

    #[test]
    fn projection_leaves_divergence_below_tolerance_with_an_obstacle() {
        for method in PressureMethod::ALL {
            let params = MacParams {
                pressure: method,
                pressure_tolerance: 1e-8,
                pressure_max_iterations: 100_000,
                ..MacParams::default()
            };
            let (mut fluid, mut state) = MacFluid::new([24, 20, 1], 2, 0.05, params).unwrap();
            fluid.set_solid(|p| (p[0] - 0.6).powi(2) + (p[1] - 0.5).powi(2) < 0.04).unwrap();
            fluid.set_velocity(&mut state, |p| [(3.0 * p[1]).sin() + 1.0, (2.0 * p[0]).cos(), 0.0]);
            let before = fluid.max_divergence(&state);
            let info = fluid.advance(&mut state, 0.01).unwrap();
            assert!(info.pressure.converged, "{method:?}");
            assert!(
                info.divergence < 1e-6 * before.max(1.0),
                "{method:?}: {} (before {before})",
                info.divergence
            );
        }
    }
}

/// Timing comparison kept out of the normal test run (`cargo test --release -p anim-fluid --lib
/// -- --ignored --nocapture mgpcg_against`); `cargo xtask bench --peers` runs the same.
#[cfg(test)]
mod timing {
    use super::*;
    use std::time::Instant;

    /// Times the pressure solve alone on the 2D box with a sphere: (seconds, residual, iterations).
    fn projection(n: usize, method: PressureMethod, tol: f64, cap: usize) -> (f64, f64, usize) {
        let (mut f, mut s) = MacFluid::new([n, n, 1], 2, 1.0 / n as f64, MacParams::default()).unwrap();
        f.set_solid(|p| (p[0] - 0.6).powi(2) + (p[1] - 0.45).powi(2) < 0.04).unwrap();
        f.set_velocity(&mut s, |p| {
            [(3.0 * p[1]).sin() + (5.0 * p[0] * p[2]).cos(), (2.0 * p[0]).cos() * p[1], 0.0]
        });
        let mut rhs = vec![0.0; n * n];
        f.outflow(&s.vel, &mut rhs);
        rhs.iter_mut().for_each(|x| *x = -*x);
        let mut solver = PressureSolver::new(f.pressure.operator().clone(), method, tol, cap).unwrap();
        let mut x = vec![0.0; n * n];
        let t = Instant::now();
        let info = solver.solve(&rhs, &mut x);
        (t.elapsed().as_secs_f64(), info.residual, info.iterations)
    }

    #[test]
    #[ignore = "timing, run by hand"]
    fn mgpcg_against_gauss_seidel_n512() {
        let n = 512;
        let (gs_t, gs_r, gs_it) = projection(n, PressureMethod::RedBlackGaussSeidel, 0.0, 20);
        let (mg_t, mg_r, mg_it) = projection(n, PressureMethod::Mgpcg, gs_r, 1000);
        println!("rb-gs 20 sweeps: {gs_it} its, residual {gs_r:.3e}, {gs_t:.4} s");
        println!(
            "mgpcg to that residual: {mg_it} its, residual {mg_r:.3e}, {mg_t:.4} s; ratio {:.2}",
            gs_t / mg_t
        );
        for tol in [1e-2, 1e-4] {
            let (mg_t, mg_r, mg_it) = projection(n, PressureMethod::Mgpcg, tol, 1000);
            let (gs_t, gs_r, gs_it) = projection(n, PressureMethod::RedBlackGaussSeidel, tol, 4000);
            println!("mgpcg {tol:e}: {mg_it} its, residual {mg_r:.3e}, {mg_t:.4} s");
            println!(
                "rb-gs {tol:e} (cap 4000): {gs_it} its, residual {gs_r:.3e}, {gs_t:.3} s; ratio {:.1}",
                gs_t / mg_t
            );
        }
    }
}

/// Reference runs kept out of the normal test run (`cargo test --release -p anim-fluid --lib --
/// --ignored --nocapture reference_`); the xtask conformance cases judge the same quantities.
#[cfg(test)]
mod reference_runs {
    use super::*;
    use crate::scenes::{self, FluidSim};
    use std::time::Instant;

    fn ghia(file: &str) -> Vec<(f64, f64)> {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("testdata").join(file);
        std::fs::read_to_string(path)
            .unwrap()
            .lines()
            .skip(1)
            .filter_map(|l| {
                let (a, b) = l.split_once(',')?;
                Some((a.parse().ok()?, b.parse().ok()?))
            })
            .filter(|&(c, _)| c > 0.0 && c < 1.0)
            .collect()
    }

    #[test]
    #[ignore = "long, run by hand"]
    fn reference_cavity_against_ghia() {
        let (tu, tv) = (ghia("ghia_re100_u.csv"), ghia("ghia_re100_v.csv"));
        let runs = std::env::var("CAVITY_RUNS").unwrap_or_else(|_| "32:all,64:all,128:maccormack".into());
        for run in runs.split(',') {
            let (n, which) = run.split_once(':').unwrap();
            let n: usize = n.parse().unwrap();
            for scheme in Advection::ALL {
                if which != "all" && which != scheme.name() {
                    continue;
                }
                let t0 = Instant::now();
                let mut scene = scenes::lid_driven_cavity(n, 100.0, scheme).unwrap();
                let dt = scene.dt;
                let FluidSim::Mac(f, s) = &mut scene.sim else { unreachable!() };
                let mut prev = s.vel[0].clone();
                let every = (0.5 / dt).round() as usize;
                let (mut t, mut k) = (0.0, 0);
                while t < 30.0 {
                    f.advance(s, dt).unwrap();
                    t += dt;
                    k += 1;
                    if k % every == 0 {
                        let ch = s.vel[0].iter().zip(&prev).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
                            / (every as f64 * dt);
                        prev.copy_from_slice(&s.vel[0]);
                        if ch < 1e-4 {
                            break;
                        }
                    }
                }
                let eu = tu
                    .iter()
                    .map(|&(y, u)| (f.velocity_at_point(s, [0.5, y, 0.0])[0] - u).abs())
                    .fold(0.0, f64::max);
                let ev = tv
                    .iter()
                    .map(|&(x, v)| (f.velocity_at_point(s, [x, 0.5, 0.0])[1] - v).abs())
                    .fold(0.0, f64::max);
                println!(
                    "cavity N = {n} {}: max err u {eu:.4}, v {ev:.4}; steady at t = {t:.1}; {:.1} s",
                    scheme.name(),
                    t0.elapsed().as_secs_f64()
                );
            }
        }
    }

    #[test]
    #[ignore = "long, run by hand"]
    fn reference_taylor_green_n128() {
        for scheme in Advection::ALL {
            let t0 = Instant::now();
            let (a, exact) = super::tests::taylor_green(128, scheme, 0.01, 1.0);
            println!(
                "taylor-green N = 128 {}: A = {a:.5}, exact {exact:.5}, rel err {:.4}; {:.1} s",
                scheme.name(),
                (a / exact - 1.0).abs(),
                t0.elapsed().as_secs_f64()
            );
        }
    }
}
