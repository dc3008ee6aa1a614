//! Conservation of mass, momentum and angular momentum by the transfers (APIC and MLS-MPM,
//! quadratic and cubic, 2D and 3D).

use super::CRATE;
use crate::{Elastic, Kernel, Material, MpmError, MpmParams, MpmSimulation, Particles, Transfer};
use anim_core::cases::{Check, Ctx, Judge};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

pub(super) fn cloud<const D: usize>(n: usize, seed: u64) -> Particles<D> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut p = Particles::<D>::new();
    for _ in 0..n {
        let x: [f32; D] = std::array::from_fn(|_| rng.random_range(0.35f32..0.65));
        let v: [f32; D] = std::array::from_fn(|_| rng.random_range(-1.0f32..1.0));
        let m = rng.random_range(0.5f32..2.0) * 1e-3;
        if p.push(x, v, m, 1e-3, 0).is_err() {
            unreachable!("finite positive input");
        }
    }
    for c in p.c.iter_mut() {
        *c = rng.random_range(-3.0f32..3.0);
    }
    for (i, f) in p.f.iter_mut().enumerate() {
        let diag = (i % (D * D)).is_multiple_of(D + 1);
        *f = if diag { 1.0 } else { 0.0 } + rng.random_range(-0.05f32..0.05);
    }
    p
}

/// Relative errors over `steps` steps: mass, momentum (particles -> grid, grid -> particles,
/// max over steps) and angular momentum likewise.
fn conservation_errors<const D: usize>(
    transfer: Transfer,
    kernel: Kernel,
    steps: usize,
) -> Result<[f64; 3], MpmError> {
    let mut params = MpmParams::with_resolution(32);
    params.transfer = transfer;
    params.kernel = kernel;
    params.gravity = [0.0; 3];
    params.cfl = f64::INFINITY;
    params.wave_cfl = f64::INFINITY;
    let mut sim = MpmSimulation::<D>::new(params, vec![Material::Elastic(Elastic::default())])?;
    let mut p = cloud::<D>(500, 11);
    let mut errs = [0.0f64; 3];
    let norm = |a: [f64; 3]| (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    for _ in 0..steps {
        let before = sim.totals(&p);
        sim.advance(&mut p, 2e-4)?;
        let after = sim.totals(&p);
        let (gm, gp, gl) = sim.grid_totals();
        let (mut sp, mut sl) = (0.0, 0.0);
        for i in 0..p.len() {
            let m = f64::from(p.mass[i]);
            sp += m * f64::from(p.velocity(i).norm());
            sl += m * f64::from(p.velocity(i).norm()) * f64::from(p.position(i).norm());
        }
        errs[0] = errs[0].max(((after.mass - before.mass).abs() + (gm - before.mass).abs()) / before.mass);
        errs[1] = errs[1].max(norm(sub(gp, before.momentum)).max(norm(sub(after.momentum, gp))) / sp);
        errs[2] = errs[2]
            .max(norm(sub(gl, before.angular_momentum)).max(norm(sub(after.angular_momentum, gl))) / sl);
    }
    Ok(errs)
}

pub(super) fn conservation(ctx: &Ctx) -> Vec<Check> {
    let steps = if ctx.quick { 5 } else { 50 };
    let mut checks = vec![];
    // f32 particles: a small multiple of eps_f32 = 1.19e-7.
    let tol = 2e-6;
    for transfer in [Transfer::Apic, Transfer::Mls] {
        for kernel in [Kernel::Quadratic, Kernel::Cubic] {
            for dim in [2, 3] {
                let errs = if dim == 2 {
                    conservation_errors::<2>(transfer, kernel, steps)
                } else {
                    conservation_errors::<3>(transfer, kernel, steps)
                };
                let errs = errs.unwrap_or([f64::NAN; 3]);
                for (metric, e) in ["mass", "linear momentum", "angular momentum"].iter().zip(errs) {
                    checks.push(Check {
                        crate_name: CRATE,
                        case: format!("{transfer:?} {kernel:?} {dim}D, elastic cloud, {steps} steps"),
                        metric: format!("max relative {metric} error P2G and G2P"),
                        measured: e,
                        reference: 0.0,
                        tolerance: tol,
                        judge: Judge::AtMost,
                        source: "exact conservation of the transfers (Jiang et al. 2015; Hu et al. 2018), f32 round-off",
                    });
                }
            }
        }
    }
    checks
}
