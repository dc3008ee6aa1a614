//! Dynamics conformance: the algorithms against Pinocchio and against each other, the steppers'
//! orders, the T-handle's flip period and the energy balance.

use crate::config::random_configuration;
use crate::scenes::{self, euler_top_period, pendulum_chain_model, t_handle_model};
use crate::sim::{RigidIntegrator, RigidSimulation, RigidState, SimParams};
use crate::{
    Axis, Data, Inertia, JointLimits, JointType, Model, ModelBuilder, UrdfOptions, aba, crba, crba_local,
    crba_world, factor_mass_matrix, forward_dynamics_cholesky, gravity_torques, kinetic_energy, load_urdf,
    nonlinear_effects, potential_energy, rnea,
};
use anim_core::cases::{Check, Ctx, Judge, nan_max};
use anim_core::glam::{DMat3, DVec3};
use anim_core::lie::Se3;
use anim_core::solver::Solver;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde_json::Value;

use crate::cases::{check, failed, floats, testdata};

const PINOCCHIO_DYN: &str =
    "Pinocchio 4.1.0 via crates/anim-rigid/testdata/make_pinocchio_dynamics_reference.py";
const CROSS: &str = "a second algorithm on the same model (Featherstone ch. 5-7)";

fn load_dynamics_reference(name: &str) -> Result<(Model, Value), String> {
    let text = std::fs::read_to_string(testdata(&format!("pinocchio_dynamics_{name}.json")))
        .map_err(|e| format!("pinocchio_dynamics_{name}.json: {e}"))?;
    let json: Value = serde_json::from_str(&text).map_err(|e| e.to_string())?;
    let mut options = UrdfOptions::default().floating_base(json["floating_base"].as_bool().unwrap_or(false));
    for n in json["locked_joints"].as_array().into_iter().flatten() {
        options = options.lock_joint(n.as_str().unwrap_or(""), 0.0);
    }
    let urdf = json["urdf"].as_str().ok_or("no urdf in the JSON")?;
    let model = load_urdf(testdata(urdf), &options).map_err(|e| e.to_string())?;
    if model.nq() as u64 != json["nq"].as_u64().unwrap_or(0)
        || model.nv() as u64 != json["nv"].as_u64().unwrap_or(0)
    {
        return Err(format!("{name}: our model has other sizes than Pinocchio's"));
    }
    Ok((model, json))
}

/// `‖ours - reference‖∞ / ‖reference‖∞` (NaN on a length mismatch or a NaN entry).
fn rel_err(ours: &[f64], reference: &[f64]) -> f64 {
    if ours.len() != reference.len() {
        return f64::NAN;
    }
    let scale = reference.iter().fold(0.0_f64, |m, x| nan_max(m, x.abs())).max(f64::MIN_POSITIVE);
    ours.iter().zip(reference).fold(0.0_f64, |m, (a, b)| nan_max(m, (a - b).abs())) / scale
}

pub(super) fn pinocchio_dynamics(_: &Ctx) -> Vec<Check> {
    let mut out = Vec::new();
    'robots: for name in ["panda", "ur5", "chain32", "panda_floating"] {
        let case = format!("{name} dynamics vs Pinocchio");
        let (model, json) = match load_dynamics_reference(name) {
            Ok(x) => x,
            Err(e) => {
                out.extend(failed(&case, &e));
                continue;
            }
        };
        let mut data = Data::new(&model);
        let mut e = [0.0_f64; 6];
        let samples = json["samples"].as_array().map(Vec::as_slice).unwrap_or(&[]);
        for s in samples {
            let (q, v, a, tau) = (floats(&s["q"]), floats(&s["v"]), floats(&s["a"]), floats(&s["tau"]));
            if q.len() != model.nq()
                || v.len() != model.nv()
                || a.len() != model.nv()
                || tau.len() != model.nv()
            {
                out.extend(failed(&case, "sample sizes differ from the model"));
                continue 'robots;
            }
            e[0] = nan_max(e[0], rel_err(rnea(&model, &mut data, &q, &v, &a), &floats(&s["rnea"])));
            e[1] = nan_max(e[1], rel_err(crba(&model, &mut data, &q).as_slice(), &floats(&s["crba"])));
            e[2] = nan_max(e[2], rel_err(nonlinear_effects(&model, &mut data, &q, &v), &floats(&s["nle"])));
            e[3] = nan_max(e[3], rel_err(gravity_torques(&model, &mut data, &q), &floats(&s["gravity"])));
            e[4] = nan_max(e[4], rel_err(aba(&model, &mut data, &q, &v, &tau), &floats(&s["aba"])));
            let ke = kinetic_energy(&model, &mut data, &q, &v);
            let pe = potential_energy(&model, &mut data, &q);
            let rke = s["kinetic_energy"].as_f64().unwrap_or(f64::NAN);
            let rpe = s["potential_energy"].as_f64().unwrap_or(f64::NAN);
            e[5] = nan_max(
                nan_max(e[5], (ke - rke).abs() / rke.abs().max(1.0)),
                (pe - rpe).abs() / rpe.abs().max(1.0),
            );
        }
        let n = samples.len();
        if n == 0 {
            // Nothing was compared: no error bound was measured.
            e = [f64::NAN; 6];
        }
        for (k, what) in [
            "RNEA tau",
            "CRBA H (all entries)",
            "bias C(q, v) = nonLinearEffects",
            "gravity g(q)",
            "ABA q''",
            "kinetic and potential energy",
        ]
        .iter()
        .enumerate()
        {
            let metric = format!("max relative error of {what}, {n} random (q, v, a, tau)");
            out.push(check(&case, &metric, e[k], 1e-9, Judge::AtMost, PINOCCHIO_DYN));
        }
    }
    out
}

