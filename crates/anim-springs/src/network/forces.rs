//! Forces and Jacobians of a spring network: the per-spring kernels and the two-pass parallel
//! evaluation behind anim-core's [`SecondOrderSystem`] and [`MechanicalSystem`].
//!
//! Per spring `s = (i, j)` with `d = x_i - x_j`, `L = |d|`, `n = d / L`:
//!
//! ```text
//! f_s = -k (L - l) n - c ((v_i - v_j) . n) n          force on i; j takes -f_s
//! K_s = -k [ t (I - n n^T) + n n^T ]                   t = 1 - l/L, clamped at 0 by the
//!                                                       definiteness fix (t = 1 when l = 0)
//! D_s = -c n n^T
//! ```
//!
//! The force is evaluated in two passes, per spring into a buffer and then per particle through
//! the incidence list in its fixed order; the Jacobian product, diagonal and assembly work per
//! particle from the per-spring blocks of the last linearisation, so no float is ever added by
//! two threads and every result is independent of the thread count. The parent module's docs
//! derive the blocks, the definiteness fix and the coincident-endpoint fallback.

use super::model::SpringModel;
use super::{CHUNK, JacobianMode, PARALLEL_THRESHOLD, Pattern, SpringNetwork, for_chunks, load};
use crate::geom::{MIN_LENGTH, outer};
use anim_core::glam::{DMat3, DVec3};
use anim_core::integrate::{MechanicalSystem, SecondOrderSystem};
use anim_core::linalg::CsrMatrix;
use anim_core::par::prelude::*;
use std::sync::atomic::Ordering;

impl SpringModel {
    /// The direction used when a spring's endpoints coincide.
    #[cold]
    fn fallback_direction(&self, s: usize) -> DVec3 {
        let sp = &self.springs[s];
        let d = DVec3::from_array(self.rest_positions[sp.i]) - DVec3::from_array(self.rest_positions[sp.j]);
        let len = d.length();
        if len > MIN_LENGTH && len.is_finite() { d / len } else { DVec3::X }
    }

    /// Direction and length of spring `s` at positions `x`.
    #[inline]
    fn frame(&self, s: usize, x: &[f64]) -> (DVec3, f64) {
        let [i, j] = self.ends[s];
        let d = load(x, i as usize) - load(x, j as usize);
        let len = d.length();
        if len > MIN_LENGTH { (d * (1.0 / len), len) } else { (self.fallback_direction(s), len) }
    }

    /// Force of spring `s` on its particle `i`.
    #[inline]
    fn spring_force(&self, s: usize, x: &[f64], v: &[f64]) -> DVec3 {
        let [i, j] = self.ends[s];
        let (i, j) = (i as usize, j as usize);
        let [rest, k, c] = self.params[s];
        let d = load(x, i) - load(x, j);
        let u = load(v, i) - load(v, j);
        let len = d.length();
        // One division instead of three: the kernel is bound by divisions and square roots.
        let n = if len > MIN_LENGTH { d * (1.0 / len) } else { self.fallback_direction(s) };
        if rest == 0.0 {
            // Zero rest length: f = -k d exactly, no direction needed but for the damping.
            return -k * d - c * n.dot(u) * n;
        }
        -(k * (len - rest) + c * n.dot(u)) * n
    }

    /// Linearisation of spring `s`: `[n, alpha, beta, c]` of the definite (or, for
    /// [`JacobianMode::Exact`], the undamped exact) `K_s = alpha I + beta n n^T`, and the exact
    /// `K_s` including the damping's position derivative when `exact`.
    #[inline]
    fn spring_jacobian(&self, s: usize, x: &[f64], v: &[f64], exact: bool) -> ([f64; 6], DMat3) {
        let [rest, k, c] = self.params[s];
        let (n, len) = self.frame(s, x);
        // K_s = -k [t (I - n n^T) + n n^T] = -k t I - k (1 - t) n n^T.
        let transverse = if rest == 0.0 {
            1.0
        } else {
            let t = 1.0 - rest / len.max(MIN_LENGTH);
            if exact { t } else { t.max(0.0) }
        };
        let (alpha, beta) = (-k * transverse, -k * (1.0 - transverse));
        let lin = [n.x, n.y, n.z, alpha, beta, c];
        if !exact {
            return (lin, DMat3::ZERO);
        }
        let nn = outer(n, n);
        let mut full = alpha * DMat3::IDENTITY + beta * nn;
        if c != 0.0 && len > MIN_LENGTH {
            let [i, j] = self.ends[s];
            let u = load(v, i as usize) - load(v, j as usize);
            let proj = DMat3::IDENTITY - nn;
            full -= (c / len) * (outer(n, proj * u) + n.dot(u) * proj);
        }
        (lin, full)
    }

