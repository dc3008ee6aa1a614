//! A PBD scene from `anim_pbd::scenes` (default: the cloth draped over a sphere), stepped with
//! its suggested settings. Prints, every 0.5 s of simulated time, the energy, the momentum, the
//! largest constraint violation, the lowest point and the cost per step.
//!
//! ```sh
//! cargo run --release -p anim-pbd --example cloth_drape [SCENE] [RESOLUTION]
//! ```
//!
//! SCENE is one of `cloth-drape`, `flag`, `rope`, `soft-blob`, `balloon`, `benchmark-cloth`.

use anim_core::solver::Solver;
use anim_pbd::scenes;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let name = std::env::args().nth(1).unwrap_or_else(|| "cloth-drape".into());
    let resolution = match std::env::args().nth(2) {
        Some(a) => Some(a.parse::<usize>().map_err(|e| format!("resolution '{a}': {e}"))?),
        None => None,
    };
    let scene = scenes::by_name(&name, resolution)
        .ok_or_else(|| format!("unknown scene '{name}' (one of {})", scenes::NAMES.join(", ")))??;
    println!(
        "{}: {} particles, {} constraints, {} colliders; {:?} / {}, {} iterations x {} substeps, dt = {:.4} s",
        scene.name,
        scene.model.num_particles(),
        scene.model.num_constraints(),
        scene.model.colliders().len(),
        scene.params.method,
        scene.params.solver.label(),
        scene.params.iterations,
        scene.params.substeps,
        scene.dt
    );
    let (dt, steps) = (scene.dt, scene.steps());
    let every = ((0.5 / dt).round() as usize).max(1);
    let (mut sim, mut state) = scene.into_simulation()?;
    println!(
        "{:>6} {:>12} {:>26} {:>12} {:>10} {:>10}",
        "t [s]", "energy [J]", "momentum [kg m/s]", "max |C|", "lowest z", "ms/step"
    );
    let start = Instant::now();
    for step in 1..=steps {
        let report = sim.step(&mut state, dt)?;
        if step % every == 0 {
            let p = report.linear_momentum.unwrap_or([f64::NAN; 3]);
            let lowest = state.x.chunks_exact(3).map(|q| q[2]).fold(f64::INFINITY, f64::min);
            println!(
                "{:>6.2} {:>12.5} {:>8.4} {:>8.4} {:>8.4} {:>12.3e} {:>10.4} {:>10.3}",
                report.time,
                report.energy.unwrap_or(f64::NAN),
                p[0],
                p[1],
                p[2],
                report.constraint_violation.unwrap_or(f64::NAN),
                lowest,
                start.elapsed().as_secs_f64() * 1e3 / step as f64
            );
        }
    }
    Ok(())
}
