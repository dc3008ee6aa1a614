//! `cargo xtask bench --peers`, anim-fluid part:
//!
//! 1. Stam's solver against Stam's C routines (anim-fluid's `testdata/stable_fluids.c`, compiled with
//!    `cc -O3 -march=native`), per-step time at N = 128, 256, 512, same source pattern and
//!    iterations (20 Gauss-Seidel sweeps), both on one thread;
//! 2. MGPCG against red-black Gauss-Seidel at equal divergence residual on the 2D box with a
//!    sphere at N = 512, the pressure solve timed alone: the residual 20 sweeps leave (Stam's
//!    budget), and a tolerance of 1e-4 (Gauss-Seidel capped at about 60 s);
//! 3. Taichi's stable-fluids example (`peers/fluid/taichi_stable_fluid.py`: 512 x 512, RK3
//!    semi-Lagrangian, 500 Jacobi pressure iterations) on the CPU, one thread and all threads,
//!    beside our Stam mode and our MAC solver at 512 x 512. Taichi is installed with pip when
//!    missing; on failure it is skipped with a visible note.

use crate::python::json_field;
use anim_fluid::cases::compile_c;
use anim_fluid::mac::{MacFluid, MacParams};
use anim_fluid::pressure::{PressureMethod, PressureSolver};
use anim_fluid::stam::{StamFluid, StamParams};
use std::process::Command;
use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Per-step seconds of our Stam mode (single thread), median of `repeats` runs of `steps`.
fn stam_per_step(n: usize, steps: usize, repeats: usize) -> f64 {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build();
    let run = || {
        median(
            (0..repeats)
                .map(|_| {
                    let Ok(mut f) = StamFluid::new(n, StamParams::default()) else { return f64::NAN };
                    for _ in 0..5 {
                        f.apply_source_pattern();
                        let _ = f.step();
                    }
                    let t = Instant::now();
                    for _ in 0..steps {
                        f.apply_source_pattern();
                        let _ = f.step();
                    }
                    t.elapsed().as_secs_f64() / steps as f64
                })
                .collect(),
        )
    };
    match pool {
        Ok(p) => p.install(run),
        Err(_) => run(),
    }
}

fn c_per_step(exe: &std::path::Path, n: usize, steps: usize, repeats: usize) -> Option<f64> {
    let mut v = Vec::new();
    for _ in 0..repeats {
        let out = Command::new(exe).args(["time", &n.to_string(), &steps.to_string()]).output().ok()?;
        let s = String::from_utf8_lossy(&out.stdout);
        v.push(json_field(s.lines().find(|l| l.starts_with('{'))?, "per_step_s")?.parse().ok()?);
    }
    Some(median(v))
}

fn box_with_sphere(
    n: usize,
    method: PressureMethod,
    tol: f64,
    cap: usize,
) -> Option<(MacFluid, anim_fluid::mac::MacState)> {
    let params = MacParams {
        pressure: method,
        pressure_tolerance: tol,
        pressure_max_iterations: cap,
        require_convergence: false,
        ..MacParams::default()
    };
    let (mut f, mut s) = MacFluid::new([n, n, 1], 2, 1.0 / n as f64, params).ok()?;
    f.set_solid(|p| (p[0] - 0.6).powi(2) + (p[1] - 0.45).powi(2) < 0.04).ok()?;
    f.set_velocity(&mut s, |p| {
        [(3.0 * p[1]).sin() + (5.0 * p[0] * p[2]).cos(), (2.0 * p[0]).cos() * p[1], 0.0]
    });
    Some((f, s))
}

/// One pressure solve on the box's divergence, timed alone: (seconds, relative residual,
/// iterations). A tolerance of 0 runs exactly `cap` sweeps.
fn projection(n: usize, method: PressureMethod, tol: f64, cap: usize) -> Option<(f64, f64, usize)> {
    let (f, s) = box_with_sphere(n, method, 1e-6, 1000)?;
    let mut rhs = vec![0.0; n * n];
    f.net_outflow(&s, &mut rhs);
    rhs.iter_mut().for_each(|x| *x = -*x);
    let mut solver = PressureSolver::new(f.pressure_operator().clone(), method, tol, cap).ok()?;
    let mut x = vec![0.0; n * n];
    let t = Instant::now();
    let info = solver.solve(&rhs, &mut x);
    Some((t.elapsed().as_secs_f64(), info.residual, info.iterations))
}

fn taichi(threads: usize) -> Result<f64, String> {
    let args = ["--res", "512", "--steps", "10", "--threads", &threads.to_string()].map(String::from);
    let line = crate::python::result_line("peers/fluid/taichi_stable_fluid.py", &args, &[])?;
    json_field(&line, "per_step_s").and_then(|v| v.parse().ok()).ok_or_else(|| "no per_step_s".into())
}

