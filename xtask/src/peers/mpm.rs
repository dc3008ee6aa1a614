//! `cargo xtask bench --peers`, anim-mpm part: Taichi's MLS-MPM fluid (`mpm88` in 2D at 8k, 32k
//! and 131k particles on 128^2, 256^2 and 512^2 grids; `mpm3d` at 65k particles on 64^3) on the
//! CPU backend beside `anim_mpm::scenes::benchmark_2d` / `benchmark_3d` (same particle count,
//! grid, dt, material, boundary), at 1 and 2 threads, time per substep and throughput in
//! particle-steps per second. Taichi is installed with pip when missing; if that fails the peer
//! is skipped with a visible note.

use crate::python::json_field as field;
use anim_mpm::cases::peer_benchmark;
use std::io::Write;

const SCRIPT: &str = "peers/mpm/taichi_mpm.py";

fn taichi(dim: usize, n: usize, steps: usize, repeats: usize, threads: usize) -> Result<(f64, f64), String> {
    let args =
        [("--dim", dim), ("--n", n), ("--steps", steps), ("--repeats", repeats), ("--threads", threads)];
    let args: Vec<String> = args.iter().flat_map(|(k, v)| [k.to_string(), v.to_string()]).collect();
    let line = crate::python::result_line(SCRIPT, &args, &[])?;
    let get = |k: &str| field(&line, k).and_then(|v| v.parse::<f64>().ok()).ok_or(format!("no {k}"));
    Ok((get("per_step_s")?, get("mean_y")?))
}

pub fn run() -> bool {
    let cases: [(usize, usize, usize); 4] = [(2, 128, 200), (2, 256, 100), (2, 512, 40), (3, 64, 20)];
    let repeats = 5;
    let peer = crate::python::ensure("taichi", &["taichi"], "");
    if let Err(e) = &peer {
        println!("\nNOTE: Taichi peer SKIPPED: {e}\n");
    }
    println!(
        "peer benchmark: MLS-MPM fluid (mpm88 / mpm3d), anim-mpm vs Taichi CPU, median of {repeats} x steps after 50 warm-up steps\n"
    );
    println!(
        "| scene | particles | threads | anim-mpm / step | taichi / step | anim Mp-steps/s | taichi Mp-steps/s | ratio (ours / theirs throughput) | mean y ours / taichi |"
    );
    println!("| --- | --- | --- | --- | --- | --- | --- | --- | --- |");
    let mut rows = vec![];
    let mut ok = true;
    for (dim, n, steps) in cases {
        for threads in [1, 2] {
            let ours = match peer_benchmark(dim, n, steps, repeats, threads) {
                Ok(r) => r,
                Err(e) => {
                    eprintln!("our run failed: {e}");
                    ok = false;
                    continue;
                }
            };
            let theirs =
                if peer.is_ok() { taichi(dim, n, steps, repeats, threads) } else { Err("skipped".into()) };
            let (t_step, t_y) = match &theirs {
                Ok(v) => *v,
                Err(e) => {
                    println!("NOTE: taichi {dim}D n={n} threads={threads}: {e}");
                    (f64::NAN, f64::NAN)
                }
            };
            let np = ours.particles as f64;
            let ratio = t_step / ours.per_step_s;
            println!(
                "| {dim}D {n}^{dim} | {} | {threads} | {} | {} | {:.2} | {:.2} | {:.2} | {:.4} / {:.4} |",
                ours.particles,
                super::human(ours.per_step_s * 1e9),
                super::human(t_step * 1e9),
                np / ours.per_step_s / 1e6,
                np / t_step / 1e6,
                ratio,
                ours.mean_y,
                t_y
            );
            rows.push((dim, n, ours.particles, threads, ours.per_step_s, t_step, ratio));
            super::ratios::record(
                "anim-mpm",
                &format!("MLS-MPM fluid {dim}D {n}^{dim}, {} particles", ours.particles),
                "Taichi",
                threads,
                ours.per_step_s,
                t_step,
            );
        }
    }
    let dir = std::path::Path::new("target/xtask");
    let written = std::fs::create_dir_all(dir).and_then(|_| {
        let mut f = std::fs::File::create(dir.join("peers_mpm.csv"))?;
        writeln!(f, "dim,n,particles,threads,ours_per_step_s,taichi_per_step_s,throughput_ratio")?;
        for (dim, n, np, th, a, b, r) in &rows {
            writeln!(f, "{dim},{n},{np},{th},{a},{b},{r}")?;
        }
        Ok(())
    });
    if let Err(e) = written {
        eprintln!("could not write target/xtask/peers_mpm.csv: {e}");
    }
    ok
}
