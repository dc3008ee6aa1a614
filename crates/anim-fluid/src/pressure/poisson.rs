//! The discrete Poisson operator over labelled cells, and the relaxation sweeps on it.
//!
//! For every fluid cell `c` of an `nx x ny x nz` grid (x fastest, then y, then z),
//!
//! ```text
//! (A s)_c = diag_c s_c - sum over fluid neighbours nb of s_nb
//! ```
//!
//! where `diag_c` counts the non-solid neighbours: an air neighbour (`p = 0`, the ghost-fluid
//! Dirichlet condition) adds to the diagonal only, a solid neighbour (Neumann) drops out. Rows
//! and columns of air and solid cells are zero. The operator is assembled from the labels into
//! the diagonal and a 6-bit mask of fluid neighbours per cell, so relabelling a grid (a
//! particle fluid does it every step) rebuilds it in place without allocating.
//!
//! Beside the products `A x` and `b - A x` live the two relaxations the solvers and the
//! multigrid smoother use: damped Jacobi with weight [`JACOBI_WEIGHT`], and the half-sweep of
//! red-black Gauss-Seidel over one colour (`(i + j + k) % 2`), each reading only the previous
//! iterate or the other colour, so their results do not depend on the thread count.

use super::reduce::chunked_sum;
use crate::error::FluidError;
use rayon::prelude::*;

/// What occupies a cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum CellLabel {
    /// Fluid: pressure unknown.
    Fluid,
    /// Air (free surface, open boundary): pressure zero.
    Air,
    /// Solid (wall, obstacle): no pressure; its faces carry the solid's velocity.
    Solid,
}

/// Damping `w` of the Jacobi iteration. On a box with solid walls the smoothest non-constant
/// error mode (one half cosine across `n` cells, eigenvalue `lambda = 4 sin^2(pi / (2 n))` of
/// the operator) shrinks by `1 - w lambda / (2 dim)` per sweep, so reaching a relative residual
/// `tol` takes about `ln(1/tol) 2 dim / (w lambda)`, i.e. `O(n^2)`, sweeps.
pub const JACOBI_WEIGHT: f64 = 0.8;

/// Bits of [`Poisson::fluid_nbrs`]: neighbour in -x, +x, -y, +y, -z, +z is fluid.
const DIRS: usize = 6;

/// The Poisson operator over labelled cells of an `nx x ny x nz` grid (`nz = 1` in 2D).
#[derive(Debug, Clone)]
pub struct Poisson {
    pub(super) dims: [usize; 3],
    pub(super) dim: usize,
    pub(super) labels: Vec<CellLabel>,
    /// Number of non-solid neighbours of each fluid cell (0 elsewhere), as f64.
    pub(super) diag: Vec<f64>,
    /// Bit d set: the neighbour in direction d is fluid.
    pub(super) fluid_nbrs: Vec<u8>,
    /// No fluid cell touches air: A is singular.
    pub(super) singular: bool,
    /// Open domain sides.
    pub(super) open: [[bool; 2]; 3],
}

impl Poisson {
    /// The operator for `labels` (x fastest, then y, then z) on a grid of `dims` cells in `dim`
    /// dimensions. `open[axis][side]` makes the outside of that domain face air (`p = 0`);
    /// otherwise it is a solid wall.
    ///
    /// # Errors
    /// [`FluidError::BadGrid`] for a zero extent or `dim` not 2 or 3 (with `nz = 1` in 2D),
    /// [`FluidError::BadLength`] if `labels` does not have one entry per cell.
    pub fn new(
        dims: [usize; 3],
        dim: usize,
        labels: Vec<CellLabel>,
        open: [[bool; 2]; 3],
    ) -> Result<Self, FluidError> {
        for (a, what) in ["nx", "ny", "nz"].iter().enumerate() {
            if dims[a] == 0 {
                return Err(FluidError::BadGrid { what, min: 1, got: 0 });
            }
        }
        if !(dim == 2 && dims[2] == 1 || dim == 3) {
            return Err(FluidError::BadGrid { what: "nz (2D grids have nz = 1)", min: 1, got: dims[2] });
        }
        let cells = dims[0] * dims[1] * dims[2];
        if labels.len() != cells {
            return Err(FluidError::BadLength { name: "labels", got: labels.len(), expected: cells });
        }
        let mut op = Self {
            dims,
            dim,
            labels,
            diag: vec![0.0; cells],
            fluid_nbrs: vec![0u8; cells],
            singular: true,
            open,
        };
        op.assemble();
        Ok(op)
    }

