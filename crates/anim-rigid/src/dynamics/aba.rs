//! The articulated-body algorithm: forward dynamics in `O(n)` (Featherstone table 7.1). [`aba`]
//! is the default form; the two forms are [`aba_local`](super::aba_local) (joint frames) and
//! [`aba_world`](super::aba_world) (world frame). See [`crate::dynamics`] for the equations.

use crate::data::Data;
use crate::model::Model;
use crate::spatial::{ArticulatedInertia, Force, Motion};

/// Forward dynamics `v̇ = FD(q, v, τ)` by the articulated-body algorithm, gravity included;
/// written into `data.ddq` and returned. This is [`aba_world`](super::aba_world), and writes
/// the same [`Data`] fields: the faster form on the robots measured (see the module
/// documentation of [`crate::dynamics`]). [`aba_local`](super::aba_local) is the accurate one
/// for bodies far from the world origin or ill-conditioned trees.
///
/// A joint whose articulated inertia `D = Sᵀ Iᴬ S` is singular (a massless leaf body) gives
/// non-finite accelerations; the simulation layer reports them at the step that made them.
///
/// # Panics
/// When `q`, `v`, `tau` or `data` does not match `model`, or when the model has coupled joints
/// ([`Model::mimic_joints`]): the recursion has no coupling between branches (Pinocchio's ABA
/// refuses such models too); [`crate::forward_dynamics_cholesky`] handles them.
#[track_caller]
pub fn aba<'d>(model: &Model, data: &'d mut Data, q: &[f64], v: &[f64], tau: &[f64]) -> &'d [f64] {
    super::aba_world(model, data, q, v, tau)
}

/// The inverse of the leading `n x n` block of a 6 x 6 matrix.
pub(crate) type Invert = fn(&[[f64; 6]; 6], usize) -> [[f64; 6]; 6];

/// The elimination step of the articulated-body algorithm for a joint of `nv = s.len()` degrees
/// of freedom (2 to 6), the same in both frames (Featherstone 2008, table 7.1): `U = Iᴬ S`,
/// `D = Sᵀ U` (inverted by `invert`), `u = τ - Sᵀ pᴬ`; then `Iᴬ -= U D⁻¹ Uᵀ` and
/// `pᴬ += Iᴬ c + U D⁻¹ u`, what the joint passes to its parent. Writes `U`, `D⁻¹` and `u` into
/// the joint's rows of `aba_u`, `aba_dinv` and `aba_uu` for the acceleration pass.
pub(crate) fn eliminate_joint(
    ia: &mut ArticulatedInertia,
    pa: &mut Force,
    c: &Motion,
    s: &[Motion],
    tau: &[f64],
    aba_u: &mut [Force],
    aba_dinv: &mut [[f64; 6]],
    aba_uu: &mut [f64],
    invert: Invert,
) {
    let nv = s.len();
    let mut u = [Force::ZERO; 6];
    let mut d = [[0.0; 6]; 6];
    for a in 0..nv {
        u[a] = ia.mul_motion(&s[a]);
    }
    for a in 0..nv {
        for b in 0..nv {
            d[a][b] = s[a].dot(&u[b]);
        }
        aba_uu[a] = tau[a] - s[a].dot(pa);
    }
    let dinv = invert(&d, nv);
    let mut w = [Force::ZERO; 6];
    for b in 0..nv {
        for a in 0..nv {
            w[b] += u[a] * dinv[a][b];
        }
    }
    for b in 0..nv {
        ia.sub_outer(&w[b], &u[b]);
    }
    let mut push = ia.mul_motion(c);
    for b in 0..nv {
        push += w[b] * aba_uu[b];
    }
    *pa += push;
    aba_u[..nv].copy_from_slice(&u[..nv]);
    aba_dinv[..nv].copy_from_slice(&dinv[..nv]);
}

/// The inverse of the leading `n x n` block of `d` (symmetric positive definite in ABA) by
/// Gauss-Jordan elimination with partial pivoting; a singular block gives non-finite entries.
pub(crate) fn invert_small(d: &[[f64; 6]; 6], n: usize) -> [[f64; 6]; 6] {
    let mut a = *d;
    let mut inv = [[0.0; 6]; 6];
    for i in 0..n {
        inv[i][i] = 1.0;
    }
    for k in 0..n {
        let mut p = k;
        for i in k + 1..n {
            if a[i][k].abs() > a[p][k].abs() {
                p = i;
            }
        }
        a.swap(k, p);
        inv.swap(k, p);
        let s = 1.0 / a[k][k];
        for j in 0..n {
            a[k][j] *= s;
            inv[k][j] *= s;
        }
        for i in 0..n {
            if i != k {
                let f = a[i][k];
                if f != 0.0 {
                    for j in 0..n {
                        a[i][j] -= f * a[k][j];
                        inv[i][j] -= f * inv[k][j];
                    }
                }
            }
        }
    }
    inv
}

/// The inverse of the leading `n x n` block of the symmetric positive-definite `d` by its
/// Cholesky factor `d = L Lᵀ`, `d⁻¹ = L⁻ᵀ L⁻¹` (Pinocchio inverts the joint block `D` of ABA the
/// same way); the result is symmetric. A block that is not positive definite gives non-finite
/// entries.
pub(crate) fn invert_spd(d: &[[f64; 6]; 6], n: usize) -> [[f64; 6]; 6] {
    let mut l = [[0.0; 6]; 6];
    for j in 0..n {
        let mut s = d[j][j];
        for k in 0..j {
            s -= l[j][k] * l[j][k];
        }
        let ljj = s.sqrt();
        l[j][j] = ljj;
        for i in j + 1..n {
            let mut s = d[i][j];
            for k in 0..j {
                s -= l[i][k] * l[j][k];
            }
            l[i][j] = s / ljj;
        }
    }
    // M = L⁻¹ (lower triangular) by forward substitution, then d⁻¹ = Mᵀ M.
    let mut m = [[0.0; 6]; 6];
    for j in 0..n {
        m[j][j] = 1.0 / l[j][j];
        for i in j + 1..n {
            let mut s = 0.0;
            for k in j..i {
                s -= l[i][k] * m[k][j];
            }
            m[i][j] = s / l[i][i];
        }
    }
    let mut inv = [[0.0; 6]; 6];
    for i in 0..n {
        for j in 0..=i {
            let mut s = 0.0;
            for k in i..n {
                s += m[k][i] * m[k][j];
            }
            inv[i][j] = s;
            inv[j][i] = s;
        }
    }
    inv
}
