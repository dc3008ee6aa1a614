//! Interleaved timings of the benchmark cloth: `cloth_timing bend` (dihedral against isometric
//! bending per solver at 100 x 100, 5 and 20 iterations) or `cloth_timing threads` (1 against 2
//! threads per solver at 100 x 100 and 200 x 200). Rounds alternate the runs compared, and the
//! medians and ranges of their ratios are printed.

use anim_pbd::SolverKind;
use anim_pbd::cases::{peer_cloth, thread_rounds};

fn time(n: usize, it: usize, dihedral: bool, solver: SolverKind, threads: usize) -> f64 {
    let steps = if n <= 100 { 15 } else { 4 };
    peer_cloth(n, it, dihedral, solver, threads, steps, 3)
        .unwrap_or_else(|e| panic!("cloth run: {e}"))
        .per_step_s
}

fn stats(mut v: Vec<f64>) -> (f64, f64, f64) {
    v.sort_by(f64::total_cmp);
    (v[v.len() / 2], v[0], v[v.len() - 1])
}

fn main() {
    let mode = std::env::args().nth(1).unwrap_or_else(|| "bend".into());
    let rounds: usize = std::env::args().nth(2).and_then(|s| s.parse().ok()).unwrap_or(3);
    let solvers = [SolverKind::GaussSeidel, SolverKind::ColoredGaussSeidel, SolverKind::Jacobi];
    if mode == "one" {
        // cloth_timing one N ITERATIONS dihedral|isometric SOLVER THREADS: one configuration, for profiling.
        let arg = |k: usize| std::env::args().nth(k).unwrap_or_default();
        let n: usize = arg(2).parse().unwrap_or(100);
        let it: usize = arg(3).parse().unwrap_or(5);
        let s = solvers.into_iter().find(|s| s.label() == arg(5)).unwrap_or(SolverKind::GaussSeidel);
        let t: usize = arg(6).parse().unwrap_or(1);
        let r = peer_cloth(n, it, arg(4) == "dihedral", s, t, 60, 3).unwrap_or_else(|e| panic!("{e}"));
        println!("{:.3} ms per step", r.per_step_s * 1e3);
    } else if mode == "bend" {
        for it in [5, 20] {
            for s in solvers {
                let (mut d, mut i) = (Vec::new(), Vec::new());
                for _ in 0..rounds {
                    d.push(time(100, it, true, s, 1));
                    i.push(time(100, it, false, s, 1));
                }
                let (dm, dl, dh) = stats(d);
                let (im, il, ih) = stats(i);
                println!(
                    "100x100 {it:2} it {:22} dihedral {:.2} ms ({:.2}-{:.2})  isometric {:.2} ms ({:.2}-{:.2})",
                    s.label(),
                    dm * 1e3,
                    dl * 1e3,
                    dh * 1e3,
                    im * 1e3,
                    il * 1e3,
                    ih * 1e3
                );
            }
        }
    } else {
        for n in [100, 200] {
            for s in solvers {
                for dihedral in [false, true] {
                    let steps = if n <= 100 { 15 } else { 4 };
                    let r = thread_rounds(n, 5, dihedral, s, 2, steps, rounds)
                        .unwrap_or_else(|e| panic!("cloth run: {e}"));
                    let (m, lo, hi) = stats(r.iter().map(|(a, b)| a / b).collect());
                    let (t1, _, _) = stats(r.iter().map(|p| p.0).collect());
                    println!(
                        "{n}x{n} 5 it {:22} {:9} 1 thread {:.2} ms, speed-up on 2: {m:.2} ({lo:.2}-{hi:.2})",
                        s.label(),
                        if dihedral { "dihedral" } else { "isometric" },
                        t1 * 1e3
                    );
                }
            }
        }
    }
}
