//! `cargo xtask bench --peers`, anim-fem part: the benchmark beam
//! (`anim_fem::scenes::benchmark_beam(50)`, 19,200 tetrahedra, stable Neo-Hookean, clamped,
//! gravity, dt = 0.01 s, lumped mass, Newton to max |dx| <= 1e-6 x bounding-box diagonal) stepped
//! by backward Euler in anim-fem and in pbatoolkit (pip `pbatoolkit`: its C++ stable Neo-Hookean
//! energy, gradient and SPD-projected Hessian, driven by a Python Newton loop with a line search
//! and scipy's sparse direct solve; `xtask/peers/fem/pbat_beam.py`). Time per implicit step
//! (median of steps 2..5 from rest) measured side by side; pbatoolkit is installed with pip when
//! missing and skipped with a visible note when that fails.

use crate::python::json_field as field;
use anim_fem::scenes;
use std::process::Command;
use std::time::Instant;

const SCRIPT: &str = "peers/fem/pbat_beam.py";
const CELLS: usize = 50;
const STEPS: usize = 5;

/// Ours: per-step seconds (median of steps 2..), Newton iterations, tip z.
fn ours() -> Result<(usize, f64, Vec<usize>, f64), String> {
    let scene = scenes::benchmark_beam(CELLS).map_err(|e| e.to_string())?;
    let elements = scene.model.elements();
    let dt = scene.dt;
    let (mut sim, mut state) = scene.into_simulation().map_err(|e| e.to_string())?;
    let mut times = Vec::new();
    let mut iters = Vec::new();
    for _ in 0..STEPS {
        let t = Instant::now();
        let r = sim.advance(&mut state, dt).map_err(|e| e.to_string())?;
        times.push(t.elapsed().as_secs_f64());
        iters.push(r.iterations);
    }
    let tip: Vec<usize> = sim.model().vertices_where(|p| p[0] > 1.0 - 1e-9);
    let z = tip.iter().map(|&v| state.x[3 * v + 2]).sum::<f64>() / tip.len() as f64;
    let mut rest = times[1..].to_vec();
    rest.sort_by(f64::total_cmp);
    Ok((elements, rest[rest.len() / 2], iters, z))
}

pub fn run() -> bool {
    println!("\n## anim-fem: benchmark beam, one backward Euler step (Newton)\n");
    let threads = rayon::current_num_threads();
    let (elements, ours_s, ours_iters, ours_tip) = match ours() {
        Ok(r) => r,
        Err(e) => {
            println!("anim-fem run failed: {e}");
            return false;
        }
    };
    println!(
        "| code | threads | elements | s / step (median) | Newton iterations per step | tip z after {STEPS} steps (m) |"
    );
    println!("| --- | --- | --- | --- | --- | --- |");
    println!(
        "| anim-fem (sparse Cholesky) | {threads} | {elements} | {ours_s:.4} | {ours_iters:?} | {ours_tip:.6} |"
    );
    if let Err(e) = crate::python::ensure("pbatoolkit", &["pbatoolkit", "scipy"], "") {
        println!("\nnote: pbatoolkit skipped: {e}");
        return true;
    }
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(SCRIPT);
    let out = Command::new(crate::python::python())
        .arg(&path)
        .args(["--cells", &CELLS.to_string(), "--steps", &STEPS.to_string(), "--tol", "1e-6"])
        .output();
    let line = match out {
        Ok(o) if o.status.success() => {
            String::from_utf8_lossy(&o.stdout).lines().last().unwrap_or("").to_string()
        }
        Ok(o) => {
            println!(
                "\nnote: pbatoolkit run failed: {}",
                String::from_utf8_lossy(&o.stderr).lines().last().unwrap_or("")
            );
            return true;
        }
        Err(e) => {
            println!("\nnote: could not run {}: {e}", crate::python::python());
            return true;
        }
    };
    let peer_s: f64 = field(&line, "per_step_s").and_then(|s| s.parse().ok()).unwrap_or(f64::NAN);
    let peer_tip = field(&line, "tip_z").unwrap_or_default();
    let peer_iters = line
        .find("\"newton_iterations\": [")
        .map(|i| {
            let rest = &line[i + 22..];
            rest[..rest.find(']').unwrap_or(0)].to_string()
        })
        .unwrap_or_default();
    let peer_elements = field(&line, "elements").unwrap_or_default();
    println!(
        "| pbatoolkit (Python Newton loop, SuperLU) | 1 | {peer_elements} | {peer_s:.4} | [{peer_iters}] | {peer_tip} |"
    );
    println!("\nspeed-up per implicit step: {:.1}x (pbatoolkit / anim-fem)", peer_s / ours_s);
    super::ratios::record(
        "anim-fem",
        &format!("benchmark beam, {elements} elements, one backward Euler step (pbatoolkit: one thread)"),
        "pbatoolkit",
        threads,
        ours_s,
        peer_s,
    );
    true
}
