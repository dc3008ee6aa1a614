//! The linear tetrahedron (Sifakis & Barbič 2012): rest shape `Dm^-1` and volume `W`, deformation gradient
//! `F = Ds Dm^-1`, the nodal forces `H = -W P(F) Dm^-T` with `f4 = -(f1 + f2 + f3)`, and the
//! element stiffness `K_e = -df/dx`.
//!
//! For an element `(x1, x2, x3, x4)` (indices 0..3 here), `Ds = [x1 - x4, x2 - x4, x3 - x4]` and
//! `Dm` the same with rest positions, so `F = Ds Dm^-1` is constant over the element and the
//! element energy is `W psi(F)` with `W = |det Dm| / 6`.
//!
//! Writing `b_a` for row `a` of `Dm^-1` (`a = 0, 1, 2`) and `b_3 = -(b_0 + b_1 + b_2)`, the
//! deformation gradient is `F = sum_a x_a b_a^T`, so `dF/dx_a = e_i b_a^T` and
//!
//! ```text
//! f_a = -W P(F) b_a                              (columns of H = -W P Dm^-T; f_3 = -(f_0 + f_1 + f_2))
//! K_e[(a,i),(b,k)] = W sum_jl b_aj (dP_ij / dF_kl) b_bl
//! ```

use anim_material::nalgebra::{Matrix3, SMatrix, Vector3};

/// `Dm^-1` and the rest volume `W = |det Dm| / 6` of a rest element, or `None` when `Dm` is
/// singular.
#[must_use]
pub fn rest_shape(rest: [[f64; 3]; 4]) -> Option<(Matrix3<f64>, f64)> {
    let dm = edge_matrix(&rest);
    let det = dm.determinant();
    let inv = dm.try_inverse()?;
    Some((inv, det.abs() / 6.0))
}

/// `[x0 - x3, x1 - x3, x2 - x3]` as columns.
#[inline]
#[must_use]
pub fn edge_matrix(x: &[[f64; 3]; 4]) -> Matrix3<f64> {
    let c = |a: usize| Vector3::new(x[a][0] - x[3][0], x[a][1] - x[3][1], x[a][2] - x[3][2]);
    Matrix3::from_columns(&[c(0), c(1), c(2)])
}

/// Gathers the four vertices of `tet` from a flat coordinate array.
#[inline]
#[must_use]
pub fn gather(x: &[f64], tet: &[usize; 4]) -> [[f64; 3]; 4] {
    tet.map(|v| [x[3 * v], x[3 * v + 1], x[3 * v + 2]])
}

/// `F = Ds Dm^-1`.
#[inline]
#[must_use]
pub fn deformation_gradient(x: &[[f64; 3]; 4], dm_inv: &Matrix3<f64>) -> Matrix3<f64> {
    edge_matrix(x) * dm_inv
}

/// The shape-function gradients `b_a` (rows of `Dm^-1`, and `b_3 = -(b_0 + b_1 + b_2)`).
#[inline]
#[must_use]
pub fn gradients(dm_inv: &Matrix3<f64>) -> [[f64; 3]; 4] {
    let r = |a: usize| [dm_inv[(a, 0)], dm_inv[(a, 1)], dm_inv[(a, 2)]];
    let (b0, b1, b2) = (r(0), r(1), r(2));
    [b0, b1, b2, [-(b0[0] + b1[0] + b2[0]), -(b0[1] + b1[1] + b2[1]), -(b0[2] + b1[2] + b2[2])]]
}

/// The elastic nodal forces of one element: `H = -W P Dm^-T` gives `f_0, f_1, f_2` as its
/// columns and `f_3 = -(f_0 + f_1 + f_2)` (Sifakis & Barbič 2012, Algorithm 1 lines 14-16).
#[inline]
#[must_use]
pub fn nodal_forces(w: f64, p: &Matrix3<f64>, dm_inv: &Matrix3<f64>) -> [[f64; 3]; 4] {
    let h = -(p * dm_inv.transpose()) * w;
    let col = |a: usize| [h[(0, a)], h[(1, a)], h[(2, a)]];
    let (f0, f1, f2) = (col(0), col(1), col(2));
    [f0, f1, f2, [-(f0[0] + f1[0] + f2[0]), -(f0[1] + f1[1] + f2[1]), -(f0[2] + f1[2] + f2[2])]]
}

