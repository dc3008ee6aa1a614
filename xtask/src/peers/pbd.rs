//! `cargo xtask bench --peers`, anim-pbd part: the benchmark cloth (N x N, N = 50 and 100, two
//! pinned corners, XPBD distance + bending, dt = 1/60, one substep, 5 and 20 iterations) in
//! anim-pbd, in Jan Bender's PositionBasedDynamics (the `pyPBD` wheel: C++, double precision,
//! sequential Gauss-Seidel, isometric bending) and in NVIDIA Newton's XPBD solver on the CPU
//! (`newton` + `warp-lang`: Jacobi without averaging, dihedral bending), equal constraint counts
//! and iterations, time per step measured side by side.
//!
//! Thread counts: pyPBD runs with `OMP_NUM_THREADS=1` and Warp runs CPU kernels on one thread,
//! so the headline ratios are at one thread; our two-thread runs are listed beside them. Every
//! configuration is measured in [`ROUNDS`] interleaved rounds (ours, then each peer, again): a
//! row gives the median of its rounds, and the closing table each ratio ours / peer as the median
//! of the per-round ratios with their range. The peers are installed with pip when missing; if
//! that fails the peer is skipped with a visible note.
//!
//! Then the two-thread speed-up of the coloured Gauss-Seidel and Jacobi sweeps on the cloth of
//! 100 x 100 and 200 x 200 (both bendings, 5 iterations): one and two threads interleaved in
//! [`ROUNDS`] rounds, the median and range of the per-round ratios.

use crate::python::json_field as field;
use anim_pbd::SolverKind;
use anim_pbd::cases::peer_cloth;
use std::io::Write;

const PYPBD: &str = "peers/pbd/pypbd_cloth.py";
const NEWTON: &str = "peers/pbd/newton_cloth.py";
/// Interleaved rounds per configuration.
const ROUNDS: usize = 3;

/// A value of a flat JSON object line.
struct Row {
    n: usize,
    iterations: usize,
    code: String,
    threads: usize,
    constraints: usize,
    per_step_s: f64,
    /// The per-round times (s per step), in round order.
    rounds: Vec<f64>,
    note: String,
}

/// Median, lowest and highest of `v`.
fn spread(v: &[f64]) -> (f64, f64, f64) {
    let mut v = v.to_vec();
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        return (f64::NAN, f64::NAN, f64::NAN);
    }
    (v[v.len() / 2], v[0], v[v.len() - 1])
}

