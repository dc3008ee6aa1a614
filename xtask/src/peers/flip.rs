//! `cargo xtask bench --peers`, anim-flip part: the 3D dam break of
//! `anim_flip::scenes::benchmark_dam_break_3d` (1 048 576 particles, 8 per cell, on a 128^3
//! grid; APIC, MGPCG, CFL-1 substeps) beside Taichi's MLS-MPM 3D fluid (the `mpm3d` example,
//! `peers/flip/taichi_mpm3d_dam_break.py`) on the CPU backend with the same block, lattice,
//! particle count, grid and thread count. Our time per substep is broken into transfer (P2G +
//! G2P), projection (pressure solve) and advection / other (`anim_flip::StepTimes`).
//!
//! The two codes solve different models: ours is incompressible (a pressure projection per
//! substep, substeps limited by the CFL condition on the flow speed, milliseconds), Taichi's is
//! weakly compressible and explicit (no solve, steps limited by the sound speed of its stiffness,
//! 1e-4 s at 128^3). So the ratio is quoted both per step and per simulated second. Taichi is
//! installed with pip when missing; if that fails the peer is skipped with a visible note.

use crate::python::json_field as field;
use anim_flip::{FlipParams, StepTimes, scenes};
use std::io::Write;

const SCRIPT: &str = "peers/flip/taichi_mpm3d_dam_break.py";
/// Grid cells per axis.
const N: usize = 128;
/// Simulated time before the timed frames, s: the block has started to collapse and its speed
/// (about 1.4 m/s) sets the CFL substeps.
const WARMUP: f64 = 0.1;
/// One timed frame, s (split into CFL substeps).
const FRAME: f64 = 0.01;
/// Timed frames; the median is quoted.
const REPEATS: usize = 3;
/// Taichi: warm-up steps (compilation and the first motion), timed steps per repeat.
const TAICHI_WARMUP: usize = 20;
const TAICHI_STEPS: usize = 5;

/// Our timed frames: the median frame by time per substep.
struct Ours {
    particles: usize,
    /// Wall time per substep, s.
    per_substep: f64,
    /// Mean substep, s (the frame over its substep count).
    dt: f64,
    /// The median frame's parts, per substep, s.
    parts: StepTimes,
    /// Largest pressure iteration count of the median frame.
    iterations: usize,
    /// Wall time per simulated second, s.
    per_sim_second: f64,
}

fn ours(threads: usize) -> Result<Ours, String> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().map_err(|e| e.to_string())?;
    pool.install(|| {
        let (mut sim, mut p) =
            scenes::benchmark_dam_break_3d(N, FlipParams::default()).map_err(|e| e.to_string())?;
        let particles = p.len();
        let mut t = 0.0;
        while t < WARMUP - 1e-12 {
            sim.advance(&mut p, FRAME).map_err(|e| e.to_string())?;
            t += FRAME;
        }
        sim.set_timing(true);
        let mut frames = vec![];
        for _ in 0..REPEATS {
            let start = std::time::Instant::now();
            let info = sim.advance(&mut p, FRAME).map_err(|e| e.to_string())?;
            let wall = start.elapsed().as_secs_f64();
            let k = info.substeps as f64;
            let s = info.times;
            frames.push(Ours {
                particles,
                per_substep: wall / k,
                dt: FRAME / k,
                parts: StepTimes {
                    transfer: s.transfer / k,
                    projection: s.projection / k,
                    advection: s.advection / k,
                    other: s.other / k,
                },
                iterations: info.pressure_iterations,
                per_sim_second: wall / FRAME,
            });
        }
        frames.sort_by(|a, b| a.per_substep.total_cmp(&b.per_substep));
        Ok(frames.swap_remove(REPEATS / 2))
    })
}

/// Taichi's time per step, its dt and the front position.
fn taichi(threads: usize) -> Result<(f64, f64, f64, String), String> {
    let args = [("--n", N), ("--steps", TAICHI_STEPS), ("--repeats", REPEATS), ("--threads", threads)];
    let mut args: Vec<String> = args.iter().flat_map(|(k, v)| [k.to_string(), v.to_string()]).collect();
    args.extend(["--warmup".to_string(), TAICHI_WARMUP.to_string()]);
    let line = crate::python::result_line(SCRIPT, &args, &[])?;
    let get = |k: &str| field(&line, k).and_then(|v| v.parse::<f64>().ok()).ok_or(format!("no {k}"));
    Ok((get("per_step_s")?, get("dt")?, get("front")?, field(&line, "taichi").unwrap_or_default()))
}