/// A floating tree with every joint type (free base, revolute about an unaligned axis, spherical,
/// prismatic, a fixed joint kept as a joint, two branches) and a full inertia on every body.
pub(super) fn floating_tree() -> Result<Model, String> {
    let mut b = ModelBuilder::new("floating-tree");
    let e = |x: crate::ModelError| x.to_string();
    let rot = anim_core::lie::so3::exp(DVec3::new(0.3, -0.2, 0.5));
    let base = b
        .add_joint(
            0,
            "base",
            JointType::Free,
            Se3::new(rot, DVec3::new(0.1, 0.2, 0.3)),
            JointLimits::UNBOUNDED,
        )
        .map_err(e)?;
    let axis = Axis::from_vector(DVec3::new(1.0, 2.0, -0.5)).ok_or("axis")?;
    let hinge = b
        .add_joint(
            base,
            "hinge",
            JointType::Revolute(axis),
            Se3::from_translation(DVec3::Z * 0.4),
            JointLimits::position(-2.0, 2.0),
        )
        .map_err(e)?;
    let ball = b
        .add_joint(
            hinge,
            "ball",
            JointType::Spherical,
            Se3::new(rot.transpose(), DVec3::new(0.3, 0.0, 0.1)),
            JointLimits::UNBOUNDED,
        )
        .map_err(e)?;
    let fixed = b
        .add_joint(
            ball,
            "rigid",
            JointType::Fixed,
            Se3::from_translation(DVec3::Y * 0.2),
            JointLimits::UNBOUNDED,
        )
        .map_err(e)?;
    let slide_axis = Axis::from_vector(DVec3::new(0.0, 1.0, 1.0)).ok_or("axis")?;
    b.add_joint(
        fixed,
        "slide",
        JointType::Prismatic(slide_axis),
        Se3::new(rot, DVec3::X * 0.1),
        JointLimits::position(-0.5, 0.5),
    )
    .map_err(e)?;
    b.add_joint(
        base,
        "branch",
        JointType::Revolute(Axis::X),
        Se3::from_translation(DVec3::Y * -0.3),
        JointLimits::UNBOUNDED,
    )
    .map_err(e)?;
    for j in 1..b.model().njoints() {
        let k = j as f64;
        let i_c = DMat3::from_cols(
            DVec3::new(0.05 + 0.01 * k, 0.004 * k.sin(), -0.003),
            DVec3::new(0.004 * k.sin(), 0.04 + 0.005 * k, 0.002 * k.cos()),
            DVec3::new(-0.003, 0.002 * k.cos(), 0.03 + 0.002 * k),
        );
        b.append_body(j, &Inertia::new(0.5 + 0.3 * k, DVec3::new(0.1, -0.05 * k, 0.02), i_c), &Se3::IDENTITY)
            .map_err(e)?;
    }
    Ok(b.build())
}

