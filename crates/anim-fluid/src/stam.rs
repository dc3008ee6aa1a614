//! Stam's stable fluids solver, reproduced operation for operation in `f32`.
//!
//! Jos Stam, *Real-Time Fluid Dynamics for Games* (GDC 2003): density and velocity live at the
//! centres of an `N x N` grid with a one-cell border (`(N+2)^2` values, `IX(i,j) = i + (N+2) j`),
//! the domain is the unit square (`h = 1/N`), and a step is
//!
//! ```text
//! vel_step:  u += dt u0;  u = (I - visc dt Lap)^-1 u;  project;  u = advect(u, u);  project
//! dens_step: d += dt d0;  d = (I - diff dt Lap)^-1 d;  d = advect(d, u)
//! ```
//!
//! with Stam's `lin_solve` (20 Gauss-Seidel sweeps of
//! `x_ij = (x0_ij + a (x_{i-1,j} + x_{i+1,j} + x_{i,j-1} + x_{i,j+1})) / c`, then `set_bnd`),
//! `advect` (back-trace `x - dt N u`, clamp to `[0.5, N + 0.5]`, bilinear), `project`
//! (central-difference divergence, the same 20 sweeps with `a = 1, c = 4`, central-difference
//! gradient) and `set_bnd` (mirror the first interior row, negated for the normal component
//! `b = 1` (u) on the x walls and `b = 2` (v) on the y walls; corners the mean of their two
//! neighbours).
//!
//! Every function here performs the same `f32` operations in the same order as the C code, so
//! the fields are identical to the last bit to a C build without contraction
//! (`cc -O2 -ffp-contract=off`; checked by the unit tests against committed C output and by
//! `cargo xtask conformance` against a freshly compiled C transcription at N = 64 and 128).
//! Rust never fuses a multiply and an add unless asked.
//!
//! **Speed without changing a bit.** The C code's Gauss-Seidel sweep walks `i` in the outer loop
//! and `j` in the inner one (a stride of `N + 2` floats), and each update waits for the previous
//! one (a chain of adds and a division). Cell `(i, j)` reads the *new* values of `(i-1, j)` and
//! `(i, j-1)` and the *old* values of `(i+1, j)` and `(i, j+1)` in any lexicographic order, so
//! [`lin_solve`] walks memory contiguously and advances a band of rows together, each row one cell
//! behind the row below it (a wavefront): every cell still sees exactly the same operands, but the
//! band's rows are independent chains the processor overlaps.

use crate::error::{self, FluidError};
use serde::Deserialize as _;

/// Gauss-Seidel sweeps per `lin_solve`, as in Stam's code.
pub const SWEEPS: usize = 20;

/// Rows advanced together by the wavefront sweep of [`lin_solve`].
const BAND: usize = 8;

/// Index of cell `(i, j)` in an `(N+2)^2` array: Stam's `IX` macro.
#[inline]
#[must_use]
pub const fn ix(n: usize, i: usize, j: usize) -> usize {
    i + (n + 2) * j
}

/// `x += dt s` over the whole array, border included (Stam's `add_source`).
pub fn add_source(x: &mut [f32], s: &[f32], dt: f32) {
    for (xi, &si) in x.iter_mut().zip(s) {
        *xi += dt * si;
    }
}

/// Stam's boundary conditions (`set_bnd`): border cells copy their interior neighbour, negated for the
/// normal velocity component (`b = 1`: u at the x walls, `b = 2`: v at the y walls); corners are
/// the mean of their two border neighbours.
pub fn set_bnd(n: usize, b: u8, x: &mut [f32]) {
    for i in 1..=n {
        x[ix(n, 0, i)] = if b == 1 { -x[ix(n, 1, i)] } else { x[ix(n, 1, i)] };
        x[ix(n, n + 1, i)] = if b == 1 { -x[ix(n, n, i)] } else { x[ix(n, n, i)] };
        x[ix(n, i, 0)] = if b == 2 { -x[ix(n, i, 1)] } else { x[ix(n, i, 1)] };
        x[ix(n, i, n + 1)] = if b == 2 { -x[ix(n, i, n)] } else { x[ix(n, i, n)] };
    }
    x[ix(n, 0, 0)] = 0.5 * (x[ix(n, 1, 0)] + x[ix(n, 0, 1)]);
    x[ix(n, 0, n + 1)] = 0.5 * (x[ix(n, 1, n + 1)] + x[ix(n, 0, n)]);
    x[ix(n, n + 1, 0)] = 0.5 * (x[ix(n, n, 0)] + x[ix(n, n + 1, 1)]);
    x[ix(n, n + 1, n + 1)] = 0.5 * (x[ix(n, n, n + 1)] + x[ix(n, n + 1, n)]);
}