    /// Sum of collider forces on particle `p`.
    #[inline]
    fn contact_force(&self, xp: DVec3, vp: DVec3) -> DVec3 {
        let mut f = DVec3::ZERO;
        for c in &self.colliders {
            f += c.force(xp, vp);
        }
        for c in &self.mesh_colliders {
            f += c.force(xp, vp);
        }
        f
    }
}

impl SpringNetwork {
    fn build_pattern(&self) -> Option<Pattern> {
        let model = &self.model;
        let n = model.particles.len();
        let mut block_start = Vec::with_capacity(n + 1);
        let mut nblocks = Vec::with_capacity(n);
        let mut diag_slot = Vec::with_capacity(n);
        let mut inc_slot = vec![0usize; model.inc.len()];
        let mut row_ptr = Vec::with_capacity(3 * n + 1);
        let mut col_idx = Vec::new();
        row_ptr.push(0);
        let mut cols = Vec::new();
        for p in 0..n {
            cols.clear();
            cols.push(p);
            cols.extend(model.inc[model.inc_ptr[p]..model.inc_ptr[p + 1]].iter().map(|e| e.other()));
            cols.sort_unstable();
            cols.dedup();
            block_start.push(col_idx.len());
            nblocks.push(cols.len());
            diag_slot.push(cols.binary_search(&p).ok()?);
            for e in model.inc_ptr[p]..model.inc_ptr[p + 1] {
                inc_slot[e] = cols.binary_search(&model.inc[e].other()).ok()?;
            }
            for _ in 0..3 {
                for &q in &cols {
                    col_idx.extend_from_slice(&[3 * q, 3 * q + 1, 3 * q + 2]);
                }
                row_ptr.push(col_idx.len());
            }
        }
        block_start.push(col_idx.len());
        let values = vec![0.0; col_idx.len()];
        let matrix = CsrMatrix::try_from_parts(3 * n, 3 * n, row_ptr, col_idx, values).ok()?;
        Some(Pattern { matrix, block_start, nblocks, diag_slot, inc_slot })
    }

    /// Writes the force (or, with `accel`, the acceleration `M^-1 f`) in two passes: per-spring
    /// forces into a buffer, then a per-particle gather in a fixed order (see the module docs).
    fn evaluate(&mut self, x: &[f64], v: &[f64], out: &mut [f64], accel: bool) {
        let model = &self.model;

        let m = model.springs.len();
        for_chunks(&mut self.data.spring_force, CHUNK, m > PARALLEL_THRESHOLD, |first, out| {
            for (k, fs) in out.iter_mut().enumerate() {
                *fs = model.spring_force(first + k, x, v);
            }
        });
        let spring_force = &self.data.spring_force;
        let n = model.particles.len();
        for_chunks(out, 3 * CHUNK, n > PARALLEL_THRESHOLD, |first, out| {
            for (k, fp) in out.chunks_exact_mut(3).enumerate() {
                let p = first / 3 + k;
                // Springs pull p as their `i` with +f_s, as their `j` with -f_s.
                let mut plus = DVec3::ZERO;
                for e in &model.inc[model.inc_ptr[p]..model.inc_mid[p]] {
                    plus += spring_force[e.spring()];
                }
                let mut minus = DVec3::ZERO;
                for e in &model.inc[model.inc_mid[p]..model.inc_ptr[p + 1]] {
                    minus += spring_force[e.spring()];
                }
                let mut acc = model.particles[p].mass * model.gravity + (plus - minus);
                if model.has_contact() {
                    acc += model.contact_force(load(x, p), load(v, p));
                }
                if accel {
                    // A pinned particle (zero inverse mass) does not accelerate, whatever the
                    // force: `0 * inf` would otherwise put a NaN on a particle that cannot move.
                    let w = model.inv_mass[p];
                    acc = if w == 0.0 { DVec3::ZERO } else { acc * w };
                }
                fp[0] = acc.x;
                fp[1] = acc.y;
                fp[2] = acc.z;
            }
        });
    }