pub(super) fn cross_checks(_: &Ctx) -> Vec<Check> {
    let mut out = Vec::new();
    let models: Vec<(&str, Result<Model, String>)> = vec![
        ("panda", crate::cases::panda()),
        ("ur5", crate::cases::ur5()),
        ("chain32", load_urdf(testdata("chain32.urdf"), &UrdfOptions::default()).map_err(|e| e.to_string())),
        ("floating tree (free, spherical, prismatic, revolute)", floating_tree()),
    ];
    let mut rng = ChaCha8Rng::seed_from_u64(91);
    for (name, model) in models {
        let case = format!("{name} dynamics cross-checks");
        let model = match model {
            Ok(m) => m,
            Err(e) => {
                out.extend(failed(&case, &e));
                continue;
            }
        };
        let nv = model.nv();
        let mut data = Data::new(&model);
        let (mut closure, mut inverse, mut columns, mut chol, mut asym, mut pivot, mut forms) =
            (0.0_f64, 0.0_f64, 0.0_f64, 0.0_f64, 0.0_f64, f64::INFINITY, 0.0_f64);
        let zero = vec![0.0; nv];
        for _ in 0..50 {
            let q = random_configuration(&model, &mut || rng.random::<f64>());
            let v: Vec<f64> = (0..nv).map(|_| rng.random_range(-2.0..2.0)).collect();
            let a: Vec<f64> = (0..nv).map(|_| rng.random_range(-3.0..3.0)).collect();
            let tau: Vec<f64> = (0..nv).map(|_| rng.random_range(-10.0..10.0)).collect();
            // H q'' + C = tau with q'' from ABA.
            let qdd = aba(&model, &mut data, &q, &v, &tau).to_vec();
            let h = crba(&model, &mut data, &q).clone();
            asym = nan_max(asym, h.asymmetry());
            let local = crba_local(&model, &mut data, &q).clone();
            forms = nan_max(forms, rel_err(crba_world(&model, &mut data, &q).as_slice(), local.as_slice()));
            let c = nonlinear_effects(&model, &mut data, &q, &v).to_vec();
            let mut hq = vec![0.0; nv];
            h.mul_vec(&qdd, &mut hq);
            let scale = tau.iter().chain(&c).chain(&hq).fold(0.0_f64, |m, x| nan_max(m, x.abs()));
            let res = (0..nv).fold(0.0_f64, |m, i| nan_max(m, (hq[i] + c[i] - tau[i]).abs()));
            closure = nan_max(closure, res / scale);
            // ABA(RNEA(a)) = a.
            let t = rnea(&model, &mut data, &q, &v, &a).to_vec();
            inverse = nan_max(inverse, rel_err(aba(&model, &mut data, &q, &v, &t), &a));
            // Cholesky forward dynamics.
            match forward_dynamics_cholesky(&model, &mut data, &q, &v, &tau) {
                Ok(x) => chol = nan_max(chol, rel_err(x, &qdd)),
                Err(_) => chol = f64::NAN,
            }
            if factor_mass_matrix(&model, &mut data).is_ok() {
                for k in 0..nv {
                    // The minimum, kept NaN once a factorisation failed or a pivot is NaN.
                    pivot = -nan_max(-pivot, -(data.mass_matrix_factor[(k, k)] / h.max_abs()));
                }
            } else {
                pivot = f64::NAN;
            }
            // H e_k = RNEA(q, 0, e_k) - g(q).
            let g = gravity_torques(&model, &mut data, &q).to_vec();
            for k in 0..nv {
                let mut e = zero.clone();
                e[k] = 1.0;
                let col = rnea(&model, &mut data, &q, &zero, &e);
                for i in 0..nv {
                    columns = nan_max(columns, (h[(i, k)] - (col[i] - g[i])).abs() / h.max_abs());
                }
            }
        }
        out.push(check(
            &case,
            "max |H q'' + C - tau| / max(|tau|, |C|, |H q''|), q'' = ABA, 50 samples",
            closure,
            1e-10,
            Judge::AtMost,
            CROSS,
        ));
        out.push(check(
            &case,
            "max |ABA(q, v, RNEA(q, v, a)) - a| / |a|",
            inverse,
            1e-9,
            Judge::AtMost,
            CROSS,
        ));
        out.push(check(
            &case,
            "max |H e_k - (RNEA(q, 0, e_k) - g)| / max|H|",
            columns,
            1e-12,
            Judge::AtMost,
            CROSS,
        ));
        out.push(check(
            &case,
            "max |ABA - H^-1 (tau - C)| / |q''| (LTDL Cholesky)",
            chol,
            1e-9,
            Judge::AtMost,
            CROSS,
        ));
        out.push(check(&case, "max |H - H^T|", asym, 0.0, Judge::AtMost, CROSS));
        out.push(check(
            &case,
            "max |H_world - H_local| / max|H| (the two CRBA forms)",
            forms,
            1e-13,
            Judge::AtMost,
            CROSS,
        ));
        out.push(check(
            &case,
            "min LTDL pivot of H / max|H| (> 0: positive definite)",
            pivot,
            f64::MIN_POSITIVE,
            Judge::AtLeast,
            CROSS,
        ));
    }
    out
}

