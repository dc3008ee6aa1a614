//! Criterion benches of anim-core's kernels over pre-generated inputs: the 3x3 SVD (f32 and f64),
//! conjugate gradients on a 2-D Poisson matrix, and one implicit and one explicit integrator step
//! on a 1-D spring chain.

use anim_core::glam::{DMat3, Mat3};
use anim_core::integrate::systems::LinearChain;
use anim_core::integrate::{IntegratorKind, NewtonParams, State};
use anim_core::linalg::{
    Cg, CsrMatrix, IterativeParams, LinearSolver, LinearSolverKind, Preconditioner, SystemMatrix, svd3,
    svd3_f32,
};
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::hint::black_box;

fn svd(c: &mut Criterion) {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let m64: Vec<DMat3> = (0..1024)
        .map(|_| DMat3::from_cols_array(&std::array::from_fn(|_| rng.random_range(-1.0..1.0))))
        .collect();
    let m32: Vec<Mat3> = m64.iter().map(|m| m.as_mat3()).collect();
    let mut g = c.benchmark_group("svd3");
    g.throughput(Throughput::Elements(m64.len() as u64));
    g.bench_function("f64 x1024", |b| {
        b.iter(|| {
            for m in &m64 {
                black_box(svd3(black_box(*m)));
            }
        })
    });
    g.bench_function("f32 x1024", |b| {
        b.iter(|| {
            for m in &m32 {
                black_box(svd3_f32(black_box(*m)));
            }
        })
    });
    g.finish();
}

/// The 5-point Laplacian on an n x n grid with Dirichlet boundaries (SPD).
fn poisson(n: usize) -> CsrMatrix {
    let id = |i: usize, j: usize| i * n + j;
    let mut t = Vec::with_capacity(5 * n * n);
    for i in 0..n {
        for j in 0..n {
            t.push((id(i, j), id(i, j), 4.0));
            if i > 0 {
                t.push((id(i, j), id(i - 1, j), -1.0));
            }
            if i + 1 < n {
                t.push((id(i, j), id(i + 1, j), -1.0));
            }
            if j > 0 {
                t.push((id(i, j), id(i, j - 1), -1.0));
            }
            if j + 1 < n {
                t.push((id(i, j), id(i, j + 1), -1.0));
            }
        }
    }
    CsrMatrix::from_triplets(n * n, n * n, &t)
}

fn cg(c: &mut Criterion) {
    let mut g = c.benchmark_group("cg poisson-2d rtol 1e-8");
    for n in [32usize, 128] {
        let a = poisson(n);
        let b: Vec<f64> = (0..n * n).map(|i| ((i * 7919) % 101) as f64 / 101.0 - 0.5).collect();
        let mut x = vec![0.0; n * n];
        for (label, pre) in [("cg", Preconditioner::Identity), ("jacobi-pcg", Preconditioner::Jacobi)] {
            let mut solver = Cg::new(pre, IterativeParams::new(1e-8, 10_000));
            g.bench_with_input(BenchmarkId::new(label, format!("{n}x{n}")), &n, |bench, _| {
                bench.iter(|| {
                    x.iter_mut().for_each(|v| *v = 0.0);
                    black_box(solver.solve(SystemMatrix::Csr(&a), &b, &mut x)).ok();
                })
            });
        }
    }
    g.finish();
}

fn integrator_step(c: &mut Criterion) {
    let mut g = c.benchmark_group("integrator step, spring chain");
    let n = 10_000;
    let chain = LinearChain::new(n, 0.01, 1e3, 0.01, 9.81).with_damping(0.1);
    let start: State = {
        // Start from a stretched, moving state so every step does real work.
        let mut s = chain.rest_state();
        for (i, v) in s.v.iter_mut().enumerate().skip(1) {
            *v = ((i % 17) as f64 - 8.0) * 1e-3;
        }
        s
    };
    g.throughput(Throughput::Elements(n as u64));
    for (label, kind, linear) in [
        ("velocity-verlet", IntegratorKind::VelocityVerlet, LinearSolverKind::Cg),
        ("backward-euler jacobi-pcg", IntegratorKind::BackwardEuler, LinearSolverKind::JacobiPcg),
        ("backward-euler cholesky", IntegratorKind::BackwardEuler, LinearSolverKind::Cholesky),
    ] {
        let mut sys = chain.clone();
        let mut integ = kind.build_with(n, NewtonParams::default(), linear);
        let mut state = start.clone();
        g.bench_function(BenchmarkId::new(label, n), |b| {
            b.iter(|| {
                integ.step(&mut sys, &mut state, 1e-3).ok();
                black_box(&state);
            })
        });
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).warm_up_time(std::time::Duration::from_millis(500)).measurement_time(std::time::Duration::from_secs(2));
    targets = svd, cg, integrator_step
}
criterion_main!(benches);
