//! Forward kinematics three ways, Jacobians against central finite differences of forward
//! kinematics on the configuration manifold, and the Jacobian time derivative against finite
//! differences of the Jacobian.

#![allow(clippy::unwrap_used, clippy::expect_used)] // integration tests: a failed unwrap is a failed test

mod common;

use anim_core::lie::{Se3, Twist};
use anim_rigid::config::{difference, integrate, random_configuration};
use anim_rigid::{
    Data, Jacobian, Model, PoeChain, ReferenceFrame, compute_joint_jacobians,
    compute_joint_jacobians_time_variation, frame_jacobian, frame_jacobian_time_variation,
    frames_forward_kinematics, joint_world_placement,
};
use common::{mixed, panda, panda_floating, puma, se3_err, ur5};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn models() -> Vec<Model> {
    vec![panda(), ur5(), puma(), panda_floating(), mixed()]
}

fn frame_at(model: &Model, data: &mut Data, q: &[f64], f: usize) -> Se3 {
    frames_forward_kinematics(model, data, q);
    data.frame_placements[f]
}

#[test]
fn forward_kinematics_three_ways_agree() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for model in models() {
        let chains: Vec<PoeChain> = (0..model.frames().len()).map(|f| PoeChain::new(&model, f)).collect();
        let mut data = Data::new(&model);
        let mut worst = 0.0_f64;
        for _ in 0..30 {
            let q = random_configuration(&model, &mut || rng.random::<f64>());
            frames_forward_kinematics(&model, &mut data, &q);
            for (f, chain) in chains.iter().enumerate() {
                let composed = data.frame_placements[f];
                let space = chain.forward_space(&q);
                let body = chain.forward_body(&q);
                worst = worst.max(se3_err(&composed, &space)).max(se3_err(&composed, &body));
            }
            for j in 0..model.njoints() {
                worst = worst.max(se3_err(&data.world_placements[j], &joint_world_placement(&model, &q, j)));
            }
        }
        assert!(worst < 1e-13, "{}: FK forms differ by {worst:e}", model.name());
    }
}

#[test]
fn poe_screws_are_the_world_axes_at_zero() {
    // For the UR5 at q = 0, every revolute screw is (-ω × r, ω) with unit ω.
    let model = ur5();
    let f = model.frame_id("tool0").unwrap();
    let chain = PoeChain::new(&model, f);
    let screws = chain.space_screws();
    assert_eq!(screws.len(), 6);
    for s in &screws {
        assert!((s.w.length() - 1.0).abs() < 1e-15);
        assert!(s.v.dot(s.w).abs() < 1e-15, "revolute screws have zero pitch");
    }
    let body = chain.body_screws();
    for (s, b) in screws.iter().zip(&body) {
        let back = chain.home().adjoint(*b);
        assert!((back - *s).to_array().iter().all(|e| e.abs() < 1e-15));
    }
}

/// Central differences of forward kinematics along each velocity direction, on the manifold:
/// LOCAL column k = (log(T⁻¹ T(q ⊕ εe_k)) - log(T⁻¹ T(q ⊕ -εe_k))) / 2ε, WORLD = Ad(T) LOCAL,
/// LOCAL_WORLD_ALIGNED = (ṗ, ω) in world axes.
fn fd_jacobian(model: &Model, data: &mut Data, q: &[f64], f: usize, rf: ReferenceFrame) -> Jacobian {
    let eps = 1e-6;
    let t = frame_at(model, data, q, f);
    let mut out = Jacobian::zeros(model.nv());
    for k in 0..model.nv() {
        let mut dv = vec![0.0; model.nv()];
        dv[k] = eps;
        let plus = frame_at(model, data, &integrate(model, q, &dv, 1.0), f);
        let minus = frame_at(model, data, &integrate(model, q, &dv, -1.0), f);
        let local = ((t.inverse() * plus).log() - (t.inverse() * minus).log()).scale(0.5 / eps);
        out.columns_mut()[k] = match rf {
            ReferenceFrame::Local => local,
            ReferenceFrame::World => t.adjoint(local),
            ReferenceFrame::LocalWorldAligned => {
                Twist::new((plus.translation - minus.translation) * (0.5 / eps), t.rotation * local.w)
            }
        };
    }
    out
}

fn max_diff(a: &Jacobian, b: &Jacobian) -> f64 {
    a.columns()
        .iter()
        .zip(b.columns())
        .flat_map(|(x, y)| (*x - *y).to_array())
        .fold(0.0_f64, |m, e| m.max(e.abs()))
}

#[test]
fn jacobians_match_finite_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    for model in models() {
        let mut data = Data::new(&model);
        let mut j = Jacobian::zeros(model.nv());
        let mut worst = 0.0_f64;
        for _ in 0..5 {
            let q = random_configuration(&model, &mut || rng.random::<f64>());
            for f in 0..model.frames().len() {
                for rf in [ReferenceFrame::World, ReferenceFrame::Local, ReferenceFrame::LocalWorldAligned] {
                    compute_joint_jacobians(&model, &mut data, &q);
                    frame_jacobian(&model, &data, f, rf, &mut j);
                    let fd = fd_jacobian(&model, &mut data, &q, f, rf);
                    worst = worst.max(max_diff(&j, &fd));
                }
            }
        }
        assert!(worst < 1e-8, "{}: Jacobian vs finite differences {worst:e}", model.name());
    }
}