pub(super) fn spinning(integrator: RigidIntegrator) -> Result<(RigidSimulation, RigidState), String> {
    let scene = scenes::t_handle().map_err(|e| e.to_string())?;
    let sim = RigidSimulation::new(scene.model, scene.params, integrator).map_err(|e| e.to_string())?;
    let state = sim.initial_state(scene.state.q, scene.state.v).map_err(|e| e.to_string())?;
    Ok((sim, state))
}

pub(super) fn small_chain(integrator: RigidIntegrator) -> Result<(RigidSimulation, RigidState), String> {
    let model = pendulum_chain_model(&[0.3, 0.2, 0.25, 0.1], 0.2).map_err(|e| e.to_string())?;
    let sim = RigidSimulation::new(model, SimParams::default(), integrator).map_err(|e| e.to_string())?;
    let state =
        sim.initial_state(vec![0.2, -0.4, 0.3, 0.5], vec![0.5, 0.0, -1.0, 0.3]).map_err(|e| e.to_string())?;
    Ok((sim, state))
}

pub(super) fn state_distance(model: &Model, a: &RigidState, b: &RigidState) -> f64 {
    let d = crate::config::difference(model, &a.q, &b.q);
    let dv = a.v.iter().zip(&b.v).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
    d.iter().fold(dv, |m, x| m.max(x.abs()))
}

type Make = fn(RigidIntegrator) -> Result<(RigidSimulation, RigidState), String>;

/// log2 of the error ratio between steps h and h/2 at time `t_end`, against RK4 at h/64.
pub(super) fn measured_order(
    integrator: RigidIntegrator,
    make: Make,
    t_end: f64,
    h: f64,
) -> Result<f64, String> {
    let solve = |integrator, dt: f64| -> Result<(Model, RigidState), String> {
        let (mut sim, mut state) = make(integrator)?;
        for _ in 0..(t_end / dt).round() as usize {
            sim.step(&mut state, dt).map_err(|e| e.to_string())?;
        }
        Ok((sim.model().clone(), state))
    };
    let (model, reference) = solve(RigidIntegrator::Rk4, h / 64.0)?;
    let (_, coarse) = solve(integrator, h)?;
    let (_, fine) = solve(integrator, h / 2.0)?;
    Ok((state_distance(&model, &coarse, &reference) / state_distance(&model, &fine, &reference)).log2())
}

pub(super) fn stepper_orders(_: &Ctx) -> Vec<Check> {
    let mut out = Vec::new();
    let problems: [(&str, Make, f64); 2] = [
        ("spinning T-handle (free joint, SE(3))", spinning, 0.01),
        ("4-link chain (revolute)", small_chain, 2e-3),
    ];
    for (problem, make, h) in problems {
        for integrator in RigidIntegrator::ALL {
            if integrator == RigidIntegrator::FreeBodyMidpoint && problem.starts_with('4') {
                continue;
            }
            let case = format!("{} on the {problem}", integrator.label());
            let order = f64::from(integrator.order());
            match measured_order(integrator, make, 0.5, h) {
                Ok(p) => out.push(Check {
                    reference: order,
                    ..check(
                        &case,
                        &format!("measured order, h = {h} and h/2 at t = 0.5 s, RK4 at h/64 as reference"),
                        p,
                        0.25,
                        Judge::Near,
                        "the method's theoretical order",
                    )
                }),
                Err(e) => out.extend(failed(&case, &e)),
            }
        }
    }
    out
}

