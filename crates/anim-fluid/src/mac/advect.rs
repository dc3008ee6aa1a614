//! Advection of the MAC fields: the *advect* step of stable fluids (Stam 1999), `w2(x) = w1(p(x, -dt))`, on the
//! staggered grid.
//!
//! Every sample (a face of velocity component `a`, or a cell centre for density and temperature)
//! takes the value the flow carried to it: from its own position `x` it is traced back through
//! the velocity at the start of the advection with the midpoint rule,
//! `x_mid = x - dt/2 u(x)`, `x_back = x - dt u(x_mid)` (each component of `u` interpolated
//! linearly on its own faces, both points clamped to the domain), and the field is sampled at
//! `x_back` on its own lattice, linearly or by a monotone cubic, the tangential velocity
//! blended toward a no-slip wall's in the half cell next to it (the samplers are in
//! [`crate::advection`]).
//!
//! That semi-Lagrangian pass (Stam 1999) is unconditionally stable but, with linear
//! interpolation, diffusive. Two schemes cancel most of its error with two extra passes over the
//! same characteristics, forward (`A`) and backward (`A^-1`, the trace with `-dt`):
//!
//! - **BFECC** (Kim, Liu, Llamas and Rossignac 2005): `phi~ = phi + (phi - A^-1 A phi) / 2`,
//!   the result `A phi~`;
//! - **MacCormack** (Selle, Fedkiw, Kim, Liu and Rossignac 2008): the result
//!   `A phi + (phi - A^-1 A phi) / 2`;
//!
//! both limited as Selle et al. propose: the result is clamped to the range of the samples the
//! forward trace interpolated (the wall value included where one is blended in), so no new
//! extrema appear and the scheme stays stable.
//!
//! Each pass writes one output row per task and reads only its inputs, so the result does not
//! depend on the number of threads.

use crate::advection::{Advection, Lattice};
use crate::mac::grid::MacGrid;
use rayon::prelude::*;

/// The advection stage's buffers, sized by the solver's constructor.
#[derive(Debug, Clone)]
pub(super) struct Transport {
    /// The velocity at the start of the advection, which carries every field.
    old_vel: [Vec<f64>; 3],
    /// The forward, backward and corrected passes of BFECC and MacCormack.
    tmp: [Vec<f64>; 3],
    /// A scalar field before its advection.
    scalar_old: Vec<f64>,
}

impl Transport {
    /// Buffers for `grid`.
    pub(super) fn new(grid: &MacGrid) -> Self {
        let max_len = grid.max_len();
        Self {
            old_vel: std::array::from_fn(|a| vec![0.0; grid.face_len(a)]),
            tmp: [vec![0.0; max_len], vec![0.0; max_len], vec![0.0; max_len]],
            scalar_old: vec![0.0; grid.cells()],
        }
    }

    /// Copies the velocity `vel` aside and advects over `dt` by it, with `scheme`: the velocity
    /// itself, or `field` (one array per component, on the velocity's faces) when given; then
    /// sets the wall faces.
    pub(super) fn velocity(
        &mut self,
        grid: &MacGrid,
        scheme: Advection,
        vel: &mut [Vec<f64>; 3],
        field: Option<&[Vec<f64>; 3]>,
        dt: f64,
    ) {
        for a in 0..grid.dim {
            self.old_vel[a].copy_from_slice(&vel[a]);
        }
        let old = &self.old_vel;
        for a in 0..grid.dim {
            let input = field.map_or(&old[a], |f| &f[a]);
            advect_field(grid, scheme, old, a, input, &mut vel[a], dt, &mut self.tmp);
        }
        grid.enforce_walls(vel);
    }

    /// Advects `density` and `temperature` over `dt` with `scheme`, by the velocity the last
    /// [`Transport::velocity`] copied aside.
    pub(super) fn scalars(
        &mut self,
        grid: &MacGrid,
        scheme: Advection,
        density: &mut [f64],
        temperature: &mut [f64],
        dt: f64,
    ) {
        for target in [density, temperature] {
            self.scalar_old.copy_from_slice(target);
            advect_field(grid, scheme, &self.old_vel, 3, &self.scalar_old, target, dt, &mut self.tmp);
        }
    }
}

/// Velocity at world position `p`, linear interpolation of each component.
#[inline]
fn velocity_at(grid: &MacGrid, vel: &[Vec<f64>; 3], p: [f64; 3]) -> [f64; 3] {
    let mut out = [0.0; 3];
    for a in 0..grid.dim {
        let lat = Lattice { values: &vel[a], dims: grid.face_dims(a), dim: grid.dim };
        let g = grid.lattice_coords(a, p);
        out[a] = lat.linear(g).0;
    }
    out
}

/// Midpoint back-trace of `p` through `vel` over `dt` (negative dt traces forward), clamped
/// to the domain.
#[inline]
fn trace(grid: &MacGrid, vel: &[Vec<f64>; 3], p: [f64; 3], dt: f64) -> [f64; 3] {
    let clamp = |mut q: [f64; 3]| {
        for b in 0..grid.dim {
            q[b] = q[b].clamp(0.0, grid.dims[b] as f64 * grid.h);
        }
        q
    };
    let u0 = velocity_at(grid, vel, p);
    let mut mid = p;
    for b in 0..grid.dim {
        mid[b] -= 0.5 * dt * u0[b];
    }
    let um = velocity_at(grid, vel, clamp(mid));
    let mut q = p;
    for b in 0..grid.dim {
        q[b] -= dt * um[b];
    }
    clamp(q)
}

