//! `cargo xtask bench`: runs the criterion benches and prints a table of medians.

use std::io::Write;
use std::process::Command;

/// One benchmark's result as reported in criterion's `bencher` output format.
struct Row {
    name: String,
    ns: f64,
    spread: f64,
}

fn parse_bencher(out: &str) -> Vec<Row> {
    // Lines look like: "test core/svd3/f64 ... bench:         123 ns/iter (+/- 4)"
    out.lines()
        .filter_map(|line| {
            let rest = line.strip_prefix("test ")?;
            let (name, rest) = rest.split_once(" ... bench:")?;
            let (ns, rest) = rest.trim().split_once(" ns/iter")?;
            let spread = rest.trim().trim_start_matches("(+/-").trim_end_matches(')').trim().replace(',', "");
            Some(Row {
                name: name.trim().to_string(),
                ns: ns.replace(',', "").trim().parse().ok()?,
                spread: spread.parse().unwrap_or(f64::NAN),
            })
        })
        .collect()
}

pub fn run(filter: Option<&str>) -> bool {
    if std::env::args().skip(2).any(|a| a == "--peers") {
        // `--filter` picks peers by name (springs, rigid, pbd, fem, mpm, fluid, flip).
        type Peer = (&'static str, fn() -> bool);
        let peers: [Peer; 7] = [
            ("springs", peers::run),
            ("rigid", peers_rigid::run),
            ("pbd", peers_pbd::run),
            ("fem", peers_fem::run),
            ("mpm", peers_mpm::run),
            ("fluid", peers_fluid::run),
            ("flip", peers_flip::run),
        ];
        let mut ok = true;
        for (name, run) in peers {
            if filter.is_none_or(|f| name.contains(f) || f.contains(name)) {
                ok &= run();
            }
        }
        // Rows of the crates measured now replace theirs in the committed file; others stay.
        let measured = crate::peers_file::take();
        let crates: std::collections::BTreeSet<String> = measured.iter().map(|r| r.krate.clone()).collect();
        let path = std::path::Path::new(crate::peers_file::PATH);
        match crate::peers_file::update(path, measured) {
            Ok(n) => eprintln!(
                "updated {} ({n} rows; measured now: {})",
                path.display(),
                if crates.is_empty() {
                    "none".to_string()
                } else {
                    crates.into_iter().collect::<Vec<_>>().join(", ")
                }
            ),
            Err(e) => {
                eprintln!("could not update {}: {e}", path.display());
                ok = false;
            }
        }
        return ok;
    }
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let mut args = vec!["bench", "-p", "anim-benches", "--benches", "--", "--output-format", "bencher"];
    if let Some(f) = filter {
        args.push(f);
    }
    eprintln!("== cargo {}", args.join(" "));
    let output = match Command::new(cargo).args(&args).output() {
        Ok(o) => o,
        Err(e) => {
            eprintln!("could not run cargo bench: {e}");
            return false;
        }
    };
    let stdout = String::from_utf8_lossy(&output.stdout);
    if !output.status.success() {
        eprintln!("{}", String::from_utf8_lossy(&output.stderr));
        eprintln!("cargo bench failed");
        return false;
    }
    let rows = parse_bencher(&stdout);
    println!("| benchmark | median | spread |\n| --- | --- | --- |");
    for r in &rows {
        println!("| {} | {} | +/- {} |", r.name, human(r.ns), human(r.spread));
    }
    let dir = std::path::Path::new("target/xtask");
    let written = std::fs::create_dir_all(dir).and_then(|_| {
        let mut f = std::fs::File::create(dir.join("bench.csv"))?;
        writeln!(f, "benchmark,median_ns,spread_ns")?;
        for r in &rows {
            writeln!(f, "{},{},{}", r.name, r.ns, r.spread)?;
        }
        Ok(())
    });
    match written {
        Ok(()) => eprintln!("wrote target/xtask/bench.csv ({} benchmarks)", rows.len()),
        Err(e) => eprintln!("could not write target/xtask/bench.csv: {e}"),
    }
    !rows.is_empty()
}

fn human(ns: f64) -> String {
    if !ns.is_finite() {
        "?".into()
    } else if ns < 1e3 {
        format!("{ns:.0} ns")
    } else if ns < 1e6 {
        format!("{:.2} us", ns / 1e3)
    } else if ns < 1e9 {
        format!("{:.2} ms", ns / 1e6)
    } else {
        format!("{:.2} s", ns / 1e9)
    }
}

/// anim-rigid's peers (Pinocchio), in its own file.
#[path = "peers_rigid.rs"]
mod peers_rigid;

/// anim-pbd's peers (pyPBD, Newton), in its own file.
#[path = "peers_pbd.rs"]
mod peers_pbd;

/// anim-fem's peers, in its own file.
#[path = "peers_fem.rs"]
mod peers_fem;

/// anim-mpm's peers (Taichi MLS-MPM), in its own file.
#[path = "peers_mpm.rs"]
mod peers_mpm;

/// anim-fluid's peers (the seed's C routines, Taichi stable fluids), in its own file.
#[path = "peers_fluid.rs"]
mod peers_fluid;

/// anim-flip's peer (Taichi MLS-MPM 3D as a dam break), in its own file.
#[path = "peers_flip.rs"]
mod peers_flip;

/// `cargo xtask bench --peers`: our per-step time against peer libraries on the same problem,
/// same integrator and same thread count, measured side by side in one run.
mod peers {
    use crate::cases::springs::peer_symplectic_cloth;
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
                        for line in String::from_utf8_lossy(&o.stdout).lines().filter(|l| l.starts_with('{'))
                        {
                            let get = |k: &str| {
                                field(line, k).and_then(|v| v.parse::<f64>().ok()).unwrap_or(f64::NAN)
                            };
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
            crate::peers_file::record(
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
}

#[cfg(test)]
mod tests {
    #[test]
    fn parses_bencher_lines() {
        let rows = super::parse_bencher(
            "noise\ntest svd3/f64 ... bench:       1,234 ns/iter (+/- 56)\ntest cg/poisson-64 ... bench: 9 ns/iter (+/- 0)\n",
        );
        assert_eq!(rows.len(), 2);
        assert_eq!(rows[0].name, "svd3/f64");
        assert_eq!(rows[0].ns, 1234.0);
        assert_eq!(rows[0].spread, 56.0);
        assert_eq!(rows[1].ns, 9.0);
    }
}