    /// `c_x K_s + c_v D_s` for spring `s` from the last linearisation.
    #[inline]
    fn block(&self, s: usize, c_x: f64, c_v: f64) -> DMat3 {
        let [nx, ny, nz, alpha, beta, c] = self.data.lin[s];
        let nn = outer(DVec3::new(nx, ny, nz), DVec3::new(nx, ny, nz));
        if self.data.mode == JacobianMode::Exact {
            c_x * self.data.k_exact[s] - (c_v * c) * nn
        } else {
            (c_x * alpha) * DMat3::IDENTITY + (c_x * beta - c_v * c) * nn
        }
    }
}

impl SecondOrderSystem for SpringNetwork {
    fn dof(&self) -> usize {
        3 * self.model.particles.len()
    }

    fn acceleration(&mut self, _t: f64, x: &[f64], v: &[f64], a: &mut [f64]) {
        self.evaluate(x, v, a, true);
    }

    fn energy(&mut self, _t: f64, x: &[f64], v: &[f64]) -> Option<f64> {
        Some(self.energy_parts(x, v).total())
    }

    fn energy_parts(&mut self, _t: f64, x: &[f64], v: &[f64]) -> Option<anim_core::solver::EnergyParts> {
        Some(self.energy_parts(x, v).split())
    }
}

impl MechanicalSystem for SpringNetwork {
    fn inverse_mass(&self, w: &mut [f64]) {
        for (p, &wp) in self.model.inv_mass.iter().enumerate() {
            w[3 * p] = wp;
            w[3 * p + 1] = wp;
            w[3 * p + 2] = wp;
        }
    }

    fn force(&mut self, _t: f64, x: &[f64], v: &[f64], f: &mut [f64]) {
        self.evaluate(x, v, f, false);
    }

    fn linearize(&mut self, _t: f64, x: &[f64], v: &[f64]) {
        let model = &self.model;
        let mode = self.data.mode;
        let exact = mode == JacobianMode::Exact;
        let m = model.springs.len();
        let data = &mut self.data;
        if exact {
            for (s, (l, k)) in data.lin.iter_mut().zip(data.k_exact.iter_mut()).enumerate() {
                (*l, *k) = model.spring_jacobian(s, x, v, true);
            }
        } else {
            for_chunks(&mut data.lin, CHUNK, m > PARALLEL_THRESHOLD, |first, out| {
                for (k, l) in out.iter_mut().enumerate() {
                    *l = model.spring_jacobian(first + k, x, v, false).0;
                }
            });
        }
        if model.has_contact() {
            let exact = mode == JacobianMode::Exact;
            let n = model.particles.len();
            let work = |p: usize, kc: &mut DMat3, dc: &mut DMat3| {
                *kc = DMat3::ZERO;
                *dc = DMat3::ZERO;
                for c in &model.colliders {
                    c.jacobians(load(x, p), load(v, p), exact, kc, dc);
                }
                for c in &model.mesh_colliders {
                    c.jacobians(load(x, p), load(v, p), exact, kc, dc);
                }
            };
            if n > PARALLEL_THRESHOLD {
                data.contact_k
                    .par_iter_mut()
                    .zip(data.contact_d.par_iter_mut())
                    .enumerate()
                    .for_each(|(p, (kc, dc))| work(p, kc, dc));
            } else {
                for (p, (kc, dc)) in data.contact_k.iter_mut().zip(data.contact_d.iter_mut()).enumerate() {
                    work(p, kc, dc);
                }
            }
        }
    }

    fn jacobian_apply(&self, c_x: f64, c_v: f64, dx: &[f64], out: &mut [f64]) {
        let model = &self.model;
        let data = &self.data;
        let n = model.particles.len();
        let contacts = !data.contact_k.is_empty();
        let exact = data.mode == JacobianMode::Exact;
        for_chunks(out, 3 * CHUNK, n > PARALLEL_THRESHOLD, |first, out| {
            for (k, op) in out.chunks_exact_mut(3).enumerate() {
                let p = first / 3 + k;
                let xp = load(dx, p);
                let mut acc = DVec3::ZERO;
                for e in &model.inc[model.inc_ptr[p]..model.inc_ptr[p + 1]] {
                    let s = e.spring();
                    let u = xp - load(dx, e.other());
                    let [nx, ny, nz, alpha, beta, c] = data.lin[s];
                    let nd = DVec3::new(nx, ny, nz);
                    if exact {
                        acc += c_x * (data.k_exact[s] * u) - (c_v * c * nd.dot(u)) * nd;
                    } else {
                        // (c_x K_s + c_v D_s) u = c_x alpha u + (c_x beta - c_v c)(n . u) n.
                        acc += (c_x * alpha) * u + ((c_x * beta - c_v * c) * nd.dot(u)) * nd;
                    }
                }
                if contacts {
                    acc += c_x * (data.contact_k[p] * xp) + c_v * (data.contact_d[p] * xp);
                }
                op[0] = acc.x;
                op[1] = acc.y;
                op[2] = acc.z;
            }
        });
    }

