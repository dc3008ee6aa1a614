//! Criterion benches of anim-springs on the 128 x 128 benchmark cloth (97,026 springs) over
//! pre-generated inputs: force evaluation, Jacobian linearisation, assembly into CSR, the
//! matrix-free Jacobian product, one symplectic Euler step and one backward Euler step.

use anim_core::integrate::{IntegratorKind, MechanicalSystem, SecondOrderSystem, State};
use anim_core::linalg::{CsrMatrix, LinearSolverKind};
use anim_springs::SpringNetwork;
use anim_springs::scenes::{self, animation_newton};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;

/// The benchmark cloth and a deformed, moving state (so every spring does real work).
fn cloth() -> (SpringNetwork, State) {
    let scene = scenes::benchmark_cloth(128).unwrap_or_else(|e| panic!("benchmark cloth: {e}"));
    let mut state = scene.state;
    for (p, (x, v)) in state.x.chunks_exact_mut(3).zip(state.v.chunks_exact_mut(3)).enumerate() {
        let s = p as f64;
        x[2] += 0.01 * (0.37 * s).sin();
        x[0] += 0.002 * (0.11 * s).cos();
        v[0] = 0.1 * (0.05 * s).sin();
        v[2] = -0.2 * (0.07 * s).cos();
    }
    (scene.network, state)
}

fn kernels(c: &mut Criterion) {
    let (mut net, state) = cloth();
    let n = net.dof();
    let springs = net.num_springs() as u64;
    let mut g = c.benchmark_group("springs cloth 128x128");
    g.throughput(Throughput::Elements(springs));
    let mut f = vec![0.0; n];
    g.bench_function("force", |b| {
        b.iter(|| {
            net.force(0.0, black_box(&state.x), black_box(&state.v), &mut f);
            black_box(&f);
        })
    });
    g.bench_function("linearize", |b| {
        b.iter(|| {
            net.linearize(0.0, black_box(&state.x), black_box(&state.v));
        })
    });
    net.linearize(0.0, &state.x, &state.v);
    let mut jac = CsrMatrix::default();
    net.jacobian_assemble(1e-6, 1e-3, &mut jac); // builds the pattern once
    g.bench_function("jacobian assemble (values)", |b| {
        b.iter(|| {
            black_box(net.jacobian_assemble(black_box(1e-6), 1e-3, &mut jac));
        })
    });
    let mut y = vec![0.0; n];
    g.bench_function("jacobian apply", |b| {
        b.iter(|| {
            net.jacobian_apply(1e-6, 1e-3, black_box(&state.v), &mut y);
            black_box(&y);
        })
    });
    g.finish();
}

fn steps(c: &mut Criterion) {
    let (net, start) = cloth();
    let mut g = c.benchmark_group("springs cloth 128x128 step");
    g.sample_size(10);
    for (label, kind, linear, dt) in [
        (
            "symplectic-euler dt 2e-5",
            IntegratorKind::SymplecticEuler,
            LinearSolverKind::Cg,
            scenes::benchmark::DT,
        ),
        (
            "backward-euler linearised jacobi-pcg dt 1e-3",
            IntegratorKind::BackwardEuler,
            LinearSolverKind::JacobiPcg,
            1e-3,
        ),
    ] {
        let mut sys = net.clone();
        let mut integ = kind.build_with::<SpringNetwork>(sys.dof(), animation_newton(), linear);
        let mut state = start.clone();
        g.bench_function(label, |b| {
            b.iter(|| {
                // Restart from the same state so every iteration does the same work.
                state.x.copy_from_slice(&start.x);
                state.v.copy_from_slice(&start.v);
                state.t = start.t;
                integ.reset();
                integ.step(&mut sys, &mut state, dt).ok();
                black_box(&state);
            })
        });
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).warm_up_time(std::time::Duration::from_millis(500)).measurement_time(std::time::Duration::from_secs(3));
    targets = kernels, steps
}
criterion_main!(benches);
