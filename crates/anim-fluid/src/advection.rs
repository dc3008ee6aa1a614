//! Interpolation and semi-Lagrangian advection on the MAC grid.
//!
//! Stable fluids (Stam 1999), *advect*: `w2(x) = w1(p(x, -dt))`, the value carried along the
//! characteristic back to where it came from. The back-trace here is second-order (midpoint:
//! `x_mid = x - dt/2 u(x)`, `x_back = x - dt u(x_mid)`), and the value is sampled
//! - **linearly** (Stam's bilinear, extended to trilinear), or
//! - by a **monotone cubic**: per axis a cubic Hermite through the 4 nearest samples with
//!   central-difference slopes, each slope set to 0 when its sign differs from the interval's
//!   difference and capped at 3 times it (Fritsch and Carlson 1980), so it never over- or
//!   undershoots the interval (Fedkiw, Stam and Jensen 2001 use it for smoke);
//!
//! and the error of the linear scheme is compensated by
//! - **BFECC** (Kim et al. 2005): advect forward, back again, correct the input by half the
//!   round-trip error, advect the corrected field; or
//! - **MacCormack** (Selle et al. 2008): advect forward and back, add half the round-trip error to
//!   the forward result;
//!
//! both with Selle's limiter: the result is clamped to the range of the samples the forward
//! back-trace interpolated, so no new extrema appear. Along a no-slip wall the tangential
//! velocity is interpolated toward the wall's velocity over the half cell between the last
//! sample and the wall (this is how the lid of a cavity drags the fluid); elsewhere outside the
//! samples the nearest value is used.
//!
//! This module holds the choice of scheme and the interpolation on one lattice; the MAC solver
//! runs the passes over its faces and cells (`mac/advect.rs`).

/// How advected quantities are carried. Serialised by its [`Advection::name`]
/// (`"sl-linear"`, `"sl-monotone-cubic"`, `"bfecc"`, `"maccormack"`), as scene files name it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Advection {
    /// Semi-Lagrangian, linear interpolation (Stam's scheme).
    #[serde(rename = "sl-linear")]
    Linear,
    /// Semi-Lagrangian, monotone cubic interpolation.
    #[serde(rename = "sl-monotone-cubic")]
    MonotoneCubic,
    /// Back and forth error compensation and correction over linear semi-Lagrangian steps.
    #[serde(rename = "bfecc")]
    Bfecc,
    /// MacCormack over linear semi-Lagrangian steps.
    #[serde(rename = "maccormack")]
    MacCormack,
}

impl Advection {
    /// All schemes, in table order.
    pub const ALL: [Advection; 4] = [Self::Linear, Self::MonotoneCubic, Self::Bfecc, Self::MacCormack];

    /// A short name for tables.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Linear => "sl-linear",
            Self::MonotoneCubic => "sl-monotone-cubic",
            Self::Bfecc => "bfecc",
            Self::MacCormack => "maccormack",
        }
    }
}

/// How one step splits advection from the pressure projection.
///
/// - **Advect, then project** (Chorin 1968; Stam 1999, his velocity step): advect the
///   velocity by itself over `dt`, then project. The projection removes the advected field's
///   gradient part and with it kinetic energy: a splitting error of first order in `dt` that
///   does not shrink with the grid (on the Taylor-Green vortex about `2 dt` of the amplitude at
///   `t = 1`, whatever the resolution).
/// - **Advection-reflection** (Zehnder, Narain and Thomaszewski 2018): advect over `dt/2`,
///   project, reflect the field about the divergence-free one (`u_hat = 2 P(u~) - u~`), advect
///   the reflection by the projected field over `dt/2` and project again. Reflecting instead of
///   projecting halfway conserves the kinetic energy the first projection would remove, so the
///   splitting error is of second order, for two projections and two half-step advections per
///   step. Scalars (density, temperature) are advected once over `dt` by the midpoint field.
///
/// Serialised by its [`Splitting::name`] (`"advect-project"`, `"reflection"`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum Splitting {
    /// Advect over `dt`, then project (first order).
    #[default]
    #[serde(rename = "advect-project")]
    AdvectProject,
    /// Advection-reflection (second order, two projections per step).
    #[serde(rename = "reflection")]
    Reflection,
}

