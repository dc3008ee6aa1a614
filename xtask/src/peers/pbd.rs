//! `cargo xtask bench --peers`, anim-pbd part: the benchmark cloth (N x N, N = 50 and 100, two
//! pinned corners, XPBD distance + bending, dt = 1/60, one substep, 5 and 20 iterations) in
//! anim-pbd, in Jan Bender's PositionBasedDynamics (the `pyPBD` wheel: C++, double precision,
//! sequential Gauss-Seidel, isometric bending) and in NVIDIA Newton's XPBD solver on the CPU
//! (`newton` + `warp-lang`: Jacobi without averaging, dihedral bending), equal constraint counts
//! and iterations, time per step measured side by side.
//!
//! Thread counts: pyPBD runs with `OMP_NUM_THREADS=1` and Warp runs CPU kernels on one thread,
//! so the headline ratios are at one thread; our two-thread run is listed beside them. The peers
//! are installed with pip when missing; if that fails the peer is skipped with a visible note.

use crate::python::json_field as field;
use anim_pbd::SolverKind;
use anim_pbd::cases::peer_cloth;
use std::io::Write;

const PYPBD: &str = "peers/pbd/pypbd_cloth.py";
const NEWTON: &str = "peers/pbd/newton_cloth.py";

/// A value of a flat JSON object line.
struct Row {
    n: usize,
    iterations: usize,
    code: String,
    threads: usize,
    constraints: usize,
    per_step_s: f64,
    note: String,
}

fn run_script(
    script: &str,
    n: usize,
    iterations: usize,
    steps: usize,
    repeats: usize,
) -> Result<String, String> {
    let args = [("--n", n), ("--iterations", iterations), ("--steps", steps), ("--repeats", repeats)];
    let args: Vec<String> = args.iter().flat_map(|(k, v)| [k.to_string(), v.to_string()]).collect();
    crate::python::result_line(script, &args, &[("OMP_NUM_THREADS", "1")])
}

pub fn run() -> bool {
    let threads = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1);
    let repeats = 5;
    println!(
        "\npeer benchmark (anim-pbd): N x N cloth, XPBD distance + bending, dt = 1/60, 1 substep; median of {repeats} runs"
    );
    let pypbd = crate::python::ensure("pypbd", &["pyPBD==2.2.2"], "");
    let newton = crate::python::ensure("newton", &["newton==1.8.0", "warp-lang==1.19.0"], "");
    if let Err(e) = &pypbd {
        println!("\nNOTE: pyPBD peer SKIPPED: {e}\n");
    }
    if let Err(e) = &newton {
        println!("\nNOTE: Newton peer SKIPPED: {e}\n");
    }
    let mut rows: Vec<Row> = Vec::new();
    let mut ok = true;
    for n in [50, 100] {
        let steps = if n == 50 { 40 } else { 15 };
        for iterations in [5, 20] {
            for (label, dihedral, solver, t) in [
                ("anim-pbd gauss-seidel, isometric", false, SolverKind::GaussSeidel, 1),
                ("anim-pbd colored-gs, isometric", false, SolverKind::ColoredGaussSeidel, 1),
                ("anim-pbd colored-gs, isometric", false, SolverKind::ColoredGaussSeidel, threads),
                ("anim-pbd colored-gs, dihedral", true, SolverKind::ColoredGaussSeidel, 1),
            ] {
                match peer_cloth(n, iterations, dihedral, solver, t, steps, repeats) {
                    Ok(r) => rows.push(Row {
                        n,
                        iterations,
                        code: label.into(),
                        threads: t,
                        constraints: r.constraints,
                        per_step_s: r.per_step_s,
                        note: format!("lowest z {:.3}", r.min_height),
                    }),
                    Err(e) => {
                        eprintln!("our run failed: {e}");
                        ok = false;
                    }
                }
            }
            for (enabled, script, name) in
                [(&pypbd, PYPBD, "pyPBD 2.2.2, isometric"), (&newton, NEWTON, "Newton XPBD (CPU), dihedral")]
            {
                if enabled.is_err() {
                    continue;
                }
                match run_script(script, n, iterations, steps, repeats) {
                    Ok(line) => {
                        let num =
                            |k: &str| field(&line, k).and_then(|v| v.parse::<f64>().ok()).unwrap_or(f64::NAN);
                        let diverged = field(&line, "diverged").is_some_and(|v| v == "true");
                        rows.push(Row {
                            n,
                            iterations,
                            code: name.into(),
                            threads: 1,
                            constraints: num("constraints") as usize,
                            per_step_s: num("per_step_s"),
                            note: if diverged {
                                "DIVERGED (left a 100 m box or NaN)".into()
                            } else {
                                format!("lowest height {:.3}", num("min_height"))
                            },
                        });
                    }
                    Err(e) => println!("\nNOTE: {name} run failed: {e}\n"),
                }
            }
        }
    }
    println!(
        "\n| N | iterations | code | threads | constraints | per step | theirs / ours (1-thread GS) | note |\n| --- | --- | --- | --- | --- | --- | --- | --- |"
    );
    for r in &rows {
        let ours = rows
            .iter()
            .find(|o| {
                o.n == r.n
                    && o.iterations == r.iterations
                    && o.threads == 1
                    && o.code.starts_with("anim-pbd gauss-seidel")
            })
            .map_or(f64::NAN, |o| o.per_step_s);
        println!(
            "| {} | {} | {} | {} | {} | {} | {:.2} | {} |",
            r.n,
            r.iterations,
            r.code,
            r.threads,
            r.constraints,
            super::human(r.per_step_s * 1e9),
            r.per_step_s / ours,
            r.note
        );
    }
    for theirs in rows.iter().filter(|r| !r.code.starts_with("anim-pbd")) {
        for ours in rows.iter().filter(|o| {
            o.n == theirs.n
                && o.iterations == theirs.iterations
                && o.threads == 1
                && o.code.starts_with("anim-pbd")
        }) {
            super::ratios::record(
                "anim-pbd",
                &format!("XPBD cloth {n}x{n}, {} iterations, {}", theirs.iterations, ours.code, n = theirs.n),
                &theirs.code,
                1,
                ours.per_step_s,
                theirs.per_step_s,
            );
        }
    }
    let dir = std::path::Path::new("target/xtask");
    let written = std::fs::create_dir_all(dir).and_then(|_| {
        let mut f = std::fs::File::create(dir.join("peers_pbd.csv"))?;
        writeln!(f, "n,iterations,code,threads,constraints,per_step_s,note")?;
        for r in &rows {
            writeln!(
                f,
                "{},{},{},{},{},{},{}",
                r.n, r.iterations, r.code, r.threads, r.constraints, r.per_step_s, r.note
            )?;
        }
        Ok(())
    });
    if let Err(e) = written {
        eprintln!("could not write target/xtask/peers_pbd.csv: {e}");
    }
    ok
}
