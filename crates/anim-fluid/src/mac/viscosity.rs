//! Implicit viscosity: the *diffuse* step of stable fluids (Stam 1999), `du/dt = nu Lap u`, by backward Euler.
//!
//! Each velocity component solves, on its own face lattice,
//!
//! ```text
//! (I - nu dt Lap) u = u*,   i.e.   (1 + kappa m) u_f - kappa sum_nb u_nb = u*_f,   kappa = nu dt / h^2
//! ```
//!
//! with `m` the number of neighbour terms: unconditionally stable at any `nu dt / h^2`, as Stam's
//! (1999) diffusion and his `diffuse` routine (2003) are, but solved here to convergence rather than by a fixed
//! number of Gauss-Seidel sweeps. The unknowns are the free faces; faces fixed by a wall or an
//! obstacle (and the normal faces of the domain) are known values that move to the right-hand
//! side. Beyond the domain in a tangential direction a no-slip wall of velocity `u_wall` half a
//! cell away is the ghost value `u_ghost = 2 u_wall - u`, adding `2 kappa` to the diagonal and
//! `2 kappa u_wall` to the right-hand side; free-slip and open walls have no term (zero normal
//! derivative).
//!
//! The system is symmetric positive definite; it is solved by conjugate gradients
//! preconditioned by its diagonal (Jacobi), from `u*`, to a relative max-norm residual of
//! `1e-10` within 500 iterations. Products and updates run over rows in parallel and the dot
//! products are summed over fixed chunks in order ([`crate::pressure`]'s reductions), so the
//! result does not depend on the number of threads.

use crate::error::FluidError;
use crate::mac::grid::{MacGrid, idx};
use rayon::prelude::*;

/// The viscosity solve and its conjugate-gradient buffers, sized by the solver's constructor.
#[derive(Debug, Clone)]
pub(super) struct ImplicitViscosity {
    /// Residual, preconditioned residual, search direction, operator times direction, diagonal.
    cg: [Vec<f64>; 5],
    /// Per-chunk partial sums of the reductions.
    partials: Vec<f64>,
}

impl ImplicitViscosity {
    /// Buffers for `grid`.
    pub(super) fn new(grid: &MacGrid) -> Self {
        let max_len = grid.max_len();
        Self {
            cg: [
                vec![0.0; max_len],
                vec![0.0; max_len],
                vec![0.0; max_len],
                vec![0.0; max_len],
                vec![0.0; max_len],
            ],
            partials: vec![0.0; max_len.div_ceil(crate::pressure::CHUNK) + 1],
        }
    }

    /// Backward-Euler viscosity `(I - nu dt Lap) u = u*` per component of `vel` by
    /// Jacobi-preconditioned CG; returns the iterations of all components.
    ///
    /// # Errors
    /// [`FluidError::NotConverged`] naming `step` when a component misses the tolerance and
    /// `require_convergence` is set.
    pub(super) fn solve(
        &mut self,
        grid: &MacGrid,
        nu: f64,
        require_convergence: bool,
        vel: &mut [Vec<f64>; 3],
        dt: f64,
        step: u64,
    ) -> Result<usize, FluidError> {
        let kappa = nu * dt / (grid.h * grid.h);
        let mut total = 0;
        for a in 0..grid.dim {
            let fd = grid.face_dims(a);
            let n = vel[a].len();
            let [mut r, mut z, mut p, mut q, mut dg] = std::mem::take(&mut self.cg);
            let mut partials = std::mem::take(&mut self.partials);
            // Neighbour classification shared by the operator and the right-hand side.
            let walls = grid.wall_values(a);
            // Returns (diag, sum of free neighbours of x, known contribution) for face f.
            let stencil = |x: &[f64], i: usize, j: usize, k: usize| -> (f64, f64, f64) {
                let n3 = [i, j, k];
                let stride = [1, fd[0], fd[0] * fd[1]];
                let f = idx(fd, i, j, k);
                let (mut diag, mut free, mut known) = (1.0, 0.0, 0.0);
                for b in 0..grid.dim {
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
                        if grid.face_fixed(a, m[0], m[1], m[2]) || (m[a] == 0 || m[a] == grid.dims[a]) {
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
                !(grid.face_fixed(a, i, j, k) || n3[a] == 0 || n3[a] == grid.dims[a])
            };
            let u = &vel[a];
            // r = b - A u with b = u* + known, starting from x = u*.
            r[..n]
                .par_chunks_mut(fd[0])
                .zip(z[..n].par_chunks_mut(fd[0]).zip(dg[..n].par_chunks_mut(fd[0])))
                .enumerate()
                .with_min_len(crate::grain::lines(fd[0], crate::grain::WIDE_STENCIL_NS))
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
            r[..n]
                .par_iter_mut()
                .zip(z[..n].par_iter_mut())
                .zip(q[..n].par_iter())
                .with_min_len(crate::grain::ENTRIES)
                .for_each(|((rr, zz), _)| {
                    *rr -= *zz;
                    *zz = 0.0;
                });
            z[..n]
                .par_iter_mut()
                .zip(r[..n].par_iter().zip(dg[..n].par_iter()))
                .with_min_len(crate::grain::ENTRIES)
                .for_each(|(zz, (&rr, &d))| {
                    *zz = if d > 0.0 { rr / d } else { 0.0 };
                });
            let mut dotp = |x: &[f64], y: &[f64]| crate::pressure::dot(x, y, &mut partials);
            p[..n].copy_from_slice(&z[..n]);
            let mut rz = dotp(&r[..n], &z[..n]);
            let mut x = std::mem::take(&mut vel[a]);
            let mut it = 0;
            let tol = 1e-10;
            let mut res = r[..n].iter().fold(0.0f64, |m, v| m.max(v.abs())) / bnorm;
            while res > tol && it < 500 {
                q[..n]
                    .par_chunks_mut(fd[0])
                    .enumerate()
                    .with_min_len(crate::grain::lines(fd[0], crate::grain::WIDE_STENCIL_NS))
                    .for_each(|(line, qq)| {
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
                x.par_iter_mut()
                    .zip(p[..n].par_iter())
                    .with_min_len(crate::grain::ENTRIES)
                    .for_each(|(x, &p)| *x += alpha * p);
                r[..n]
                    .par_iter_mut()
                    .zip(q[..n].par_iter())
                    .with_min_len(crate::grain::ENTRIES)
                    .for_each(|(r, &q)| *r -= alpha * q);
                it += 1;
                res = r[..n].iter().fold(0.0f64, |m, v| m.max(v.abs())) / bnorm;
                z[..n]
                    .par_iter_mut()
                    .zip(r[..n].par_iter().zip(dg[..n].par_iter()))
                    .with_min_len(crate::grain::ENTRIES)
                    .for_each(|(zz, (&rr, &d))| {
                        *zz = if d > 0.0 { rr / d } else { 0.0 };
                    });
                let rz_new = dotp(&r[..n], &z[..n]);
                let beta = rz_new / rz;
                rz = rz_new;
                p[..n]
                    .par_iter_mut()
                    .zip(z[..n].par_iter())
                    .with_min_len(crate::grain::ENTRIES)
                    .for_each(|(p, &z)| *p = z + beta * *p);
            }
            vel[a] = x;
            self.partials = partials;
            self.cg = [r, z, p, q, dg];
            total += it;
            if res > tol && require_convergence {
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
}
