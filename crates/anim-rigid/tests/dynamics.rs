//! Dynamics cross-checks that need no reference data: each algorithm against another one or
//! against finite differences, on fixed- and floating-base trees with every joint type.
//!
//! - ABA inverts RNEA: `ABA(q, v, RNEA(q, v, a)) = a`;
//! - CRBA columns are RNEA differences: `H e_k = RNEA(q, 0, e_k) - g(q)`;
//! - `H q̈ + C = τ` closes for `q̈ = ABA(q, v, τ)`, and the Cholesky forward dynamics agrees;
//! - `H` is symmetric positive definite and `½ vᵀ H v` is the kinetic energy;
//! - `g(q)` is the gradient of the potential energy (finite differences on the manifold);
//! - power balance `dE/dt = τ·v` along the motion, and conservation of the spatial momentum of a
//!   floating tree without gravity;
//! - a reused `Data` gives bit-identical results.

#![allow(clippy::unwrap_used, clippy::expect_used)] // integration tests: a failed unwrap is a failed test

mod common;

use anim_core::glam::DVec3;
use anim_rigid::config::{integrate, random_configuration};
use anim_rigid::{
    Data, Model, aba, crba, crba_local, crba_world, factor_mass_matrix, forward_dynamics_cholesky,
    gravity_torques, kinetic_energy, nonlinear_effects, potential_energy, rnea, spatial_momentum,
};
use common::{chain32, mixed_massive, panda, panda_floating, ur5};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn models() -> Vec<Model> {
    vec![panda(), ur5(), panda_floating(), mixed_massive(), chain32()]
}

fn random_vec(rng: &mut ChaCha8Rng, n: usize, scale: f64) -> Vec<f64> {
    (0..n).map(|_| rng.random_range(-scale..scale)).collect()
}

fn max_abs(x: &[f64]) -> f64 {
    x.iter().fold(0.0_f64, |m, v| m.max(v.abs()))
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()))
}

#[test]
fn aba_inverts_rnea() {
    let mut rng = ChaCha8Rng::seed_from_u64(71);
    for model in models() {
        let mut data = Data::new(&model);
        let mut worst = 0.0_f64;
        for _ in 0..50 {
            let q = random_configuration(&model, &mut || rng.random::<f64>());
            let v = random_vec(&mut rng, model.nv(), 2.0);
            let a = random_vec(&mut rng, model.nv(), 3.0);
            let tau = rnea(&model, &mut data, &q, &v, &a).to_vec();
            let back = aba(&model, &mut data, &q, &v, &tau);
            worst = worst.max(max_diff(back, &a) / max_abs(&a));
        }
        eprintln!("{}: ABA(RNEA(a)) - a: {worst:.2e}", model.name());
        assert!(worst < 1e-10, "{}: ABA does not invert RNEA: {worst:e}", model.name());
    }
}

#[test]
fn crba_columns_are_rnea_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(72);
    for model in models() {
        let mut data = Data::new(&model);
        let nv = model.nv();
        let zero = vec![0.0; nv];
        let mut worst = 0.0_f64;
        for _ in 0..20 {
            let q = random_configuration(&model, &mut || rng.random::<f64>());
            let h = crba(&model, &mut data, &q).clone();
            let g = gravity_torques(&model, &mut data, &q).to_vec();
            for k in 0..nv {
                let mut e = zero.clone();
                e[k] = 1.0;
                let col = rnea(&model, &mut data, &q, &zero, &e).to_vec();
                for i in 0..nv {
                    worst = worst.max((h[(i, k)] - (col[i] - g[i])).abs() / h.max_abs());
                }
            }
            assert_eq!(h.asymmetry(), 0.0);
        }
        eprintln!("{}: H e_k vs RNEA(q, 0, e_k) - g: {worst:.2e}", model.name());
        assert!(worst < 1e-13, "{}: {worst:e}", model.name());
    }
}

#[test]
fn crba_local_and_world_forms_agree() {
    let mut rng = ChaCha8Rng::seed_from_u64(79);
    for model in models() {
        let mut data = Data::new(&model);
        let mut worst = 0.0_f64;
        for _ in 0..20 {
            let q = random_configuration(&model, &mut || rng.random::<f64>());
            let local = crba_local(&model, &mut data, &q).clone();
            let world = crba_world(&model, &mut data, &q).clone();
            let diff =
                local.as_slice().iter().zip(world.as_slice()).fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
            worst = worst.max(diff / world.max_abs());
            assert_eq!(local.asymmetry(), 0.0);
        }
        eprintln!("{}: crba_local vs crba_world {worst:.2e}", model.name());
        assert!(worst < 1e-14, "{}: {worst:e}", model.name());
    }
}

