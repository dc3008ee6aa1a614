//! The `6 x n` matrix of twists that holds Jacobians (Pinocchio's `Matrix6x`): `n` columns,
//! each a twist with its linear part first, so rows `0..3` are `v_x, v_y, v_z` and rows `3..6`
//! are `ω_x, ω_y, ω_z`. Column `k` is the twist a unit rate of velocity entry `k` gives a body;
//! the algorithms that fill it are in `jacobian`.

use std::ops::Index;

use anim_core::lie::Twist;

/// A `6 x n` matrix stored as `n` column twists (rows: linear then angular).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Jacobian {
    pub(crate) columns: Vec<Twist>,
}

impl Jacobian {
    /// The zero `6 x ncols` matrix.
    #[must_use]
    pub fn zeros(ncols: usize) -> Self {
        Self { columns: vec![Twist::ZERO; ncols] }
    }

    /// Number of columns (`nv` of the model).
    #[inline]
    #[must_use]
    pub fn ncols(&self) -> usize {
        self.columns.len()
    }

    /// Column `k` as a twist.
    ///
    /// # Panics
    /// When `k >= ncols()`.
    #[inline]
    #[must_use]
    #[track_caller]
    pub fn column(&self, k: usize) -> Twist {
        self.columns[k]
    }

    /// Every column.
    #[inline]
    #[must_use]
    pub fn columns(&self) -> &[Twist] {
        &self.columns
    }

    /// Every column, mutable.
    #[inline]
    #[must_use]
    pub fn columns_mut(&mut self) -> &mut [Twist] {
        &mut self.columns
    }

    /// Sets every entry to zero.
    pub fn fill_zero(&mut self) {
        self.columns.fill(Twist::ZERO);
    }

    /// `J v` (a twist).
    ///
    /// # Panics
    /// When `v.len() != ncols()`.
    #[must_use]
    #[track_caller]
    pub fn mul_vec(&self, v: &[f64]) -> Twist {
        assert_eq!(v.len(), self.ncols(), "vector length {} for a 6x{} Jacobian", v.len(), self.ncols());
        self.columns.iter().zip(v).fold(Twist::ZERO, |acc, (c, &x)| acc + c.scale(x))
    }

    /// `Jᵀ t` written into `out`.
    ///
    /// # Panics
    /// When `out.len() != ncols()`.
    #[track_caller]
    pub fn transpose_mul(&self, t: Twist, out: &mut [f64]) {
        assert_eq!(out.len(), self.ncols(), "output length {} for a 6x{} Jacobian", out.len(), self.ncols());
        for (o, c) in out.iter_mut().zip(&self.columns) {
            *o = c.v.dot(t.v) + c.w.dot(t.w);
        }
    }

    /// The rows as six `Vec`s (row-major copy), linear rows first.
    #[must_use]
    pub fn to_rows(&self) -> [Vec<f64>; 6] {
        std::array::from_fn(|r| (0..self.ncols()).map(|c| self[(r, c)]).collect())
    }
}

impl Index<(usize, usize)> for Jacobian {
    type Output = f64;
    /// Entry `(row, col)`, `row < 6` (0-2 linear, 3-5 angular).
    #[inline]
    #[track_caller]
    fn index(&self, (row, col): (usize, usize)) -> &f64 {
        let c = &self.columns[col];
        match row {
            0 => &c.v.x,
            1 => &c.v.y,
            2 => &c.v.z,
            3 => &c.w.x,
            4 => &c.w.y,
            5 => &c.w.z,
            _ => panic!("row {row} of a 6-row Jacobian"),
        }
    }
}
