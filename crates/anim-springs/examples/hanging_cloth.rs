//! The hanging-cloth scene: a square cloth pinned at two corners falls and swings, stepped with
//! backward Euler and Jacobi-preconditioned CG. Prints energy, momentum, the lowest point and
//! the cost per step every 0.25 s of simulated time.
//!
//! ```sh
//! cargo run --release -p anim-springs --example hanging_cloth [RESOLUTION]
//! ```

use anim_core::solver::Solver;
use anim_springs::scenes;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let resolution = match std::env::args().nth(1) {
        Some(a) => Some(a.parse::<usize>().map_err(|e| format!("resolution '{a}': {e}"))?),
        None => None,
    };
    let scene = scenes::hanging_cloth(resolution)?;
    println!(
        "{}: {} particles, {} springs, {} triangles; {} with {:?}, dt = {} s",
        scene.name,
        scene.network.num_particles(),
        scene.network.num_springs(),
        scene.network.triangles().len(),
        scene.integrator.label(),
        scene.linear_solver,
        scene.dt
    );
    let (dt, steps) = (scene.dt, scene.steps());
    let every = ((0.25 / dt).round() as usize).max(1);
    let (mut sim, mut state) = scene.into_simulation()?;
    println!(
        "{:>6} {:>12} {:>24} {:>10} {:>8} {:>10}",
        "t [s]", "energy [J]", "momentum [kg m/s]", "lowest z", "newton", "ms/step"
    );
    let start = Instant::now();
    let mut newton = 0;
    for step in 1..=steps {
        let report = sim.step(&mut state, dt)?;
        newton += report.iterations;
        if step % every == 0 {
            let p = report.linear_momentum.unwrap_or([f64::NAN; 3]);
            let lowest = state.x.chunks_exact(3).map(|q| q[2]).fold(f64::INFINITY, f64::min);
            println!(
                "{:>6.2} {:>12.6} {:>8.4} {:>7.4} {:>7.4} {:>10.4} {:>8.1} {:>10.2}",
                report.time,
                report.energy.unwrap_or(f64::NAN),
                p[0],
                p[1],
                p[2],
                lowest,
                newton as f64 / every as f64,
                start.elapsed().as_secs_f64() * 1e3 / step as f64
            );
            newton = 0;
        }
    }
    Ok(())
}
