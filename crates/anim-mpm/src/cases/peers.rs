//! The timed runs of `cargo xtask bench --peers`: anim-mpm's benchmark scenes beside Taichi's.

use crate::scenes;

/// One timed run of a benchmark scene.
pub struct PeerRun {
    /// Number of particles.
    pub particles: usize,
    /// Median wall time per step (s).
    pub per_step_s: f64,
    /// Mean particle height at the end (m), to compare the runs' states.
    pub mean_y: f64,
}

/// Times `steps` steps of `scenes::benchmark_2d(n)` (dim 2) or `benchmark_3d(n)` (dim 3) on a
/// pool of `threads`, after 50 warm-up steps; median over `repeats`.
pub fn peer_benchmark(
    dim: usize,
    n: usize,
    steps: usize,
    repeats: usize,
    threads: usize,
) -> Result<PeerRun, String> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().map_err(|e| e.to_string())?;
    pool.install(|| {
        fn go<const D: usize>(
            mut s: scenes::Scene<D>,
            steps: usize,
            repeats: usize,
        ) -> Result<PeerRun, String> {
            for _ in 0..50 {
                s.sim.advance(&mut s.state, s.dt).map_err(|e| e.to_string())?;
            }
            let mut times = vec![];
            for _ in 0..repeats {
                let start = std::time::Instant::now();
                for _ in 0..steps {
                    s.sim.advance(&mut s.state, s.dt).map_err(|e| e.to_string())?;
                }
                times.push(start.elapsed().as_secs_f64() / steps as f64);
            }
            times.sort_by(f64::total_cmp);
            let mean_y =
                s.state.x.chunks_exact(D).map(|c| f64::from(c[1])).sum::<f64>() / s.state.len() as f64;
            Ok(PeerRun { particles: s.state.len(), per_step_s: times[times.len() / 2], mean_y })
        }
        if dim == 2 {
            go(scenes::benchmark_2d(n).map_err(|e| e.to_string())?, steps, repeats)
        } else {
            go(scenes::benchmark_3d(n).map_err(|e| e.to_string())?, steps, repeats)
        }
    })
}
