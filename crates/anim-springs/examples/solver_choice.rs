//! Times the hanging cloth with each linear solver under linearised backward Euler, to choose
//! the scene's default: `cargo run --release -p anim-springs --example solver_choice`.

use anim_core::linalg::LinearSolverKind;
use anim_core::solver::Solver;
use anim_springs::scenes;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    for linear in LinearSolverKind::ALL {
        let mut scene = scenes::hanging_cloth(None)?;
        scene.linear_solver = linear;
        let dt = scene.dt;
        let (mut sim, mut state) = scene.into_simulation()?;
        let start = std::time::Instant::now();
        let mut linear_iterations = 0;
        let steps = 100;
        let mut failed = None;
        for k in 0..steps {
            if let Err(e) = sim.step(&mut state, dt) {
                failed = Some(format!("step {k}: {e}"));
                break;
            }
            linear_iterations += sim.last_step_info().linear_iterations;
        }
        let ms = start.elapsed().as_secs_f64() * 1e3 / steps as f64;
        match failed {
            None => println!(
                "{:<22} {ms:8.2} ms/step, {:7.1} linear iterations/step",
                linear.name(),
                linear_iterations as f64 / steps as f64
            ),
            Some(e) => println!("{:<22} failed: {e}", linear.name()),
        }
    }
    Ok(())
}
