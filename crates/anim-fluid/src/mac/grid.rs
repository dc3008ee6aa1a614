//! The staggered (MAC) grid: where each quantity lives, and the walls around it.
//!
//! Harlow and Welch's (1965) marker-and-cell layout: the domain is `nx x ny x nz` cells of size
//! `h` (`nz = 1` in 2D). Density, temperature and pressure sit at cell centres; each velocity
//! component sits on the faces normal to its axis, so `u` has `(nx + 1) x ny x nz` samples, `v`
//! `nx x (ny + 1) x nz` and `w` `nx x ny x (nz + 1)` (none in 2D). Face `(i, j, k)` of component
//! `a` is the low face of cell `(i, j, k)` along `a`. The discrete divergence of a cell is then
//! the difference of the face values across it, `h div u = sum_a (u_a(+) - u_a(-))`, and a
//! pressure difference between two cells lands exactly on the face between them, which is why
//! the layout has no checkerboard mode. Every array is x fastest: sample `(i, j, k)` of a
//! lattice of extents `d` is at `i + d[0] (j + d[1] k)`.
//!
//! Boundary conditions act on faces ([`Wall`]): the normal velocity is zero on a no-slip or
//! free-slip wall and on every face of a solid (obstacle) cell; an open wall copies the inner
//! neighbour (zero normal gradient). A no-slip wall also sets the tangential velocity at the wall
//! to its own, which the samplers and the viscosity solve use (the wall lies half a cell beyond
//! the last tangential sample).

use crate::advection::WallValues;

/// A domain wall.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Wall {
    /// No-slip, moving with this velocity (its normal component must be 0).
    NoSlip([f64; 3]),
    /// Free-slip (zero normal velocity, zero tangential stress).
    FreeSlip,
    /// Open: pressure 0 outside, velocity and scalars extrapolated.
    Open,
}

/// Index of `(i, j, k)` in a lattice of `d`.
#[inline]
pub(super) fn idx(d: [usize; 3], i: usize, j: usize, k: usize) -> usize {
    i + d[0] * (j + d[1] * k)
}

/// The grid's geometry and boundaries: cell extents, dimension, cell size, walls and obstacles.
#[derive(Debug, Clone)]
pub(super) struct MacGrid {
    /// Cell extents (`nz = 1` in 2D).
    pub(super) dims: [usize; 3],
    /// 2 or 3.
    pub(super) dim: usize,
    /// Cell size.
    pub(super) h: f64,
    /// `walls[axis][0]` at the low side, `[1]` at the high side (the solver's settings' walls).
    pub(super) walls: [[Wall; 2]; 3],
    /// Whether each cell is a solid obstacle.
    pub(super) solid: Vec<bool>,
}

impl MacGrid {
    /// Number of cells.
    pub(super) fn cells(&self) -> usize {
        self.dims[0] * self.dims[1] * self.dims[2]
    }

    /// Number of samples of velocity component `a` (0 for `w` in 2D).
    pub(super) fn face_len(&self, a: usize) -> usize {
        if a < self.dim { self.cells() / self.dims[a] * (self.dims[a] + 1) } else { 0 }
    }

    /// The longest lattice: a velocity component's or the cells'.
    pub(super) fn max_len(&self) -> usize {
        (0..3).map(|a| self.face_len(a)).max().unwrap_or(0).max(self.cells())
    }

    /// Which sides are open (`p = 0` beyond them), as the pressure operator takes them.
    pub(super) fn open_sides(&self) -> [[bool; 2]; 3] {
        let mut open = [[false; 2]; 3];
        for a in 0..3 {
            for s in 0..2 {
                open[a][s] = self.walls[a][s] == Wall::Open;
            }
        }
        open
    }

    /// Lattice extents of velocity component `a`.
    pub(super) fn face_dims(&self, a: usize) -> [usize; 3] {
        let mut d = self.dims;
        if a < self.dim {
            d[a] += 1;
        } else {
            d = [0, 0, 0];
        }
        d
    }

    /// World position of the centre of cell `(i, j, k)` (z = 0 in 2D).
    pub(super) fn cell_centre(&self, i: usize, j: usize, k: usize) -> [f64; 3] {
        let z = if self.dim == 3 { (k as f64 + 0.5) * self.h } else { 0.0 };
        [(i as f64 + 0.5) * self.h, (j as f64 + 0.5) * self.h, z]
    }

    /// World position of face `(i, j, k)` of component `a`.
    pub(super) fn face_centre(&self, a: usize, i: usize, j: usize, k: usize) -> [f64; 3] {
        let mut p = self.cell_centre(i, j, k);
        p[a] -= 0.5 * self.h;
        p
    }

    /// Whether face `(i, j, k)` of component `a` is fixed by a wall or an obstacle.
    #[inline]
    pub(super) fn face_fixed(&self, a: usize, i: usize, j: usize, k: usize) -> bool {
        let n = [i, j, k];
        if n[a] == 0 || n[a] == self.dims[a] {
            return self.walls[a][usize::from(n[a] != 0)] != Wall::Open;
        }
        let stride = [1, self.dims[0], self.dims[0] * self.dims[1]][a];
        let hi = idx(self.dims, i, j, k);
        self.solid[hi] || self.solid[hi - stride]
    }

    /// Sets wall-normal and obstacle face velocities; open walls copy their inner neighbour.
    pub(super) fn enforce_walls(&self, vel: &mut [Vec<f64>; 3]) {
        for a in 0..self.dim {
            let d = self.face_dims(a);
            let stride = [1, d[0], d[0] * d[1]][a];
            let field = &mut vel[a];
            for k in 0..d[2] {
                for j in 0..d[1] {
                    for i in 0..d[0] {
                        let n = [i, j, k];
                        let f = idx(d, i, j, k);
                        if n[a] == 0 || n[a] == self.dims[a] {
                            let side = usize::from(n[a] != 0);
                            field[f] = match self.walls[a][side] {
                                Wall::Open => {
                                    if side == 0 {
                                        field[f + stride]
                                    } else {
                                        field[f - stride]
                                    }
                                }
                                _ => 0.0,
                            };
                        } else if self.face_fixed(a, i, j, k) {
                            field[f] = 0.0;
                        }
                    }
                }
            }
        }
    }

    /// Tangential wall values for sampling component `a` (no-slip walls only).
    pub(super) fn wall_values(&self, a: usize) -> WallValues {
        let mut w: WallValues = [[None; 2]; 3];
        for b in 0..self.dim {
            if b == a {
                continue;
            }
            for s in 0..2 {
                if let Wall::NoSlip(v) = self.walls[b][s] {
                    w[b][s] = Some(v[a]);
                }
            }
        }
        w
    }

    /// Index coordinates of world point `p` in the lattice of component `a` (3 = cell centres).
    #[inline]
    pub(super) fn lattice_coords(&self, a: usize, p: [f64; 3]) -> [f64; 3] {
        let mut g = [0.0; 3];
        for b in 0..self.dim {
            g[b] = p[b] / self.h - if b == a { 0.0 } else { 0.5 };
        }
        g
    }
}
