//! `cargo xtask bench --peers`, anim-springs part: the benchmark cloth
//! (`anim_springs::scenes::benchmark_cloth`, 128 x 128 particles, structural, shear and bending
//! springs) stepped by symplectic Euler in anim-springs and in Taichi on the CPU
//! (`xtask/peers/taichi_cloth.py`: the same cloth in float64, timed with a spring-list kernel and
//! a grid-stencil kernel), same step, same thread count, time per step measured side by side and
//! the motions compared by checksums of the final positions. Taichi is installed with pip when
//! missing; if that fails the peer is skipped with a visible note.

use anim_springs::cases::peer_symplectic_cloth;
use std::io::Write;
use std::process::Command;

const SCRIPT: &str = "xtask/peers/taichi_cloth.py";

/// A value of a flat JSON object line (numbers and strings only; the script prints no nesting).
fn field(line: &str, key: &str) -> Option<String> {
    let rest = &line[line.find(&format!("\"{key}\":"))? + key.len() + 3..];
    let rest = rest.trim_start();
    let end = rest.find([',', '}']).unwrap_or(rest.len());
    Some(rest[..end].trim().trim_matches('"').to_string())
}

pub fn run() -> bool {
    let threads = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1);
    let (n, steps, repeats) = (128, 200, 5);
    println!(
        "peer benchmark: {n}x{n} cloth (anim_springs::scenes::benchmark_cloth), symplectic Euler, {steps} steps, {threads} threads, median of {repeats}"
    );
    let ours = match peer_symplectic_cloth(n, steps, threads, repeats) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("our run failed: {e}");
            return false;
        }
    };
    let mut rows = vec![("anim-springs".to_string(), ours.per_step_s, ours.sum_z, ours.min_z)];
    match crate::python::ensure(
        "taichi",
        &["taichi"],
        " (taichi publishes wheels for CPython 3.7 to 3.12 on x86-64 and arm64 only)",
    ) {
        Err(e) => println!("\nNOTE: Taichi peer SKIPPED: {e}\n"),
        Ok(()) => {
            let out = Command::new(crate::python::python())
                .args([SCRIPT, "--n", &n.to_string(), "--steps", &steps.to_string()])
                .args(["--repeats", &repeats.to_string(), "--threads", &threads.to_string()])
                .output();
            match out {
                Ok(o) if o.status.success() => {
                    for line in String::from_utf8_lossy(&o.stdout).lines().filter(|l| l.starts_with('{')) {
                        let get =
                            |k: &str| field(line, k).and_then(|v| v.parse::<f64>().ok()).unwrap_or(f64::NAN);
                        let name = format!(
                            "taichi {} ({})",
                            field(line, "taichi").unwrap_or_default(),
                            field(line, "variant").unwrap_or_default()
                        );
                        rows.push((name, get("per_step_s"), get("sum_z"), get("min_z")));
                    }
                }
                Ok(o) => {
                    println!("\nNOTE: Taichi script failed: {}\n", String::from_utf8_lossy(&o.stderr))
                }
                Err(e) => println!("\nNOTE: could not run {}: {e}\n", crate::python::python()),
            }
        }
    }
    println!(
        "\n| code | per step | ours / theirs | sum z after {steps} steps | min z |\n| --- | --- | --- | --- | --- |"
    );
    for (name, t, sum_z, min_z) in &rows {
        println!(
            "| {name} | {} | {:.3} | {sum_z:.9} | {min_z:.9} |",
            super::human(t * 1e9),
            ours.per_step_s / t
        );
    }
    for (name, t, _, _) in rows.iter().skip(1) {
        super::ratios::record(
            "anim-springs",
            &format!("cloth {n}x{n}, symplectic Euler, per step"),
            name,
            threads,
            ours.per_step_s,
            *t,
        );
    }
    let mut agree = true;
    for (name, _, sum_z, min_z) in rows.iter().skip(1) {
        let dz = ((sum_z - ours.sum_z) / ours.sum_z).abs().max((min_z - ours.min_z).abs());
        if !(dz < 1e-9) {
            println!("WARNING: {name} computed a different motion (checksum difference {dz:e})");
            agree = false;
        }
    }
    let dir = std::path::Path::new("target/xtask");
    let written = std::fs::create_dir_all(dir).and_then(|_| {
        let mut f = std::fs::File::create(dir.join("peers.csv"))?;
        writeln!(f, "code,threads,per_step_s,ours_over_theirs,sum_z,min_z")?;
        for (name, t, sum_z, min_z) in &rows {
            writeln!(f, "{name},{threads},{t},{},{sum_z},{min_z}", ours.per_step_s / t)?;
        }
        Ok(())
    });
    if let Err(e) = written {
        eprintln!("could not write target/xtask/peers.csv: {e}");
    }
    agree
}
