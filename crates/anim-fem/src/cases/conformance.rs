//! Every material model's stress and tangent against finite differences of its energy (random F
//! with rotations, reflections and det F near 0), rotation invariance, the patch test and momentum
//! conservation of the internal forces.

use super::CRATE;
use crate::generate::box_mesh;
use crate::material::{Material, MaterialModel};
use crate::model::FemModel;
use crate::sim::{FemParams, FemSimulation};
use anim_core::cases::{Check, Ctx, Judge, nan_max};
use anim_material::nalgebra::{Matrix3, Rotation3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A check that could not run: measured NaN (a failure), the error in the metric.
fn failed(case: String, why: &str) -> Check {
    Check::could_not_run(CRATE, case, why)
}

fn random_rotation(rng: &mut ChaCha8Rng) -> Matrix3<f64> {
    let axis =
        Vector3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
    let angle = rng.random_range(-3.0..3.0);
    Rotation3::from_scaled_axis(axis.normalize() * angle).into_inner()
}

/// Random deformation gradients: `U diag(s) V^T` with stretches in [0.5, 1.6], some with a
/// singular value near 0 (det F ~ 1e-3) and some pure rotations.
fn random_f(rng: &mut ChaCha8Rng, k: usize) -> Matrix3<f64> {
    let u = random_rotation(rng);
    let v = random_rotation(rng);
    let mut s =
        Vector3::new(rng.random_range(0.5..1.6), rng.random_range(0.5..1.6), rng.random_range(0.5..1.6));
    match k % 4 {
        1 => s[2] = 1e-3 * rng.random_range(1.0..2.0),
        2 => s = Vector3::new(1.0, 1.0, 1.0),
        _ => {}
    }
    u * Matrix3::from_diagonal(&s) * v.transpose()
}

pub(super) fn material_derivatives(ctx: &Ctx) -> Vec<Check> {
    let samples = if ctx.quick { 40 } else { 200 };
    let lame = match anim_material::Lame::from_young_poisson(1.0, 0.3) {
        Ok(l) => l,
        Err(e) => {
            return vec![failed(
                format!("material derivatives, {samples} random F"),
                &format!("Lame parameters: {e}"),
            )];
        }
    };
    let mut checks = Vec::new();
    for model in MaterialModel::ALL {
        let mut rng = ChaCha8Rng::seed_from_u64(42);
        let (mut err_p, mut err_c, mut err_rot) = (0.0f64, 0.0f64, 0.0f64);
        for k in 0..samples {
            let f = random_f(&mut rng, k);
            // Step relative to the smallest singular value, so det F near 0 stays resolved.
            let h = 1e-6 * f.norm().min(1.0) * if k % 4 == 1 { 1e-3 } else { 1.0 };
            let p = model.pk1(&lame, &f);
            let c = model.dpdf(&lame, &f);
            let (mut num_p, mut num_c) = (0.0f64, 0.0f64);
            // Relative to the stress, or to the shear modulus where the stress vanishes (F = R).
            let scale_p = p.norm().max(lame.mu);
            let scale_c = c.to_matrix().norm().max(lame.mu);
            for kk in 0..3 {
                for l in 0..3 {
                    let mut fp = f;
                    fp[(kk, l)] += h;
                    let mut fm = f;
                    fm[(kk, l)] -= h;
                    let dpsi = (model.energy(&lame, &fp) - model.energy(&lame, &fm)) / (2.0 * h);
                    num_p = nan_max(num_p, (dpsi - p[(kk, l)]).abs());
                    let dp = (model.pk1(&lame, &fp) - model.pk1(&lame, &fm)) / (2.0 * h);
                    num_c = (dp - c.d[kk][l]).iter().fold(num_c, |m, x| nan_max(m, x.abs()));
                }
            }
            err_p = nan_max(err_p, num_p / scale_p);
            err_c = nan_max(err_c, num_c / scale_c);
            if model != MaterialModel::Linear {
                let r = random_rotation(&mut rng);
                let e0 = model.energy(&lame, &f);
                let e1 = model.energy(&lame, &(r * f));
                err_rot = nan_max(err_rot, (e1 - e0).abs() / e0.abs().max(1.0));
            }
        }
        let name = model.name();
        checks.push(Check {
            crate_name: CRATE,
            case: format!("{name}: {samples} random F (rotations, det F ~ 1e-3, pure rotations)"),
            metric: "max |P - dpsi/dF (central FD)| / max(|P|, mu)".into(),
            measured: err_p,
            reference: 0.0,
            tolerance: 1e-6,
            judge: Judge::AtMost,
            source: "central differences of psi",
        });
        checks.push(Check {
            crate_name: CRATE,
            case: format!("{name}: {samples} random F"),
            metric: "max |dP/dF - dP/dF (central FD of P)| / max(|dP/dF|, mu)".into(),
            measured: err_c,
            reference: 0.0,
            tolerance: 1e-6,
            judge: Judge::AtMost,
            source: "central differences of P",
        });
        if model != MaterialModel::Linear {
            checks.push(Check {
                crate_name: CRATE,
                case: format!("{name}: psi(R F) = psi(F)"),
                metric: "max relative change of psi under a random rotation".into(),
                measured: err_rot,
                reference: 0.0,
                tolerance: 1e-12,
                judge: Judge::AtMost,
                source: "frame indifference",
            });
        }
    }
    checks
}

// ---------------------------------------------------------------------------------------------
// Patch test, momentum.

pub(super) fn patch_and_momentum(_ctx: &Ctx) -> Vec<Check> {
    let mut checks = Vec::new();
    let mesh = match box_mesh([0.0; 3], [1.0; 3], [4, 4, 4]) {
        Ok(m) => m,
        Err(e) => return vec![failed("patch test and momentum, 4x4x4 patch".into(), &format!("mesh: {e}"))],
    };
    let interior = |p: [f64; 3]| p.iter().all(|&c| c > 1e-9 && c < 1.0 - 1e-9);
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let mut distorted = mesh.clone();
    for p in distorted.positions.iter_mut() {
        if interior(*p) {
            for c in p.iter_mut() {
                *c += 0.06 * rng.random_range(-1.0..1.0);
            }
        }
    }
    let a = [[1.1, 0.05, -0.02], [0.03, 0.92, 0.06], [-0.04, 0.02, 1.05]];
    let affine =
        |p: [f64; 3]| [0, 1, 2].map(|i| a[i][0] * p[0] + a[i][1] * p[1] + a[i][2] * p[2] + 0.1 * i as f64);
    for model in MaterialModel::ALL {
        let patch_case =
            format!("{}: patch test, distorted 4x4x4 patch, u = A X + b on the boundary", model.name());
        let free_case = format!("{}: internal forces of a randomly deformed free body", model.name());
        // A setup failure fails the checks it prevents, with the reason, instead of dropping them.
        let material = match Material::new(model, 1e6, 0.3, 1000.0) {
            Ok(m) => m,
            Err(e) => {
                checks.push(failed(patch_case, &format!("material: {e}")));
                checks.push(failed(free_case, &format!("material: {e}")));
                continue;
            }
        };
        let mut m = match FemModel::new(distorted.clone(), material) {
            Ok(m) => m,
            Err(e) => {
                checks.push(failed(patch_case, &format!("model: {e}")));
                checks.push(failed(free_case, &format!("model: {e}")));
                continue;
            }
        };
        let boundary = m.vertices_where(|p| !interior(p));
        let pinned = m.pin_vertices(&boundary).map_err(|e| format!("pinning the boundary: {e}"));
        let mut x = Vec::new();
        for v in 0..m.vertices() {
            x.extend_from_slice(&affine(m.mesh().positions[v]));
        }
        let mut start = x.clone();
        for v in 0..m.vertices() {
            if interior(m.mesh().positions[v]) {
                for c in 0..3 {
                    start[3 * v + c] += 0.01 * rng.random_range(-1.0..1.0);
                }
            }
        }
        let sim = pinned.and_then(|()| {
            FemSimulation::new(m, FemParams::default().with_newton_tolerance(1e-15))
                .map_err(|e| format!("simulation: {e}"))
        });
        match sim {
            Ok(mut sim) => {
                let err = match sim.solve_static(&mut start, 1) {
                    Ok(_) => start.iter().zip(&x).fold(0.0f64, |e, (a, b)| nan_max(e, (a - b).abs())),
                    Err(_) => f64::NAN,
                };
                checks.push(Check {
                    crate_name: CRATE,
                    case: patch_case,
                    metric: "max |x - (A X + b)| over all vertices (unit cube)".into(),
                    measured: err,
                    reference: 0.0,
                    tolerance: 1e-10,
                    judge: Judge::AtMost,
                    source: "Irons patch test",
                });
            }
            Err(e) => checks.push(failed(patch_case, &e)),
        }
        // Momentum: internal forces of a randomly deformed free body.
        let free = FemModel::new(distorted.clone(), material).map_err(|e| format!("model: {e}"));
        let mut sim = match free.and_then(|free| {
            FemSimulation::new(free, FemParams::default()).map_err(|e| format!("simulation: {e}"))
        }) {
            Ok(sim) => sim,
            Err(e) => {
                checks.push(failed(free_case, &e));
                continue;
            }
        };
        let y: Vec<f64> = x.iter().map(|v| v + 0.05 * rng.random_range(-1.0..1.0)).collect();
        let mut f = vec![0.0; y.len()];
        if let Err(e) = sim.internal_forces(&y, &mut f) {
            checks.push(failed(free_case, &format!("internal forces: {e}")));
            continue;
        }
        let scale: f64 = f.iter().map(|v| v.abs()).sum();
        let (mut sum, mut torque) = ([0.0f64; 3], [0.0f64; 3]);
        for i in 0..y.len() / 3 {
            let (p, q) = (&y[3 * i..3 * i + 3], &f[3 * i..3 * i + 3]);
            for c in 0..3 {
                sum[c] += q[c];
            }
            torque[0] += p[1] * q[2] - p[2] * q[1];
            torque[1] += p[2] * q[0] - p[0] * q[2];
            torque[2] += p[0] * q[1] - p[1] * q[0];
        }
        let norm = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        checks.push(Check {
            crate_name: CRATE,
            case: free_case.clone(),
            metric: "|sum f| / sum |f|".into(),
            measured: norm(sum) / scale,
            reference: 0.0,
            tolerance: 1e-14,
            judge: Judge::AtMost,
            source: "translation invariance (f4 = -(f1 + f2 + f3))",
        });
        if model != MaterialModel::Linear {
            checks.push(Check {
                crate_name: CRATE,
                case: free_case,
                metric: "|sum x x f| / sum |f|".into(),
                measured: norm(torque) / scale,
                reference: 0.0,
                tolerance: 1e-14,
                judge: Judge::AtMost,
                source: "rotation invariance of psi",
            });
        }
    }
    checks
}