    /// Replaces the labels by `labels` (one per cell of the same grid) and rebuilds the
    /// operator in place, allocating nothing: the result equals [`Poisson::new`] for them.
    ///
    /// # Errors
    /// [`FluidError::BadLength`] if `labels` does not have one entry per cell; the operator is
    /// then unchanged.
    pub fn relabel(&mut self, labels: &[CellLabel]) -> Result<(), FluidError> {
        if labels.len() != self.labels.len() {
            return Err(FluidError::BadLength {
                name: "labels",
                got: labels.len(),
                expected: self.labels.len(),
            });
        }
        self.labels.copy_from_slice(labels);
        self.assemble();
        Ok(())
    }

    /// The diagonal, the fluid-neighbour masks and the singularity flag from the labels.
    pub(super) fn assemble(&mut self) {
        let Self { dims, dim, labels, diag, fluid_nbrs, open, .. } = self;
        let (dims, dim, open) = (*dims, *dim, *open);
        let mut touches_air = false;
        let [nx, ny, nz] = dims;
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    let c = i + nx * (j + ny * k);
                    if labels[c] != CellLabel::Fluid {
                        diag[c] = 0.0;
                        fluid_nbrs[c] = 0;
                        continue;
                    }
                    let mut count = 0u32;
                    let mut mask = 0u8;
                    let idx = [i, j, k];
                    for axis in 0..dim {
                        let stride = [1, nx, nx * ny][axis];
                        for side in 0..2 {
                            let inside = if side == 0 { idx[axis] > 0 } else { idx[axis] + 1 < dims[axis] };
                            let label = if inside {
                                labels[if side == 0 { c - stride } else { c + stride }]
                            } else if open[axis][side] {
                                CellLabel::Air
                            } else {
                                CellLabel::Solid
                            };
                            match label {
                                CellLabel::Fluid => {
                                    count += 1;
                                    mask |= 1 << (2 * axis + side);
                                }
                                CellLabel::Air => {
                                    count += 1;
                                    touches_air = true;
                                }
                                CellLabel::Solid => {}
                            }
                        }
                    }
                    diag[c] = f64::from(count);
                    fluid_nbrs[c] = mask;
                }
            }
        }
        self.singular = !touches_air;
    }

    /// Grid extents.
    #[must_use]
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// 2 or 3.
    #[must_use]
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Number of cells.
    #[must_use]
    pub fn len(&self) -> usize {
        self.labels.len()
    }

    /// Whether the grid has no cells (never: construction rejects it).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.labels.is_empty()
    }

    /// The labels.
    #[must_use]
    pub fn labels(&self) -> &[CellLabel] {
        &self.labels
    }

    /// Whether no fluid cell touches air (the constants are then a null space).
    #[must_use]
    pub fn is_singular(&self) -> bool {
        self.singular
    }

    fn strides(&self) -> [usize; DIRS] {
        let [nx, ny, _] = self.dims;
        [1, 1, nx, nx, nx * ny, nx * ny]
    }

    /// Sum of the fluid neighbours' values of cell `c`.
    #[inline]
    fn nbr_sum(&self, x: &[f64], c: usize, strides: &[usize; DIRS]) -> f64 {
        let m = self.fluid_nbrs[c];
        // Interior cells (every neighbour fluid) without the per-direction branches; the same
        // additions in the same order as the loop below, so the same bits.
        if m == (1 << (2 * self.dim)) - 1 {
            let s = 0.0 + x[c - strides[0]] + x[c + strides[1]] + x[c - strides[2]] + x[c + strides[3]];
            return if self.dim == 3 { s + x[c - strides[4]] + x[c + strides[5]] } else { s };
        }
        let mut s = 0.0;
        for d in 0..2 * self.dim {
            if m & (1 << d) != 0 {
                s += if d % 2 == 0 { x[c - strides[d]] } else { x[c + strides[d]] };
            }
        }
        s
    }

    /// `y = A x` on fluid cells, 0 elsewhere.
    pub fn apply(&self, x: &[f64], y: &mut [f64]) {
        let strides = self.strides();
        let nx = self.dims[0];
        y.par_chunks_mut(nx)
            .enumerate()
            .with_min_len(crate::grain::lines(nx, crate::grain::STENCIL_NS))
            .for_each(|(line, row)| {
                let base = line * nx;
                for (i, yi) in row.iter_mut().enumerate() {
                    let c = base + i;
                    *yi = if self.diag[c] > 0.0 {
                        self.diag[c] * x[c] - self.nbr_sum(x, c, &strides)
                    } else {
                        0.0
                    };
                }
            });
    }

    /// `r = b - A x` on fluid cells, 0 elsewhere.
    pub fn residual(&self, b: &[f64], x: &[f64], r: &mut [f64]) {
        let strides = self.strides();
        let nx = self.dims[0];
        r.par_chunks_mut(nx)
            .enumerate()
            .with_min_len(crate::grain::lines(nx, crate::grain::STENCIL_NS))
            .for_each(|(line, row)| {
                let base = line * nx;
                for (i, ri) in row.iter_mut().enumerate() {
                    let c = base + i;
                    *ri = if self.diag[c] > 0.0 {
                        b[c] - (self.diag[c] * x[c] - self.nbr_sum(x, c, &strides))
                    } else {
                        0.0
                    };
                }
            });
    }

    /// One damped Jacobi sweep `x_new = (1 - w) x + w (b + sum x_nb) / diag` on fluid cells.
    pub(super) fn jacobi_sweep(&self, b: &[f64], x: &[f64], x_new: &mut [f64]) {
        let strides = self.strides();
        let nx = self.dims[0];
        x_new
            .par_chunks_mut(nx)
            .enumerate()
            .with_min_len(crate::grain::lines(nx, crate::grain::STENCIL_NS))
            .for_each(|(line, row)| {
                let base = line * nx;
                for (i, xi) in row.iter_mut().enumerate() {
                    let c = base + i;
                    *xi = if self.diag[c] > 0.0 {
                        (1.0 - JACOBI_WEIGHT) * x[c]
                            + JACOBI_WEIGHT * (b[c] + self.nbr_sum(x, c, &strides)) / self.diag[c]
                    } else {
                        0.0
                    };
                }
            });
    }

    /// Gauss-Seidel update of the cells of one colour (`(i + j + k) % 2 == colour`): new values
    /// into `tmp` from `x` (which holds the other colour's latest values), then copied back.
    pub(super) fn colour_sweep(&self, colour: usize, b: &[f64], x: &mut [f64], tmp: &mut [f64]) {
        let strides = self.strides();
        let [nx, ny, _] = self.dims;
        {
            let x: &[f64] = x;
            tmp.par_chunks_mut(nx)
                .enumerate()
                .with_min_len(crate::grain::lines(nx, crate::grain::STENCIL_NS))
                .for_each(|(line, row)| {
                    let base = line * nx;
                    let (j, k) = (line % ny, line / ny);
                    let start = (colour + j + k) % 2;
                    for i in (start..nx).step_by(2) {
                        let c = base + i;
                        if self.diag[c] > 0.0 {
                            row[i] = (b[c] + self.nbr_sum(x, c, &strides)) / self.diag[c];
                        }
                    }
                });
        }
        x.par_chunks_mut(nx)
            .zip(tmp.par_chunks(nx))
            .enumerate()
            .with_min_len(crate::grain::lines(nx, crate::grain::STENCIL_NS))
            .for_each(|(line, (xr, tr))| {
                let base = line * nx;
                let (j, k) = (line % ny, line / ny);
                let start = (colour + j + k) % 2;
                for i in (start..nx).step_by(2) {
                    if self.diag[base + i] > 0.0 {
                        xr[i] = tr[i];
                    }
                }
            });
    }

    /// Subtracts the mean over fluid cells (the null space of a singular operator).
    pub(super) fn remove_mean(&self, x: &mut [f64], partials: &mut [f64]) {
        let fluid = self.diag.iter().filter(|&&d| d > 0.0).count();
        if fluid == 0 {
            return;
        }
        let diag = &self.diag;
        let sum = chunked_sum(x.len(), partials, |range| {
            range.filter(|&c| diag[c] > 0.0).map(|c| x[c]).sum::<f64>()
        });
        let mean = sum / fluid as f64;
        x.par_iter_mut().zip(diag.par_iter()).with_min_len(crate::grain::ENTRIES).for_each(|(v, &d)| {
            if d > 0.0 {
                *v -= mean;
            }
        });
    }
}