/// One lexicographic Gauss-Seidel sweep over the interior, as a wavefront over bands of rows
/// (same operands for every cell as Stam's loop; see the module doc).
fn gauss_seidel_sweep(n: usize, x: &mut [f32], x0: &[f32], a: f32, c: f32) {
    let w = n + 2;
    let mut j0 = 1;
    while j0 <= n {
        let rows = BAND.min(n + 1 - j0);
        // At wavefront time t, row r of the band updates cell i = t + 1 - r (1 <= i <= n).
        for t in 0..n + rows - 1 {
            let r_lo = (t + 1).saturating_sub(n);
            let r_hi = rows.min(t + 1);
            for r in r_lo..r_hi {
                let k = (t + 1 - r) + w * (j0 + r);
                x[k] = (x0[k] + a * (((x[k - 1] + x[k + 1]) + x[k - w]) + x[k + w])) / c;
            }
        }
        j0 += rows;
    }
}

/// [`SWEEPS`] Gauss-Seidel sweeps of `x_ij = (x0_ij + a * (sum of the 4 neighbours)) / c`, each
/// followed by [`set_bnd`] (Stam's `lin_solve`).
pub fn lin_solve(n: usize, b: u8, x: &mut [f32], x0: &[f32], a: f32, c: f32) {
    for _ in 0..SWEEPS {
        gauss_seidel_sweep(n, x, x0, a, c);
        set_bnd(n, b, x);
    }
}

/// Implicit diffusion `(I - diff dt Lap) x = x0` with `a = dt diff N^2` (Stam's `diffuse`).
pub fn diffuse(n: usize, b: u8, x: &mut [f32], x0: &[f32], diff: f32, dt: f32) {
    let nf = n as f32;
    let a = dt * diff * nf * nf;
    lin_solve(n, b, x, x0, a, 1.0 + 4.0 * a);
}

/// Semi-Lagrangian advection of `d0` by `(u, v)` into `d` (Stam's `advect`).
pub fn advect(n: usize, b: u8, d: &mut [f32], d0: &[f32], u: &[f32], v: &[f32], dt: f32) {
    let nf = n as f32;
    let dt0 = dt * nf;
    for j in 1..=n {
        for i in 1..=n {
            let k = ix(n, i, j);
            let mut x = i as f32 - dt0 * u[k];
            let mut y = j as f32 - dt0 * v[k];
            if x < 0.5 {
                x = 0.5;
            }
            if x > nf + 0.5 {
                x = nf + 0.5;
            }
            let i0 = x as usize;
            let i1 = i0 + 1;
            if y < 0.5 {
                y = 0.5;
            }
            if y > nf + 0.5 {
                y = nf + 0.5;
            }
            let j0 = y as usize;
            let j1 = j0 + 1;
            let s1 = x - i0 as f32;
            let s0 = 1.0 - s1;
            let t1 = y - j0 as f32;
            let t0 = 1.0 - t1;
            d[k] = s0 * (t0 * d0[ix(n, i0, j0)] + t1 * d0[ix(n, i0, j1)])
                + s1 * (t0 * d0[ix(n, i1, j0)] + t1 * d0[ix(n, i1, j1)]);
        }
    }
    set_bnd(n, b, d);
}

