//! How much of a grid one parallel task takes: the grid solvers' loops split into tasks of at
//! least `anim_core::par::TASK_NS` of work, so that the loops of a small grid (a 64 x 64 cavity,
//! the coarse levels of a multigrid V-cycle, whose sweeps cost microseconds) run on the calling
//! thread instead of waking the pool for each. Splitting never changes what these loops compute
//! (each item is written from values the loop does not write), so results stay the same bits on
//! any number of threads.
//!
//! The costs per item were measured single-threaded by
//! `cargo test --release -p anim-fluid --lib -- --ignored --nocapture grain_costs` (a 256 x 256
//! grid, median of 21 repetitions, two runs on the workspace's 2-core test machine under a load
//! average of about 20): the 5-point pressure stencil (`Poisson::apply`) 3.0 ns per cell, a
//! vector update (`y += a x`) 0.2 ns per entry, the linear advection of the velocity 350-380 ns
//! per face (trace, interpolation and wall blend). The constants are whole nanoseconds: the
//! stencil's as measured, a vector update's rounded up to 1 (its tasks of 50,000 entries hold
//! about 10 us; such a loop is bound by memory bandwidth, which two threads share, and gains
//! little from a split), the trace's well below its measure (its tasks hold more than the
//! target).

use anim_core::par::min_len;

/// Nanoseconds per entry of a vector update (`axpy`, a mask, a copy, a negation).
pub(crate) const ENTRY_NS: usize = 1;

/// Nanoseconds per cell of a stencil over the grid: the pressure operator, its residual and
/// relaxation sweeps, the multigrid transfers, the divergence and the pressure gradient.
pub(crate) const STENCIL_NS: usize = 3;

/// Nanoseconds per cell of the heavier stencils: vorticity and its confinement force, the
/// implicit viscosity's operator (several faces per unknown); not measured on their own, taken
/// as a few pressure stencils.
pub(crate) const WIDE_STENCIL_NS: usize = 8;

/// Nanoseconds per cell of a semi-Lagrangian trace and interpolation.
pub(crate) const TRACE_NS: usize = 100;

/// The least number of entries per task of a vector update.
pub(crate) const ENTRIES: usize = min_len(ENTRY_NS);

/// The least number of lines of `nx` cells per task when a cell costs `ns`.
#[inline]
pub(crate) fn lines(nx: usize, ns: usize) -> usize {
    min_len(nx.max(1) * ns)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pressure::{CellLabel, Poisson};
    use std::time::Instant;

    #[test]
    fn small_grids_run_on_one_task_and_large_ones_split() {
        // A 64 x 64 sweep: 64 lines, fewer than one task's worth.
        assert!(lines(64, STENCIL_NS) >= 64);
        // A 256 x 384 x 256 sweep splits into many tasks.
        assert!(lines(256, STENCIL_NS) * 8 < 384 * 256);
        const { assert!(ENTRIES > 4096 && ENTRIES < 1 << 20) };
        assert_eq!(lines(0, STENCIL_NS), min_len(STENCIL_NS));
    }

    /// Median of `f`'s wall time over 21 runs, seconds.
    fn median(mut f: impl FnMut()) -> f64 {
        let mut t: Vec<f64> = (0..21)
            .map(|_| {
                let s = Instant::now();
                f();
                s.elapsed().as_secs_f64()
            })
            .collect();
        t.sort_by(f64::total_cmp);
        t[10]
    }

    #[test]
    #[ignore = "timing, run by hand"]
    fn grain_costs() {
        let n = 256;
        let op = Poisson::new([n, n, 1], 2, vec![CellLabel::Fluid; n * n], [[false; 2]; 3]).unwrap();
        let x: Vec<f64> = (0..n * n).map(|i| (i as f64 * 0.37).sin()).collect();
        let mut y = vec![0.0; n * n];
        anim_core::par::with_threads(1, || {
            let stencil = median(|| op.apply(&x, &mut y)) / (n * n) as f64;
            let axpy = median(|| y.iter_mut().zip(&x).for_each(|(y, &x)| *y += 0.5 * x)) / (n * n) as f64;
            println!("stencil {:.2} ns per cell, axpy {:.2} ns per entry", stencil * 1e9, axpy * 1e9);
        })
        .unwrap();
        let (mut fluid, mut state) = crate::mac::MacFluid::new(
            [n, n, 1],
            2,
            1.0 / n as f64,
            crate::mac::MacParams { advection: crate::advection::Advection::Linear, ..Default::default() },
        )
        .unwrap();
        fluid.set_velocity(&mut state, |p| [(3.0 * p[1]).sin(), (2.0 * p[0]).cos(), 0.0]);
        anim_core::par::with_threads(1, || {
            let advect = median(|| fluid.advect_for_timing(&mut state, 1e-3)) / (2 * n * (n + 1)) as f64;
            println!("trace {:.2} ns per face", advect * 1e9);
        })
        .unwrap();
    }
}
