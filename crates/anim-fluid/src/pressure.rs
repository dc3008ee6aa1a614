//! Pressure projection on a MAC grid: the Poisson problem over labelled cells and its solvers.
//!
//! Seed section 6.1: `w4 = w3 - grad p` with `Lap p = div w3`. On a MAC grid (velocities on cell
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

/// The pressure solve method. Serialised by its [`PressureMethod::name`] (`"jacobi"`,
/// `"rb-gauss-seidel"`, `"cg"`, `"mgpcg"`), as scene files name it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum PressureMethod {
    /// Jacobi iteration.
    #[serde(rename = "jacobi")]
    Jacobi,
    /// Red-black Gauss-Seidel.
    #[serde(rename = "rb-gauss-seidel")]
    RedBlackGaussSeidel,
    /// Conjugate gradients.
    #[serde(rename = "cg")]
    ConjugateGradient,
    /// Multigrid-preconditioned conjugate gradients.
    #[serde(rename = "mgpcg")]
    Mgpcg,
}

impl PressureMethod {
    /// All methods, in the order of the tables.
    pub const ALL: [PressureMethod; 4] =
        [Self::Jacobi, Self::RedBlackGaussSeidel, Self::ConjugateGradient, Self::Mgpcg];

    /// A short name for tables.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Jacobi => "jacobi",
            Self::RedBlackGaussSeidel => "rb-gauss-seidel",
            Self::ConjugateGradient => "cg",
            Self::Mgpcg => "mgpcg",
        }
    }
}