/// One semi-Lagrangian pass: `out[x] = field(trace(x, dt))` on the lattice of component `a`
/// (3 for cell scalars). With `clamp_to`, `out` is also clamped into the range of the samples of
/// `clamp_to` around the traced point.
fn sl_pass(
    grid: &MacGrid,
    vel: &[Vec<f64>; 3],
    a: usize,
    field: &[f64],
    out: &mut [f64],
    dt: f64,
    cubic: bool,
    clamp_to: Option<&[f64]>,
) {
    let d = if a < 3 { grid.face_dims(a) } else { grid.dims };
    let lat = Lattice { values: field, dims: d, dim: grid.dim };
    let walls = if a < 3 { grid.wall_values(a) } else { [[None; 2]; 3] };
    let range = clamp_to.map(|v| Lattice { values: v, dims: d, dim: grid.dim });
    let offset = |b: usize| if b == a { 0.0 } else { 0.5 };
    out[..field.len()]
        .par_chunks_mut(d[0])
        .enumerate()
        .with_min_len(crate::grain::lines(d[0], crate::grain::TRACE_NS))
        .for_each(|(line, row)| {
            let (j, k) = (line % d[1], line / d[1]);
            for (i, o) in row.iter_mut().enumerate() {
                let n = [i, j, k];
                let mut p = [0.0; 3];
                for b in 0..grid.dim {
                    p[b] = (n[b] as f64 + offset(b)) * grid.h;
                }
                let q = trace(grid, vel, p, dt);
                let g = grid.lattice_coords(a, q);
                let mut v = if cubic { lat.cubic(g) } else { lat.linear(g).0 };
                v = lat.wall_blend(g, v, &walls);
                if let Some(r) = &range {
                    let (_, lo, hi) = r.linear(g);
                    let w = r.wall_blend(g, v, &walls);
                    let (lo, hi) = (lo.min(w), hi.max(w));
                    v = v.clamp(lo, hi);
                }
                *o = v;
            }
        });
}

/// Advects `field_in` (lattice of component `a`, 3 for scalars) by `old` (the velocity at the
/// start of the advection) with `scheme` into `out`; `tmp` is scratch.
fn advect_field(
    grid: &MacGrid,
    scheme: Advection,
    old: &[Vec<f64>; 3],
    a: usize,
    field_in: &[f64],
    out: &mut [f64],
    dt: f64,
    tmp: &mut [Vec<f64>; 3],
) {
    let [fwd, back, corrected] = tmp;
    let n = field_in.len();
    match scheme {
        Advection::Linear => sl_pass(grid, old, a, field_in, out, dt, false, None),
        Advection::MonotoneCubic => sl_pass(grid, old, a, field_in, out, dt, true, None),
        Advection::Bfecc => {
            sl_pass(grid, old, a, field_in, fwd, dt, false, None);
            sl_pass(grid, old, a, &fwd[..n], back, -dt, false, None);
            corrected[..n]
                .par_iter_mut()
                .zip(field_in.par_iter().zip(back[..n].par_iter()))
                .with_min_len(crate::grain::ENTRIES)
                .for_each(|(c, (&f, &b))| *c = f + 0.5 * (f - b));
            sl_pass(grid, old, a, &corrected[..n], out, dt, false, Some(field_in));
        }
        Advection::MacCormack => {
            sl_pass(grid, old, a, field_in, fwd, dt, false, None);
            sl_pass(grid, old, a, &fwd[..n], back, -dt, false, None);
            corrected[..n]
                .par_iter_mut()
                .zip(fwd[..n].par_iter().zip(field_in.par_iter().zip(back[..n].par_iter())))
                .with_min_len(crate::grain::ENTRIES)
                .for_each(|(c, (&fw, (&f, &b)))| *c = fw + 0.5 * (f - b));
            // Limiter: clamp into the range of the samples the forward trace used.
            let d = if a < 3 { grid.face_dims(a) } else { grid.dims };
            let lat = Lattice { values: field_in, dims: d, dim: grid.dim };
            let walls = if a < 3 { grid.wall_values(a) } else { [[None; 2]; 3] };
            let offset = |b: usize| if b == a { 0.0 } else { 0.5 };
            out[..n]
                .par_chunks_mut(d[0])
                .zip(corrected[..n].par_chunks(d[0]))
                .enumerate()
                .with_min_len(crate::grain::lines(d[0], crate::grain::TRACE_NS))
                .for_each(|(line, (row, crow))| {
                    let (j, k) = (line % d[1], line / d[1]);
                    for (i, (o, &c)) in row.iter_mut().zip(crow).enumerate() {
                        let nn = [i, j, k];
                        let mut p = [0.0; 3];
                        for b in 0..grid.dim {
                            p[b] = (nn[b] as f64 + offset(b)) * grid.h;
                        }
                        let g = grid.lattice_coords(a, trace(grid, old, p, dt));
                        let (v, lo, hi) = lat.linear(g);
                        let w = lat.wall_blend(g, v, &walls);
                        *o = c.clamp(lo.min(w), hi.max(w));
                    }
                });
        }
    }
}
