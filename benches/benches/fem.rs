//! Criterion benches of anim-fem on the benchmark beam (`anim_fem::scenes::benchmark_beam(50)`:
//! 19,200 tetrahedra, stable Neo-Hookean, clamped, gravity, dt = 0.01 s): one backward Euler
//! (Newton, sparse Cholesky) step and one symplectic Euler step from a pre-generated sagging
//! state, the elastic force evaluation (Sifakis & Barbič 2012, Algorithm 1) and the stiffness assembly, with
//! throughput in elements per second.

use anim_fem::newton::assemble_stiffness;
use anim_fem::scenes;
use anim_fem::sim::{FemParams, FemSimulation, TimeIntegrator};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;

fn beam(c: &mut Criterion) {
    let scene = scenes::benchmark_beam(50).unwrap_or_else(|e| panic!("benchmark beam: {e}"));
    let dt = scene.dt;
    let elements = scene.model.elements() as u64;
    // A sagging state: 5 implicit steps from rest.
    let mut start = scene.state.clone();
    let mut warm = FemSimulation::new(scene.model.clone(), scene.params).unwrap_or_else(|e| panic!("{e}"));
    for _ in 0..5 {
        warm.advance(&mut start, dt).unwrap_or_else(|e| panic!("warm-up: {e}"));
    }
    let mut g = c.benchmark_group(format!("fem beam {elements} tets"));
    g.sample_size(10);
    g.throughput(Throughput::Elements(elements));
    let mut implicit =
        FemSimulation::new(scene.model.clone(), scene.params).unwrap_or_else(|e| panic!("{e}"));
    g.bench_function("backward euler step (newton, cholesky)", |b| {
        b.iter(|| {
            let mut s = start.clone();
            implicit.advance(black_box(&mut s), dt).unwrap_or_else(|e| panic!("step: {e}"));
            black_box(&s);
        })
    });
    let explicit_params = FemParams::new(TimeIntegrator::SymplecticEuler).with_energy_report(false);
    let mut explicit =
        FemSimulation::new(scene.model.clone(), explicit_params).unwrap_or_else(|e| panic!("{e}"));
    g.bench_function("symplectic euler step", |b| {
        b.iter(|| {
            let mut s = start.clone();
            explicit.advance(black_box(&mut s), 1e-5).unwrap_or_else(|e| panic!("step: {e}"));
            black_box(&s);
        })
    });
    let mut forces = vec![0.0; start.x.len()];
    g.bench_function("elastic forces", |b| {
        b.iter(|| {
            explicit.internal_forces(black_box(&start.x), &mut forces).unwrap_or_else(|e| panic!("{e}"));
            black_box(&forces);
        })
    });
    let model = &scene.model;
    let mut k = model.assembly().matrix();
    let mut buf = vec![0.0; 144 * model.elements()];
    g.bench_function("stiffness assembly (psd-projected)", |b| {
        b.iter(|| {
            assemble_stiffness(model, model.assembly(), black_box(&start.x), true, &mut buf, &mut k);
            black_box(&k);
        })
    });
    g.bench_function("stiffness assembly (unprojected)", |b| {
        b.iter(|| {
            assemble_stiffness(model, model.assembly(), black_box(&start.x), false, &mut buf, &mut k);
            black_box(&k);
        })
    });
    g.finish();
}

criterion_group!(benches, beam);
criterion_main!(benches);
