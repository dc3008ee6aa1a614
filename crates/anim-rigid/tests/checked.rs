//! The checked entry points refuse wrong lengths, non-finite entries, zero quaternions, bad
//! indices and a foreign `Data` with an error instead of the unchecked functions' panic, and
//! return exactly what the unchecked functions return on good input.

#![allow(clippy::unwrap_used, clippy::expect_used)] // integration tests: a failed unwrap is a failed test

mod common;

use anim_rigid::checked::{self, InputError};
use anim_rigid::config::{neutral, random_configuration};
use anim_rigid::{Data, Jacobian, ReferenceFrame};
use common::{mixed, panda, panda_floating};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

#[test]
fn wrong_lengths_are_errors_not_panics() {
    let m = panda();
    let mut d = Data::new(&m);
    let (q, v) = (vec![0.1; 7], vec![0.2; 7]);
    let short = vec![0.0; 6];
    let e = checked::forward_kinematics(&m, &mut d, &short).unwrap_err();
    assert_eq!(e, InputError::Length { name: "q", expected: 7, got: 6, size: "nq" });
    assert_eq!(e.to_string(), "q has length 6, the model needs 7 (nq)");
    assert!(matches!(
        checked::rnea(&m, &mut d, &q, &v, &short),
        Err(InputError::Length { name: "a", expected: 7, got: 6, .. })
    ));
    assert!(matches!(
        checked::aba(&m, &mut d, &q, &short, &v),
        Err(InputError::Length { name: "v", got: 6, .. })
    ));
    assert!(matches!(
        checked::aba(&m, &mut d, &q, &v, &[0.0; 8]),
        Err(InputError::Length { name: "tau", got: 8, .. })
    ));
    assert!(matches!(checked::crba(&m, &mut d, &[]), Err(InputError::Length { name: "q", got: 0, .. })));
    assert!(matches!(checked::gravity_torques(&m, &mut d, &short), Err(InputError::Length { .. })));
    assert!(matches!(checked::nonlinear_effects(&m, &mut d, &q, &short), Err(InputError::Length { .. })));
    assert!(matches!(
        checked::forward_dynamics_cholesky(&m, &mut d, &q, &v, &short),
        Err(InputError::Length { name: "tau", .. })
    ));
    assert!(matches!(checked::compute_joint_jacobians(&m, &mut d, &short), Err(InputError::Length { .. })));
    assert!(matches!(
        checked::compute_joint_jacobians_time_variation(&m, &mut d, &q, &short),
        Err(InputError::Length { name: "v", .. })
    ));
    assert!(matches!(checked::integrate(&m, &q, &short, 0.1), Err(InputError::Length { name: "v", .. })));
    let mut out = vec![0.0; 8];
    assert!(matches!(
        checked::integrate_into(&m, &q, &v, 0.1, &mut out),
        Err(InputError::Length { name: "out", expected: 7, got: 8, .. })
    ));
    assert!(matches!(checked::difference(&m, &q, &short), Err(InputError::Length { name: "q1", .. })));
    assert!(matches!(
        checked::difference_into(&m, &q, &q, &mut out),
        Err(InputError::Length { name: "out", .. })
    ));
    // A Data made for another model, a joint or frame past the end, a Jacobian of the wrong width.
    let other = panda_floating();
    let mut d_other = Data::new(&other);
    assert_eq!(checked::forward_kinematics(&m, &mut d_other, &q), Err(InputError::DataMismatch));
    checked::compute_joint_jacobians(&m, &mut d, &q).unwrap();
    let mut j = Jacobian::zeros(7);
    assert!(matches!(
        checked::joint_jacobian(&m, &d, 8, ReferenceFrame::World, &mut j),
        Err(InputError::IndexOutOfRange { what: "joint", index: 8, count: 8 })
    ));
    let nf = m.frames().len();
    assert!(matches!(
        checked::frame_jacobian(&m, &d, nf, ReferenceFrame::Local, &mut j),
        Err(InputError::IndexOutOfRange { what: "frame", .. })
    ));
    let mut wide = Jacobian::zeros(9);
    assert_eq!(
        checked::frame_jacobian(&m, &d, 1, ReferenceFrame::Local, &mut wide),
        Err(InputError::JacobianColumns { expected: 7, got: 9 })
    );
}

