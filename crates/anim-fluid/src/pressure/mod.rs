//! Pressure projection on a MAC grid: the Poisson problem over labelled cells and its solvers.
//!
//! The projection of stable fluids (Stam 1999): `w4 = w3 - grad p` with `Lap p = div w3`. On a MAC grid (velocities on cell
//! faces, pressure at cell centres) with cells labelled [`CellLabel::Fluid`],
//! [`CellLabel::Air`] (free surface or open boundary, `p = 0`: the ghost-fluid Dirichlet
//! condition) and [`CellLabel::Solid`] (walls and obstacles, `dp/dn` set by the wall velocity:
//! Neumann), the discrete problem for `s = dt p / (rho h)` is, for every fluid cell `c`,
//!
//! ```text
//! (A s)_c = sum over non-solid neighbours nb of (s_c - s_nb [0 if nb is air]) = -(div u)_c h
//! ```
//!
//! where `(div u)_c h` is the net outflow of the cell's faces; the velocity update
//! `u_f -= s_+ - s_-` across every face between two non-solid cells then makes every fluid cell's
//! outflow zero ([`crate::mac`] builds the right-hand side and applies the gradient). `A` is
//! symmetric positive (semi-)definite: singular, with the constants as null space, when no cell
//! touches air; the solvers then work in the zero-mean subspace.
//!
//! This module only knows cells and labels, so a particle fluid (PIC/FLIP/APIC) that labels the
//! cells holding particles as fluid and the others as air reuses it unchanged for its
//! free-surface projection.
//!
//! Solvers ([`PressureMethod`]):
//! - **Jacobi**: `s_c <- (1 - w) s_c + w (b_c + sum s_nb) / diag_c` from the previous iterate,
//!   parallel, damped with `w = 4/5` (undamped Jacobi does not converge when every cell is fluid:
//!   the checkerboard mode has iteration eigenvalue -1).
//! - **Red-black Gauss-Seidel**: the same update, red cells (`i + j + k` even) then black cells,
//!   each colour in parallel; about twice Jacobi's convergence per sweep.
//! - **Conjugate gradients** (Hestenes-Stiefel), unpreconditioned.
//! - **MGPCG**: conjugate gradients preconditioned by one geometric multigrid V-cycle (McAdams,
//!   Sifakis and Teran 2010): cell-centred coarsening by 2 per axis (a coarse cell is air if any
//!   child is air, else fluid if any child is fluid, else solid), the operator rediscretised on
//!   each level, red-black Gauss-Seidel smoothing (red-black before, black-red after, so the
//!   cycle is symmetric), piecewise constant prolongation and its scaled transpose as
//!   restriction; iterations nearly independent of the resolution.
//!
//! Every reduction (dot products, norms) is summed over fixed chunks in a fixed order, and every
//! update reads only values of the previous colour or iterate, so results are bitwise identical
//! for any number of rayon threads. All buffers are allocated when the solver is built.
//!
//! The module is laid out by concept: [`Poisson`] (the labelled operator, its products and
//! relaxation sweeps), [`PressureSolver`] (the four methods), the multigrid hierarchy of the
//! MGPCG preconditioner, and the ordered reductions every solver shares.

mod multigrid;
mod poisson;
mod reduce;
mod solver;

pub use poisson::{CellLabel, JACOBI_WEIGHT, Poisson};
pub(crate) use reduce::{CHUNK, dot, max_abs};
pub use solver::{PressureMethod, PressureSolver, SolveInfo};

#[cfg(test)]
mod tests;
