//! Criterion benches of anim-rigid on the Franka Panda (fingers locked, 7 DoF): forward
//! kinematics, frame placements, joint Jacobians, one frame Jacobian, the analytic and numerical
//! IK; and the dynamics (RNEA, CRBA, ABA in both forms, the Cholesky forward dynamics, one simulation step) on
//! the Panda and the 32-joint chain of `crates/anim-rigid/testdata/chain32.urdf`, over 1024
//! pre-generated random inputs. `cargo xtask bench --peers` compares FK, Jacobians, RNEA, CRBA
//! and ABA with Pinocchio's C++.

use anim_core::solver::Solver;
use anim_rigid::config::random_configuration;
use anim_rigid::sim::{RigidIntegrator, RigidSimulation, SimParams};
use anim_rigid::{
    AnalyticIk, Data, IkParams, Jacobian, Model, NumericalIk, ReferenceFrame, UrdfOptions, aba, aba_local,
    aba_world, compute_joint_jacobians, crba, crba_local, crba_world, forward_dynamics_cholesky,
    forward_kinematics, frame_jacobian, frames_forward_kinematics, load_urdf, rnea,
};
use criterion::{Criterion, criterion_group, criterion_main};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::hint::black_box;

fn testdata(file: &str) -> String {
    format!("{}/../crates/anim-rigid/testdata/{file}", env!("CARGO_MANIFEST_DIR"))
}

fn panda() -> Model {
    let options =
        UrdfOptions::default().lock_joint("panda_finger_joint1", 0.0).lock_joint("panda_finger_joint2", 0.0);
    load_urdf(testdata("panda.urdf"), &options).unwrap_or_else(|e| panic!("{e}"))
}

fn configurations(model: &Model) -> Vec<Vec<f64>> {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    (0..1024).map(|_| random_configuration(model, &mut || rng.random::<f64>())).collect()
}

