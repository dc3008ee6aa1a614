//! Pressure projection: the *project* step of stable fluids (Stam 1999), `w4 = w3 - grad p` with `Lap p = div w3`.
//!
//! The Helmholtz-Hodge decomposition splits the velocity into a divergence-free part and a
//! gradient; projection keeps the first (Chorin 1968). On the MAC grid:
//!
//! 1. the right-hand side is the negated net outflow of every fluid cell,
//!    `b_c = -sum_a (u_a(+) - u_a(-)) = -h (div u)_c` (0 in solid cells);
//! 2. [`crate::pressure`] solves `A s = b` for `s = dt p / (rho h)` over the cells labelled
//!    fluid, solid (obstacles: no pressure, Neumann) or air (`s = 0`: the outside of an open
//!    wall is air too), warm-started from the last step's `s`;
//! 3. every face between two cells with a pressure subtracts the difference,
//!    `u_f -= s_+ - s_-`, with `s = 0` beyond an open wall; faces of solid cells and of closed
//!    walls keep their (wall) velocity.
//!
//! After it the net outflow of every fluid cell is within the solver's tolerance of zero, which
//! the step reports as `max |div u|`.

use crate::error::FluidError;
use crate::mac::grid::{MacGrid, Wall, idx};
use crate::pressure::{CellLabel, Poisson, PressureMethod, PressureSolver, SolveInfo};
use rayon::prelude::*;

/// The pressure solver of the grid's cells, the pressure it carries from step to step, and the
/// buffers of the projection, sized by the solver's constructor.
#[derive(Debug, Clone)]
pub(super) struct Projection {
    solver: PressureSolver,
    /// `s` of the last solve, the next solve's starting guess.
    pub(super) pressure: Vec<f64>,
    /// The right-hand side, and the outflow the step measures after it.
    rhs: Vec<f64>,
    /// Per-chunk partial sums of the divergence's maximum.
    partials: Vec<f64>,
}

/// A pressure solver by `method` for the cells of `grid` labelled `labels`, the open walls
/// its air beyond the domain.
///
/// # Errors
/// The errors of [`Poisson::new`] and [`PressureSolver::new`].
pub(super) fn pressure_solver(
    grid: &MacGrid,
    labels: Vec<CellLabel>,
    method: PressureMethod,
    tolerance: f64,
    max_iterations: usize,
) -> Result<PressureSolver, FluidError> {
    let op = Poisson::new(grid.dims, grid.dim, labels, grid.open_sides())?;
    PressureSolver::new(op, method, tolerance, max_iterations)
}

/// Net outflow of every fluid cell, `sum (u_+ - u_-)` (= h div u), into `out` (0 in solids).
pub(super) fn outflow(grid: &MacGrid, vel: &[Vec<f64>; 3], out: &mut [f64]) {
    let d = grid.dims;
    let dim = grid.dim;
    let fds: [[usize; 3]; 3] = std::array::from_fn(|a| grid.face_dims(a));
    let solid = &grid.solid;
    out.par_chunks_mut(d[0])
        .enumerate()
        .with_min_len(crate::grain::lines(d[0], crate::grain::STENCIL_NS))
        .for_each(|(line, row)| {
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

impl Projection {
    /// A projection by `solver` on `grid`, at rest (zero pressure).
    pub(super) fn new(grid: &MacGrid, solver: PressureSolver) -> Self {
        let cells = grid.cells();
        Self {
            solver,
            pressure: vec![0.0; cells],
            rhs: vec![0.0; cells],
            partials: vec![0.0; grid.max_len().div_ceil(crate::pressure::CHUNK) + 1],
        }
    }

    /// The pressure operator.
    pub(super) fn operator(&self) -> &Poisson {
        self.solver.operator()
    }

    /// Replaces the pressure solver (same grid; the warm-start pressure is kept).
    pub(super) fn set_solver(&mut self, solver: PressureSolver) {
        self.solver = solver;
    }

    /// Projects `vel` onto divergence-free fields.
    pub(super) fn project(&mut self, grid: &MacGrid, vel: &mut [Vec<f64>; 3]) -> SolveInfo {
        let mut rhs = std::mem::take(&mut self.rhs);
        outflow(grid, vel, &mut rhs);
        rhs.par_iter_mut().with_min_len(crate::grain::ENTRIES).for_each(|x| *x = -*x);
        let mut s = std::mem::take(&mut self.pressure);
        let info = self.solver.solve(&rhs, &mut s);
        let d = grid.dims;
        let labels = self.solver.operator().labels();
        let walls = grid.walls;
        for a in 0..grid.dim {
            let fd = grid.face_dims(a);
            vel[a]
                .par_chunks_mut(fd[0])
                .enumerate()
                .with_min_len(crate::grain::lines(fd[0], crate::grain::STENCIL_NS))
                .for_each(|(line, row)| {
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
        self.pressure = s;
        info
    }

    /// `max |div u|` of `vel` over the cells (1/s), reduced over fixed chunks in the
    /// right-hand side's buffer.
    pub(super) fn max_divergence(&mut self, grid: &MacGrid, vel: &[Vec<f64>; 3]) -> f64 {
        let mut out = std::mem::take(&mut self.rhs);
        outflow(grid, vel, &mut out);
        let divergence = crate::pressure::max_abs(&out, &mut self.partials) / grid.h;
        self.rhs = out;
        divergence
    }
}
