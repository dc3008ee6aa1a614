//! Criterion benches of anim-material: throughput of `pk1` and `dpdf` per model and of the PSD
//! projection `dpdf_psd` (analytic against eigenvalue clamping), in f32 and f64,
//! 2D and 3D, over 1024 pre-generated deformation gradients (`R1 diag(s) R2^T`, `s` in
//! [0.6, 1.6], ChaCha-seeded, all with `det F > 0` so that every model is defined).

use anim_material::nalgebra::{Rotation2, Rotation3, Vector3};
use anim_material::{
    CorotatedLinear, FixedCorotated, Hyperelastic, Lame, LinearElastic, Mat, NeoHookean, Scalar,
    StVenantKirchhoff, StableNeoHookean,
};
use criterion::{
    BenchmarkGroup, Criterion, Throughput, criterion_group, criterion_main, measurement::WallTime,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::hint::black_box;
use std::time::Duration;

const N: usize = 1024;

fn inputs<T: Scalar, const D: usize>() -> Vec<Mat<T, D>> {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    (0..N)
        .map(|_| {
            let mut rot = || -> Mat<f64, D> {
                if D == 2 {
                    let r = Rotation2::new(rng.random_range(-3.0..3.0));
                    Mat::<f64, D>::from_fn(|i, j| r.matrix()[(i, j)])
                } else {
                    let v = Vector3::new(
                        rng.random_range(-1.5..1.5),
                        rng.random_range(-1.5..1.5),
                        rng.random_range(-1.5..1.5),
                    );
                    let r = Rotation3::new(v);
                    Mat::<f64, D>::from_fn(|i, j| r.matrix()[(i, j)])
                }
            };
            let (r1, r2) = (rot(), rot());
            let s = Mat::<f64, D>::from_fn(|i, j| if i == j { 0.6 + (i as f64 + 1.0) * 0.3 } else { 0.0 });
            (r1 * s * r2.transpose()).map(T::of)
        })
        .collect()
}

fn bench_model<T: Scalar, const D: usize, M: Hyperelastic<T, D>>(
    g: &mut BenchmarkGroup<'_, WallTime>,
    name: &str,
    m: &M,
    lame: &Lame<T>,
    fs: &[Mat<T, D>],
    tangent: bool,
) {
    if tangent {
        g.bench_function(name, |b| {
            b.iter(|| {
                for f in fs {
                    black_box(m.dpdf(lame, black_box(f)));
                }
            })
        });
    } else {
        g.bench_function(name, |b| {
            b.iter(|| {
                for f in fs {
                    black_box(m.pk1(lame, black_box(f)));
                }
            })
        });
    }
}

fn run<T: Scalar, const D: usize>(c: &mut Criterion, precision: &str) {
    let fs = inputs::<T, D>();
    let lame = Lame::<T>::from_young_poisson(1e4, 0.3).unwrap_or_else(|e| panic!("lame: {e}"));
    for (quantity, tangent) in [("pk1", false), ("dpdf", true)] {
        let mut g = c.benchmark_group(format!("material {quantity} {precision} {D}D"));
        g.sample_size(10).warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(1));
        g.throughput(Throughput::Elements(N as u64));
        bench_model(&mut g, "linear", &LinearElastic, &lame, &fs, tangent);
        bench_model(&mut g, "stvk", &StVenantKirchhoff, &lame, &fs, tangent);
        bench_model(&mut g, "corotated", &CorotatedLinear, &lame, &fs, tangent);
        bench_model(&mut g, "neo-hookean", &NeoHookean, &lame, &fs, tangent);
        bench_model(&mut g, "fixed-corotated", &FixedCorotated, &lame, &fs, tangent);
        bench_model(&mut g, "stable-neo-hookean", &StableNeoHookean, &lame, &fs, tangent);
        g.finish();
    }
    let mut g = c.benchmark_group(format!("material dpdf_psd {precision} {D}D"));
    g.sample_size(10).warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(1));
    g.throughput(Throughput::Elements(N as u64));
    bench_psd(&mut g, "fixed-corotated (analytic)", &FixedCorotated, &lame, &fs, false);
    bench_psd(&mut g, "stable-neo-hookean (analytic)", &StableNeoHookean, &lame, &fs, false);
    bench_psd(&mut g, "stable-neo-hookean (eigenvalue clamping)", &StableNeoHookean, &lame, &fs, true);
    g.finish();
}

/// `dpdf_psd` of a model, or with `clamp` the generic projection `dpdf(F).project_psd()`.
fn bench_psd<T: Scalar, const D: usize, M: Hyperelastic<T, D>>(
    g: &mut BenchmarkGroup<'_, WallTime>,
    name: &str,
    m: &M,
    lame: &Lame<T>,
    fs: &[Mat<T, D>],
    clamp: bool,
) {
    g.bench_function(name, |b| {
        b.iter(|| {
            for f in fs {
                if clamp {
                    black_box(m.dpdf(lame, black_box(f)).project_psd());
                } else {
                    black_box(m.dpdf_psd(lame, black_box(f)));
                }
            }
        })
    });
}

fn materials(c: &mut Criterion) {
    run::<f64, 3>(c, "f64");
    run::<f32, 3>(c, "f32");
    run::<f64, 2>(c, "f64");
    run::<f32, 2>(c, "f32");
}

criterion_group!(benches, materials);
criterion_main!(benches);
