//! The timed runs of `cargo xtask bench --peers` for anim-pbd: the benchmark cloth of
//! `crate::scenes::benchmark` stepped by XPBD on a pool of a given thread count, as the peer
//! codes step the same cloth.

use crate::{
    Bending, Cloth, ConstraintParams, EARTH_GRAVITY, Method, PbdBuilder, PbdParams, PbdSimulation, SolverKind,
};

/// One timed run of the benchmark cloth.
#[derive(Debug, Clone, Copy)]
pub struct PeerRun {
    /// Median wall time of one step (s).
    pub per_step_s: f64,
    /// Number of constraints.
    pub constraints: usize,
    /// Lowest height after the timed steps (sanity check).
    pub min_height: f64,
}

/// Times `steps` steps of the `n x n` benchmark cloth (XPBD, dt = 1/60, `iterations` iterations,
/// isometric or dihedral bending) with `solver` on a pool of `threads` threads; median of
/// `repeats` runs, each from the rest state after one warm-up step.
pub fn peer_cloth(
    n: usize,
    iterations: usize,
    dihedral: bool,
    solver: SolverKind,
    threads: usize,
    steps: usize,
    repeats: usize,
) -> Result<PeerRun, String> {
    use crate::scenes::benchmark::*;
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().map_err(|e| e.to_string())?;
    pool.install(|| {
        let mut b = PbdBuilder::new();
        b.gravity(EARTH_GRAVITY);
        let bending = ConstraintParams::with_compliance(BENDING_COMPLIANCE);
        let c = b
            .cloth(&Cloth {
                nx: n,
                ny: n,
                origin: [0.0; 3],
                u: [SIZE, 0.0, 0.0],
                v: [0.0, SIZE, 0.0],
                particle_mass: PARTICLE_MASS,
                stretch: ConstraintParams::with_compliance(STRETCH_COMPLIANCE),
                bending: if dihedral { Bending::Dihedral(bending) } else { Bending::Isometric(bending) },
            })
            .map_err(|e| e.to_string())?;
        b.pin(c.at(0, 0)).pin(c.at(n - 1, 0));
        let model = b.build().map_err(|e| e.to_string())?;
        let mut times = Vec::new();
        let mut min_height = f64::NAN;
        for rep in 0..=repeats {
            let mut state = model.rest_state();
            let mut params = PbdParams::new(Method::Xpbd, solver, iterations, 1);
            params.max_stretch = f64::INFINITY;
            let mut sim = PbdSimulation::new(model.clone(), params).map_err(|e| e.to_string())?;
            sim.advance(&mut state, DT).map_err(|e| e.to_string())?;
            let start = std::time::Instant::now();
            sim.run(&mut state, DT, steps).map_err(|e| e.to_string())?;
            if rep > 0 {
                times.push(start.elapsed().as_secs_f64() / steps as f64);
            }
            min_height = state.x.chunks_exact(3).map(|p| p[2]).fold(f64::INFINITY, f64::min);
        }
        times.sort_by(f64::total_cmp);
        Ok(PeerRun { per_step_s: times[times.len() / 2], constraints: model.num_constraints(), min_height })
    })
}

/// The speed-up of `threads` threads over one on the benchmark cloth, measured in interleaved
/// rounds (one thread, then `threads`, `rounds` times, each a [`peer_cloth`] run of `steps`
/// steps, median of 3): the per-round times `(one thread, threads)` in seconds per step.
pub fn thread_rounds(
    n: usize,
    iterations: usize,
    dihedral: bool,
    solver: SolverKind,
    threads: usize,
    steps: usize,
    rounds: usize,
) -> Result<Vec<(f64, f64)>, String> {
    (0..rounds)
        .map(|_| {
            let one = peer_cloth(n, iterations, dihedral, solver, 1, steps, 3)?.per_step_s;
            let many = peer_cloth(n, iterations, dihedral, solver, threads, steps, 3)?.per_step_s;
            Ok((one, many))
        })
        .collect()
}
