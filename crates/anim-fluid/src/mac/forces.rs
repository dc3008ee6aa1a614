//! Body forces and sources: the *add force* step of stable fluids (Stam 1999), `w1 = w0 + dt f`, for smoke.
//!
//! - **Buoyancy** (Fedkiw, Stam and Jensen 2001): `f = (-alpha rho + beta (T - T_amb)) e_y`,
//!   dense smoke sinks and hot smoke rises; evaluated on each interior `v` face from the mean of
//!   the density and temperature of the two cells it separates.
//! - **Vorticity confinement** (Steinhoff and Underhill 1994, for smoke Fedkiw, Stam and Jensen
//!   2001): puts back the small swirls numerical dissipation smears out. With the vorticity
//!   `omega = curl u` at cell centres (central differences of the cell-averaged velocity,
//!   one-sided at the walls) and `N = grad|omega| / |grad|omega||` pointing toward stronger
//!   vorticity, the force `f = eps h (N x omega)` spins each vortex up around its core; it is
//!   averaged from the two cells onto each interior face. In 2D `omega` has only its z
//!   component.
//! - **Sources** ([`Source`]): inflow boxes that raise the density to theirs, set the
//!   temperature and optionally the velocity of the cells and faces inside (wall and obstacle
//!   faces excepted). A [`RegionSource`] does the same over cells and faces of any shape, given
//!   as masks (a sphere's, a mesh's), solid cells excepted; region sources act after the boxes.
//!
//! Each force pass writes one row of faces or cells per task from the previous arrays only, so
//! the result does not depend on the number of threads.

use crate::error::FluidError;
use crate::mac::grid::{MacGrid, idx};
use rayon::prelude::*;

/// An inflow box: every step, inside it the density and temperature are set to these values and
/// the velocity to `velocity`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Source {
    /// Lower corner (world units).
    pub min: [f64; 3],
    /// Upper corner.
    pub max: [f64; 3],
    /// Density set inside.
    pub density: f64,
    /// Temperature set inside.
    pub temperature: f64,
    /// Velocity set on the faces inside, or `None` to leave it.
    pub velocity: Option<[f64; 3]>,
}

/// An inflow region of any shape, given as masks of the cells and faces whose centres lie
/// inside it: every step, the density of its cells is raised to `density`, their temperature
/// set to `temperature` and, when `velocity` is given, the velocity of its faces set to it.
/// Solid (obstacle) cells and wall and obstacle faces are left alone.
#[derive(Debug, Clone, PartialEq)]
pub struct RegionSource {
    /// Per cell (x fastest, the layout of the cell fields), whether its centre lies inside.
    pub cells: Vec<bool>,
    /// Per velocity component `a`, whether each face centre of its lattice
    /// ([`MacFluid::face_dims`](crate::mac::MacFluid::face_dims)) lies inside; empty for `w` in
    /// 2D.
    pub faces: [Vec<bool>; 3],
    /// Density the cells are raised to.
    pub density: f64,
    /// Temperature the cells are set to.
    pub temperature: f64,
    /// Velocity set on the faces inside, or `None` to leave it.
    pub velocity: Option<[f64; 3]>,
}

impl RegionSource {
    /// Checks the masks' lengths against `grid` and that the values are finite.
    pub(super) fn check(&self, grid: &MacGrid) -> Result<(), FluidError> {
        let cells = grid.cells();
        if self.cells.len() != cells {
            return Err(FluidError::BadLength {
                name: "source cells",
                got: self.cells.len(),
                expected: cells,
            });
        }
        for (a, name) in ["source u faces", "source v faces", "source w faces"].into_iter().enumerate() {
            let expected = grid.face_len(a);
            if self.faces[a].len() != expected {
                return Err(FluidError::BadLength { name, got: self.faces[a].len(), expected });
            }
        }
        let scalars = [self.density, self.temperature];
        if scalars.iter().chain(self.velocity.iter().flatten()).any(|x| !x.is_finite()) {
            return Err(FluidError::BadParameter {
                name: "sources",
                requirement: "must be finite",
                value: format!(
                    "density {}, temperature {}, velocity {:?}",
                    self.density, self.temperature, self.velocity
                ),
            });
        }
        Ok(())
    }
}

/// Buoyancy `v += dt (-alpha rho + beta (T - amb))` on the interior faces of `vy`, the y
/// component of the velocity (`rho` and `temp` are the cells' density and temperature).
pub(super) fn buoyancy(
    grid: &MacGrid,
    alpha: f64,
    beta: f64,
    amb: f64,
    vy: &mut [f64],
    rho: &[f64],
    temp: &[f64],
    dt: f64,
) {
    let d = grid.dims;
    let fd = grid.face_dims(1);
    vy.par_chunks_mut(fd[0])
        .enumerate()
        .with_min_len(crate::grain::lines(fd[0], crate::grain::STENCIL_NS))
        .for_each(|(line, row)| {
            let (j, k) = (line % fd[1], line / fd[1]);
            if j == 0 || j == d[1] {
                return;
            }
            for (i, v) in row.iter_mut().enumerate() {
                let (lo, hi) = (idx(d, i, j - 1, k), idx(d, i, j, k));
                let f = -alpha * 0.5 * (rho[lo] + rho[hi]) + beta * (0.5 * (temp[lo] + temp[hi]) - amb);
                *v += dt * f;
            }
        });
}