#[test]
fn poe_jacobians_equal_world_and_local() {
    let mut rng = ChaCha8Rng::seed_from_u64(13);
    for model in models() {
        let mut data = Data::new(&model);
        let (mut j, mut jp) = (Jacobian::zeros(model.nv()), Jacobian::zeros(model.nv()));
        for _ in 0..10 {
            let q = random_configuration(&model, &mut || rng.random::<f64>());
            compute_joint_jacobians(&model, &mut data, &q);
            for f in 0..model.frames().len() {
                let chain = PoeChain::new(&model, f);
                frame_jacobian(&model, &data, f, ReferenceFrame::World, &mut j);
                chain.jacobian_space(&q, &mut jp);
                assert!(max_diff(&j, &jp) < 1e-13, "{} frame {f} space", model.name());
                frame_jacobian(&model, &data, f, ReferenceFrame::Local, &mut j);
                chain.jacobian_body(&q, &mut jp);
                assert!(max_diff(&j, &jp) < 1e-13, "{} frame {f} body", model.name());
            }
        }
    }
}

#[test]
fn jacobian_time_derivative_matches_finite_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(14);
    let eps = 1e-6;
    for model in models() {
        let mut data = Data::new(&model);
        let (mut dj, mut jp, mut jm) =
            (Jacobian::zeros(model.nv()), Jacobian::zeros(model.nv()), Jacobian::zeros(model.nv()));
        let mut worst = 0.0_f64;
        for _ in 0..5 {
            let q = random_configuration(&model, &mut || rng.random::<f64>());
            let v: Vec<f64> = (0..model.nv()).map(|_| rng.random_range(-1.0..1.0)).collect();
            let (qp, qm) = (integrate(&model, &q, &v, eps), integrate(&model, &q, &v, -eps));
            for f in 0..model.frames().len() {
                for rf in [ReferenceFrame::World, ReferenceFrame::Local, ReferenceFrame::LocalWorldAligned] {
                    compute_joint_jacobians_time_variation(&model, &mut data, &q, &v);
                    frame_jacobian_time_variation(&model, &data, f, rf, &mut dj);
                    compute_joint_jacobians(&model, &mut data, &qp);
                    frame_jacobian(&model, &data, f, rf, &mut jp);
                    compute_joint_jacobians(&model, &mut data, &qm);
                    frame_jacobian(&model, &data, f, rf, &mut jm);
                    let fd: Vec<Twist> = jp
                        .columns()
                        .iter()
                        .zip(jm.columns())
                        .map(|(a, b)| (*a - *b).scale(0.5 / eps))
                        .collect();
                    let e = dj
                        .columns()
                        .iter()
                        .zip(&fd)
                        .flat_map(|(a, b)| (*a - *b).to_array())
                        .fold(0.0_f64, |m, x| m.max(x.abs()));
                    worst = worst.max(e);
                }
            }
        }
        assert!(worst < 1e-7, "{}: dJ/dt vs finite differences {worst:e}", model.name());
    }
}

#[test]
fn data_reuse_gives_identical_results() {
    let model = panda();
    let mut rng = ChaCha8Rng::seed_from_u64(15);
    let q1 = random_configuration(&model, &mut || rng.random::<f64>());
    let q2 = random_configuration(&model, &mut || rng.random::<f64>());
    let mut fresh = Data::new(&model);
    let mut reused = Data::new(&model);
    compute_joint_jacobians(&model, &mut reused, &q1);
    compute_joint_jacobians(&model, &mut reused, &q2);
    compute_joint_jacobians(&model, &mut fresh, &q2);
    assert_eq!(fresh.world_placements, reused.world_placements);
    assert_eq!(fresh.jacobian, reused.jacobian);
}

#[test]
fn difference_is_the_inverse_of_integrate_on_every_model() {
    let mut rng = ChaCha8Rng::seed_from_u64(16);
    for model in models() {
        for _ in 0..20 {
            let q0 = random_configuration(&model, &mut || rng.random::<f64>());
            let v: Vec<f64> = (0..model.nv()).map(|_| rng.random_range(-0.5..0.5)).collect();
            let q1 = integrate(&model, &q0, &v, 1.0);
            let d = difference(&model, &q0, &q1);
            let e = d.iter().zip(&v).fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
            assert!(e < 1e-13, "{}: {e:e}", model.name());
        }
    }
}

#[test]
fn joint_jacobian_equals_its_joint_frame_jacobian() {
    let mut rng = ChaCha8Rng::seed_from_u64(17);
    for model in models() {
        let mut data = Data::new(&model);
        let (mut a, mut b) = (Jacobian::zeros(model.nv()), Jacobian::zeros(model.nv()));
        let q = random_configuration(&model, &mut || rng.random::<f64>());
        compute_joint_jacobians(&model, &mut data, &q);
        for j in 1..model.njoints() {
            let f = model.frame_id_of_kind(&model.joint(j).name, anim_rigid::FrameKind::Joint).unwrap();
            for rf in [ReferenceFrame::World, ReferenceFrame::Local, ReferenceFrame::LocalWorldAligned] {
                anim_rigid::joint_jacobian(&model, &data, j, rf, &mut a);
                frame_jacobian(&model, &data, f, rf, &mut b);
                assert_eq!(a, b, "{} joint {j}", model.name());
            }
            // Columns outside the support are zero; the joint's own columns are not.
            let support = model.support(j);
            for k in 0..model.nv() {
                let owner = (1..model.njoints())
                    .find(|&i| {
                        (model.joint(i).idx_v..model.joint(i).idx_v + model.joint(i).nv()).contains(&k)
                    })
                    .unwrap();
                let zero = a.column(k) == Twist::ZERO;
                assert_eq!(zero, !support.contains(&owner), "{} joint {j} column {k}", model.name());
            }
        }
    }
}
