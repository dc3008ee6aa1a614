//! The fourth-order stress derivative `dP/dF` and its projection onto positive semi-definite
//! tensors.
//!
//! `dP/dF = d^2 psi / dF^2` is the Hessian of the energy density with respect to `F`; flattened on
//! column-major `vec(F)` it is a symmetric `D^2 x D^2` matrix. Newton solvers need it positive
//! semi-definite per element (Teran et al., *Robust quasistatic finite elements and flesh
//! simulation*, SCA 2005), which [`Tangent::project_psd`] provides by clamping the negative
//! eigenvalues of the flattened matrix to zero: `H+ = Q max(Lambda, 0) Q^T`, the nearest PSD
//! matrix in the Frobenius norm.

use crate::decomposition::assert_dim;
use crate::{Mat, Scalar};
use nalgebra::{SMatrix, SymmetricEigen};

/// The fourth-order tensor `dP/dF`: `d[k][l]` is the `D x D` matrix `dP/dF_kl`, so that for a
/// perturbation `dF`, `dP = sum_kl d[k][l] dF_kl`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tangent<T: Scalar, const D: usize> {
    /// `d[k][l] = dP / dF_kl`.
    pub d: [[Mat<T, D>; D]; D],
}

impl<T: Scalar, const D: usize> Tangent<T, D> {
    /// The zero tensor.
    #[must_use]
    pub fn zeros() -> Self {
        Self { d: [[Mat::<T, D>::zeros(); D]; D] }
    }

    /// The directional derivative `dP[dF] = sum_kl d[k][l] dF_kl`.
    #[must_use]
    pub fn apply(&self, df: &Mat<T, D>) -> Mat<T, D> {
        let mut out = Mat::<T, D>::zeros();
        for k in 0..D {
            for l in 0..D {
                out += self.d[k][l] * df[(k, l)];
            }
        }
        out
    }

    /// Entry `dP_ij / dF_kl`.
    #[inline]
    #[must_use]
    pub fn entry(&self, i: usize, j: usize, k: usize, l: usize) -> T {
        self.d[k][l][(i, j)]
    }

    /// Whether every entry is finite.
    #[must_use]
    pub fn is_finite(&self) -> bool {
        self.d.iter().flatten().all(|m| m.iter().all(|x| num_traits::Float::is_finite(*x)))
    }

    /// Frobenius norm of the flattened tensor.
    #[must_use]
    pub fn norm(&self) -> T {
        let s = self.d.iter().flatten().flat_map(|m| m.iter()).fold(T::zero(), |acc, x| acc + *x * *x);
        num_traits::Float::sqrt(s)
    }

    /// The projection onto positive semi-definite tensors: the flattened `D^2 x D^2` matrix is
    /// symmetrised and its negative eigenvalues set to zero (nalgebra's `SymmetricEigen`). The
    /// result is the nearest symmetric PSD tensor in the Frobenius norm.
    #[must_use]
    pub fn project_psd(&self) -> Self {
        assert_dim!(D);
        if D == 2 {
            let m = project_flat4(&self.flatten::<4>());
            Self::unflatten::<4>(&m)
        } else {
            let m = project_flat9(&self.flatten::<9>());
            Self::unflatten::<9>(&m)
        }
    }

    /// `M[i + D j, k + D l] = dP_ij / dF_kl` (`N = D^2`).
    fn flatten<const N: usize>(&self) -> SMatrix<T, N, N> {
        let mut m = SMatrix::<T, N, N>::zeros();
        for k in 0..D {
            for l in 0..D {
                for i in 0..D {
                    for j in 0..D {
                        m[(i + D * j, k + D * l)] = self.d[k][l][(i, j)];
                    }
                }
            }
        }
        m
    }

    fn unflatten<const N: usize>(m: &SMatrix<T, N, N>) -> Self {
        let mut t = Self::zeros();
        for k in 0..D {
            for l in 0..D {
                for i in 0..D {
                    for j in 0..D {
                        t.d[k][l][(i, j)] = m[(i + D * j, k + D * l)];
                    }
                }
            }
        }
        t
    }
}

/// Symmetrises an `N x N` matrix and clamps its negative eigenvalues to zero.
macro_rules! project_flat {
    ($name:ident, $n:literal) => {
        fn $name<T: Scalar>(m: &SMatrix<T, $n, $n>) -> SMatrix<T, $n, $n> {
            let sym = (m + m.transpose()) * T::of(0.5);
            let mut eig = SymmetricEigen::new(sym);
            let mut all_nonneg = true;
            for x in eig.eigenvalues.iter_mut() {
                if *x < T::zero() {
                    *x = T::zero();
                    all_nonneg = false;
                }
            }
            if all_nonneg {
                return sym;
            }
            eig.recompose()
        }
    };
}
project_flat!(project_flat4, 4);
project_flat!(project_flat9, 9);

impl<T: Scalar> Tangent<T, 3> {
    /// The tensor as a 9 x 9 matrix on column-major `vec(F)` (`vec(F)[k + 3 l] = F_kl`):
    /// `vec(dP) = M vec(dF)`.
    #[must_use]
    pub fn to_matrix(&self) -> SMatrix<T, 9, 9> {
        self.flatten::<9>()
    }

    /// The inverse of [`Tangent::to_matrix`].
    #[must_use]
    pub fn from_matrix(m: &SMatrix<T, 9, 9>) -> Self {
        Self::unflatten::<9>(m)
    }
}

impl<T: Scalar> Tangent<T, 2> {
    /// The tensor as a 4 x 4 matrix on column-major `vec(F)` (`vec(F)[k + 2 l] = F_kl`):
    /// `vec(dP) = M vec(dF)`.
    #[must_use]
    pub fn to_matrix(&self) -> SMatrix<T, 4, 4> {
        self.flatten::<4>()
    }

    /// The inverse of [`Tangent::to_matrix`].
    #[must_use]
    pub fn from_matrix(m: &SMatrix<T, 4, 4>) -> Self {
        Self::unflatten::<4>(m)
    }
}