/// Makes `(u, v)` divergence free: central-difference divergence into `div`, Poisson solve for
/// `p` by [`lin_solve`], `u -= grad p` (Stam's `project`).
pub fn project(n: usize, u: &mut [f32], v: &mut [f32], p: &mut [f32], div: &mut [f32]) {
    let nf = n as f32;
    let w = n + 2;
    for j in 1..=n {
        for i in 1..=n {
            let k = ix(n, i, j);
            div[k] = -0.5 * (u[k + 1] - u[k - 1] + v[k + w] - v[k - w]) / nf;
            p[k] = 0.0;
        }
    }
    set_bnd(n, 0, div);
    set_bnd(n, 0, p);
    lin_solve(n, 0, p, div, 1.0, 4.0);
    for j in 1..=n {
        for i in 1..=n {
            let k = ix(n, i, j);
            u[k] -= 0.5 * nf * (p[k + 1] - p[k - 1]);
            v[k] -= 0.5 * nf * (p[k + w] - p[k - w]);
        }
    }
    set_bnd(n, 1, u);
    set_bnd(n, 2, v);
}

/// Stam's `dens_step`: add the source `x0`, diffuse, advect by `(u, v)`. `x0` is scratch
/// afterwards (as in C, where the swapped pointers reuse it).
pub fn dens_step(n: usize, x: &mut [f32], x0: &mut [f32], u: &[f32], v: &[f32], diff: f32, dt: f32) {
    add_source(x, x0, dt);
    // SWAP(x0, x); diffuse(N, 0, x, x0): the diffused field goes into the source array.
    diffuse(n, 0, x0, x, diff, dt);
    // SWAP(x0, x); advect(N, 0, x, x0, u, v)
    advect(n, 0, x, x0, u, v, dt);
}

/// Stam's `vel_step`: add the forces `(u0, v0)`, diffuse, project, self-advect, project.
/// `u0`, `v0` are scratch afterwards.
pub fn vel_step(n: usize, u: &mut [f32], v: &mut [f32], u0: &mut [f32], v0: &mut [f32], visc: f32, dt: f32) {
    add_source(u, u0, dt);
    add_source(v, v0, dt);
    diffuse(n, 1, u0, u, visc, dt);
    diffuse(n, 2, v0, v, visc, dt);
    project(n, u0, v0, u, v);
    advect(n, 1, u, u0, u0, v0, dt);
    advect(n, 2, v, v0, u0, v0, dt);
    project(n, u, v, u0, v0);
}

/// The fixed source pattern used to compare against the C transcription (and by the 2D smoke
/// scene): the `prev` arrays are cleared, then a block of `(2r+1) x (r+1)` cells at the bottom
/// centre (`r = max(N/16, 1)`, columns `N/2 - r..=N/2 + r`, rows `2..=2+r`) emits density 100 and an upward force 5, and a
/// sideways force of +2 or -2 that flips every 25 steps.
pub fn source_pattern(n: usize, step: u64, d: &mut [f32], u: &mut [f32], v: &mut [f32]) {
    d.fill(0.0);
    u.fill(0.0);
    v.fill(0.0);
    let c = n / 2;
    let r = (n / 16).max(1);
    let side = if (step / 25) % 2 == 1 { -2.0 } else { 2.0 };
    for i in c - r..=c + r {
        for j in 2..=2 + r {
            let k = ix(n, i, j);
            d[k] = 100.0;
            v[k] = 5.0;
            u[k] = side;
        }
    }
}

/// Settings of [`StamFluid`].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StamParams {
    /// Time step. Default 0.1 (Stam's demo).
    pub dt: f32,
    /// Density diffusion coefficient `diff`. Default 1e-4.
    pub diff: f32,
    /// Kinematic viscosity `visc`. Default 1e-4.
    pub visc: f32,
}

impl Default for StamParams {
    fn default() -> Self {
        Self { dt: 0.1, diff: 1e-4, visc: 1e-4 }
    }
}

/// Stam's solver state: `N`, the six `(N+2)^2` arrays of the C program and its settings.
///
/// Fill the sources ([`StamFluid::sources_mut`], or [`StamFluid::apply_source_pattern`]) before
/// each [`StamFluid::step`], as the `get_force_source` of Stam's demo does; the step consumes them.
/// [`StamFluid::memory`] and [`StamFluid::restore_memory`] checkpoint it.
#[derive(Debug, Clone)]
pub struct StamFluid {
    n: usize,
    params: StamParams,
    steps: u64,
    time: f64,
    dens: Vec<f32>,
    dens_prev: Vec<f32>,
    u: Vec<f32>,
    v: Vec<f32>,
    u_prev: Vec<f32>,
    v_prev: Vec<f32>,
    /// The six arrays before the current step, restored when the step fails.
    backup: [Vec<f32>; 6],
}