    fn jacobian_diagonal(&self, c_x: f64, c_v: f64, out: &mut [f64]) -> bool {
        let model = &self.model;
        let data = &self.data;
        let n = model.particles.len();
        let contacts = !data.contact_k.is_empty();
        for_chunks(out, 3 * CHUNK, n > PARALLEL_THRESHOLD, |first, out| {
            for (k, op) in out.chunks_exact_mut(3).enumerate() {
                let p = first / 3 + k;
                let mut acc = DVec3::ZERO;
                for e in &model.inc[model.inc_ptr[p]..model.inc_ptr[p + 1]] {
                    let b = self.block(e.spring(), c_x, c_v);
                    acc += DVec3::new(b.x_axis.x, b.y_axis.y, b.z_axis.z);
                }
                if contacts {
                    let b = c_x * data.contact_k[p] + c_v * data.contact_d[p];
                    acc += DVec3::new(b.x_axis.x, b.y_axis.y, b.z_axis.z);
                }
                op[0] = acc.x;
                op[1] = acc.y;
                op[2] = acc.z;
            }
        });
        true
    }

    fn jacobian_assemble(&self, c_x: f64, c_v: f64, out: &mut CsrMatrix) -> bool {
        let Some(pattern) = self.data.pattern.get_or_init(|| self.build_pattern()).as_ref() else {
            return false;
        };
        let address = out.col_idx().as_ptr() as usize;
        let same = out.nrows() == pattern.matrix.nrows()
            && out.ncols() == pattern.matrix.ncols()
            && out.row_ptr() == pattern.matrix.row_ptr()
            && (address == self.data.checked_pattern.load(Ordering::Relaxed)
                || out.col_idx() == pattern.matrix.col_idx());
        if !same {
            *out = pattern.matrix.clone();
        }
        self.data.checked_pattern.store(out.col_idx().as_ptr() as usize, Ordering::Relaxed);
        let model = &self.model;
        let data = &self.data;
        let n = model.particles.len();
        let contacts = !data.contact_k.is_empty();
        let fill = |p: usize, row: &mut [f64]| {
            row.iter_mut().for_each(|v| *v = 0.0);
            let width = 3 * pattern.nblocks[p];
            let diag = pattern.diag_slot[p];
            for e in model.inc_ptr[p]..model.inc_ptr[p + 1] {
                let b = self.block(model.inc[e].spring(), c_x, c_v);
                add_block(row, width, diag, &b, 1.0);
                add_block(row, width, pattern.inc_slot[e], &b, -1.0);
            }
            if contacts {
                let b = c_x * data.contact_k[p] + c_v * data.contact_d[p];
                add_block(row, width, diag, &b, 1.0);
            }
        };
        for_block_rows(out.values_mut(), &pattern.block_start, 0, n, n > PARALLEL_THRESHOLD, &fill);
        true
    }
}

/// Runs `f(p, values of block row p)` for particles `lo..hi`, splitting `values` at the block-row
/// boundaries `bounds` and recursing in parallel (no allocation).
fn for_block_rows(
    values: &mut [f64],
    bounds: &[usize],
    lo: usize,
    hi: usize,
    parallel: bool,
    f: &(impl Fn(usize, &mut [f64]) + Sync),
) {
    if !parallel || hi - lo <= CHUNK {
        let mut rest = values;
        for p in lo..hi {
            let (row, tail) = rest.split_at_mut(bounds[p + 1] - bounds[p]);
            f(p, row);
            rest = tail;
        }
        return;
    }
    let mid = lo + (hi - lo) / 2;
    let (left, right) = values.split_at_mut(bounds[mid] - bounds[lo]);
    anim_core::par::join(
        || for_block_rows(left, bounds, lo, mid, parallel, f),
        || for_block_rows(right, bounds, mid, hi, parallel, f),
    );
}

/// Adds `sign * b` to the block in `slot` of a block row whose rows are `width` entries long.
#[inline]
fn add_block(row: &mut [f64], width: usize, slot: usize, b: &DMat3, sign: f64) {
    for a in 0..3 {
        let base = a * width + 3 * slot;
        row[base] += sign * b.x_axis[a];
        row[base + 1] += sign * b.y_axis[a];
        row[base + 2] += sign * b.z_axis[a];
    }
}