impl Splitting {
    /// Both splittings, in table order.
    pub const ALL: [Splitting; 2] = [Self::AdvectProject, Self::Reflection];

    /// A short name for tables.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::AdvectProject => "advect-project",
            Self::Reflection => "reflection",
        }
    }
}

/// A sampled field: values on a regular lattice `dims` (x fastest) whose sample `(i, j, k)`
/// sits at index coordinates `(i, j, k)`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Lattice<'a> {
    pub values: &'a [f64],
    pub dims: [usize; 3],
    pub dim: usize,
}

/// Wall blending of one lattice axis: values at index coordinate `-0.5` and `n - 0.5` that the
/// field tends to (no-slip tangential velocity), or `None` (nearest value).
pub(crate) type WallValues = [[Option<f64>; 2]; 3];

#[inline]
fn split(g: f64, n: usize) -> (usize, f64) {
    if n == 1 {
        return (0, 0.0);
    }
    let g = g.clamp(0.0, (n - 1) as f64);
    let i = (g.floor() as usize).min(n - 2);
    (i, g - i as f64)
}

/// Monotone cubic Hermite on `[f1, f2]` at `t`, with neighbours `f0`, `f3`.
#[inline]
fn monotone_cubic(f0: f64, f1: f64, f2: f64, f3: f64, t: f64) -> f64 {
    let delta = f2 - f1;
    let mut d1 = 0.5 * (f2 - f0);
    let mut d2 = 0.5 * (f3 - f1);
    if delta == 0.0 {
        d1 = 0.0;
        d2 = 0.0;
    } else {
        let lim = 3.0 * delta.abs();
        d1 = if d1 * delta <= 0.0 { 0.0 } else { d1.signum() * d1.abs().min(lim) };
        d2 = if d2 * delta <= 0.0 { 0.0 } else { d2.signum() * d2.abs().min(lim) };
    }
    let a2 = 3.0 * delta - 2.0 * d1 - d2;
    let a3 = d1 + d2 - 2.0 * delta;
    ((a3 * t + a2) * t + d1) * t + f1
}