pub fn run() -> bool {
    let threads = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1);
    println!(
        "peer benchmark: 3D dam break, {N}^3 grid, block of {} x {} x {} cells at 8 particles per cell, {threads} threads; anim-flip APIC + MGPCG (CFL-1 substeps, {REPEATS} frames of {FRAME} s after {WARMUP} s, median) against Taichi MLS-MPM mpm3d (explicit, weakly compressible; median of {REPEATS} x {TAICHI_STEPS} steps after {TAICHI_WARMUP})\n",
        N / 4,
        N / 2,
        N / 2
    );
    let ours = match ours(threads) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("our run failed: {e}");
            return false;
        }
    };
    let ms = |s: f64| super::human(s * 1e9);
    let p = ours.parts;
    println!(
        "anim-flip: {} particles, {} per substep (dt {:.2} ms, {} pressure iterations at most): transfer {} ({:.0}%), projection {} ({:.0}%), advection {} ({:.0}%), other {} ({:.0}%); {} per simulated second",
        ours.particles,
        ms(ours.per_substep),
        ours.dt * 1e3,
        ours.iterations,
        ms(p.transfer),
        100.0 * p.transfer / ours.per_substep,
        ms(p.projection),
        100.0 * p.projection / ours.per_substep,
        ms(p.advection),
        100.0 * p.advection / ours.per_substep,
        ms(p.other),
        100.0 * p.other / ours.per_substep,
        ms(ours.per_sim_second),
    );
    let peer = crate::python::ensure("taichi", &["taichi"], "").and_then(|()| taichi(threads));
    let (t_step, t_dt, front, version) = match peer {
        Ok(v) => v,
        Err(e) => {
            println!("\nNOTE: Taichi peer SKIPPED: {e}\n");
            return true;
        }
    };
    let t_sim = t_step / t_dt;
    println!(
        "taichi {version} mpm3d: {} per step (dt {:.3} ms), {} per simulated second; front {front:.3} m after {} steps",
        ms(t_step),
        t_dt * 1e3,
        ms(t_sim),
        TAICHI_WARMUP + REPEATS * TAICHI_STEPS
    );
    println!(
        "\n| measure | anim-flip | taichi | ours / theirs |\n| --- | --- | --- | --- |\n| per step | {} | {} | {:.2} |\n| per simulated second | {} | {} | {:.3} |",
        ms(ours.per_substep),
        ms(t_step),
        ours.per_substep / t_step,
        ms(ours.per_sim_second),
        ms(t_sim),
        ours.per_sim_second / t_sim
    );
    let case = |what: &str| {
        format!(
            "3D dam break {N}^3, {} particles, APIC + MGPCG (dt {:.2} ms) vs explicit MLS-MPM (dt {:.2} ms), {what}",
            ours.particles,
            ours.dt * 1e3,
            t_dt * 1e3
        )
    };
    let peer_name = format!("Taichi {version} mpm3d");
    super::ratios::record("anim-flip", &case("per step"), &peer_name, threads, ours.per_substep, t_step);
    super::ratios::record(
        "anim-flip",
        &case("per simulated second"),
        &peer_name,
        threads,
        ours.per_sim_second,
        t_sim,
    );
    let dir = std::path::Path::new("target/xtask");
    let written = std::fs::create_dir_all(dir).and_then(|_| {
        let mut f = std::fs::File::create(dir.join("peers_flip.csv"))?;
        writeln!(
            f,
            "particles,threads,ours_per_step_s,ours_dt_s,transfer_s,projection_s,advection_s,other_s,taichi_per_step_s,taichi_dt_s"
        )?;
        writeln!(
            f,
            "{},{threads},{},{},{},{},{},{},{t_step},{t_dt}",
            ours.particles, ours.per_substep, ours.dt, p.transfer, p.projection, p.advection, p.other
        )
    });
    if let Err(e) = written {
        eprintln!("could not write target/xtask/peers_flip.csv: {e}");
    }
    true
}
