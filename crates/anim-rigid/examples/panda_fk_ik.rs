//! Forward kinematics, Jacobians and inverse kinematics on the Franka Panda and the UR5.
//!
//! `cargo run --release -p anim-rigid --example panda_fk_ik`

use std::error::Error;
use std::time::Instant;

use anim_core::glam::DVec3;
use anim_core::lie::Se3;
use anim_rigid::ik::pose_error;
use anim_rigid::{
    AnalyticIk, Data, IkParams, Jacobian, NumericalIk, ReferenceFrame, UrdfOptions, compute_joint_jacobians,
    frame_jacobian, frames_forward_kinematics, load_urdf,
};

fn main() -> Result<(), Box<dyn Error>> {
    let testdata = concat!(env!("CARGO_MANIFEST_DIR"), "/testdata");

    // The Panda as a 7-DoF arm: the finger joints locked at 0 (as Pinocchio's buildReducedModel).
    let options =
        UrdfOptions::default().lock_joint("panda_finger_joint1", 0.0).lock_joint("panda_finger_joint2", 0.0);
    let panda = load_urdf(format!("{testdata}/panda.urdf"), &options)?;
    let tcp = panda.frame_id("panda_hand_tcp").ok_or("no panda_hand_tcp frame")?;
    println!(
        "{}: {} joints, nq = {}, {} frames",
        panda.name(),
        panda.njoints() - 1,
        panda.nq(),
        panda.frames().len()
    );

    let mut data = Data::new(&panda);
    let q = [0.1, -0.4, 0.2, -2.0, 0.1, 1.8, 0.7];
    frames_forward_kinematics(&panda, &mut data, &q);
    let pose = data.frame_placements[tcp];
    println!("tool centre at {:.4?}", pose.translation.to_array());

    compute_joint_jacobians(&panda, &mut data, &q);
    let mut j = Jacobian::zeros(panda.nv());
    frame_jacobian(&panda, &data, tcp, ReferenceFrame::LocalWorldAligned, &mut j);
    println!("tool-centre Jacobian (LOCAL_WORLD_ALIGNED, rows vx vy vz wx wy wz):");
    for row in j.to_rows() {
        println!("  {:+.4?}", row);
    }

    // Numerical IK: move the tool 10 cm down, keep its orientation.
    let target = Se3::new(pose.rotation, pose.translation - DVec3::new(0.0, 0.0, 0.1));
    let mut ik = NumericalIk::new(&panda, tcp, IkParams::default());
    let start = Instant::now();
    let report = ik.solve(&panda, &target, &q);
    println!(
        "numerical IK: success {} in {} iterations ({:.0} us), error {:.1e} m / {:.1e} rad, q = {:+.4?}",
        report.success,
        report.iterations,
        start.elapsed().as_secs_f64() * 1e6,
        report.position_error,
        report.rotation_error,
        report.q
    );
    let far = Se3::from_translation(DVec3::new(2.0, 0.0, 0.5));
    let report = ik.solve(&panda, &far, &q);
    println!(
        "unreachable target: success {}, closest pose {:.3} m away, tool at {:.3?}",
        report.success,
        report.position_error,
        report.placement.translation.to_array()
    );

    // Analytic IK on the UR5: all eight solutions of one pose.
    let ur5 = load_urdf(format!("{testdata}/ur5_robot.urdf"), &UrdfOptions::default())?;
    let tool0 = ur5.frame_id("tool0").ok_or("no tool0 frame")?;
    let analytic = AnalyticIk::new(&ur5, tool0)?;
    let mut data = Data::new(&ur5);
    frames_forward_kinematics(&ur5, &mut data, &[0.4, -1.2, 1.1, -0.6, 1.3, 0.2]);
    let target = data.frame_placements[tool0];
    let solutions = analytic.solve(&target);
    println!("UR5 analytic IK ({:?}): {} solutions", analytic.kind(), solutions.len());
    for s in &solutions {
        frames_forward_kinematics(&ur5, &mut data, &s.q);
        let (dp, dr) = pose_error(&data.frame_placements[tool0], &target);
        println!("  q = {:+.4?}  error {dp:.1e} m / {dr:.1e} rad", s.q);
    }
    Ok(())
}
