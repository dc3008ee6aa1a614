//! Criterion benches of anim-fluid: one step of Stam's solver (N = 128), one MAC step of the cavity (2D)
//! and of the smoke plume (3D), and one pressure solve per solver, from zero, on the 2D box with a
//! sphere (N = 128) to a relative residual of 1e-5.

use anim_fluid::mac::{MacFluid, MacParams};
use anim_fluid::pressure::{PressureMethod, PressureSolver};
use anim_fluid::scenes;
use anim_fluid::stam::{StamFluid, StamParams};
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;

fn stam_step(c: &mut Criterion) {
    let Ok(mut f) = StamFluid::new(128, StamParams::default()) else { return };
    for _ in 0..20 {
        f.apply_source_pattern();
        let _ = f.step();
    }
    c.bench_function("fluid/stam_step/N128", |b| {
        b.iter(|| {
            f.apply_source_pattern();
            black_box(f.step()).ok();
        });
    });
}

fn mac_steps(c: &mut Criterion) {
    let mut group = c.benchmark_group("fluid/mac_step");
    group.sample_size(10);
    for (name, res) in [("lid-driven-cavity", 64), ("smoke-plume-3d", 24)] {
        let Some(Ok(mut scene)) = scenes::by_name(name, Some(res)) else { continue };
        for _ in 0..5 {
            let _ = scene.step();
        }
        group.bench_function(format!("{name}/N{res}"), |b| b.iter(|| black_box(scene.step()).ok()));
    }
    group.finish();
}

fn projection(c: &mut Criterion) {
    let mut group = c.benchmark_group("fluid/pressure_solve_N128_tol1e-5");
    group.sample_size(10);
    let n = 128;
    let Ok((mut f, mut s)) = MacFluid::new([n, n, 1], 2, 1.0 / n as f64, MacParams::default()) else {
        return;
    };
    if f.set_solid(|p| (p[0] - 0.6).powi(2) + (p[1] - 0.45).powi(2) < 0.04).is_err() {
        return;
    }
    f.set_velocity(&mut s, |p| [(3.0 * p[1]).sin() + 1.0, (2.0 * p[0]).cos() * p[1], 0.0]);
    let mut rhs = vec![0.0; n * n];
    f.net_outflow(&s, &mut rhs);
    rhs.iter_mut().for_each(|x| *x = -*x);
    for method in PressureMethod::ALL {
        let Ok(mut solver) = PressureSolver::new(f.pressure_operator().clone(), method, 1e-5, 1_000_000)
        else {
            continue;
        };
        let mut x = vec![0.0; n * n];
        // Cold start every time: the solve from zero, as in the first step of a simulation.
        group.bench_function(method.name(), |b| {
            b.iter(|| {
                x.fill(0.0);
                black_box(solver.solve(&rhs, &mut x));
            });
        });
    }
    group.finish();
}

criterion_group!(benches, stam_step, mac_steps, projection);
criterion_main!(benches);
