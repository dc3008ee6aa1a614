//! The sparse `Lᵀ D L` factorisation of the mass matrix (Featherstone section 6.5, table 6.3)
//! and forward dynamics through it, `v̇ = H⁻¹ (τ - C)`.
//!
//! Eliminating degrees of freedom from the leaves towards the root, `H = Lᵀ D L` with `L` unit
//! lower triangular and `D` diagonal; when the degrees of freedom are numbered in topological
//! order (a parent before its children, as in every [`Model`]), `L` has exactly the sparsity of
//! `H` (entry `(i, j)` only when `j` supports `i`), so the factorisation walks the tree of
//! degrees of freedom ([`Data::dof_parents`]) and costs `O(n d²)` for depth `d`; a chain is the
//! dense case.

use thiserror::Error;

use crate::data::{Data, NO_PARENT};
use crate::dynamics::check::{check_q, check_v};
use crate::dynamics::crba::crba;
use crate::dynamics::rnea::{nonlinear_effects, nonlinear_effects_placed};
use crate::model::Model;

/// A numerical failure of the dynamics.
#[derive(Debug, Clone, Copy, PartialEq, Error)]
#[non_exhaustive]
pub enum DynamicsError {
    /// The mass matrix is not positive definite: the `LᵀDL` pivot of degree of freedom `dof` is
    /// not positive (a massless subtree, or a degenerate inertia).
    #[error("mass matrix not positive definite: pivot {pivot:e} at degree of freedom {dof}")]
    NotPositiveDefinite {
        /// The degree of freedom whose pivot failed.
        dof: usize,
        /// The pivot.
        pivot: f64,
    },
}

/// Factorises `data.mass_matrix` (run [`crba`] first) into `data.mass_matrix_factor` as
/// `H = Lᵀ D L`: `D` on the diagonal, the strict lower triangle of `L` below it.
///
/// # Errors
/// [`DynamicsError::NotPositiveDefinite`] when a pivot is not positive.
///
/// # Panics
/// When `data` does not match `model`.
#[track_caller]
pub fn factor_mass_matrix(model: &Model, data: &mut Data) -> Result<(), DynamicsError> {
    assert!(data.fits(model), "this Data was not made for this Model (Data::new(&model))");
    let nv = model.nv();
    data.mass_matrix_factor.copy_from(&data.mass_matrix);
    let parents = &data.dof_parents;
    let h = data.mass_matrix_factor.as_mut_slice();
    for k in (0..nv).rev() {
        let pivot = h[k * nv + k];
        if !(pivot > 0.0) || !pivot.is_finite() {
            return Err(DynamicsError::NotPositiveDefinite { dof: k, pivot });
        }
        let mut i = parents[k];
        while i != NO_PARENT {
            let a = h[k * nv + i] / pivot;
            let mut j = i;
            while j != NO_PARENT {
                h[i * nv + j] -= a * h[k * nv + j];
                j = parents[j];
            }
            h[k * nv + i] = a;
            i = parents[i];
        }
    }
    Ok(())
}

/// Solves `H x = b` in place (`b` becomes `x`) with the factor of [`factor_mass_matrix`]:
/// `x = L⁻¹ D⁻¹ L⁻ᵀ b`.
///
/// # Panics
/// When `b.len() != nv` or `data` does not match `model`.
#[track_caller]
pub fn solve_mass_matrix(model: &Model, data: &Data, b: &mut [f64]) {
    assert!(data.fits(model), "this Data was not made for this Model (Data::new(&model))");
    check_v(model, "b", b);
    let nv = model.nv();
    let parents = &data.dof_parents;
    let h = data.mass_matrix_factor.as_slice();
    // Lᵀ y = b, from the leaves up.
    for i in (0..nv).rev() {
        let bi = b[i];
        let mut j = parents[i];
        while j != NO_PARENT {
            b[j] -= h[i * nv + j] * bi;
            j = parents[j];
        }
    }
    for i in 0..nv {
        b[i] /= h[i * nv + i];
    }
    // L x = z, from the root down.
    for i in 0..nv {
        let mut s = b[i];
        let mut j = parents[i];
        while j != NO_PARENT {
            s -= h[i * nv + j] * b[j];
            j = parents[j];
        }
        b[i] = s;
    }
}

/// Forward dynamics by the mass matrix: `v̇ = H(q)⁻¹ (τ - C(q, v))` with [`crba`],
/// [`nonlinear_effects`] and the `LᵀDL` factorisation; written into `data.ddq` and returned.
/// Slower than [`aba`](crate::aba) for long chains (`O(n²)` to `O(n³)` against `O(n)`), and
/// independent of it: the two are tested against each other.
///
/// # Errors
/// [`DynamicsError::NotPositiveDefinite`] when `H` is not positive definite.
///
/// # Panics
/// When `q`, `v`, `tau` or `data` does not match `model`.
#[track_caller]
pub fn forward_dynamics_cholesky<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
) -> Result<&'d [f64], DynamicsError> {
    check_q(model, data, q);
    check_v(model, "v", v);
    check_v(model, "tau", tau);
    crba(model, data, q);
    if model.mimic_joints().is_empty() {
        // Both forms of CRBA leave the joint placements for this q in data.
        nonlinear_effects_placed(model, data, v);
    } else {
        nonlinear_effects(model, data, q, v);
    }
    factor_mass_matrix(model, data)?;
    let mut rhs = std::mem::take(&mut data.scratch);
    for ((r, t), c) in rhs.iter_mut().zip(tau).zip(&data.nle) {
        *r = t - c;
    }
    solve_mass_matrix(model, data, &mut rhs);
    data.ddq.copy_from_slice(&rhs);
    data.scratch = rhs;
    Ok(&data.ddq)
}
