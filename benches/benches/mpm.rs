//! Criterion benches of anim-mpm on the peer-benchmark fluid scenes
//! (`anim_mpm::scenes::benchmark_2d` / `benchmark_3d`, Taichi's `mpm88` / `mpm3d`): one step from
//! a pre-generated state (100 steps after release) for MLS-MPM and APIC with the quadratic and
//! cubic kernels; throughput in particles.

use anim_mpm::{Kernel, MpmSimulation, Transfer, scenes};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;

fn bench_scene<const D: usize>(c: &mut Criterion, label: &str, scene: scenes::Scene<D>) {
    let dt = scene.dt;
    let mut start = scene.state.clone();
    let mut warm = scene.sim.clone();
    for _ in 0..100 {
        warm.advance(&mut start, dt).unwrap_or_else(|e| panic!("warm-up: {e}"));
    }
    let mut g = c.benchmark_group(format!("mpm {label} step"));
    g.sample_size(10);
    g.throughput(Throughput::Elements(start.len() as u64));
    for (transfer, kernel) in [
        (Transfer::Mls, Kernel::Quadratic),
        (Transfer::Apic, Kernel::Quadratic),
        (Transfer::Mls, Kernel::Cubic),
        (Transfer::Apic, Kernel::Cubic),
    ] {
        let mut params = scene.sim.params().clone();
        params.transfer = transfer;
        params.kernel = kernel;
        let mut sim = MpmSimulation::<D>::new(params, scene.sim.materials().to_vec())
            .unwrap_or_else(|e| panic!("params: {e}"));
        let mut state = start.clone();
        sim.advance(&mut state, dt).unwrap_or_else(|e| panic!("step: {e}"));
        g.bench_function(format!("{transfer:?} {kernel:?}"), |b| {
            b.iter(|| {
                sim.advance(black_box(&mut state), dt).unwrap_or_else(|e| panic!("step: {e}"));
            })
        });
    }
    g.finish();
}

fn steps(c: &mut Criterion) {
    bench_scene(
        c,
        "2D fluid 8192 particles 128^2",
        scenes::benchmark_2d(128).unwrap_or_else(|e| panic!("{e}")),
    );
    bench_scene(
        c,
        "3D fluid 8192 particles 32^3",
        scenes::benchmark_3d(32).unwrap_or_else(|e| panic!("{e}")),
    );
}

criterion_group!(benches, steps);
criterion_main!(benches);