/// What [`StamFluid::memory`] writes: everything a step reads.
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct StamMemory {
    n: usize,
    params: StamParams,
    steps: u64,
    time: f64,
    density: Vec<f32>,
    density_source: Vec<f32>,
    u: Vec<f32>,
    v: Vec<f32>,
    u_source: Vec<f32>,
    v_source: Vec<f32>,
}

impl StamFluid {
    /// An `N x N` fluid at rest.
    ///
    /// # Errors
    /// [`FluidError::BadGrid`] for `N < 2` (Stam's border handling needs two interior cells),
    /// [`FluidError::BadParameter`] for `dt <= 0`, negative `diff` or `visc`, or non-finite ones.
    pub fn new(n: usize, params: StamParams) -> Result<Self, FluidError> {
        if n < 2 {
            return Err(FluidError::BadGrid { what: "N", min: 2, got: n });
        }
        error::positive("dt", f64::from(params.dt))?;
        error::non_negative("diff", f64::from(params.diff))?;
        error::non_negative("visc", f64::from(params.visc))?;
        let size = (n + 2) * (n + 2);
        Ok(Self {
            n,
            params,
            steps: 0,
            time: 0.0,
            backup: std::array::from_fn(|_| vec![0.0; size]),
            dens: vec![0.0; size],
            dens_prev: vec![0.0; size],
            u: vec![0.0; size],
            v: vec![0.0; size],
            u_prev: vec![0.0; size],
            v_prev: vec![0.0; size],
        })
    }

    /// `N`.
    #[must_use]
    pub fn n(&self) -> usize {
        self.n
    }

    /// The settings.
    #[must_use]
    pub fn params(&self) -> StamParams {
        self.params
    }

    /// Steps taken.
    #[must_use]
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// Simulated time: the sum of the steps' `dt` (in `f64`).
    #[must_use]
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Changes the time step of the following steps.
    ///
    /// # Errors
    /// [`FluidError::BadParameter`] for `dt <= 0` or a non-finite `dt`.
    pub fn set_dt(&mut self, dt: f32) -> Result<(), FluidError> {
        error::positive("dt", f64::from(dt))?;
        self.params.dt = dt;
        Ok(())
    }

    /// Density, `(N+2)^2` values indexed by [`ix`].
    #[must_use]
    pub fn density(&self) -> &[f32] {
        &self.dens
    }

    /// Velocity `(u, v)`, each `(N+2)^2` values indexed by [`ix`].
    #[must_use]
    pub fn velocity(&self) -> (&[f32], &[f32]) {
        (&self.u, &self.v)
    }

    /// Density, `(N+2)^2` values indexed by [`ix`], to set an initial condition (the next step
    /// checks what it produces from it).
    pub fn density_mut(&mut self) -> &mut [f32] {
        &mut self.dens
    }

    /// The source arrays `(dens_prev, u_prev, v_prev)` the next step adds (times `dt`).
    pub fn sources_mut(&mut self) -> (&mut [f32], &mut [f32], &mut [f32]) {
        (&mut self.dens_prev, &mut self.u_prev, &mut self.v_prev)
    }

    /// Fills the sources with [`source_pattern`] for the current step.
    pub fn apply_source_pattern(&mut self) {
        source_pattern(self.n, self.steps, &mut self.dens_prev, &mut self.u_prev, &mut self.v_prev);
    }

    /// The `sim_main` of Stam's demo after `get_force_source`: `vel_step`, then `dens_step`.
    ///
    /// # Errors
    /// [`FluidError::NonFinite`] naming the field, the cell (`i`, `j` index the `(N+2)^2` array,
    /// border included; `k = 0`), the value and the value the cell held before the step, if the
    /// step produced NaN or infinity (from non-finite sources, or finite ones large enough to
    /// overflow `f32`). The six arrays, sources included, and the step count are then exactly as
    /// before the step (they are copied aside before each step; nothing is allocated).
    pub fn step(&mut self) -> Result<(), FluidError> {
        self.back_up();
        self.step_backed_up()
    }