fn kinematics(c: &mut Criterion) {
    let model = panda();
    let qs = configurations(&model);
    let mut data = Data::new(&model);
    let tcp = model.frame_id("panda_hand_tcp").unwrap_or_else(|| panic!("no panda_hand_tcp frame"));
    let mut j = Jacobian::zeros(model.nv());
    let mut g = c.benchmark_group("rigid/panda");
    let mut i = 0;
    g.bench_function("forward_kinematics", |b| {
        b.iter(|| {
            i = (i + 1) & 1023;
            forward_kinematics(&model, &mut data, black_box(&qs[i]));
            black_box(data.world_placements[7].translation.x)
        })
    });
    g.bench_function("frames_forward_kinematics", |b| {
        b.iter(|| {
            i = (i + 1) & 1023;
            frames_forward_kinematics(&model, &mut data, black_box(&qs[i]));
            black_box(data.frame_placements[tcp].translation.x)
        })
    });
    g.bench_function("compute_joint_jacobians", |b| {
        b.iter(|| {
            i = (i + 1) & 1023;
            compute_joint_jacobians(&model, &mut data, black_box(&qs[i]));
            black_box(data.jacobian.column(6).v.x)
        })
    });
    g.bench_function("frame_jacobian_local (after joint Jacobians)", |b| {
        b.iter(|| {
            frame_jacobian(&model, &data, tcp, ReferenceFrame::Local, &mut j);
            black_box(j.column(6).v.x)
        })
    });
    let mut ik = NumericalIk::new(&model, tcp, IkParams::default());
    let q0 = ik.mid_configuration(&model);
    let targets: Vec<_> = qs
        .iter()
        .map(|q| {
            frames_forward_kinematics(&model, &mut data, q);
            data.frame_placements[tcp]
        })
        .collect();
    g.bench_function("numerical_ik (random reachable target)", |b| {
        b.iter(|| {
            i = (i + 1) & 1023;
            black_box(ik.solve(&model, black_box(&targets[i]), &q0).error)
        })
    });
    g.finish();

    let ur5 =
        load_urdf(testdata("ur5_robot.urdf"), &UrdfOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    let tool = ur5.frame_id("tool0").unwrap_or_else(|| panic!("no tool0 frame"));
    let analytic = AnalyticIk::new(&ur5, tool).unwrap_or_else(|e| panic!("{e}"));
    let mut data = Data::new(&ur5);
    let targets: Vec<_> = configurations(&ur5)
        .iter()
        .map(|q| {
            frames_forward_kinematics(&ur5, &mut data, q);
            data.frame_placements[tool]
        })
        .collect();
    c.bench_function("rigid/ur5/analytic_ik (all solutions)", |b| {
        b.iter(|| {
            i = (i + 1) & 1023;
            black_box(analytic.solve(black_box(&targets[i])).len())
        })
    });
}

/// One input of the dynamics kernels: (q, v, a, tau).
type Sample = (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>);

/// Random (q, v, a, tau) with the ranges of the Pinocchio peer program.
fn samples(model: &Model) -> Vec<Sample> {
    let mut rng = ChaCha8Rng::seed_from_u64(6);
    let nv = model.nv();
    (0..1024)
        .map(|_| {
            let q = random_configuration(model, &mut || rng.random::<f64>());
            let mut r = |s: f64| (0..nv).map(|_| rng.random_range(-s..s)).collect::<Vec<f64>>();
            (q, r(2.0), r(3.0), r(10.0))
        })
        .collect()
}

fn dynamics(c: &mut Criterion) {
    let chain32 =
        load_urdf(testdata("chain32.urdf"), &UrdfOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    let ur5 =
        load_urdf(testdata("ur5_robot.urdf"), &UrdfOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    let chain8 = anim_rigid::scenes::pendulum_chain_model(&[0.1; 8], 0.1).unwrap_or_else(|e| panic!("{e}"));
    let chain16 = anim_rigid::scenes::pendulum_chain_model(&[0.1; 16], 0.1).unwrap_or_else(|e| panic!("{e}"));
    for (name, model) in
        [("panda", panda()), ("ur5", ur5), ("chain8", chain8), ("chain16", chain16), ("chain32", chain32)]
    {
        let inputs = samples(&model);
        let mut data = Data::new(&model);
        let last = model.nv() - 1;
        let mut g = c.benchmark_group(format!("rigid/{name}"));
        let mut i = 0;
        g.bench_function("rnea", |b| {
            b.iter(|| {
                i = (i + 1) & 1023;
                let (q, v, a, _) = &inputs[i];
                black_box(rnea(&model, &mut data, black_box(q), black_box(v), black_box(a))[last])
            })
        });
        g.bench_function("crba", |b| {
            b.iter(|| {
                i = (i + 1) & 1023;
                black_box(crba(&model, &mut data, black_box(&inputs[i].0))[(0, last)])
            })
        });
        g.bench_function("crba_local", |b| {
            b.iter(|| {
                i = (i + 1) & 1023;
                black_box(crba_local(&model, &mut data, black_box(&inputs[i].0))[(0, last)])
            })
        });
        g.bench_function("crba_world", |b| {
            b.iter(|| {
                i = (i + 1) & 1023;
                black_box(crba_world(&model, &mut data, black_box(&inputs[i].0))[(0, last)])
            })
        });
        g.bench_function("aba", |b| {
            b.iter(|| {
                i = (i + 1) & 1023;
                let (q, v, _, tau) = &inputs[i];
                black_box(aba(&model, &mut data, black_box(q), black_box(v), black_box(tau))[last])
            })
        });
        g.bench_function("aba_local", |b| {
            b.iter(|| {
                i = (i + 1) & 1023;
                let (q, v, _, tau) = &inputs[i];
                black_box(aba_local(&model, &mut data, black_box(q), black_box(v), black_box(tau))[last])
            })
        });
        g.bench_function("aba_world", |b| {
            b.iter(|| {
                i = (i + 1) & 1023;
                let (q, v, _, tau) = &inputs[i];
                black_box(aba_world(&model, &mut data, black_box(q), black_box(v), black_box(tau))[last])
            })
        });
        g.bench_function("forward_dynamics_cholesky", |b| {
            b.iter(|| {
                i = (i + 1) & 1023;
                let (q, v, _, tau) = &inputs[i];
                let ddq =
                    forward_dynamics_cholesky(&model, &mut data, black_box(q), black_box(v), black_box(tau));
                black_box(ddq.map(|x| x[last]).unwrap_or(f64::NAN))
            })
        });
        for integrator in [RigidIntegrator::Rk4, RigidIntegrator::ImplicitMidpoint] {
            let mut sim = RigidSimulation::new(model.clone(), SimParams::default(), integrator)
                .unwrap_or_else(|e| panic!("{e}"));
            let (q, v, _, _) = inputs[0].clone();
            let mut state =
                sim.initial_state(q, v.iter().map(|x| 0.1 * x).collect()).unwrap_or_else(|e| panic!("{e}"));
            g.bench_function(format!("step {} (1 ms, with energy and momentum)", integrator.label()), |b| {
                b.iter(|| black_box(sim.step(&mut state, 1e-3).map(|r| r.time).unwrap_or(f64::NAN)))
            });
        }
        g.finish();
    }
}

criterion_group!(benches, kinematics, dynamics);
criterion_main!(benches);