pub(super) fn t_handle_period(_: &Ctx) -> Vec<Check> {
    let case = "T-handle spinning at 10 rad/s about its intermediate axis (free-body midpoint, 1 ms)";
    let result = (|| -> Result<(f64, f64, f64, usize), String> {
        let (_, moments) = t_handle_model().map_err(|e| e.to_string())?;
        let scene = scenes::t_handle().map_err(|e| e.to_string())?;
        let w0 = DVec3::new(scene.state.v[3], scene.state.v[4], scene.state.v[5]);
        let axis = (0..3).max_by(|&a, &b| w0[a].abs().total_cmp(&w0[b].abs())).ok_or("axis")?;
        let period = euler_top_period(moments, w0).ok_or("no period")?;
        let (mut sim, mut state) = spinning(RigidIntegrator::FreeBodyMidpoint)?;
        let dt = 1e-3;
        let (mut crossings, mut prev, mut min_w) = (Vec::new(), state.v[3 + axis], f64::INFINITY);
        while state.t < 2.3 * period {
            sim.step(&mut state, dt).map_err(|e| e.to_string())?;
            let w = state.v[3 + axis];
            min_w = min_w.min(w);
            if prev > 0.0 && w <= 0.0 {
                crossings.push(state.t - dt * w / (w - prev));
            }
            prev = w;
        }
        if crossings.len() < 2 {
            return Err(format!("{} flips in {:.1} s", crossings.len(), state.t));
        }
        let measured = crossings[crossings.len() - 1] - crossings[crossings.len() - 2];
        Ok((measured, period, min_w / w0[axis], crossings.len()))
    })();
    match result {
        Ok((measured, period, flip, n)) => vec![
            check(
                case,
                "spin component along the intermediate axis at its most negative / initial (-1: a full flip)",
                flip,
                -0.99,
                Judge::AtMost,
                "the Dzhanibekov effect: rotation about the intermediate axis is unstable",
            ),
            check(
                case,
                &format!(
                    "|T - T_exact| / T_exact, T = {measured:.6} s between the last 2 of {n} flips, T_exact = 4 K(k) / p = {period:.6} s"
                ),
                (measured - period).abs() / period,
                1e-3,
                Judge::AtMost,
                "Euler's top in Jacobi elliptic functions (Landau & Lifshitz, Mechanics, sec. 37)",
            ),
        ],
        Err(e) => failed(case, &e),
    }
}

pub(super) fn energy_balance(_: &Ctx) -> Vec<Check> {
    let case = "UR5 with torques, damping 0.3, driven into a joint limit (RK4, 0.1 ms, 0.5 s)";
    let result = (|| -> Result<(f64, f64, f64), String> {
        let model = crate::cases::ur5()?;
        let lower = model.joint(2).limits.lower;
        let params = SimParams::default()
            .with_damping(0.3)
            .with_torque(vec![2.0, -5.0, 1.0, 0.5, -0.2, 0.1])
            .with_limits(2000.0, 3.0);
        let mut sim = RigidSimulation::new(model, params, RigidIntegrator::Rk4).map_err(|e| e.to_string())?;
        let mut state = sim
            .initial_state(vec![0.0, lower + 0.05, 0.5, 0.0, 0.3, 0.0], vec![0.0, -1.5, 0.0, 0.0, 0.0, 0.0])
            .map_err(|e| e.to_string())?;
        let dt = 1e-4;
        let e0 = sim.energy(&state);
        let (mut work, mut p_prev, mut deepest) = (0.0, sim.system().power(&state.q, &state.v), 0.0_f64);
        for _ in 0..5000 {
            sim.step(&mut state, dt).map_err(|e| e.to_string())?;
            let p = sim.system().power(&state.q, &state.v);
            work += 0.5 * dt * (p + p_prev);
            p_prev = p;
            deepest = deepest.min(state.q[1] - lower);
        }
        Ok((sim.energy(&state) - e0, work, deepest))
    })();
    match result {
        Ok((de, work, deepest)) => vec![check(
            case,
            &format!(
                "|E(T) - E(0) - integral of power| / |integral| (work {work:.4} J, limit reached by {:.1e} rad)",
                -deepest
            ),
            (de - work).abs() / work.abs(),
            1e-4,
            Judge::AtMost,
            "dE/dt = tau.v - d |v|^2 + limit damping power (trapezoidal quadrature)",
        )],
        Err(e) => failed(case, &e),
    }
}
