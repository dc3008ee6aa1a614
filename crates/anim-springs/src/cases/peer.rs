//! The benchmark cloth timed for the peer comparison (`cargo xtask bench --peers`).

use crate::SpringNetwork;
use anim_core::integrate::{IntegratorKind, SecondOrderSystem};

/// One timed run of the benchmark cloth for the peer comparison (`cargo xtask bench --peers`).
#[derive(Debug, Clone, Copy)]
pub struct PeerRun {
    /// Median wall time of one step (s).
    pub per_step_s: f64,
    /// Sum of the final z coordinates (checksum against the peer).
    pub sum_z: f64,
    /// Lowest final z coordinate.
    pub min_z: f64,
}

/// Times `steps` symplectic Euler steps of the `n x n` benchmark cloth from rest on a rayon pool
/// of `threads` threads (median over `repeats` runs), with the integrator driven directly (no
/// divergence guard: the peer has none either; the integrator's NaN check stays).
pub fn peer_symplectic_cloth(
    n: usize,
    steps: usize,
    threads: usize,
    repeats: usize,
) -> Result<PeerRun, String> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().map_err(|e| e.to_string())?;
    pool.install(|| {
        let scene = crate::scenes::benchmark_cloth(n).map_err(|e| e.to_string())?;
        let mut times = Vec::new();
        let mut last = None;
        for rep in 0..=repeats {
            let mut net = scene.network.clone();
            let mut state = scene.state.clone();
            let mut integ = IntegratorKind::SymplecticEuler
                .build_explicit::<SpringNetwork>(net.dof())
                .ok_or("symplectic Euler is explicit")?;
            integ.step(&mut net, &mut state.clone(), scene.dt).map_err(|e| e.to_string())?; // warm up
            let start = std::time::Instant::now();
            for _ in 0..steps {
                integ.step(&mut net, &mut state, scene.dt).map_err(|e| e.to_string())?;
            }
            if rep > 0 {
                times.push(start.elapsed().as_secs_f64() / steps as f64);
            }
            last = Some(state);
        }
        times.sort_by(f64::total_cmp);
        let state = last.ok_or("no run")?;
        Ok(PeerRun {
            per_step_s: times[times.len() / 2],
            sum_z: state.x.chunks_exact(3).map(|p| p[2]).sum(),
            min_z: state.x.chunks_exact(3).map(|p| p[2]).fold(f64::INFINITY, f64::min),
        })
    })
}