/// Vorticity confinement and its per-cell buffers, sized by the solver's constructor.
#[derive(Debug, Clone)]
pub(super) struct Confinement {
    /// The cell-centred velocity, then the force per cell.
    cell_vec: [Vec<f64>; 3],
    /// `|omega|` per cell.
    cell_mag: Vec<f64>,
    /// `omega` per cell.
    cell_force: [Vec<f64>; 3],
}

impl Confinement {
    /// Buffers for `cells` cells.
    pub(super) fn new(cells: usize) -> Self {
        Self {
            cell_vec: [vec![0.0; cells], vec![0.0; cells], vec![0.0; cells]],
            cell_mag: vec![0.0; cells],
            cell_force: [vec![0.0; cells], vec![0.0; cells], vec![0.0; cells]],
        }
    }

    /// `vel += dt f` with the confinement force of strength `eps`.
    pub(super) fn apply(&mut self, grid: &MacGrid, eps: f64, vel: &mut [Vec<f64>; 3], dt: f64) {
        let (d, h, dim) = (grid.dims, grid.h, grid.dim);
        // Cell-centred velocity.
        {
            let vel = &*vel;
            for a in 0..dim {
                let fd = grid.face_dims(a);
                let stride = [1, fd[0], fd[0] * fd[1]][a];
                self.cell_vec[a]
                    .par_chunks_mut(d[0])
                    .enumerate()
                    .with_min_len(crate::grain::lines(d[0], crate::grain::WIDE_STENCIL_NS))
                    .for_each(|(line, row)| {
                        let (j, k) = (line % d[1], line / d[1]);
                        for (i, c) in row.iter_mut().enumerate() {
                            let f = idx(fd, i, j, k);
                            *c = 0.5 * (vel[a][f] + vel[a][f + stride]);
                        }
                    });
            }
        }
        // Vorticity (central differences, one-sided at the walls) into cell_force, |omega| into cell_mag.
        let cv = &self.cell_vec;
        let deriv = |field: &[f64], i: usize, j: usize, k: usize, b: usize| -> f64 {
            let n = [i, j, k];
            let (lo, hi) = (n[b].saturating_sub(1), (n[b] + 1).min(d[b] - 1));
            let mut a = n;
            a[b] = lo;
            let mut c = n;
            c[b] = hi;
            (field[idx(d, c[0], c[1], c[2])] - field[idx(d, a[0], a[1], a[2])])
                / ((hi - lo).max(1) as f64 * h)
        };
        {
            let [f0, f1, f2] = &mut self.cell_force;
            let mag = &mut self.cell_mag;
            mag.par_chunks_mut(d[0])
                .zip(f0.par_chunks_mut(d[0]).zip(f1.par_chunks_mut(d[0]).zip(f2.par_chunks_mut(d[0]))))
                .enumerate()
                .with_min_len(crate::grain::lines(d[0], crate::grain::WIDE_STENCIL_NS))
                .for_each(|(line, (m, (o0, (o1, o2))))| {
                    let (j, k) = (line % d[1], line / d[1]);
                    for i in 0..d[0] {
                        let wz = deriv(&cv[1], i, j, k, 0) - deriv(&cv[0], i, j, k, 1);
                        let (wx, wy) = if dim == 3 {
                            (
                                deriv(&cv[2], i, j, k, 1) - deriv(&cv[1], i, j, k, 2),
                                deriv(&cv[0], i, j, k, 2) - deriv(&cv[2], i, j, k, 0),
                            )
                        } else {
                            (0.0, 0.0)
                        };
                        o0[i] = wx;
                        o1[i] = wy;
                        o2[i] = wz;
                        m[i] = (wx * wx + wy * wy + wz * wz).sqrt();
                    }
                });
        }
        // Force per cell: eps h (N x omega), stored in cell_vec (velocities no longer needed).
        let (omega, mag) = (&self.cell_force, &self.cell_mag);
        {
            let [c0, c1, c2] = &mut self.cell_vec;
            c0.par_chunks_mut(d[0])
                .zip(c1.par_chunks_mut(d[0]).zip(c2.par_chunks_mut(d[0])))
                .enumerate()
                .with_min_len(crate::grain::lines(d[0], crate::grain::WIDE_STENCIL_NS))
                .for_each(|(line, (f0, (f1, f2)))| {
                    let (j, k) = (line % d[1], line / d[1]);
                    for i in 0..d[0] {
                        let gx = deriv(mag, i, j, k, 0);
                        let gy = deriv(mag, i, j, k, 1);
                        let gz = if dim == 3 { deriv(mag, i, j, k, 2) } else { 0.0 };
                        let len = (gx * gx + gy * gy + gz * gz).sqrt() + 1e-12 / h;
                        let (nx, ny, nz) = (gx / len, gy / len, gz / len);
                        let c = idx(d, i, j, k);
                        let (ox, oy, oz) = (omega[0][c], omega[1][c], omega[2][c]);
                        f0[i] = eps * h * (ny * oz - nz * oy);
                        f1[i] = eps * h * (nz * ox - nx * oz);
                        f2[i] = eps * h * (nx * oy - ny * ox);
                    }
                });
        }
        for a in 0..dim {
            let fd = grid.face_dims(a);
            let cf = &self.cell_vec[a];
            vel[a]
                .par_chunks_mut(fd[0])
                .enumerate()
                .with_min_len(crate::grain::lines(fd[0], crate::grain::STENCIL_NS))
                .for_each(|(line, row)| {
                    let (j, k) = (line % fd[1], line / fd[1]);
                    for (i, v) in row.iter_mut().enumerate() {
                        let n = [i, j, k];
                        if n[a] == 0 || n[a] == d[a] {
                            continue;
                        }
                        let mut lo = n;
                        lo[a] -= 1;
                        *v += dt * 0.5 * (cf[idx(d, lo[0], lo[1], lo[2])] + cf[idx(d, i, j, k)]);
                    }
                });
        }
    }
}