#[test]
fn equation_of_motion_closes_and_cholesky_agrees() {
    let mut rng = ChaCha8Rng::seed_from_u64(73);
    for model in models() {
        let mut data = Data::new(&model);
        let nv = model.nv();
        let (mut closure, mut chol, mut min_pivot) = (0.0_f64, 0.0_f64, f64::INFINITY);
        for _ in 0..50 {
            let q = random_configuration(&model, &mut || rng.random::<f64>());
            let v = random_vec(&mut rng, nv, 2.0);
            let tau = random_vec(&mut rng, nv, 10.0);
            let qdd = aba(&model, &mut data, &q, &v, &tau).to_vec();
            let h = crba(&model, &mut data, &q).clone();
            let c = nonlinear_effects(&model, &mut data, &q, &v).to_vec();
            let mut hq = vec![0.0; nv];
            h.mul_vec(&qdd, &mut hq);
            let residual: Vec<f64> = (0..nv).map(|i| hq[i] + c[i] - tau[i]).collect();
            let scale = max_abs(&tau).max(max_abs(&c)).max(max_abs(&hq));
            closure = closure.max(max_abs(&residual) / scale);
            let by_cholesky = forward_dynamics_cholesky(&model, &mut data, &q, &v, &tau).unwrap().to_vec();
            chol = chol.max(max_diff(&by_cholesky, &qdd) / max_abs(&qdd));
            factor_mass_matrix(&model, &mut data).unwrap();
            for k in 0..nv {
                min_pivot = min_pivot.min(data.mass_matrix_factor[(k, k)] / h.max_abs());
            }
        }
        eprintln!(
            "{}: |H q'' + C - tau| {closure:.2e}, Cholesky vs ABA {chol:.2e}, min pivot / max|H| {min_pivot:.2e}",
            model.name()
        );
        assert!(closure < 1e-10, "{}: closure {closure:e}", model.name());
        assert!(chol < 1e-9, "{}: Cholesky vs ABA {chol:e}", model.name());
        assert!(min_pivot > 0.0);
    }
}

#[test]
fn kinetic_energy_is_the_mass_matrix_quadratic_form() {
    let mut rng = ChaCha8Rng::seed_from_u64(74);
    for model in models() {
        let mut data = Data::new(&model);
        for _ in 0..20 {
            let q = random_configuration(&model, &mut || rng.random::<f64>());
            let v = random_vec(&mut rng, model.nv(), 2.0);
            let h = crba(&model, &mut data, &q).clone();
            let mut hv = vec![0.0; model.nv()];
            h.mul_vec(&v, &mut hv);
            let quad: f64 = 0.5 * hv.iter().zip(&v).map(|(a, b)| a * b).sum::<f64>();
            let t = kinetic_energy(&model, &mut data, &q, &v);
            assert!((t - quad).abs() < 1e-13 * quad.max(1.0), "{}: {t} vs {quad}", model.name());
        }
    }
}

#[test]
fn gravity_term_is_the_potential_gradient() {
    let mut rng = ChaCha8Rng::seed_from_u64(75);
    let eps = 1e-6;
    for model in models() {
        let mut data = Data::new(&model);
        let nv = model.nv();
        let mut worst = 0.0_f64;
        for _ in 0..10 {
            let q = random_configuration(&model, &mut || rng.random::<f64>());
            let g = gravity_torques(&model, &mut data, &q).to_vec();
            for k in 0..nv {
                let mut dv = vec![0.0; nv];
                dv[k] = eps;
                let plus = potential_energy(&model, &mut data, &integrate(&model, &q, &dv, 1.0));
                let minus = potential_energy(&model, &mut data, &integrate(&model, &q, &dv, -1.0));
                worst = worst.max(((plus - minus) / (2.0 * eps) - g[k]).abs() / max_abs(&g).max(1.0));
            }
        }
        eprintln!("{}: g(q) vs dV/dq: {worst:.2e}", model.name());
        assert!(worst < 1e-7, "{}: {worst:e}", model.name());
    }
}

/// The state at `t + s` of the motion through `(q, v)` with acceleration `a`, to `O(s³)`.
fn advance(model: &Model, q: &[f64], v: &[f64], a: &[f64], s: f64) -> (Vec<f64>, Vec<f64>) {
    let dq: Vec<f64> = v.iter().zip(a).map(|(vi, ai)| s * vi + 0.5 * s * s * ai).collect();
    let v1: Vec<f64> = v.iter().zip(a).map(|(vi, ai)| vi + s * ai).collect();
    (integrate(model, q, &dq, 1.0), v1)
}

#[test]
fn power_balance_along_the_motion() {
    // dE/dt = τ·v for E = T + V and v̇ = ABA(q, v, τ).
    let mut rng = ChaCha8Rng::seed_from_u64(76);
    let s = 2e-4;
    for model in models() {
        let mut data = Data::new(&model);
        let mut worst = 0.0_f64;
        for _ in 0..10 {
            let q = random_configuration(&model, &mut || rng.random::<f64>());
            let v = random_vec(&mut rng, model.nv(), 1.0);
            let tau = random_vec(&mut rng, model.nv(), 5.0);
            let a = aba(&model, &mut data, &q, &v, &tau).to_vec();
            let mut energy = |(q, v): (Vec<f64>, Vec<f64>)| {
                kinetic_energy(&model, &mut data, &q, &v) + potential_energy(&model, &mut data, &q)
            };
            let mut central = |s: f64| {
                (energy(advance(&model, &q, &v, &a, s)) - energy(advance(&model, &q, &v, &a, -s))) / (2.0 * s)
            };
            // Richardson: the central difference is f'(0) + f'''(0) s²/6 + O(s⁴).
            let rate = (4.0 * central(0.5 * s) - central(s)) / 3.0;
            let power: f64 = tau.iter().zip(&v).map(|(t, w)| t * w).sum();
            worst = worst.max((rate - power).abs() / power.abs().max(1.0));
        }
        eprintln!("{}: dE/dt vs tau.v: {worst:.2e}", model.name());
        assert!(worst < 1e-6, "{}: {worst:e}", model.name());
    }
}