/// The element stiffness `K_e = W B^T C B` (12 x 12, row-major, row `3a + i`) from the 9 x 9
/// tangent `C` on column-major `vec(F)` and the shape-function gradients `b` of any element with
/// `N` nodes at one quadrature point: `out[(3a+i) * 3N + 3b + k] += w sum_jl b_aj C[i+3j, k+3l] b_bl`.
#[inline]
pub fn add_stiffness<const N: usize>(w: f64, b: &[[f64; 3]; N], c: &SMatrix<f64, 9, 9>, out: &mut [f64]) {
    let n3 = 3 * N;
    debug_assert_eq!(out.len(), n3 * n3);
    // t[a][i][col] = sum_j b_aj C[i + 3j, col]
    let mut t = [[[0.0f64; 9]; 3]; N];
    for a in 0..N {
        for i in 0..3 {
            for col in 0..9 {
                t[a][i][col] = b[a][0] * c[(i, col)] + b[a][1] * c[(i + 3, col)] + b[a][2] * c[(i + 6, col)];
            }
        }
    }
    for a in 0..N {
        for i in 0..3 {
            let row = &mut out[(3 * a + i) * n3..(3 * a + i + 1) * n3];
            let ta = &t[a][i];
            for bb in 0..N {
                for k in 0..3 {
                    let v = ta[k] * b[bb][0] + ta[k + 3] * b[bb][1] + ta[k + 6] * b[bb][2];
                    row[3 * bb + k] += w * v;
                }
            }
        }
    }
}

/// The directional derivative of the nodal forces, `-K_e u` for nodal displacements `u`, without
/// forming `K_e`: `dF = sum_a u_a b_a^T`, `dP = (dP/dF)[dF]`, `-K_e u = -W dP Dm^-T` (the force
/// formula applied to `dP`). Used for Rayleigh damping forces `-gamma K v` in explicit steps.
#[inline]
#[must_use]
pub fn force_differential(
    w: f64,
    dm_inv: &Matrix3<f64>,
    tangent: &anim_material::Tangent<f64, 3>,
    u: &[[f64; 3]; 4],
) -> [[f64; 3]; 4] {
    let df = edge_matrix(u) * dm_inv;
    let dp = tangent.apply(&df);
    nodal_forces(w, &dp, dm_inv)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn forces_are_the_gradient_formula() {
        // f_a = -W P b_a for a = 0..3 agrees with Sifakis & Barbič's H = -W P Dm^-T, f_3 = -sum.
        let rest = [[0.1, 0.0, 0.0], [1.0, 0.2, 0.0], [0.0, 1.1, 0.3], [0.2, 0.1, 0.9]];
        let (dm_inv, w) = rest_shape(rest).unwrap();
        let p = Matrix3::new(1.0, 2.0, -0.5, 0.3, -1.2, 0.7, 0.25, 0.5, 2.0);
        let f = nodal_forces(w, &p, &dm_inv);
        let b = gradients(&dm_inv);
        for a in 0..4 {
            let fa = -(p * Vector3::new(b[a][0], b[a][1], b[a][2])) * w;
            for i in 0..3 {
                assert!((fa[i] - f[a][i]).abs() < 1e-14);
            }
        }
        // Rest volume.
        let v6 = crate::mesh::signed_volume6(rest[0], rest[1], rest[2], rest[3]);
        assert!((w - v6.abs() / 6.0).abs() < 1e-15);
    }

    #[test]
    fn deformation_gradient_of_an_affine_map() {
        let rest = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let (dm_inv, _) = rest_shape(rest).unwrap();
        let a = Matrix3::new(1.1, 0.2, 0.0, -0.3, 0.9, 0.4, 0.05, 0.0, 1.3);
        let x = rest.map(|p| {
            let q = a * Vector3::new(p[0], p[1], p[2]);
            [q[0] + 2.0, q[1] - 1.0, q[2] + 0.5]
        });
        let f = deformation_gradient(&x, &dm_inv);
        assert!((f - a).norm() < 1e-14);
    }
}