pub fn run() -> bool {
    let threads = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1);
    println!("\npeer benchmark (anim-fluid)");
    // 1. Stam mode vs C -O3.
    println!(
        "\n1. Stam mode (f32, 20 Gauss-Seidel sweeps) vs Stam's C code (cc -O3 -march=native), one thread, median of 3 runs"
    );
    println!("| N | C -O3 per step | anim-fluid Stam per step | C / ours |\n| --- | --- | --- | --- |");
    match compile_c("stable_fluids_o3", &["-O3", "-march=native"]) {
        Ok(exe) => {
            for n in [128, 256, 512] {
                let steps = (6400 / n).max(4);
                let c = c_per_step(&exe, n, steps, 3);
                let ours = stam_per_step(n, steps, 3);
                match c {
                    Some(c) => {
                        println!("| {n} | {:.2} ms | {:.2} ms | {:.2}x |", c * 1e3, ours * 1e3, c / ours);
                        super::ratios::record(
                            "anim-fluid",
                            &format!("Stam's stable fluids N = {n}, 20 Gauss-Seidel sweeps"),
                            "Stam's C (cc -O3 -march=native)",
                            1,
                            ours,
                            c,
                        );
                    }
                    None => println!("| {n} | (C run failed) | {:.2} ms | - |", ours * 1e3),
                }
            }
        }
        Err(e) => println!("\nNOTE: C reference SKIPPED: {e}\n"),
    }
    // 2. MGPCG vs Gauss-Seidel at equal residual, N = 512.
    let n = 512;
    println!("\n2. pressure projection on the 2D box with a sphere, N = {n}, {threads} threads");
    println!(
        "| solver | target | iterations | relative residual | time | GS time / MGPCG time |\n| --- | --- | --- | --- | --- | --- |"
    );
    if let Some((gs_t, gs_r, gs_it)) = projection(n, PressureMethod::RedBlackGaussSeidel, 0.0, 20)
        && let Some((mg_t, mg_r, mg_it)) = projection(n, PressureMethod::Mgpcg, gs_r, 1000)
    {
        println!("| rb-gauss-seidel | 20 sweeps | {gs_it} | {gs_r:.3e} | {:.3} s | |", gs_t);
        println!(
            "| mgpcg | residual of 20 GS sweeps | {mg_it} | {mg_r:.3e} | {:.3} s | {:.1}x |",
            mg_t,
            gs_t / mg_t
        );
    }
    let tol = 1e-4;
    if let Some((mg_t, mg_r, mg_it)) = projection(n, PressureMethod::Mgpcg, tol, 1000) {
        // Gauss-Seidel to the same tolerance, capped at about 60 s.
        let per_sweep =
            projection(n, PressureMethod::RedBlackGaussSeidel, 0.0, 50).map_or(0.05, |(t, _, _)| t / 50.0);
        let cap = ((60.0 / per_sweep) as usize).max(100);
        if let Some((gs_t, gs_r, gs_it)) = projection(n, PressureMethod::RedBlackGaussSeidel, tol, cap) {
            let reached = gs_r <= tol;
            println!("| mgpcg | {tol:e} | {mg_it} | {mg_r:.3e} | {:.3} s | |", mg_t);
            println!(
                "| rb-gauss-seidel | {tol:e} | {gs_it}{} | {gs_r:.3e} | {:.1} s | {}{:.0}x |",
                if reached { "" } else { " (cap)" },
                gs_t,
                if reached { "" } else { ">= " },
                gs_t / mg_t
            );
        }
    }
    // 3. Taichi.
    println!("\n3. Taichi stable_fluid example, 512 x 512, 500 Jacobi iterations, CPU");
    match crate::python::ensure("taichi", &["taichi==1.7.4"], "") {
        Err(e) => println!("\nNOTE: Taichi peer SKIPPED: {e}\n"),
        Ok(()) => {
            let stam = stam_per_step(512, 5, 1);
            let mac = box_with_sphere(512, PressureMethod::Mgpcg, 1e-5, 1000).map(|(mut f, mut s)| {
                f.set_advection(anim_fluid::advection::Advection::Linear);
                let _ = f.advance(&mut s, 1e-3);
                let t = Instant::now();
                for _ in 0..3 {
                    let _ = f.advance(&mut s, 1e-3);
                }
                t.elapsed().as_secs_f64() / 3.0
            });
            println!("| code | threads | per step |\n| --- | --- | --- |");
            for t in [1, threads] {
                match taichi(t) {
                    Ok(s) => {
                        println!("| taichi stable_fluid (500 Jacobi) | {t} | {:.1} ms |", s * 1e3);
                        if t == 1 {
                            super::ratios::record(
                                "anim-fluid",
                                "stable fluids 512 x 512: our Stam mode (20 GS sweeps) vs Taichi (500 Jacobi)",
                                "Taichi 1.7.4 stable_fluid",
                                1,
                                stam,
                                s,
                            );
                        }
                    }
                    Err(e) => println!("| taichi stable_fluid | {t} | failed: {e} |"),
                }
            }
            println!("| anim-fluid Stam mode (20 GS sweeps) | 1 | {:.1} ms |", stam * 1e3);
            if let Some(m) = mac {
                println!("| anim-fluid MAC, sl-linear, MGPCG 1e-5 (f64) | {threads} | {:.1} ms |", m * 1e3);
            }
        }
    }
    true
}
