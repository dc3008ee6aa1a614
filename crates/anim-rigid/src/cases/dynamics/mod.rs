//! Dynamics: RNEA, CRBA, the bias and gravity terms, ABA and the energies against Pinocchio on
//! the Panda, the UR5, a generated 32-joint chain and the floating-base Panda; the algorithms
//! against each other (closure of `H q'' + C = tau`, ABA inverting RNEA, CRBA columns from RNEA,
//! ABA against the Cholesky forward dynamics, `H` symmetric positive definite); the steppers'
//! orders; the Dzhanibekov flip period against Euler's top; the energy balance with torques,
//! damping and limits ([`conformance`]). Hard cases: the torque-free spinning body over 1e5 steps
//! per stepper, a 100-link chain, a 1e-4 mass-ratio chain, joints driven into their limits, a
//! massless leaf ([`hard_cases`]). The accuracy of the two forms of ABA on iCub, TIAGo and the
//! human model against an exact solve, beside Pinocchio's ([`aba_accuracy`]). Study:
//! work-precision of the steppers on the 32-link pendulum chain ([`study`]).

mod aba_accuracy;
mod conformance;
mod hard_cases;
mod study;

use crate::sim::RigidIntegrator;
use anim_core::cases::{ConformanceCase, Outcome, Registry, StabilityCase, Study};

use crate::cases::CRATE;

/// Registers the dynamics cases: conformance, hard cases, then the steppers' study.
pub(super) fn register(r: &mut Registry) {
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "RNEA, CRBA, C, g, ABA vs Pinocchio (Panda, UR5, chain32, floating Panda)",
        run: Box::new(conformance::pinocchio_dynamics),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "ABA local and world vs an exact solve, with Pinocchio's (iCub, TIAGo, human)",
        run: Box::new(aba_accuracy::aba_accuracy),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "dynamics cross-checks (closure, ABA/RNEA, CRBA/RNEA, Cholesky, H SPD)",
        run: Box::new(conformance::cross_checks),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "rigid steppers: measured orders of accuracy",
        run: Box::new(conformance::stepper_orders),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "T-handle: Dzhanibekov flip and Euler-top period",
        run: Box::new(conformance::t_handle_period),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "energy balance with torques, damping and limits (UR5)",
        run: Box::new(conformance::energy_balance),
    });
    for integrator in RigidIntegrator::ALL {
        r.stability.push(StabilityCase {
            crate_name: CRATE,
            name: match integrator {
                RigidIntegrator::FreeBodyMidpoint => {
                    "torque-free T-handle, 1e5 steps of 1 ms: free-body midpoint (default), E and L drift"
                }
                RigidIntegrator::ImplicitMidpoint => {
                    "torque-free T-handle, 1e5 steps of 1 ms: implicit midpoint, E and L drift"
                }
                RigidIntegrator::Rk4 => "torque-free T-handle, 1e5 steps of 1 ms: RK4 (CF4), E and L drift",
                RigidIntegrator::SymplecticEuler => {
                    "torque-free T-handle, 1e5 steps of 1 ms: symplectic Euler, E and L drift"
                }
                RigidIntegrator::ExplicitEuler => {
                    "torque-free T-handle, 1e5 steps of 1 ms: explicit Euler, E and L drift"
                }
            },
            // For a free body the velocity update of both Euler steppers is explicit Euler on
            // Euler's equations (the acceleration does not depend on q), whose energy grows
            // every step: both drift beyond 1e-2 and are reported as diverged.
            expected: match integrator {
                RigidIntegrator::ExplicitEuler | RigidIntegrator::SymplecticEuler => {
                    || Outcome::Diverged(String::new())
                }
                _ => || Outcome::Stable(String::new()),
            },
            run: match integrator {
                RigidIntegrator::FreeBodyMidpoint => {
                    |_| hard_cases::spinning_drift(RigidIntegrator::FreeBodyMidpoint)
                }
                RigidIntegrator::ImplicitMidpoint => {
                    |_| hard_cases::spinning_drift(RigidIntegrator::ImplicitMidpoint)
                }
                RigidIntegrator::Rk4 => |_| hard_cases::spinning_drift(RigidIntegrator::Rk4),
                RigidIntegrator::SymplecticEuler => {
                    |_| hard_cases::spinning_drift(RigidIntegrator::SymplecticEuler)
                }
                RigidIntegrator::ExplicitEuler => {
                    |_| hard_cases::spinning_drift(RigidIntegrator::ExplicitEuler)
                }
            },
        });
    }
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "100-link pendulum chain released horizontal, 1 s (0.25 s with --quick), implicit midpoint, 1 ms",
        expected: || Outcome::Stable(String::new()),
        run: hard_cases::long_chain,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "chain with a 1e-4 link-mass ratio (alternating 1 kg and 0.1 g), 1 s (0.25 s with --quick)",
        expected: || Outcome::Stable(String::new()),
        run: hard_cases::mass_ratio_chain,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "Panda started at its joint limits, driven into them (penalty limits), 2 s",
        expected: || Outcome::Stable(String::new()),
        run: |_| hard_cases::panda_at_limits(),
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "chain with a massless leaf body (singular articulated inertia)",
        expected: || Outcome::Diverged(String::new()),
        run: |_| hard_cases::massless_leaf(),
    });
    r.studies.push(Study {
        crate_name: CRATE,
        name: "rigid steppers on the 32-link pendulum chain",
        run: study::chain_study,
    });
}