/// What a solve did.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SolveInfo {
    /// Iterations (sweeps for Jacobi and Gauss-Seidel, CG iterations otherwise).
    pub iterations: usize,
    /// Final residual `max |b - A s| / max |b|` (0 for a zero right-hand side).
    pub residual: f64,
    /// Whether the tolerance was reached.
    pub converged: bool,
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
    dims: [usize; 3],
    dim: usize,
    labels: Vec<CellLabel>,
    /// Number of non-solid neighbours of each fluid cell (0 elsewhere), as f64.
    diag: Vec<f64>,
    /// Bit d set: the neighbour in direction d is fluid.
    fluid_nbrs: Vec<u8>,
    /// No fluid cell touches air: A is singular.
    singular: bool,
    /// Open domain sides.
    open: [[bool; 2]; 3],
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
    fn assemble(&mut self) {
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
        y.par_chunks_mut(nx).enumerate().for_each(|(line, row)| {
            let base = line * nx;
            for (i, yi) in row.iter_mut().enumerate() {
                let c = base + i;
                *yi =
                    if self.diag[c] > 0.0 { self.diag[c] * x[c] - self.nbr_sum(x, c, &strides) } else { 0.0 };
            }
        });
    }

    /// `r = b - A x` on fluid cells, 0 elsewhere.
    pub fn residual(&self, b: &[f64], x: &[f64], r: &mut [f64]) {
        let strides = self.strides();
        let nx = self.dims[0];
        r.par_chunks_mut(nx).enumerate().for_each(|(line, row)| {
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
    fn jacobi_sweep(&self, b: &[f64], x: &[f64], x_new: &mut [f64]) {
        let strides = self.strides();
        let nx = self.dims[0];
        x_new.par_chunks_mut(nx).enumerate().for_each(|(line, row)| {
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
    fn colour_sweep(&self, colour: usize, b: &[f64], x: &mut [f64], tmp: &mut [f64]) {
        let strides = self.strides();
        let [nx, ny, _] = self.dims;
        {
            let x: &[f64] = x;
            tmp.par_chunks_mut(nx).enumerate().for_each(|(line, row)| {
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
        x.par_chunks_mut(nx).zip(tmp.par_chunks(nx)).enumerate().for_each(|(line, (xr, tr))| {
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
    fn remove_mean(&self, x: &mut [f64], partials: &mut [f64]) {
        let fluid = self.diag.iter().filter(|&&d| d > 0.0).count();
        if fluid == 0 {
            return;
        }
        let diag = &self.diag;
        let sum = chunked_sum(x.len(), partials, |range| {
            range.filter(|&c| diag[c] > 0.0).map(|c| x[c]).sum::<f64>()
        });
        let mean = sum / fluid as f64;
        x.par_iter_mut().zip(diag.par_iter()).for_each(|(v, &d)| {
            if d > 0.0 {
                *v -= mean;
            }
        });
    }

    /// The extents of the next multigrid level, or `None` when an extent would fall below 2
    /// cells (they depend on the grid only, not on the labels).
    fn coarse_dims(&self) -> Option<[usize; 3]> {
        let [nx, ny, nz] = self.dims;
        let coarse = |n: usize| n.div_ceil(2);
        let cd = [coarse(nx), coarse(ny), if self.dim == 3 { coarse(nz) } else { 1 }];
        if cd[0] < 2 || cd[1] < 2 || (self.dim == 3 && cd[2] < 2) || (nx <= 4 && ny <= 4) {
            return None;
        }
        Some(cd)
    }

    /// The labels of the next level (extents `cd`) into `labels`: air where a child is air,
    /// else fluid where a child is fluid, else solid.
    fn coarse_labels(&self, cd: [usize; 3], labels: &mut [CellLabel]) {
        let [nx, ny, nz] = self.dims;
        labels.fill(CellLabel::Solid);
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    let f = self.labels[i + nx * (j + ny * k)];
                    let kc = if self.dim == 3 { k / 2 } else { 0 };
                    let c = &mut labels[i / 2 + cd[0] * (j / 2 + cd[1] * kc)];
                    *c = match (*c, f) {
                        (CellLabel::Air, _) | (_, CellLabel::Air) => CellLabel::Air,
                        (CellLabel::Fluid, _) | (_, CellLabel::Fluid) => CellLabel::Fluid,
                        _ => CellLabel::Solid,
                    };
                }
            }
        }
    }

    /// The coarse operator of the next multigrid level, or `None` when an extent would fall
    /// below 2 cells.
    fn coarsen(&self) -> Option<Poisson> {
        let cd = self.coarse_dims()?;
        let mut labels = vec![CellLabel::Solid; cd[0] * cd[1] * cd[2]];
        self.coarse_labels(cd, &mut labels);
        Poisson::new(cd, self.dim, labels, self.open).ok()
    }
}

/// Sum of `f(range)` over fixed chunks of `0..len`, in chunk order (thread-count independent).
fn chunked_sum(len: usize, partials: &mut [f64], f: impl Fn(std::ops::Range<usize>) -> f64 + Sync) -> f64 {
    let chunks = len.div_ceil(CHUNK);
    partials[..chunks].par_iter_mut().enumerate().for_each(|(q, p)| {
        *p = f(q * CHUNK..((q + 1) * CHUNK).min(len));
    });
    partials[..chunks].iter().sum()
}

/// Chunk length of the ordered reductions.
pub(crate) const CHUNK: usize = 4096;

pub(crate) fn dot(a: &[f64], b: &[f64], partials: &mut [f64]) -> f64 {
    chunked_sum(a.len(), partials, |r| a[r.clone()].iter().zip(&b[r]).map(|(x, y)| x * y).sum())
}

pub(crate) fn max_abs(a: &[f64], partials: &mut [f64]) -> f64 {
    let chunks = a.len().div_ceil(CHUNK);
    partials[..chunks].par_iter_mut().enumerate().for_each(|(q, p)| {
        *p = a[q * CHUNK..((q + 1) * CHUNK).min(a.len())].iter().fold(0.0f64, |m, x| m.max(x.abs()));
    });
    partials[..chunks].iter().fold(0.0f64, |m, &x| m.max(x))
}

/// One multigrid level: its operator and buffers.
#[derive(Debug, Clone)]
struct Level {
    op: Poisson,
    x: Vec<f64>,
    b: Vec<f64>,
    r: Vec<f64>,
    tmp: Vec<f64>,
}

/// Pre- and post-smoothing sweeps (each a red and a black half-sweep) of the V-cycle.
const SMOOTH: usize = 2;
/// Symmetric sweep pairs on the coarsest level.
const COARSE_SWEEPS: usize = 20;

/// A pressure solver bound to one [`Poisson`] operator, with every buffer it needs.
#[derive(Debug, Clone)]
pub struct PressureSolver {
    method: PressureMethod,
    /// Relative residual tolerance `max|b - A s| / max|b|`.
    tolerance: f64,
    /// Iteration cap.
    max_iterations: usize,
    levels: Vec<Level>,
    r: Vec<f64>,
    z: Vec<f64>,
    p: Vec<f64>,
    q: Vec<f64>,
    b: Vec<f64>,
    partials: Vec<f64>,
}

impl PressureSolver {
    /// A solver for `op` by `method`, stopping at relative residual `tolerance` or after
    /// `max_iterations` (sweeps or CG iterations). A tolerance of 0 (or `f64::MIN_POSITIVE`,
    /// which [`crate::mac::MacParams`] accepts) runs exactly `max_iterations` sweeps of Jacobi or
    /// Gauss-Seidel without residual checks, like the seed's fixed 20.
    ///
    /// # Errors
    /// [`FluidError::BadParameter`] for a negative or non-finite tolerance or zero iterations.
    pub fn new(
        op: Poisson,
        method: PressureMethod,
        tolerance: f64,
        max_iterations: usize,
    ) -> Result<Self, FluidError> {
        crate::error::non_negative("pressure tolerance", tolerance)?;
        if max_iterations == 0 {
            return Err(FluidError::BadParameter {
                name: "pressure max_iterations",
                requirement: "must be at least 1",
                value: "0".into(),
            });
        }
        let n = op.len();
        let mut levels = Vec::new();
        if method == PressureMethod::Mgpcg {
            let mut cur = op.clone();
            while let Some(c) = cur.coarsen() {
                let m = c.len();
                levels.push(Level {
                    op: c.clone(),
                    x: vec![0.0; m],
                    b: vec![0.0; m],
                    r: vec![0.0; m],
                    tmp: vec![0.0; m],
                });
                cur = c;
            }
            levels.insert(
                0,
                Level { op, x: vec![0.0; n], b: vec![0.0; n], r: vec![0.0; n], tmp: vec![0.0; n] },
            );
        } else {
            levels.push(Level { op, x: Vec::new(), b: Vec::new(), r: Vec::new(), tmp: vec![0.0; n] });
        }
        Ok(Self {
            method,
            tolerance,
            max_iterations,
            levels,
            r: vec![0.0; n],
            z: vec![0.0; n],
            p: vec![0.0; n],
            q: vec![0.0; n],
            b: vec![0.0; n],
            partials: vec![0.0; n.div_ceil(CHUNK) + 1],
        })
    }

    /// Rebinds the solver to new cell labels of the same grid: the operator and its multigrid
    /// hierarchy are rebuilt in their buffers, allocating nothing, and every buffer is cleared,
    /// so the solver is then exactly what [`PressureSolver::new`] builds for the new labels
    /// (the same solves, bit for bit).
    ///
    /// # Errors
    /// [`FluidError::BadLength`] if `labels` does not have one entry per cell; the solver is
    /// then unchanged.
    pub fn relabel(&mut self, labels: &[CellLabel]) -> Result<(), FluidError> {
        self.levels[0].op.relabel(labels)?;
        for l in 1..self.levels.len() {
            let (fine, coarse) = self.levels.split_at_mut(l);
            let (fine, coarse) = (&fine[l - 1].op, &mut coarse[0].op);
            fine.coarse_labels(coarse.dims, &mut coarse.labels);
            coarse.assemble();
        }
        for lv in &mut self.levels {
            for v in [&mut lv.x, &mut lv.b, &mut lv.r, &mut lv.tmp] {
                v.fill(0.0);
            }
        }
        for v in [&mut self.r, &mut self.z, &mut self.p, &mut self.q, &mut self.b, &mut self.partials] {
            v.fill(0.0);
        }
        Ok(())
    }

    /// The operator.
    #[must_use]
    pub fn operator(&self) -> &Poisson {
        &self.levels[0].op
    }

    /// The method.
    #[must_use]
    pub fn method(&self) -> PressureMethod {
        self.method
    }

    /// Number of multigrid levels (1 unless MGPCG).
    #[must_use]
    pub fn levels(&self) -> usize {
        self.levels.len()
    }

    /// Changes the tolerance and iteration cap.
    ///
    /// # Errors
    /// As [`PressureSolver::new`].
    pub fn set_tolerance(&mut self, tolerance: f64, max_iterations: usize) -> Result<(), FluidError> {
        crate::error::non_negative("pressure tolerance", tolerance)?;
        if max_iterations == 0 {
            return Err(FluidError::BadParameter {
                name: "pressure max_iterations",
                requirement: "must be at least 1",
                value: "0".into(),
            });
        }
        self.tolerance = tolerance;
        self.max_iterations = max_iterations;
        Ok(())
    }

    /// Solves `A s = rhs` for `s`, starting from the given `s` (non-fluid entries are set to 0).
    ///
    /// # Panics
    /// If `rhs` or `s` does not have one entry per cell (a programming error).
    #[track_caller]
    pub fn solve(&mut self, rhs: &[f64], s: &mut [f64]) -> SolveInfo {
        let n = self.levels[0].op.len();
        assert!(rhs.len() == n && s.len() == n, "pressure solve: arrays must have one entry per cell");
        // Right-hand side restricted to fluid cells, projected onto the range when singular.
        {
            let op = &self.levels[0].op;
            self.b.par_iter_mut().zip(rhs.par_iter()).zip(op.diag.par_iter()).for_each(|((b, &r), &d)| {
                *b = if d > 0.0 { r } else { 0.0 };
            });
            s.par_iter_mut().zip(op.diag.par_iter()).for_each(|(x, &d)| {
                if d <= 0.0 {
                    *x = 0.0;
                }
            });
            if op.singular {
                op.remove_mean(&mut self.b, &mut self.partials);
            }
        }
        let bnorm = max_abs(&self.b, &mut self.partials);
        if bnorm == 0.0 {
            s.fill(0.0);
            return SolveInfo { iterations: 0, residual: 0.0, converged: true };
        }
        match self.method {
            PressureMethod::Jacobi | PressureMethod::RedBlackGaussSeidel => self.relax(s, bnorm),
            PressureMethod::ConjugateGradient | PressureMethod::Mgpcg => self.pcg(s, bnorm),
        }
    }

    fn relative_residual(&mut self, s: &[f64], bnorm: f64) -> f64 {
        let op = &self.levels[0].op;
        op.residual(&self.b, s, &mut self.r);
        if op.singular {
            op.remove_mean(&mut self.r, &mut self.partials);
        }
        max_abs(&self.r, &mut self.partials) / bnorm
    }

    fn relax(&mut self, s: &mut [f64], bnorm: f64) -> SolveInfo {
        /// Sweeps between residual checks (even: Jacobi sweeps in pairs).
        const CHECK_EVERY: usize = 10;
        let fixed = self.tolerance <= f64::MIN_POSITIVE;
        let mut it = 0;
        while it < self.max_iterations {
            let Level { op, tmp, .. } = &mut self.levels[0];
            if self.method == PressureMethod::Jacobi {
                // Two sweeps per pass, `s -> tmp -> s`, so that no copy is needed; CHECK_EVERY is
                // even, so the residual is checked after the same sweeps as one at a time.
                op.jacobi_sweep(&self.b, s, tmp);
                it += 1;
                if it == self.max_iterations {
                    s.copy_from_slice(tmp);
                    break;
                }
                op.jacobi_sweep(&self.b, tmp, s);
                it += 1;
            } else {
                op.colour_sweep(0, &self.b, s, tmp);
                op.colour_sweep(1, &self.b, s, tmp);
                it += 1;
            }
            if !fixed && it % CHECK_EVERY == 0 && self.relative_residual(s, bnorm) <= self.tolerance {
                break;
            }
        }
        let op = &self.levels[0].op;
        if op.singular {
            op.remove_mean(s, &mut self.partials);
        }
        let residual = self.relative_residual(s, bnorm);
        SolveInfo { iterations: it, residual, converged: fixed || residual <= self.tolerance }
    }

    fn precondition(&mut self) {
        if self.method == PressureMethod::Mgpcg {
            self.levels[0].b.copy_from_slice(&self.r);
            v_cycle(&mut self.levels, 0);
            self.z.copy_from_slice(&self.levels[0].x);
            let op = &self.levels[0].op;
            if op.singular {
                op.remove_mean(&mut self.z, &mut self.partials);
            }
        } else {
            self.z.copy_from_slice(&self.r);
        }
    }

    fn pcg(&mut self, s: &mut [f64], bnorm: f64) -> SolveInfo {
        self.levels[0].op.residual(&self.b, s, &mut self.r);
        if self.levels[0].op.singular {
            self.levels[0].op.remove_mean(&mut self.r, &mut self.partials);
        }
        let mut residual = max_abs(&self.r, &mut self.partials) / bnorm;
        if residual <= self.tolerance {
            return SolveInfo { iterations: 0, residual, converged: true };
        }
        self.precondition();
        self.p.copy_from_slice(&self.z);
        let mut rz = dot(&self.r, &self.z, &mut self.partials);
        let mut it = 0;
        while it < self.max_iterations {
            self.levels[0].op.apply(&self.p, &mut self.q);
            let pq = dot(&self.p, &self.q, &mut self.partials);
            if !(pq > 0.0) {
                break;
            }
            let alpha = rz / pq;
            s.par_iter_mut().zip(self.p.par_iter()).for_each(|(x, &p)| *x += alpha * p);
            self.r.par_iter_mut().zip(self.q.par_iter()).for_each(|(r, &q)| *r -= alpha * q);
            it += 1;
            residual = max_abs(&self.r, &mut self.partials) / bnorm;
            if residual <= self.tolerance {
                break;
            }
            self.precondition();
            let rz_new = dot(&self.r, &self.z, &mut self.partials);
            let beta = rz_new / rz;
            rz = rz_new;
            self.p.par_iter_mut().zip(self.z.par_iter()).for_each(|(p, &z)| *p = z + beta * *p);
        }
        if self.levels[0].op.singular {
            self.levels[0].op.remove_mean(s, &mut self.partials);
        }
        // The recurrence residual drifts from the true one; report the true one.
        let true_residual = self.relative_residual(s, bnorm);
        SolveInfo { iterations: it, residual: true_residual, converged: residual <= self.tolerance }
    }
}

/// One V-cycle on `levels[l..]` for `levels[l].b`, result in `levels[l].x` (starting from 0).
fn v_cycle(levels: &mut [Level], l: usize) {
    let (head, tail) = levels.split_at_mut(l + 1);
    let lv = &mut head[l];
    lv.x.fill(0.0);
    if tail.is_empty() {
        for _ in 0..COARSE_SWEEPS {
            lv.op.colour_sweep(0, &lv.b, &mut lv.x, &mut lv.tmp);
            lv.op.colour_sweep(1, &lv.b, &mut lv.x, &mut lv.tmp);
            lv.op.colour_sweep(1, &lv.b, &mut lv.x, &mut lv.tmp);
            lv.op.colour_sweep(0, &lv.b, &mut lv.x, &mut lv.tmp);
        }
        return;
    }
    for _ in 0..SMOOTH {
        lv.op.colour_sweep(0, &lv.b, &mut lv.x, &mut lv.tmp);
        lv.op.colour_sweep(1, &lv.b, &mut lv.x, &mut lv.tmp);
    }
    lv.op.residual(&lv.b, &lv.x, &mut lv.r);
    // Restriction: coarse rhs = (4 / 2^dim) * sum of the children's residuals (h^2 scaling).
    let coarse = &mut tail[0];
    let [nx, ny, nz] = lv.op.dims;
    let [cx, cy, _] = coarse.op.dims;
    let three = lv.op.dim == 3;
    let scale = if three { 0.5 } else { 1.0 };
    coarse.b.par_chunks_mut(cx).enumerate().for_each(|(line, row)| {
        let (jc, kc) = (line % cy, line / cy);
        for (ic, bc) in row.iter_mut().enumerate() {
            let mut sum = 0.0;
            for dk in 0..if three { 2 } else { 1 } {
                let k = if three { 2 * kc + dk } else { 0 };
                if k >= nz {
                    continue;
                }
                for dj in 0..2 {
                    let j = 2 * jc + dj;
                    if j >= ny {
                        continue;
                    }
                    for di in 0..2 {
                        let i = 2 * ic + di;
                        if i < nx {
                            sum += lv.r[i + nx * (j + ny * k)];
                        }
                    }
                }
            }
            *bc = scale * sum;
        }
    });
    v_cycle(&mut levels[l + 1..], 0);
    let (head, tail) = levels.split_at_mut(l + 1);
    let lv = &mut head[l];
    let coarse = &tail[0];
    // Prolongation: piecewise constant.
    let diag = &lv.op.diag;
    lv.x.par_chunks_mut(nx).enumerate().for_each(|(line, row)| {
        let (j, k) = (line % ny, line / ny);
        let kc = if three { k / 2 } else { 0 };
        for (i, x) in row.iter_mut().enumerate() {
            if diag[i + nx * line] > 0.0 {
                *x += coarse.x[i / 2 + cx * (j / 2 + cy * kc)];
            }
        }
    });
    for _ in 0..SMOOTH {
        lv.op.colour_sweep(1, &lv.b, &mut lv.x, &mut lv.tmp);
        lv.op.colour_sweep(0, &lv.b, &mut lv.x, &mut lv.tmp);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn box_problem(n: usize, dim: usize, open_top: bool) -> Poisson {
        let dims = if dim == 2 { [n, n, 1] } else { [n, n, n] };
        let cells = dims[0] * dims[1] * dims[2];
        let mut labels = vec![CellLabel::Fluid; cells];
        // A solid block in the middle.
        for k in 0..dims[2] {
            for j in n / 3..n / 2 {
                for i in n / 3..n / 2 {
                    labels[i + n * (j + n * k)] = CellLabel::Solid;
                }
            }
        }
        let mut open = [[false; 2]; 3];
        open[1][1] = open_top;
        Poisson::new(dims, dim, labels, open).unwrap()
    }

    fn rhs(op: &Poisson) -> Vec<f64> {
        (0..op.len()).map(|c| ((c * 7919) % 97) as f64 / 97.0 - 0.5).collect()
    }

    /// Labels of a free-surface problem on `dims`: solid border, fluid below `level` cells
    /// (shifted by `tilt` per column), air above.
    fn pool(dims: [usize; 3], level: usize, tilt: usize) -> Vec<CellLabel> {
        let mut labels = vec![CellLabel::Air; dims[0] * dims[1] * dims[2]];
        for (c, l) in labels.iter_mut().enumerate() {
            let (i, j, k) = (c % dims[0], (c / dims[0]) % dims[1], c / (dims[0] * dims[1]));
            let border = |x: usize, n: usize| n > 1 && (x == 0 || x + 1 == n);
            if border(i, dims[0]) || border(j, dims[1]) || border(k, dims[2]) {
                *l = CellLabel::Solid;
            } else if j < level + (i * tilt) / dims[0] {
                *l = CellLabel::Fluid;
            }
        }
        labels
    }

    /// A solver relabelled in place is the solver built for the new labels: every method gives
    /// the same solution, bit for bit, and the operators are equal.
    #[test]
    fn relabelling_in_place_equals_building_anew() {
        for dims in [[20, 17, 1], [9, 10, 8]] {
            let dim = if dims[2] == 1 { 2 } else { 3 };
            let (first, second) = (pool(dims, 6, 0), pool(dims, 4, 5));
            for method in PressureMethod::ALL {
                let op = Poisson::new(dims, dim, first.clone(), [[false; 2]; 3]).unwrap();
                let mut reused = PressureSolver::new(op, method, 1e-9, 5000).unwrap();
                let b = rhs(reused.operator());
                let mut s = vec![0.0; b.len()];
                reused.solve(&b, &mut s);
                reused.relabel(&second).unwrap();
                let op = Poisson::new(dims, dim, second.clone(), [[false; 2]; 3]).unwrap();
                let mut fresh = PressureSolver::new(op, method, 1e-9, 5000).unwrap();
                assert_eq!(reused.levels(), fresh.levels());
                for (a, f) in reused.levels.iter().zip(&fresh.levels) {
                    assert_eq!(
                        (&a.op.labels, &a.op.diag, &a.op.fluid_nbrs),
                        (&f.op.labels, &f.op.diag, &f.op.fluid_nbrs)
                    );
                    assert_eq!(a.op.singular, f.op.singular);
                }
                let (mut x, mut y) = (vec![0.0; b.len()], vec![0.0; b.len()]);
                let (i, j) = (reused.solve(&b, &mut x), fresh.solve(&b, &mut y));
                assert!(i.converged && i.iterations > 0, "{method:?} {dims:?}: {i:?}");
                assert_eq!(i, j, "{method:?} {dims:?}");
                assert!(x.iter().zip(&y).all(|(p, q)| p.to_bits() == q.to_bits()), "{method:?} {dims:?}");
            }
        }
        let mut op = box_problem(8, 2, true);
        let before = op.labels().to_vec();
        assert!(matches!(op.relabel(&before[1..]), Err(FluidError::BadLength { got: 63, expected: 64, .. })));
        assert_eq!(op.labels(), before);
    }

    /// Every method solves the same system: the residual it reports is the true one, and the
    /// solutions agree with each other.
    #[test]
    fn all_methods_reach_tolerance_and_agree() {
        for (dim, n) in [(2, 24), (3, 10)] {
            for open_top in [false, true] {
                let op = box_problem(n, dim, open_top);
                let b = rhs(&op);
                let mut reference: Option<Vec<f64>> = None;
                for method in [
                    PressureMethod::ConjugateGradient,
                    PressureMethod::Mgpcg,
                    PressureMethod::RedBlackGaussSeidel,
                    PressureMethod::Jacobi,
                ] {
                    let mut solver = PressureSolver::new(op.clone(), method, 1e-9, 200_000).unwrap();
                    let mut s = vec![0.0; op.len()];
                    let info = solver.solve(&b, &mut s);
                    assert!(info.converged && info.residual <= 1e-9, "{method:?} dim {dim}: {info:?}");
                    // Independent residual check.
                    let mut bb = b.clone();
                    for (c, v) in bb.iter_mut().enumerate() {
                        if op.diag[c] == 0.0 {
                            *v = 0.0;
                        }
                    }
                    if op.singular {
                        let fluid: Vec<usize> = (0..op.len()).filter(|&c| op.diag[c] > 0.0).collect();
                        let mean = fluid.iter().map(|&c| bb[c]).sum::<f64>() / fluid.len() as f64;
                        fluid.iter().for_each(|&c| bb[c] -= mean);
                    }
                    let mut y = vec![0.0; op.len()];
                    op.apply(&s, &mut y);
                    let bmax = bb.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                    let rmax = y.iter().zip(&bb).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
                    assert!(rmax / bmax <= 1.01e-9, "{method:?}: {}", rmax / bmax);
                    match &reference {
                        None => reference = Some(s),
                        Some(r) => {
                            let d = r.iter().zip(&s).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
                            assert!(d < 1e-5, "{method:?} differs from CG by {d}");
                        }
                    }
                }
            }
        }
    }

    /// A fixed number of Jacobi sweeps, odd or even (the solver sweeps in pairs), matches a
    /// textbook damped Jacobi written out here cell by cell from the labels.
    #[test]
    fn jacobi_sweeps_match_a_textbook_iteration() {
        for open_top in [false, true] {
            let n = 12;
            let op = box_problem(n, 2, open_top);
            let labels = op.labels().to_vec();
            let fluid = |i: isize, j: isize| -> Option<CellLabel> {
                if i < 0 || j < 0 || i >= n as isize {
                    return Some(CellLabel::Solid);
                }
                if j >= n as isize {
                    return Some(if open_top { CellLabel::Air } else { CellLabel::Solid });
                }
                Some(labels[i as usize + n * j as usize])
            };
            let mut b = rhs(&op);
            let cells: Vec<usize> = (0..op.len()).filter(|&c| labels[c] == CellLabel::Fluid).collect();
            let mean = |x: &[f64]| cells.iter().map(|&c| x[c]).sum::<f64>() / cells.len() as f64;
            for (c, v) in b.iter_mut().enumerate() {
                if labels[c] != CellLabel::Fluid {
                    *v = 0.0;
                }
            }
            if !open_top {
                let m = mean(&b);
                cells.iter().for_each(|&c| b[c] -= m);
            }
            for sweeps in 1..=7 {
                let mut x = vec![0.0; op.len()];
                for _ in 0..sweeps {
                    let mut next = vec![0.0; op.len()];
                    for &c in &cells {
                        let (i, j) = ((c % n) as isize, (c / n) as isize);
                        let (mut diag, mut sum) = (0.0, 0.0);
                        for (di, dj) in [(-1, 0), (1, 0), (0, -1), (0, 1)] {
                            match fluid(i + di, j + dj) {
                                Some(CellLabel::Fluid) => {
                                    diag += 1.0;
                                    sum += x[(i + di) as usize + n * (j + dj) as usize];
                                }
                                Some(CellLabel::Air) => diag += 1.0,
                                _ => {}
                            }
                        }
                        next[c] = (1.0 - JACOBI_WEIGHT) * x[c] + JACOBI_WEIGHT * (b[c] + sum) / diag;
                    }
                    x = next;
                }
                if !open_top {
                    let m = mean(&x);
                    cells.iter().for_each(|&c| x[c] -= m);
                }
                let mut solver =
                    PressureSolver::new(op.clone(), PressureMethod::Jacobi, 0.0, sweeps).unwrap();
                let mut s = vec![0.0; op.len()];
                let info = solver.solve(&rhs(&op), &mut s);
                assert_eq!(info.iterations, sweeps);
                let d = s.iter().zip(&x).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
                assert!(d < 1e-13, "{sweeps} sweeps, open top {open_top}: differs by {d}");
            }
        }
    }

    #[test]
    fn mgpcg_iterations_nearly_independent_of_resolution() {
        let mut its = Vec::new();
        for n in [32, 64, 128] {
            let op = box_problem(n, 2, false);
            let b = rhs(&op);
            let mut solver = PressureSolver::new(op, PressureMethod::Mgpcg, 1e-8, 1000).unwrap();
            let mut s = vec![0.0; b.len()];
            its.push(solver.solve(&b, &mut s).iterations);
        }
        assert!(its[2] <= its[0] * 2, "{its:?}");
    }

    #[test]
    fn bitwise_identical_across_thread_counts() {
        let op = box_problem(40, 2, true);
        let b = rhs(&op);
        let run = |threads: usize, method| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let mut solver = PressureSolver::new(op.clone(), method, 1e-10, 10_000).unwrap();
                let mut s = vec![0.0; b.len()];
                solver.solve(&b, &mut s);
                s.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
            })
        };
        for method in PressureMethod::ALL {
            assert_eq!(run(1, method), run(3, method), "{method:?}");
        }
    }

    #[test]
    fn rejects_bad_labels() {
        assert!(matches!(
            Poisson::new([4, 4, 1], 2, vec![CellLabel::Fluid; 15], [[false; 2]; 3]),
            Err(FluidError::BadLength { .. })
        ));
        assert!(matches!(
            Poisson::new([0, 4, 1], 2, vec![], [[false; 2]; 3]),
            Err(FluidError::BadGrid { .. })
        ));
    }
}
