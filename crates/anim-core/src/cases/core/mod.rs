//! anim-core's own cases: integrators on the harmonic oscillator and the Kepler orbit, Lie-group
//! identities, the 3x3 SVD, determinism across thread counts, the Kepler soak run, and the
//! work-precision of a mesh obstacle's distance field.

mod determinism;
mod distance;
mod integrators;
mod lie_svd;
mod soak;
mod study;

pub use study::{KEPLER_HORIZON, OSCILLATOR_HORIZON};

use crate::cases::{ConformanceCase, Outcome, Registry, StabilityCase, Study, StudyUse};
use crate::integrate::study::advance;
use crate::integrate::systems::{HarmonicOscillator, KeplerOrbit};
use crate::integrate::{Integrator, IntegratorKind, NewtonParams, State};
use crate::linalg::LinearSolverKind;
use std::f64::consts::PI;

const CRATE: &str = "anim-core";

/// Registers anim-core's cases: conformance, hard cases, studies, the determinism check and the
/// soak run.
pub fn register(r: &mut Registry) {
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "oscillator convergence order",
        run: Box::new(integrators::oscillator_orders),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "kepler convergence order",
        run: Box::new(integrators::kepler_orders),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "energy behaviour over 1e5 steps",
        run: Box::new(integrators::energy_behaviour),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "SO(3)/SE(3) exp-log identities",
        run: Box::new(lie_svd::lie_identities),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "3x3 SVD reconstruction",
        run: Box::new(lie_svd::svd_checks),
    });

    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "explicit Euler, stiff oscillator omega*dt = 100",
        expected: || Outcome::Diverged(String::new()),
        run: |_| integrators::stiff_oscillator(IntegratorKind::ExplicitEuler),
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "symplectic Euler, stiff oscillator omega*dt = 100",
        expected: || Outcome::Diverged(String::new()),
        run: |_| integrators::stiff_oscillator(IntegratorKind::SymplecticEuler),
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "backward Euler, stiff oscillator omega*dt = 100",
        expected: || Outcome::Stable(String::new()),
        run: |_| integrators::stiff_oscillator(IntegratorKind::BackwardEuler),
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "implicit midpoint, stiff oscillator omega*dt = 100",
        expected: || Outcome::Stable(String::new()),
        run: |_| integrators::stiff_oscillator(IntegratorKind::ImplicitMidpoint),
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "symplectic-Euler stability bound omega*dt < 2 over 6 decades of k",
        expected: || Outcome::Stable(String::new()),
        run: |_| integrators::stability_bound(IntegratorKind::SymplecticEuler, 2.0),
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "velocity-Verlet stability bound omega*dt < 2 over 6 decades of k",
        expected: || Outcome::Stable(String::new()),
        run: |_| integrators::stability_bound(IntegratorKind::VelocityVerlet, 2.0),
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "RK4 stability bound omega*dt < 2.8284 over 6 decades of k",
        expected: || Outcome::Stable(String::new()),
        run: |_| integrators::stability_bound(IntegratorKind::Rk4, 2.0 * 2f64.sqrt()),
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "force returning NaN",
        expected: || Outcome::Diverged(String::new()),
        run: |_| integrators::nan_force(),
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "time step dt = 0",
        expected: || Outcome::Rejected(String::new()),
        run: |_| integrators::zero_dt(),
    });

    r.studies.push(Study {
        crate_name: CRATE,
        name: "integrators on the harmonic oscillator",
        run: study::oscillator_study,
    });
    r.studies.push(Study {
        crate_name: CRATE,
        name: "integrators on the Kepler orbit",
        run: study::kepler_study,
    });
    r.studies.push(Study {
        crate_name: CRATE,
        name: "distance field of a mesh obstacle",
        run: distance::distance_field_study,
    });
    // `anim run --tolerance` picks an integrator for the oscillator and Kepler kinds from these.
    r.study_uses.push(StudyUse::scene("core-oscillator", "harmonic-oscillator", Some(OSCILLATOR_HORIZON)));
    r.study_uses.push(StudyUse::scene("core-kepler", "kepler-orbit", Some(KEPLER_HORIZON)));

    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "determinism: 40k-dof chain on 1, 2, 4 threads",
        run: Box::new(determinism::chain),
    });
    r.soak.push(soak::KEPLER);
}

pub(crate) fn theory_order(kind: IntegratorKind) -> f64 {
    f64::from(kind.order())
}

pub(crate) fn build(kind: IntegratorKind, dof: usize) -> Box<dyn Integrator<dyn MechanicalDyn> + Send> {
    kind.build_with(dof, NewtonParams::with_tolerance(1e-13), LinearSolverKind::Cg)
}

/// Object-safe alias so the oscillator and the orbit share one builder.
pub(crate) trait MechanicalDyn: crate::integrate::MechanicalSystem {}
impl<T: crate::integrate::MechanicalSystem> MechanicalDyn for T {}

/// Runs `kind` on the unit oscillator for `periods` periods in `steps` steps; returns the error
/// of (x, v) against the exact solution.
pub(crate) fn oscillator_run(kind: IntegratorKind, steps: usize, periods: f64) -> f64 {
    let mut sys = HarmonicOscillator::new(1.0, 1.0);
    let mut state = State::new(vec![1.0], vec![0.0]);
    let mut integ = build(kind, 1);
    let t_end = 2.0 * PI * periods;
    let sys_dyn: &mut dyn MechanicalDyn = &mut sys;
    if advance(integ.as_mut(), sys_dyn, &mut state, t_end / steps as f64, steps).is_err() {
        return f64::NAN;
    }
    let (xe, ve) = sys.exact(1.0, 0.0, t_end);
    ((state.x[0] - xe).powi(2) + (state.v[0] - ve).powi(2)).sqrt()
}

pub(crate) fn kepler_run(kind: IntegratorKind, steps: usize, orbits: f64) -> f64 {
    let mut sys = KeplerOrbit::ellipse(0.5);
    let (x0, v0) = sys.initial();
    let mut state = State::new(x0.to_vec(), v0.to_vec());
    let mut integ = build(kind, 2);
    let t_end = sys.period() * orbits;
    let sys_dyn: &mut dyn MechanicalDyn = &mut sys;
    if advance(integ.as_mut(), sys_dyn, &mut state, t_end / steps as f64, steps).is_err() {
        return f64::NAN;
    }
    let (xe, _) = sys.exact(t_end);
    ((state.x[0] - xe[0]).powi(2) + (state.x[1] - xe[1]).powi(2)).sqrt()
}
