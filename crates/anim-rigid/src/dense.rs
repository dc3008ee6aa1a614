//! A small dense square matrix (row-major `f64`, sized once) for the joint-space quantities of
//! dynamics: the mass matrix `H`, its factor, and the Newton matrices of the implicit stepper.
//! Sizes are `nv`, a few dozen at most, where a hand-rolled loop beats calling into a general
//! library and nothing allocates after construction.

use std::ops::{Index, IndexMut};

/// An `n x n` matrix stored row by row.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct SquareMatrix {
    n: usize,
    values: Vec<f64>,
}

impl SquareMatrix {
    /// The zero `n x n` matrix.
    #[must_use]
    pub fn zeros(n: usize) -> Self {
        Self { n, values: vec![0.0; n * n] }
    }

    /// The `n x n` identity.
    #[must_use]
    pub fn identity(n: usize) -> Self {
        let mut m = Self::zeros(n);
        for i in 0..n {
            m[(i, i)] = 1.0;
        }
        m
    }

    /// The matrix of the rows `rows` (each of length `rows.len()`).
    ///
    /// # Panics
    /// When a row has the wrong length.
    #[must_use]
    #[track_caller]
    pub fn from_rows(rows: &[Vec<f64>]) -> Self {
        let n = rows.len();
        let mut m = Self::zeros(n);
        for (i, r) in rows.iter().enumerate() {
            assert_eq!(r.len(), n, "row {i} has length {}, expected {n}", r.len());
            m.row_mut(i).copy_from_slice(r);
        }
        m
    }

    /// The dimension `n`.
    #[inline]
    #[must_use]
    pub fn n(&self) -> usize {
        self.n
    }

    /// The entries, row-major.
    #[inline]
    #[must_use]
    pub fn as_slice(&self) -> &[f64] {
        &self.values
    }

    /// The entries, row-major, mutable.
    #[inline]
    #[must_use]
    pub fn as_mut_slice(&mut self) -> &mut [f64] {
        &mut self.values
    }

    /// Row `i`.
    #[inline]
    #[must_use]
    #[track_caller]
    pub fn row(&self, i: usize) -> &[f64] {
        &self.values[i * self.n..(i + 1) * self.n]
    }

    /// Row `i`, mutable.
    #[inline]
    #[must_use]
    #[track_caller]
    pub fn row_mut(&mut self, i: usize) -> &mut [f64] {
        &mut self.values[i * self.n..(i + 1) * self.n]
    }

    /// Sets every entry to zero.
    pub fn fill_zero(&mut self) {
        self.values.fill(0.0);
    }

    /// Copies `other` (same size) into `self`.
    ///
    /// # Panics
    /// When the sizes differ.
    #[track_caller]
    pub fn copy_from(&mut self, other: &SquareMatrix) {
        assert_eq!(
            self.n, other.n,
            "copy between {}x{} and {}x{} matrices",
            self.n, self.n, other.n, other.n
        );
        self.values.copy_from_slice(&other.values);
    }

    /// `out = self x`.
    ///
    /// # Panics
    /// When a length differs from `n`.
    #[track_caller]
    pub fn mul_vec(&self, x: &[f64], out: &mut [f64]) {
        assert!(
            x.len() == self.n && out.len() == self.n,
            "mul_vec: lengths {} and {} for n = {}",
            x.len(),
            out.len(),
            self.n
        );
        for (i, o) in out.iter_mut().enumerate() {
            *o = self.row(i).iter().zip(x).map(|(a, b)| a * b).sum();
        }
    }

    /// `max |a_ij - a_ji|`.
    #[must_use]
    pub fn asymmetry(&self) -> f64 {
        let mut m = 0.0_f64;
        for i in 0..self.n {
            for j in 0..i {
                m = m.max((self[(i, j)] - self[(j, i)]).abs());
            }
        }
        m
    }

    /// `max |a_ij|`.
    #[must_use]
    pub fn max_abs(&self) -> f64 {
        self.values.iter().fold(0.0_f64, |m, v| m.max(v.abs()))
    }

    /// Copies the lower triangle into the upper one.
    pub fn mirror_lower(&mut self) {
        let n = self.n;
        for i in 0..n {
            for j in 0..i {
                self.values[j * n + i] = self.values[i * n + j];
            }
        }
    }

    /// Copies the upper triangle into the lower one.
    pub fn mirror_upper(&mut self) {
        let n = self.n;
        for i in 0..n {
            for j in 0..i {
                self.values[i * n + j] = self.values[j * n + i];
            }
        }
    }