    /// [`StamFluid::apply_source_pattern`], then [`StamFluid::step`], as one step: on error
    /// the six arrays are as before the call, the sources included (the ones the pattern
    /// replaced).
    ///
    /// # Errors
    /// As [`StamFluid::step`].
    pub fn step_with_source_pattern(&mut self) -> Result<(), FluidError> {
        self.back_up();
        self.apply_source_pattern();
        self.step_backed_up()
    }

    /// Copies the six arrays aside.
    fn back_up(&mut self) {
        for (b, a) in self.backup.iter_mut().zip([
            &self.dens,
            &self.dens_prev,
            &self.u,
            &self.v,
            &self.u_prev,
            &self.v_prev,
        ]) {
            b.copy_from_slice(a);
        }
    }

    /// The step after [`StamFluid::back_up`]; on error the arrays are restored from the backup.
    fn step_backed_up(&mut self) -> Result<(), FluidError> {
        let (n, p) = (self.n, self.params);
        vel_step(n, &mut self.u, &mut self.v, &mut self.u_prev, &mut self.v_prev, p.visc, p.dt);
        dens_step(n, &mut self.dens, &mut self.dens_prev, &self.u, &self.v, p.diff, p.dt);
        let step = self.steps;
        // Backup order: dens, dens_prev, u, v, u_prev, v_prev.
        let mut failure = None;
        for (field, values, before) in [("density", &self.dens, 0), ("u", &self.u, 2), ("v", &self.v, 3)] {
            // One multiply-add per value: NaN as soon as any value is NaN or infinite.
            if values.iter().fold(0.0f32, |acc, &x| acc + x * 0.0) != 0.0 {
                let at = values.iter().position(|x| !x.is_finite()).unwrap_or(0);
                let last = self.backup[before][at];
                failure = Some(FluidError::NonFinite {
                    step,
                    field,
                    i: at % (n + 2),
                    j: at / (n + 2),
                    k: 0,
                    value: f64::from(values[at]),
                    last_finite: last.is_finite().then_some(f64::from(last)),
                });
                break;
            }
        }
        if let Some(err) = failure {
            let [d, dp, u, v, up, vp] = &self.backup;
            self.dens.copy_from_slice(d);
            self.dens_prev.copy_from_slice(dp);
            self.u.copy_from_slice(u);
            self.v.copy_from_slice(v);
            self.u_prev.copy_from_slice(up);
            self.v_prev.copy_from_slice(vp);
            return Err(err);
        }
        self.steps += 1;
        self.time += f64::from(p.dt);
        Ok(())
    }

    /// Everything a step reads (the six arrays, step count, time, `N` and the settings), for
    /// checkpoints: a fluid built with the same `N` and settings and given this by
    /// [`StamFluid::restore_memory`] continues bit for bit (`f32` values round-trip exactly
    /// through JSON).
    #[must_use]
    pub fn memory(&self) -> serde_json::Value {
        let m = StamMemory {
            n: self.n,
            params: self.params,
            steps: self.steps,
            time: self.time,
            density: self.dens.clone(),
            density_source: self.dens_prev.clone(),
            u: self.u.clone(),
            v: self.v.clone(),
            u_source: self.u_prev.clone(),
            v_source: self.v_prev.clone(),
        };
        serde_json::to_value(m).unwrap_or(serde_json::Value::Null)
    }