impl Lattice<'_> {
    #[inline]
    fn at(&self, i: usize, j: usize, k: usize) -> f64 {
        self.values[i + self.dims[0] * (j + self.dims[1] * k)]
    }

    /// Linear interpolation at index coordinates `g`, with the min and max of the samples used.
    #[inline]
    pub fn linear(&self, g: [f64; 3]) -> (f64, f64, f64) {
        let (i, s) = split(g[0], self.dims[0]);
        let (j, t) = split(g[1], self.dims[1]);
        let i1 = (i + 1).min(self.dims[0] - 1);
        let j1 = (j + 1).min(self.dims[1] - 1);
        let plane = |k: usize| {
            let (a, b, c, d) = (self.at(i, j, k), self.at(i1, j, k), self.at(i, j1, k), self.at(i1, j1, k));
            let v = (1.0 - t) * ((1.0 - s) * a + s * b) + t * ((1.0 - s) * c + s * d);
            (v, a.min(b).min(c.min(d)), a.max(b).max(c.max(d)))
        };
        if self.dim == 2 {
            return plane(0);
        }
        let (k, u) = split(g[2], self.dims[2]);
        let (v0, lo0, hi0) = plane(k);
        let (v1, lo1, hi1) = plane((k + 1).min(self.dims[2] - 1));
        ((1.0 - u) * v0 + u * v1, lo0.min(lo1), hi0.max(hi1))
    }

    /// Monotone cubic interpolation at index coordinates `g`, tensor product over the axes.
    #[inline]
    pub fn cubic(&self, g: [f64; 3]) -> f64 {
        let axis = |a: usize| {
            let (i, t) = split(g[a], self.dims[a]);
            let n = self.dims[a] as isize;
            let idx = |o: isize| (i as isize + o).clamp(0, n - 1) as usize;
            ([idx(-1), idx(0), idx(1), idx(2)], t)
        };
        let (xs, tx) = axis(0);
        let (ys, ty) = axis(1);
        let row = |j: usize, k: usize| {
            monotone_cubic(
                self.at(xs[0], j, k),
                self.at(xs[1], j, k),
                self.at(xs[2], j, k),
                self.at(xs[3], j, k),
                tx,
            )
        };
        let plane = |k: usize| monotone_cubic(row(ys[0], k), row(ys[1], k), row(ys[2], k), row(ys[3], k), ty);
        if self.dim == 2 {
            return plane(0);
        }
        let (zs, tz) = axis(2);
        monotone_cubic(plane(zs[0]), plane(zs[1]), plane(zs[2]), plane(zs[3]), tz)
    }

    /// Blends `value` toward the wall values where `g` lies between the last sample and a wall.
    #[inline]
    pub fn wall_blend(&self, g: [f64; 3], value: f64, walls: &WallValues) -> f64 {
        let mut v = value;
        for a in 0..self.dim {
            if let Some(w) = walls[a][0]
                && g[a] < 0.0
            {
                let t = ((g[a] + 0.5) * 2.0).clamp(0.0, 1.0);
                v = w + t * (v - w);
            }
            let last = (self.dims[a] - 1) as f64;
            if let Some(w) = walls[a][1]
                && g[a] > last
            {
                let t = ((last + 0.5 - g[a]) * 2.0).clamp(0.0, 1.0);
                v = w + t * (v - w);
            }
        }
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_and_cubic_reproduce_linear_functions() {
        let dims = [7, 6, 5];
        let f = |i: f64, j: f64, k: f64| 0.3 * i - 1.2 * j + 0.7 * k + 2.0;
        let values: Vec<f64> = (0..dims[0] * dims[1] * dims[2])
            .map(|c| f((c % 7) as f64, ((c / 7) % 6) as f64, (c / 42) as f64))
            .collect();
        let lat = Lattice { values: &values, dims, dim: 3 };
        for g in [[1.3, 2.7, 0.2], [0.0, 4.9, 3.999], [5.5, 0.5, 2.5], [2.25, 3.75, 1.5]] {
            assert!((lat.linear(g).0 - f(g[0], g[1], g[2])).abs() < 1e-12);
        }
        // The cubic is exact away from the first and last intervals (where the missing neighbour
        // is replaced by the nearest sample).
        for g in [[1.3, 2.7, 1.2], [2.25, 3.75, 1.5], [4.9, 1.1, 2.999]] {
            assert!((lat.cubic(g) - f(g[0], g[1], g[2])).abs() < 1e-12, "{g:?}");
        }
    }

    /// The cubic reproduces a cubic polynomial in the interior (where no limiter acts, the
    /// central slopes are exact for quadratics), and stays within its interval near a jump.
    #[test]
    fn cubic_is_accurate_on_smooth_data_and_monotone_at_a_step() {
        let f = |x: f64| 0.5 * x * x + x;
        let v: Vec<f64> = (0..8).map(|i| f(i as f64)).collect();
        let lat = Lattice { values: &v, dims: [8, 1, 1], dim: 2 };
        for g in [2.3, 3.5, 4.9] {
            assert!((lat.cubic([g, 0.0, 0.0]) - f(g)).abs() < 1e-12, "{g}");
        }
        let step = [0.0, 0.0, 0.0, 1.0, 1.0, 1.0];
        let lat = Lattice { values: &step, dims: [6, 1, 1], dim: 2 };
        for q in 0..=50 {
            let x = 1.0 + 3.0 * f64::from(q) / 50.0;
            let y = lat.cubic([x, 0.0, 0.0]);
            assert!((0.0..=1.0).contains(&y), "{x}: {y}");
        }
    }
}