    /// LU factorisation with partial pivoting, in place (`L` unit lower below the diagonal, `U`
    /// on and above), the row permutation written into `pivots`. Returns `false` when a pivot is
    /// exactly zero or not finite (the matrix is singular to working precision).
    ///
    /// # Panics
    /// When `pivots.len() != n`.
    #[track_caller]
    pub fn lu_factor(&mut self, pivots: &mut [usize]) -> bool {
        let n = self.n;
        assert_eq!(pivots.len(), n, "pivots has length {}, expected {n}", pivots.len());
        for k in 0..n {
            let mut p = k;
            let mut best = self.values[k * n + k].abs();
            for i in k + 1..n {
                let v = self.values[i * n + k].abs();
                if v > best {
                    best = v;
                    p = i;
                }
            }
            pivots[k] = p;
            if !(best > 0.0) || !best.is_finite() {
                return false;
            }
            if p != k {
                for j in 0..n {
                    self.values.swap(k * n + j, p * n + j);
                }
            }
            let inv = 1.0 / self.values[k * n + k];
            for i in k + 1..n {
                let l = self.values[i * n + k] * inv;
                self.values[i * n + k] = l;
                if l != 0.0 {
                    for j in k + 1..n {
                        self.values[i * n + j] -= l * self.values[k * n + j];
                    }
                }
            }
        }
        true
    }

    /// Solves `A x = b` in place (`b` becomes `x`) with the factors of [`lu_factor`](Self::lu_factor).
    ///
    /// # Panics
    /// When a length differs from `n`.
    #[track_caller]
    pub fn lu_solve(&self, pivots: &[usize], b: &mut [f64]) {
        let n = self.n;
        assert!(
            pivots.len() == n && b.len() == n,
            "lu_solve: lengths {} and {} for n = {n}",
            pivots.len(),
            b.len()
        );
        for k in 0..n {
            b.swap(k, pivots[k]);
        }
        for i in 0..n {
            let mut s = b[i];
            for j in 0..i {
                s -= self.values[i * n + j] * b[j];
            }
            b[i] = s;
        }
        for i in (0..n).rev() {
            let mut s = b[i];
            for j in i + 1..n {
                s -= self.values[i * n + j] * b[j];
            }
            b[i] = s / self.values[i * n + i];
        }
    }
}

impl Index<(usize, usize)> for SquareMatrix {
    type Output = f64;
    #[inline]
    #[track_caller]
    fn index(&self, (i, j): (usize, usize)) -> &f64 {
        assert!(i < self.n && j < self.n, "entry ({i}, {j}) of a {}x{} matrix", self.n, self.n);
        &self.values[i * self.n + j]
    }
}

impl IndexMut<(usize, usize)> for SquareMatrix {
    #[inline]
    #[track_caller]
    fn index_mut(&mut self, (i, j): (usize, usize)) -> &mut f64 {
        assert!(i < self.n && j < self.n, "entry ({i}, {j}) of a {}x{} matrix", self.n, self.n);
        &mut self.values[i * self.n + j]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lu_solves_a_nonsymmetric_system_that_needs_pivoting() {
        let a = SquareMatrix::from_rows(&[
            vec![0.0, 2.0, 1.0, -1.0],
            vec![1.0, 1.0, 0.0, 3.0],
            vec![4.0, -1.0, 2.0, 0.5],
            vec![-2.0, 0.3, 5.0, 1.0],
        ]);
        let x = [1.0, -2.0, 0.5, 3.0];
        let mut b = [0.0; 4];
        a.mul_vec(&x, &mut b);
        let mut lu = a.clone();
        let mut piv = [0; 4];
        assert!(lu.lu_factor(&mut piv));
        lu.lu_solve(&piv, &mut b);
        for (got, want) in b.iter().zip(x) {
            assert!((got - want).abs() < 1e-14, "{got} vs {want}");
        }
        let mut singular = SquareMatrix::from_rows(&[vec![1.0, 2.0], vec![2.0, 4.0]]);
        assert!(!singular.lu_factor(&mut [0; 2]));
    }

    #[test]
    fn mirror_and_asymmetry() {
        let mut m = SquareMatrix::from_rows(&[vec![1.0, 2.0], vec![0.0, 3.0]]);
        assert_eq!(m.asymmetry(), 2.0);
        m.mirror_upper();
        assert_eq!(m[(1, 0)], 2.0);
        assert_eq!(m.asymmetry(), 0.0);
        m[(1, 0)] = 5.0;
        m.mirror_lower();
        assert_eq!(m[(0, 1)], 5.0);
        assert_eq!(SquareMatrix::identity(3).max_abs(), 1.0);
    }
}