    /// Restores what [`StamFluid::memory`] returned. Nothing changes on error.
    ///
    /// # Errors
    /// [`FluidError::Checkpoint`] naming the problem: not a Stam-fluid memory (missing, unknown
    /// or mistyped fields), another `N` or other settings, an array of the wrong length, a
    /// non-finite value (naming the array and index) or a non-finite time.
    pub fn restore_memory(&mut self, memory: &serde_json::Value) -> Result<(), FluidError> {
        let m = StamMemory::deserialize(memory)
            .map_err(|e| FluidError::Checkpoint(format!("not a Stam-fluid memory: {e}")))?;
        if m.n != self.n {
            return Err(FluidError::Checkpoint(format!(
                "the checkpoint is of an N = {} grid, this fluid has N = {}",
                m.n, self.n
            )));
        }
        if m.params != self.params {
            return Err(FluidError::Checkpoint(format!(
                "the checkpoint's settings {:?} differ from this fluid's {:?}",
                m.params, self.params
            )));
        }
        if !m.time.is_finite() || m.time < 0.0 {
            return Err(FluidError::Checkpoint(format!("time {} is not finite and non-negative", m.time)));
        }
        let size = (self.n + 2) * (self.n + 2);
        let arrays = [
            ("density", &m.density),
            ("density_source", &m.density_source),
            ("u", &m.u),
            ("v", &m.v),
            ("u_source", &m.u_source),
            ("v_source", &m.v_source),
        ];
        for (name, a) in arrays {
            if a.len() != size {
                return Err(FluidError::Checkpoint(format!(
                    "`{name}` has {} values, an N = {} grid has (N+2)^2 = {size}",
                    a.len(),
                    self.n
                )));
            }
            if let Some(at) = a.iter().position(|x| !x.is_finite()) {
                return Err(FluidError::Checkpoint(format!("`{name}`[{at}] is {}", a[at])));
            }
        }
        self.steps = m.steps;
        self.time = m.time;
        self.dens = m.density;
        self.dens_prev = m.density_source;
        self.u = m.u;
        self.v = m.v;
        self.u_prev = m.u_source;
        self.v_prev = m.v_source;
        Ok(())
    }

    /// The three fields as the C driver writes them: density, u, v, raw little-endian `f32`.
    #[must_use]
    pub fn to_le_bytes(&self) -> Vec<u8> {
        [&self.dens, &self.u, &self.v].iter().flat_map(|f| f.iter().flat_map(|x| x.to_le_bytes())).collect()
    }
}

