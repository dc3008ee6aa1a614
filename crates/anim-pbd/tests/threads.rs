//! The parallel solvers give the same bits on any thread count: the coloured Gauss-Seidel sweep
//! (each colour split by particle ranges, the halves in parallel) and the Jacobi sweep, on cloths
//! large enough that their parallel paths run at the library's own thresholds, stepped on rayon
//! pools of 1, 2 and 3 threads; positions and velocities compared bit for bit.

#![allow(clippy::expect_used)] // a test file: its helpers panic on a failed setup like its tests

use anim_pbd::{
    Bending, Cloth, Collider, ConstraintParams, EARTH_GRAVITY, Method, PbdBuilder, PbdModel, PbdParams,
    PbdSimulation, SolverKind,
};

/// An `n x n` cloth of 1 m, pinned at two corners, falling onto a sphere.
fn cloth(n: usize, dihedral: bool) -> PbdModel {
    let mut b = PbdBuilder::new();
    b.gravity(EARTH_GRAVITY);
    let bend = ConstraintParams::with_compliance(0.5);
    let c = b
        .cloth(&Cloth {
            nx: n,
            ny: n,
            origin: [-0.5, -0.5, 0.2],
            u: [1.0, 0.0, 0.0],
            v: [0.0, 1.0, 0.0],
            particle_mass: 1e-3,
            stretch: ConstraintParams::with_compliance(1e-6),
            bending: if dihedral { Bending::Dihedral(bend) } else { Bending::Isometric(bend) },
        })
        .expect("cloth");
    b.pin(c.at(0, 0)).pin(c.at(n - 1, 0));
    b.collider(Collider::sphere([0.0, 0.0, 0.0], 0.2).with_thickness(0.005).with_friction(0.3, 0.2));
    b.build().expect("model")
}

/// The bits of the positions and velocities after `steps` steps on a pool of `threads`.
fn bits(model: &PbdModel, solver: SolverKind, threads: usize, steps: usize) -> Vec<u64> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
    pool.install(|| {
        let mut state = model.rest_state();
        let mut sim =
            PbdSimulation::new(model.clone(), PbdParams::new(Method::Xpbd, solver, 5, 1)).expect("params");
        sim.run(&mut state, 1.0 / 60.0, steps).expect("steps");
        state.x.iter().chain(&state.v).map(|v| v.to_bits()).collect()
    })
}

#[test]
fn coloured_and_jacobi_sweeps_are_the_same_bits_on_1_2_and_3_threads() {
    for (n, dihedral) in [(90, true), (90, false)] {
        let model = cloth(n, dihedral);
        for solver in [SolverKind::ColoredGaussSeidel, SolverKind::Jacobi] {
            let one = bits(&model, solver, 1, 12);
            // The cloth moved: the comparison is not of a state at rest.
            let rest: Vec<u64> = model.rest_state().x.iter().map(|v| v.to_bits()).collect();
            let moved = one.iter().zip(&rest).filter(|(a, b)| a != b).count();
            assert!(moved > n * n, "{solver:?}: only {moved} coordinates moved");
            for threads in [2, 3] {
                let other = bits(&model, solver, threads, 12);
                let differing = one.iter().zip(&other).filter(|(a, b)| a != b).count();
                assert_eq!(differing, 0, "{solver:?}, dihedral {dihedral}, {threads} threads");
            }
        }
    }
}
