//! Every robot of the example-robot-data collection, on a fixed and on a floating base, against
//! Pinocchio 4.1: FK, world Jacobians, RNEA, CRBA and ABA (the reader and the error measures
//! are `anim_rigid::cases::collection`'s; the reference is written by
//! `testdata/make_pinocchio_collection_reference.py`). Fails when any robot is refused, builds
//! another joint layout, or disagrees beyond the tolerances. All 20 samples of every robot and
//! base: about 3 s in the test profile (opt-level 1), 2 s in release.
//!
//! With `ANIM_ROBOT_COLLECTION` and `ANIM_ROBOT_COLLECTION_REFERENCE` set, the models of that
//! external reference are compared as well (the `alex_description` models, which are not in
//! the repository).

#![allow(clippy::unwrap_used, clippy::expect_used)] // integration tests: a failed unwrap is a failed test

use anim_rigid::cases::collection::{
    ABA_C, Base, Errors, ModelResult, Outcome, SAMPLES, TOLERANCE, committed_reference, committed_robots,
    compare, external,
};

fn report(results: &[ModelResult]) -> Vec<String> {
    let mut failures = Vec::new();
    for r in results {
        let base = r.base.map_or("", Base::label);
        match &r.outcome {
            Outcome::Compared { samples, errors, nv } => {
                let v = errors.values();
                eprintln!(
                    "{:<62} {base:<8} nv {nv:>3} x{samples}: fk {:.1e} J {:.1e} rnea {:.1e} crba {:.1e} aba {:.1e} ({:.1e} nv eps cond, cond {:.1e}, {} singular H, finite ABA on {})",
                    r.urdf,
                    v[0],
                    v[1],
                    v[2],
                    v[3],
                    v[4],
                    v[5],
                    errors.cond,
                    errors.singular,
                    errors.singular_finite
                );
                if !errors.pass() {
                    failures.push(format!("{} ({base}): {errors:?}", r.urdf));
                }
            }
            Outcome::RefusedByPinocchio { pinocchio, ours } => {
                eprintln!("{}: Pinocchio refuses it ({pinocchio}); here: {ours:?}", r.urdf);
            }
            Outcome::Failed(e) => failures.push(format!("{} ({base}): {e}", r.urdf)),
        }
    }
    let worst = results.iter().filter_map(|r| match r.outcome {
        Outcome::Compared { errors, .. } => Some(errors.values()),
        _ => None,
    });
    let worst = worst.fold([0.0_f64; 6], |mut m, v| {
        for (a, b) in m.iter_mut().zip(v) {
            *a = a.max(b);
        }
        m
    });
    for (name, e) in Errors::NAMES.iter().zip(worst) {
        eprintln!("worst {name}: {e:.2e}");
    }
    failures
}

#[test]
fn every_robot_of_the_collection_matches_pinocchio() {
    let results = compare(&committed_robots(), &committed_reference(), SAMPLES).unwrap();
    let failures = report(&results);
    assert!(
        failures.is_empty(),
        "tolerance {TOLERANCE:e}, ABA {ABA_C} nv eps cond(H):\n{}",
        failures.join("\n")
    );
    let compared = results.iter().filter(|r| matches!(r.outcome, Outcome::Compared { .. })).count();
    // H is singular only where whole subtrees have neither mass nor inertia (romeo's hands): there
    // forward dynamics is undefined, and Pinocchio's ABA returns no finite answer.
    let mut singular = Vec::new();
    for r in &results {
        if let Outcome::Compared { errors, samples, .. } = r.outcome
            && errors.singular > 0
        {
            assert_eq!((errors.singular, errors.singular_reference_finite), (samples, 0), "{}", r.urdf);
            singular.push(r.urdf.as_str());
        }
    }
    singular.dedup();
    assert_eq!(
        singular,
        ["romeo_description/urdf/romeo.urdf", "romeo_description/urdf/romeo_laas_small.urdf"]
    );
    // 66 URDFs, one refused by Pinocchio, each of the others on two bases.
    assert_eq!(compared, 2 * 65);
    let refused: Vec<_> =
        results.iter().filter(|r| matches!(r.outcome, Outcome::RefusedByPinocchio { .. })).collect();
    assert_eq!(refused.len(), 1);
    assert_eq!(refused[0].urdf, "ur_description/urdf/ur3.urdf");
    // The file is an empty <robot> without a name: this crate refuses it as well, naming why.
    let Outcome::RefusedByPinocchio { ours: Err(e), .. } = &refused[0].outcome else {
        panic!("ur3.urdf is loaded here: {:?}", refused[0].outcome);
    };
    assert!(e.contains("ur3.urdf.gz") && e.contains("no <link>"), "{e}");
}

#[test]
fn external_collection_matches_pinocchio() {
    let Some((robots, reference)) = external() else {
        eprintln!("ANIM_ROBOT_COLLECTION and ANIM_ROBOT_COLLECTION_REFERENCE not set: nothing to compare");
        return;
    };
    let results = compare(&robots, &reference, SAMPLES).unwrap();
    let failures = report(&results);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