/// FNV-1a (64 bit) of a byte string: the checksum the committed reference output uses.
#[must_use]
pub fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(n: usize, steps: usize) -> StamFluid {
        let mut f = StamFluid::new(n, StamParams::default()).unwrap();
        for _ in 0..steps {
            f.apply_source_pattern();
            f.step().unwrap();
        }
        f
    }

    #[test]
    fn matches_c_output_bit_for_bit_at_n32() {
        let reference = include_bytes!("../testdata/stam_n32_s20.bin");
        let ours = run(32, 20).to_le_bytes();
        assert_eq!(ours.len(), reference.len());
        let first = ours.chunks(4).zip(reference.chunks(4)).position(|(a, b)| a != b);
        assert_eq!(first, None, "first differing value (dens, u, v concatenated)");
    }

    #[test]
    fn matches_c_checksum_at_n64() {
        let expected = include_str!("../testdata/stam_n64_s100.fnv1a").trim();
        let ours = format!("{:016x}", fnv1a(&run(64, 100).to_le_bytes()));
        assert_eq!(ours, expected);
    }

    /// The wavefront sweep against the literal loop order of Stam's C code (i outer, j inner).
    #[test]
    fn wavefront_sweep_equals_c_loop_order() {
        for n in [2, 5, 9, 17] {
            let size = (n + 2) * (n + 2);
            let x0: Vec<f32> = (0..size).map(|k| ((k * 7919) % 101) as f32 * 0.37 - 11.0).collect();
            let mut ours: Vec<f32> = (0..size).map(|k| ((k * 104_729) % 37) as f32 * 0.11).collect();
            let mut c_order = ours.clone();
            let (a, c) = (0.73f32, 1.0 + 4.0 * 0.73f32);
            gauss_seidel_sweep(n, &mut ours, &x0, a, c);
            for i in 1..=n {
                for j in 1..=n {
                    c_order[ix(n, i, j)] = (x0[ix(n, i, j)]
                        + a * (c_order[ix(n, i - 1, j)]
                            + c_order[ix(n, i + 1, j)]
                            + c_order[ix(n, i, j - 1)]
                            + c_order[ix(n, i, j + 1)]))
                        / c;
                }
            }
            assert!(ours.iter().zip(&c_order).all(|(a, b)| a.to_bits() == b.to_bits()), "n = {n}");
        }
    }

    /// Projection lowers the divergence of a smooth field (a wrong sign or scale in the gradient
    /// would raise it). 20 sweeps do not converge: at N = 16 they remove about a third of the
    /// smoothest mode's divergence, which is what Stam's routine does.
    #[test]
    fn project_reduces_divergence() {
        let n = 16;
        let size = (n + 2) * (n + 2);
        // A smooth field with divergence pi (cos(pi x) + cos(pi y)).
        let mut u = vec![0.0f32; size];
        let mut v = vec![0.0f32; size];
        for j in 0..n + 2 {
            for i in 0..n + 2 {
                let (x, y) = ((i as f32 - 0.5) / n as f32, (j as f32 - 0.5) / n as f32);
                u[ix(n, i, j)] = (std::f32::consts::PI * x).sin() * 0.3;
                v[ix(n, i, j)] = (std::f32::consts::PI * y).sin() * 0.3;
            }
        }
        set_bnd(n, 1, &mut u);
        set_bnd(n, 2, &mut v);
        let div = |u: &[f32], v: &[f32]| {
            let mut s = 0.0f64;
            for j in 2..n {
                for i in 2..n {
                    let k = ix(n, i, j);
                    s += f64::from(u[k + 1] - u[k - 1] + v[k + n + 2] - v[k - n - 2]).powi(2);
                }
            }
            s.sqrt()
        };
        let before = div(&u, &v);
        let (mut p, mut d) = (vec![0.0; size], vec![0.0; size]);
        project(n, &mut u, &mut v, &mut p, &mut d);
        assert!(div(&u, &v) < 0.75 * before, "{} vs {before}", div(&u, &v));
    }

    #[test]
    fn rejects_bad_input() {
        assert!(matches!(StamFluid::new(1, StamParams::default()), Err(FluidError::BadGrid { .. })));
        let p = StamParams { dt: 0.0, ..StamParams::default() };
        assert!(matches!(StamFluid::new(8, p), Err(FluidError::BadParameter { name: "dt", .. })));
        let p = StamParams { visc: -1.0, ..StamParams::default() };
        assert!(matches!(StamFluid::new(8, p), Err(FluidError::BadParameter { name: "visc", .. })));
    }

    #[test]
    fn non_finite_source_is_reported() {
        let mut f = StamFluid::new(8, StamParams::default()).unwrap();
        f.sources_mut().0[ix(8, 4, 4)] = f32::NAN;
        assert!(matches!(f.step(), Err(FluidError::NonFinite { field: "density", step: 0, .. })));
    }

    /// A finite but huge force overflows `f32` inside the step (`u += dt * f` is infinite, and
    /// the solves turn it into NaN): the error names the step, field, cell, value and the cell's
    /// value before the step, and the fluid (sources included) is bitwise as before.
    #[test]
    fn overflow_is_reported_and_the_step_undone() {
        let n = 8;
        let mut f = StamFluid::new(n, StamParams { dt: 4.0, ..StamParams::default() }).unwrap();
        for _ in 0..3 {
            f.apply_source_pattern();
            f.step().unwrap();
        }
        f.apply_source_pattern();
        f.sources_mut().1[ix(n, 3, 5)] = f32::MAX;
        let before = f.clone();
        let err = f.step().unwrap_err();
        let FluidError::NonFinite { step, field, i, j, k, value, last_finite } = err.clone() else {
            panic!("{err}")
        };
        assert_eq!((step, k), (3, 0));
        assert!(!value.is_finite());
        let old = match field {
            "density" => before.density(),
            "u" => before.velocity().0,
            "v" => before.velocity().1,
            other => panic!("field {other}"),
        };
        assert_eq!(last_finite, Some(f64::from(old[ix(n, i, j)])));
        let msg = err.to_string();
        for part in [
            "anim-fluid: ".to_string(),
            format!("step 3: non-finite {field} {value}"),
            format!("cell ({i}, {j}, 0)"),
            format!("last finite value there {}", f64::from(old[ix(n, i, j)])),
        ] {
            assert!(msg.contains(&part), "{part:?} not in {msg}");
        }
        assert!(msg.starts_with("anim-fluid: "), "{msg}");
        assert_eq!(f.steps(), 3);
        assert_eq!(f.time().to_bits(), before.time().to_bits());
        assert_eq!(f.to_le_bytes(), before.to_le_bytes());
        let text = |f: &StamFluid| serde_json::to_string(&f.memory()).unwrap();
        assert_eq!(text(&f), text(&before), "sources differ");
        // The same step with the force removed goes through.
        f.sources_mut().1[ix(n, 3, 5)] = 0.0;
        f.step().unwrap();
    }
}