#[test]
fn floating_tree_conserves_spatial_momentum_without_gravity() {
    let mut rng = ChaCha8Rng::seed_from_u64(77);
    let s = 2e-4;
    for mut model in [panda_floating(), mixed_massive()] {
        model.set_gravity(DVec3::ZERO);
        let mut data = Data::new(&model);
        let mut worst = 0.0_f64;
        for _ in 0..10 {
            let q = random_configuration(&model, &mut || rng.random::<f64>());
            let v = random_vec(&mut rng, model.nv(), 1.0);
            // Internal joint torques, none on the free base: momentum is still conserved.
            let mut tau = random_vec(&mut rng, model.nv(), 5.0);
            tau[..6].fill(0.0);
            let a = aba(&model, &mut data, &q, &v, &tau).to_vec();
            let mut central = |s: f64| {
                let (qp, vp) = advance(&model, &q, &v, &a, s);
                let (qm, vm) = advance(&model, &q, &v, &a, -s);
                let hp = spatial_momentum(&model, &mut data, &qp, &vp);
                let hm = spatial_momentum(&model, &mut data, &qm, &vm);
                (hp - hm).scale(0.5 / s)
            };
            // Richardson extrapolation of the central difference (error O(s⁴)).
            let rate = (central(0.5 * s) * 4.0 - central(s)) * (1.0 / 3.0);
            let h0 = spatial_momentum(&model, &mut data, &q, &v);
            let scale = h0.linear.length().max(h0.angular.length()).max(1.0);
            worst = worst.max(rate.linear.length().max(rate.angular.length()) / scale);
        }
        eprintln!("{}: |dh/dt| / |h| without gravity: {worst:.2e}", model.name());
        assert!(worst < 1e-6, "{}: {worst:e}", model.name());
    }
}

#[test]
fn reused_data_gives_identical_results() {
    let mut rng = ChaCha8Rng::seed_from_u64(78);
    for model in models() {
        let q = random_configuration(&model, &mut || rng.random::<f64>());
        let q2 = random_configuration(&model, &mut || rng.random::<f64>());
        let v = random_vec(&mut rng, model.nv(), 2.0);
        let tau = random_vec(&mut rng, model.nv(), 5.0);
        let mut fresh = Data::new(&model);
        let first = (aba(&model, &mut fresh, &q, &v, &tau).to_vec(), crba(&model, &mut fresh, &q).clone());
        let mut reused = Data::new(&model);
        let _ = crba(&model, &mut reused, &q2);
        let _ = aba(&model, &mut reused, &q2, &tau, &v);
        let _ = rnea(&model, &mut reused, &q2, &v, &tau);
        let again = (aba(&model, &mut reused, &q, &v, &tau).to_vec(), crba(&model, &mut reused, &q).clone());
        assert_eq!(first, again, "{}", model.name());
    }
}

#[test]
fn rnea_of_a_pendulum_matches_the_closed_form() {
    // One revolute joint about y with a point mass m at distance l along +x:
    // τ = m l² q̈ + m g l cos q (gravity -z), from Lagrange's equation.
    let urdf = r#"<robot name="p"><link name="base"/>
      <link name="rod"><inertial><origin xyz="0.7 0 0"/><mass value="2"/>
        <inertia ixx="0" iyy="0" izz="0" ixy="0" ixz="0" iyz="0"/></inertial></link>
      <joint name="hinge" type="continuous"><parent link="base"/><child link="rod"/>
        <axis xyz="0 1 0"/></joint></robot>"#;
    let model = anim_rigid::parse_urdf(urdf, &anim_rigid::UrdfOptions::default()).unwrap();
    let mut data = Data::new(&model);
    let (m, l, g) = (2.0, 0.7, 9.81);
    for (q, v, a) in [(0.3, 1.2, -0.4), (-1.1, -0.5, 2.0), (2.5, 3.0, 0.0)] {
        let tau = rnea(&model, &mut data, &[q], &[v], &[a])[0];
        // Rotation about +y by q moves +x towards -z: height z = -l sin q, V = -m g l sin q.
        let expected = m * l * l * a - m * g * l * f64::cos(q);
        assert!((tau - expected).abs() < 1e-13, "{tau} vs {expected}");
        let qdd = aba(&model, &mut data, &[q], &[v], &[tau])[0];
        assert!((qdd - a).abs() < 1e-13);
    }
}