/// Adds the time `t` of one round to the row of `code` for `(n, iterations, threads)`, creating it.
fn add(
    rows: &mut Vec<Row>,
    n: usize,
    iterations: usize,
    code: &str,
    threads: usize,
    constraints: usize,
    t: f64,
    note: String,
) {
    if let Some(r) = rows
        .iter_mut()
        .find(|r| r.n == n && r.iterations == iterations && r.code == code && r.threads == threads)
    {
        r.rounds.push(t);
        r.per_step_s = spread(&r.rounds).0;
        r.note = note;
    } else {
        rows.push(Row {
            n,
            iterations,
            code: code.into(),
            threads,
            constraints,
            per_step_s: t,
            rounds: vec![t],
            note,
        });
    }
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
            for _round in 0..ROUNDS {
                for (label, dihedral, solver, t) in [
                    ("anim-pbd gauss-seidel, isometric", false, SolverKind::GaussSeidel, 1),
                    ("anim-pbd colored-gs, isometric", false, SolverKind::ColoredGaussSeidel, 1),
                    ("anim-pbd colored-gs, isometric", false, SolverKind::ColoredGaussSeidel, threads),
                    ("anim-pbd gauss-seidel, dihedral", true, SolverKind::GaussSeidel, 1),
                    ("anim-pbd colored-gs, dihedral", true, SolverKind::ColoredGaussSeidel, 1),
                    ("anim-pbd colored-gs, dihedral", true, SolverKind::ColoredGaussSeidel, threads),
                ] {
                    match peer_cloth(n, iterations, dihedral, solver, t, steps, repeats) {
                        Ok(r) => {
                            let note = format!("lowest z {:.3}", r.min_height);
                            add(&mut rows, n, iterations, label, t, r.constraints, r.per_step_s, note);
                        }
                        Err(e) => {
                            eprintln!("our run failed: {e}");
                            ok = false;
                        }
                    }
                }
                for (enabled, script, name) in [
                    (&pypbd, PYPBD, "pyPBD 2.2.2, isometric"),
                    (&newton, NEWTON, "Newton XPBD (CPU), dihedral"),
                ] {
                    if enabled.is_err() {
                        continue;
                    }
                    match run_script(script, n, iterations, steps, repeats) {
                        Ok(line) => {
                            let num = |k: &str| {
                                field(&line, k).and_then(|v| v.parse::<f64>().ok()).unwrap_or(f64::NAN)
                            };
                            let diverged = field(&line, "diverged").is_some_and(|v| v == "true");
                            let note = if diverged {
                                "DIVERGED (left a 100 m box or NaN)".into()
                            } else {
                                format!("lowest height {:.3}", num("min_height"))
                            };
                            let constraints = num("constraints") as usize;
                            add(&mut rows, n, iterations, name, 1, constraints, num("per_step_s"), note);
                        }
                        Err(e) => println!("\nNOTE: {name} run failed: {e}\n"),
                    }
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
    println!(
        "\nours / peer, per-round ratios of {ROUNDS} interleaved rounds (median, range):\n\n| N | iterations | ours (1 thread) | peer | ours / peer |\n| --- | --- | --- | --- | --- |"
    );
    for theirs in rows.iter().filter(|r| !r.code.starts_with("anim-pbd")) {
        for ours in rows.iter().filter(|o| {
            o.n == theirs.n
                && o.iterations == theirs.iterations
                && o.threads == 1
                && o.code.starts_with("anim-pbd")
        }) {
            let ratios: Vec<f64> = ours.rounds.iter().zip(&theirs.rounds).map(|(a, b)| a / b).collect();
            let (m, lo, hi) = spread(&ratios);
            println!(
                "| {} | {} | {} | {} | {m:.2} ({lo:.2}-{hi:.2}) |",
                theirs.n, theirs.iterations, ours.code, theirs.code
            );
        }
    }
    ok &= thread_speedups();
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

/// The two-thread speed-up table (see the module docs); false if a run failed.
fn thread_speedups() -> bool {
    println!(
        "\ntwo-thread speed-up of the parallel sweeps, benchmark cloth, 5 iterations, {ROUNDS} interleaved rounds of 1 and 2 threads:\n\n| N | solver | bending | 1 thread | 2 threads | speed-up (median, range) |\n| --- | --- | --- | --- | --- | --- |"
    );
    let mut ok = true;
    for n in [100, 200] {
        let steps = if n == 100 { 15 } else { 5 };
        for solver in [SolverKind::ColoredGaussSeidel, SolverKind::Jacobi] {
            for dihedral in [false, true] {
                match anim_pbd::cases::thread_rounds(n, 5, dihedral, solver, 2, steps, ROUNDS) {
                    Ok(r) => {
                        let (one, _, _) = spread(&r.iter().map(|p| p.0).collect::<Vec<_>>());
                        let (two, _, _) = spread(&r.iter().map(|p| p.1).collect::<Vec<_>>());
                        let (m, lo, hi) = spread(&r.iter().map(|(a, b)| a / b).collect::<Vec<_>>());
                        println!(
                            "| {n} | {} | {} | {} | {} | {m:.2} ({lo:.2}-{hi:.2}) |",
                            solver.label(),
                            if dihedral { "dihedral" } else { "isometric" },
                            super::human(one * 1e9),
                            super::human(two * 1e9)
                        );
                    }
                    Err(e) => {
                        eprintln!("our run failed: {e}");
                        ok = false;
                    }
                }
            }
        }
    }
    ok
}
