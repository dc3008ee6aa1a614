//! The crate's conformance checks, hard cases, soak runs and studies (feature `cases`): run by
//! its own tests in quick mode and by `cargo xtask conformance`, `stability` and `report`.
//!
//! The two-particle spring against its closed form, convergence orders of every integrator, the
//! hanging chain's static stretch, the force Jacobian against finite differences; stability
//! bounds `dt <= c sqrt(m/k)` of the explicit methods, stiff backward Euler, degenerate springs,
//! a detected divergence, the speed up to which the penalty contact catches particles thrown at a
//! 1 cm mesh plate (`thin_plate`); a work-precision study on the cloth; determinism across thread counts
//! and a soak run of the stiff cloth.

mod conformance;
mod determinism;
mod hard_cases;
mod peer;
mod roofline;
mod soak;
mod study;
mod thin_plate;

pub use peer::{PeerRun, peer_symplectic_cloth};
pub use study::study_problem;

use anim_core::cases::{ConformanceCase, Outcome, Registry, StabilityCase, Study, StudyUse};
use anim_core::integrate::IntegratorKind;

const CRATE: &str = "anim-springs";

/// Registers the crate's cases: conformance, hard cases, the cloth study, the determinism check
/// and the stiff-cloth soak run, in that order.
pub fn register(r: &mut Registry) {
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "two-particle spring vs closed form",
        run: Box::new(conformance::two_particle),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "two-particle spring convergence order",
        run: Box::new(conformance::two_particle_orders),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "hanging chain static stretch",
        run: Box::new(conformance::hanging_chain),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "spring network Jacobians vs finite differences",
        run: Box::new(conformance::jacobian_fd),
    });

    for kind in hard_cases::EXPLICIT {
        r.stability.push(StabilityCase {
            crate_name: CRATE,
            name: match kind {
                IntegratorKind::ExplicitEuler => {
                    "explicit Euler: largest stable dt on a chain, k over 6 decades"
                }
                IntegratorKind::SymplecticEuler => {
                    "symplectic Euler: largest stable dt on a chain, k over 6 decades"
                }
                IntegratorKind::PositionVerlet => {
                    "position Verlet: largest stable dt on a chain, k over 6 decades"
                }
                IntegratorKind::Leapfrog => "leapfrog: largest stable dt on a chain, k over 6 decades",
                IntegratorKind::VelocityVerlet => {
                    "velocity Verlet: largest stable dt on a chain, k over 6 decades"
                }
                _ => "RK4: largest stable dt on a chain, k over 6 decades",
            },
            expected: || Outcome::Stable(String::new()),
            run: match kind {
                IntegratorKind::ExplicitEuler => {
                    |ctx| hard_cases::stable_dt_sweep(ctx, IntegratorKind::ExplicitEuler)
                }
                IntegratorKind::SymplecticEuler => {
                    |ctx| hard_cases::stable_dt_sweep(ctx, IntegratorKind::SymplecticEuler)
                }
                IntegratorKind::PositionVerlet => {
                    |ctx| hard_cases::stable_dt_sweep(ctx, IntegratorKind::PositionVerlet)
                }
                IntegratorKind::Leapfrog => |ctx| hard_cases::stable_dt_sweep(ctx, IntegratorKind::Leapfrog),
                IntegratorKind::VelocityVerlet => {
                    |ctx| hard_cases::stable_dt_sweep(ctx, IntegratorKind::VelocityVerlet)
                }
                _ => |ctx| hard_cases::stable_dt_sweep(ctx, IntegratorKind::Rk4),
            },
        });
    }
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "backward Euler, cloth with k = 1e6, m = 1e-3 at dt = 1/30 s",
        expected: || Outcome::Stable(String::new()),
        run: hard_cases::stiff_backward_euler,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "zero-length and coincident-particle springs, every integrator",
        expected: || Outcome::Stable(String::new()),
        run: hard_cases::degenerate_springs,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "symplectic Euler on a chain at dt = 3 sqrt(m/k)",
        expected: || Outcome::Diverged(String::new()),
        run: hard_cases::explicit_divergence,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "particles thrown at a 1 cm mesh plate: the speed the penalty catches",
        expected: || Outcome::Stable(String::new()),
        run: thin_plate::thin_mesh_plate,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "mesh with a zero-area triangle",
        expected: || Outcome::Rejected(String::new()),
        run: hard_cases::degenerate_mesh,
    });

    r.studies.push(Study {
        crate_name: CRATE,
        name: "integrators and linear solvers on the cloth",
        run: study::cloth_study,
    });
    r.study_uses.push(StudyUse {
        problem: study::study_problem,
        ..StudyUse::scene("springs-cloth", "springs/hanging-cloth", Some(0.25))
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "determinism: 110 x 110 hanging cloth on 1, 2, 4 threads",
        run: Box::new(determinism::cloth),
    });
    r.soak.push(soak::STIFF_CLOTH);
    roofline::register(r);
}

anim_core::quick_cases_test!(crate::cases::register);
