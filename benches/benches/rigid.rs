//! Criterion benches of anim-rigid's kinematics on the Franka Panda (fingers locked, 7 DoF):
//! forward kinematics, frame placements, joint Jacobians, one frame Jacobian, and the analytic
//! and numerical IK, over 1024 pre-generated random configurations.
//! `cargo xtask bench --peers` compares FK and Jacobians with Pinocchio's C++.

use anim_rigid::config::random_configuration;
use anim_rigid::{
    AnalyticIk, Data, IkParams, Jacobian, Model, NumericalIk, ReferenceFrame, UrdfOptions,
    compute_joint_jacobians, forward_kinematics, frame_jacobian, frames_forward_kinematics, load_urdf,
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

criterion_group!(benches, kinematics);
criterion_main!(benches);
