//! The multigrid hierarchy of the MGPCG preconditioner (McAdams, Sifakis and Teran 2010, "A
//! parallel multigrid Poisson solver for fluids simulation on large grids").
//!
//! Cell-centred coarsening halves every axis (rounding up) until an extent would fall below 2
//! cells. A coarse cell is air if any of its children is air, else fluid if any child is fluid,
//! else solid: air wins because losing a Dirichlet cell would make the coarse problem singular
//! where the fine one is not. The operator is rediscretised on each level from these labels
//! (not the Galerkin product), which keeps every level a 5- or 7-point stencil.
//!
//! One V-cycle for `A x = b` starting from `x = 0`:
//!
//! 1. pre-smooth with [`SMOOTH`] red-black Gauss-Seidel sweeps (red then black);
//! 2. restrict the residual `r = b - A x`: the coarse right-hand side is the sum of the
//!    children's residuals times `4 / 2^dim` (the `h^2` scaling of the coarse operator);
//! 3. recurse; on the coarsest level, [`COARSE_SWEEPS`] symmetric sweep pairs instead;
//! 4. prolong the coarse correction piecewise constantly onto the fluid cells;
//! 5. post-smooth with the same sweeps in the reverse colour order (black then red).
//!
//! Restriction is the scaled transpose of prolongation and the smoothing is mirrored, so the
//! cycle is a symmetric linear operator, as conjugate gradients require of a preconditioner.

use super::poisson::{CellLabel, Poisson};
use rayon::prelude::*;

/// One multigrid level: its operator and buffers.
#[derive(Debug, Clone)]
pub(super) struct Level {
    pub(super) op: Poisson,
    pub(super) x: Vec<f64>,
    pub(super) b: Vec<f64>,
    pub(super) r: Vec<f64>,
    pub(super) tmp: Vec<f64>,
}

/// Pre- and post-smoothing sweeps (each a red and a black half-sweep) of the V-cycle.
const SMOOTH: usize = 2;
/// Symmetric sweep pairs on the coarsest level.
const COARSE_SWEEPS: usize = 20;

/// One V-cycle on `levels[l..]` for `levels[l].b`, result in `levels[l].x` (starting from 0).
pub(super) fn v_cycle(levels: &mut [Level], l: usize) {
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
    coarse
        .b
        .par_chunks_mut(cx)
        .enumerate()
        .with_min_len(crate::grain::lines(cx, crate::grain::STENCIL_NS))
        .for_each(|(line, row)| {
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
    lv.x.par_chunks_mut(nx)
        .enumerate()
        .with_min_len(crate::grain::lines(nx, crate::grain::STENCIL_NS))
        .for_each(|(line, row)| {
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

/// Coarsening of the labelled operator.
impl Poisson {
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
    pub(super) fn coarse_labels(&self, cd: [usize; 3], labels: &mut [CellLabel]) {
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
    pub(super) fn coarsen(&self) -> Option<Poisson> {
        let cd = self.coarse_dims()?;
        let mut labels = vec![CellLabel::Solid; cd[0] * cd[1] * cd[2]];
        self.coarse_labels(cd, &mut labels);
        Poisson::new(cd, self.dim, labels, self.open).ok()
    }
}