/// Applies the sources: density, temperature and velocity inside each box.
pub(super) fn apply_sources(
    grid: &MacGrid,
    sources: &[Source],
    vel: &mut [Vec<f64>; 3],
    density: &mut [f64],
    temperature: &mut [f64],
) {
    let inside = |s: &Source, p: [f64; 3]| (0..grid.dim).all(|b| p[b] >= s.min[b] && p[b] <= s.max[b]);
    let d = grid.dims;
    for s in sources {
        for k in 0..d[2] {
            for j in 0..d[1] {
                for i in 0..d[0] {
                    if inside(s, grid.cell_centre(i, j, k)) {
                        let c = idx(d, i, j, k);
                        density[c] = density[c].max(s.density);
                        temperature[c] = s.temperature;
                    }
                }
            }
        }
        if let Some(v) = s.velocity {
            for a in 0..grid.dim {
                let fd = grid.face_dims(a);
                for k in 0..fd[2] {
                    for j in 0..fd[1] {
                        for i in 0..fd[0] {
                            if inside(s, grid.face_centre(a, i, j, k)) && !grid.face_fixed(a, i, j, k) {
                                vel[a][idx(fd, i, j, k)] = v[a];
                            }
                        }
                    }
                }
            }
        }
    }
}

/// A checked [`RegionSource`] as a step applies it: the indices of the cells and faces it covers
/// (the masks' true entries), so that a step costs what the source covers, not the grid.
#[derive(Debug, Clone)]
pub(super) struct CoveredRegion {
    cells: Vec<usize>,
    faces: [Vec<usize>; 3],
    density: f64,
    temperature: f64,
    velocity: Option<[f64; 3]>,
}

impl CoveredRegion {
    /// The cells and faces `source` covers (its masks checked against the grid already).
    pub(super) fn of(source: &RegionSource) -> Self {
        let covered = |mask: &[bool]| -> Vec<usize> {
            mask.iter().enumerate().filter(|&(_, &inside)| inside).map(|(c, _)| c).collect()
        };
        CoveredRegion {
            cells: covered(&source.cells),
            faces: std::array::from_fn(|a| covered(&source.faces[a])),
            density: source.density,
            temperature: source.temperature,
            velocity: source.velocity,
        }
    }
}

/// Applies the region sources, in order: density and temperature on their fluid cells, velocity
/// on their free faces.
pub(super) fn apply_region_sources(
    grid: &MacGrid,
    sources: &[CoveredRegion],
    vel: &mut [Vec<f64>; 3],
    density: &mut [f64],
    temperature: &mut [f64],
) {
    for s in sources {
        for &c in s.cells.iter().filter(|&&c| !grid.solid[c]) {
            density[c] = density[c].max(s.density);
            temperature[c] = s.temperature;
        }
        if let Some(v) = s.velocity {
            for a in 0..grid.dim {
                let fd = grid.face_dims(a);
                for &f in &s.faces[a] {
                    let (i, j, k) = (f % fd[0], (f / fd[0]) % fd[1], f / (fd[0] * fd[1]));
                    if !grid.face_fixed(a, i, j, k) {
                        vel[a][f] = v[a];
                    }
                }
            }
        }
    }
}
