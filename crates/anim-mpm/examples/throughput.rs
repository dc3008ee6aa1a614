//! Times the peer-benchmark scenes: `cargo run --release -p anim-mpm --example throughput --
//! [2|3] [cells] [steps] [threads]`. Prints the median time per step of 5 repeats after 50
//! warm-up steps and the throughput in particle-steps per second.

use anim_mpm::scenes;

fn time<const D: usize>(mut s: scenes::Scene<D>, steps: usize) -> Result<(usize, f64), anim_mpm::MpmError> {
    for _ in 0..50 {
        s.sim.advance(&mut s.state, s.dt)?;
    }
    let mut times = vec![];
    for _ in 0..5 {
        let start = std::time::Instant::now();
        for _ in 0..steps {
            s.sim.advance(&mut s.state, s.dt)?;
        }
        times.push(start.elapsed().as_secs_f64() / steps as f64);
    }
    times.sort_by(f64::total_cmp);
    Ok((s.state.len(), times[2]))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<usize> = std::env::args().skip(1).filter_map(|a| a.parse().ok()).collect();
    let dim = args.first().copied().unwrap_or(2);
    let n = args.get(1).copied().unwrap_or(if dim == 2 { 128 } else { 64 });
    let steps = args.get(2).copied().unwrap_or(100);
    let threads = args.get(3).copied().unwrap_or(1);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build()?;
    let (np, t) = pool.install(|| {
        if dim == 2 { time(scenes::benchmark_2d(n)?, steps) } else { time(scenes::benchmark_3d(n)?, steps) }
    })?;
    println!(
        "{dim}D n={n} particles={np} threads={threads}: {:.3} ms/step, {:.2} M particle-steps/s",
        t * 1e3,
        np as f64 / t / 1e6
    );
    Ok(())
}
