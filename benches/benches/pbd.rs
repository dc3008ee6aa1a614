//! Criterion benches of anim-pbd on the benchmark cloth (`anim_pbd::scenes::benchmark_cloth`):
//! N x N particles (N = 50 and 100), two pinned corners, XPBD distance + isometric bending,
//! dt = 1/60, one step from a pre-generated swinging state, for each solver at 5 iterations and
//! for sequential Gauss-Seidel at 20 iterations.

use anim_pbd::{Method, PbdParams, PbdSimulation, SolverKind, scenes};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;

fn steps(c: &mut Criterion) {
    for n in [50, 100] {
        let scene = scenes::benchmark_cloth(n).unwrap_or_else(|e| panic!("benchmark cloth: {e}"));
        let dt = scene.dt;
        // A swinging state: 20 steps from rest.
        let mut start = scene.state.clone();
        let mut warm =
            PbdSimulation::new(scene.model.clone(), scene.params).unwrap_or_else(|e| panic!("params: {e}"));
        warm.run(&mut start, dt, 20).unwrap_or_else(|e| panic!("warm-up: {e}"));
        let mut g = c.benchmark_group(format!("pbd cloth {n}x{n} step"));
        g.sample_size(10);
        g.throughput(Throughput::Elements(scene.model.num_constraints() as u64));
        for (solver, iterations) in [
            (SolverKind::GaussSeidel, 5),
            (SolverKind::ColoredGaussSeidel, 5),
            (SolverKind::Jacobi, 5),
            (SolverKind::GaussSeidel, 20),
        ] {
            let mut params = PbdParams::new(Method::Xpbd, solver, iterations, 1);
            params.max_stretch = f64::INFINITY;
            let mut sim =
                PbdSimulation::new(scene.model.clone(), params).unwrap_or_else(|e| panic!("params: {e}"));
            let mut state = start.clone();
            sim.advance(&mut state, dt).unwrap_or_else(|e| panic!("step: {e}"));
            g.bench_function(format!("xpbd {} {iterations} iterations", solver.label()), |b| {
                b.iter(|| {
                    let mut s = start.clone();
                    sim.advance(black_box(&mut s), dt).unwrap_or_else(|e| panic!("step: {e}"));
                    black_box(&s);
                })
            });
        }
        g.finish();
    }
}

criterion_group!(benches, steps);
criterion_main!(benches);