#[test]
fn the_unchecked_functions_panic_on_the_same_input() {
    let m = panda();
    let mut d = Data::new(&m);
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        anim_rigid::rnea(&m, &mut d, &[0.0; 7], &[0.0; 7], &[0.0; 6]);
    }));
    assert!(r.is_err(), "the hot path asserts lengths");
}

#[test]
fn non_finite_entries_name_the_joint() {
    let m = panda();
    let mut d = Data::new(&m);
    let mut q = vec![0.1; 7];
    q[3] = f64::NAN;
    let e = checked::rnea(&m, &mut d, &q, &[0.0; 7], &[0.0; 7]).unwrap_err();
    assert!(
        matches!(&e, InputError::NonFinite { name: "q", index: 3, joint, .. } if joint == "panda_joint4"),
        "{e}"
    );
    assert_eq!(e.to_string(), "q[3] = NaN is not finite (joint 'panda_joint4')");
    let mut v = vec![0.0; 7];
    v[6] = f64::INFINITY;
    let e = checked::aba(&m, &mut d, &[0.1; 7], &v, &[0.0; 7]).unwrap_err();
    assert!(
        matches!(&e, InputError::NonFinite { name: "v", index: 6, joint, .. } if joint == "panda_joint7")
    );
    let e = checked::aba(&m, &mut d, &[0.1; 7], &[0.0; 7], &v).unwrap_err();
    assert!(matches!(&e, InputError::NonFinite { name: "tau", .. }));
    assert!(matches!(
        checked::integrate(&m, &[0.1; 7], &[0.0; 7], f64::NAN),
        Err(InputError::NonFiniteScalar { name: "dt", .. })
    ));
    // A free base: entry 8 of v is the second angular rate of root_joint.
    let f = panda_floating();
    let mut df = Data::new(&f);
    let mut vf = vec![0.0; f.nv()];
    vf[4] = f64::NEG_INFINITY;
    let e = checked::nonlinear_effects(&f, &mut df, &neutral(&f), &vf).unwrap_err();
    assert!(matches!(&e, InputError::NonFinite { index: 4, joint, .. } if joint == "root_joint"), "{e}");
}

#[test]
fn a_zero_quaternion_is_refused() {
    let m = mixed();
    let mut d = Data::new(&m);
    let mut q = neutral(&m);
    // The free base's quaternion is q[3..7].
    q[3..7].fill(0.0);
    let e = checked::frames_forward_kinematics(&m, &mut d, &q).unwrap_err();
    assert!(matches!(&e, InputError::ZeroQuaternion { name: "q", index: 3, .. }), "{e}");
}

#[test]
fn good_input_gives_the_unchecked_results() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    // `mixed` has massless leaves (a singular articulated inertia): ABA only on the Pandas.
    for (m, with_aba) in [(panda(), true), (panda_floating(), true), (mixed(), false)] {
        let (mut d1, mut d2) = (Data::new(&m), Data::new(&m));
        let q = random_configuration(&m, &mut || rng.random::<f64>());
        let v: Vec<f64> = (0..m.nv()).map(|_| rng.random::<f64>() - 0.5).collect();
        let a: Vec<f64> = (0..m.nv()).map(|_| rng.random::<f64>() - 0.5).collect();
        let tau = checked::rnea(&m, &mut d1, &q, &v, &a).unwrap().to_vec();
        assert_eq!(tau, anim_rigid::rnea(&m, &mut d2, &q, &v, &a));
        if with_aba {
            let ddq = checked::aba(&m, &mut d1, &q, &v, &tau).unwrap().to_vec();
            assert!(ddq.iter().all(|x| x.is_finite()));
            assert_eq!(ddq, anim_rigid::aba(&m, &mut d2, &q, &v, &tau));
        }
        let q1 = checked::integrate(&m, &q, &v, 0.01).unwrap();
        assert_eq!(q1, anim_rigid::config::integrate(&m, &q, &v, 0.01));
        assert_eq!(checked::difference(&m, &q, &q1).unwrap(), anim_rigid::config::difference(&m, &q, &q1));
    }
}
