//! The integrators on the harmonic oscillator and the Kepler orbit: convergence orders, energy
//! behaviour over long runs, stability bounds, and the stiff, NaN and zero-step hard cases.

use super::{CRATE, MechanicalDyn, build, kepler_run, oscillator_run, theory_order};
use crate::cases::{Check, Ctx, Judge, Outcome, fmt_num, nan_max};
use crate::integrate::study::fit_order;
use crate::integrate::systems::{HarmonicOscillator, KeplerOrbit};
use crate::integrate::{IntegrateError, IntegratorKind, SecondOrderSystem, State};
use std::f64::consts::PI;

fn order_checks(
    case: &str,
    source: &'static str,
    steps_for: impl Fn(IntegratorKind) -> Vec<usize>,
    run: impl Fn(IntegratorKind, usize) -> (f64, f64),
) -> Vec<Check> {
    IntegratorKind::ALL
        .iter()
        .map(|&kind| {
            let (dts, errs): (Vec<f64>, Vec<f64>) = steps_for(kind).into_iter().map(|n| run(kind, n)).unzip();
            Check {
                crate_name: CRATE,
                case: format!("{case} / {}", kind.label()),
                metric: format!("order (error {} at finest dt)", fmt_num(*errs.last().unwrap_or(&f64::NAN))),
                measured: fit_order(&dts, &errs),
                reference: theory_order(kind),
                tolerance: 0.15,
                judge: Judge::Near,
                source,
            }
        })
        .collect()
}

pub(super) fn oscillator_orders(ctx: &Ctx) -> Vec<Check> {
    let doublings = if ctx.quick { 4 } else { 6 };
    order_checks(
        "oscillator",
        "exact solution x = cos t, t = 1.3 periods",
        |kind| {
            let base = if kind == IntegratorKind::Rk4 { 40 } else { 400 };
            (0..doublings).map(|i| base << i).collect()
        },
        |kind, n| (2.6 * PI / n as f64, oscillator_run(kind, n, 1.3)),
    )
}

pub(super) fn kepler_orders(ctx: &Ctx) -> Vec<Check> {
    let doublings = if ctx.quick { 4 } else { 5 };
    order_checks(
        "kepler e=0.5",
        "Kepler's equation, t = 1.3 orbits",
        |kind| {
            let base = if kind == IntegratorKind::Rk4 { 400 } else { 4000 };
            (0..doublings).map(|i| base << i).collect()
        },
        |kind, n| (2.6 * PI / n as f64, kepler_run(kind, n, 1.3)),
    )
}

/// Max |E - E0| over the first and the last tenth of a long run.
fn energy_window(
    kind: IntegratorKind,
    sys: &mut (dyn MechanicalDyn + 'static),
    mut state: State,
    dt: f64,
    steps: usize,
) -> (f64, f64) {
    let mut integ = build(kind, state.dof());
    let e0 = sys.energy(0.0, &state.x, &state.v).unwrap_or(f64::NAN);
    let (mut first, mut last) = (0.0f64, 0.0f64);
    for i in 0..steps {
        if integ.step(sys, &mut state, dt).is_err() {
            return (first, f64::INFINITY);
        }
        let err = (sys.energy(state.t, &state.x, &state.v).unwrap_or(f64::NAN) - e0).abs();
        if i < steps / 10 {
            first = nan_max(first, err);
        } else if i >= steps - steps / 10 {
            last = nan_max(last, err);
        }
    }
    (first, last)
}

pub(super) fn energy_behaviour(_ctx: &Ctx) -> Vec<Check> {
    let steps = 100_000;
    let mut checks = Vec::new();
    for kind in IntegratorKind::ALL {
        let symplectic = kind.is_symplectic();
        if !(symplectic || kind == IntegratorKind::ExplicitEuler) {
            continue;
        }
        let (first, last) = energy_window(
            kind,
            &mut HarmonicOscillator::new(1.0, 1.0),
            State::new(vec![1.0], vec![0.0]),
            0.05,
            steps,
        );
        if symplectic {
            checks.push(Check {
                crate_name: CRATE,
                case: format!("oscillator energy, dt = 0.05 / {}", kind.label()),
                metric: format!(
                    "no drift: max |dE| last tenth / (1.05 max |dE| first tenth + 1e-11 |E0|) (max |dE| = {})",
                    fmt_num(last)
                ),
                measured: last / (1.05 * first + 1e-11 * 0.5),
                reference: 1.0,
                tolerance: 1.0,
                judge: Judge::AtMost,
                source: "bounded energy error of symplectic maps",
            });
        } else {
            checks.push(Check {
                crate_name: CRATE,
                case: format!("oscillator energy, dt = 0.05 / {}", kind.label()),
                metric: "max |dE| last tenth / first tenth (must grow)".into(),
                measured: if first.is_nan() || last.is_nan() {
                    f64::NAN
                } else if last.is_finite() {
                    last / first
                } else {
                    f64::MAX
                },
                reference: 1.0,
                tolerance: 100.0,
                judge: Judge::AtLeast,
                source: "|1 + i h| > 1: explicit Euler gains energy",
            });
        }
    }
    for kind in
        [IntegratorKind::SymplecticEuler, IntegratorKind::VelocityVerlet, IntegratorKind::ImplicitMidpoint]
    {
        let orbit = KeplerOrbit::ellipse(0.5);
        let (x0, v0) = orbit.initial();
        let (first, last) = energy_window(
            kind,
            &mut orbit.clone(),
            State::new(x0.to_vec(), v0.to_vec()),
            2.0 * PI / 2000.0,
            steps,
        );
        checks.push(Check {
            crate_name: CRATE,
            case: format!("kepler energy, 50 orbits / {}", kind.label()),
            metric: format!(
                "no drift: max |dE| last tenth / (1.05 max |dE| first tenth + 1e-11 |E0|) (max |dE| = {})",
                fmt_num(last)
            ),
            measured: last / (1.05 * first + 1e-11 * 0.5),
            reference: 1.0,
            tolerance: 1.0,
            judge: Judge::AtMost,
            source: "bounded energy error of symplectic maps",
        });
    }
    checks
}

pub(super) fn stiff_oscillator(kind: IntegratorKind) -> Outcome {
    // omega = 1000, dt = 0.1: omega dt = 100, far beyond explicit stability (omega dt < 2).
    let mut sys = HarmonicOscillator::new(1e-3, 1e3);
    let mut state = State::new(vec![1.0], vec![0.0]);
    let mut integ = build(kind, 1);
    let e0 = sys.energy(0.0, &state.x, &state.v).unwrap_or(f64::NAN);
    for step in 0..10_000 {
        if let Err(e) = integ.step(&mut sys, &mut state, 0.1) {
            return Outcome::Diverged(format!("detected at step {step}: {e}"));
        }
        let e = sys.energy(0.0, &state.x, &state.v).unwrap_or(f64::NAN);
        if e > 1e6 * e0 {
            return Outcome::Diverged(format!("energy grew by {:.1e} at step {step}; stopped", e / e0));
        }
    }
    let e = sys.energy(0.0, &state.x, &state.v).unwrap_or(f64::NAN);
    Outcome::Stable(format!("10^4 steps, energy ratio E/E0 = {}", fmt_num(e / e0)))
}

/// Largest stable omega*dt found by bisection, for k over 6 decades; compares with `theory`.
pub(super) fn stability_bound(kind: IntegratorKind, theory: f64) -> Outcome {
    let mut worst: f64 = 0.0;
    let mut found = Vec::new();
    for decade in 0..=6 {
        let k = 10f64.powi(decade);
        let omega = k.sqrt(); // m = 1
        let stable = |dt: f64| {
            let mut sys = HarmonicOscillator::new(1.0, k);
            let mut state = State::new(vec![1.0], vec![0.0]);
            let mut integ = build(kind, 1);
            for _ in 0..2000 {
                if integ.step(&mut sys, &mut state, dt).is_err() || state.x[0].abs() > 10.0 {
                    return false;
                }
            }
            true
        };
        let (mut lo, mut hi) = (0.1 / omega, 4.0 / omega);
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            if stable(mid) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let c = lo * omega;
        found.push(c);
        worst = worst.max((c - theory).abs() / theory);
    }
    let c_mean = found.iter().sum::<f64>() / found.len() as f64;
    let detail = format!(
        "max stable omega*dt = {:.4} (theory {theory:.4}, worst relative deviation {:.1e}), i.e. dt <= c sqrt(m/k) with c = {:.4}",
        c_mean, worst, c_mean
    );
    if worst < 0.02 {
        Outcome::Stable(detail)
    } else {
        Outcome::Diverged(format!("bound off theory: {detail}"))
    }
}

pub(super) fn nan_force() -> Outcome {
    struct NanAfter(usize);
    impl SecondOrderSystem for NanAfter {
        fn dof(&self) -> usize {
            2
        }
        fn acceleration(&mut self, t: f64, _x: &[f64], _v: &[f64], a: &mut [f64]) {
            a[0] = -1.0;
            a[1] = if t > 0.05 * self.0 as f64 { f64::NAN } else { 0.0 };
        }
    }
    let mut integ = match IntegratorKind::VelocityVerlet.build_explicit::<NanAfter>(2) {
        Some(i) => i,
        None => return Outcome::Stable("no explicit integrator".into()),
    };
    let mut state = State::new(vec![0.0; 2], vec![0.0; 2]);
    let mut sys = NanAfter(10);
    for _ in 0..100 {
        if let Err(e) = integ.step(&mut sys, &mut state, 0.05) {
            let kept = state.x.iter().chain(&state.v).all(|v| v.is_finite());
            return Outcome::Diverged(format!("{e}; previous state kept finite: {kept}"));
        }
    }
    Outcome::Stable("NaN not detected".into())
}

pub(super) fn zero_dt() -> Outcome {
    let mut sys = HarmonicOscillator::new(1.0, 1.0);
    let mut state = State::new(vec![1.0], vec![0.0]);
    let mut integ = build(IntegratorKind::Rk4, 1);
    match integ.step(&mut sys, &mut state, 0.0) {
        Err(e @ IntegrateError::BadTimeStep { .. }) => Outcome::Rejected(e.to_string()),
        Err(e) => Outcome::Diverged(e.to_string()),
        Ok(_) => Outcome::Stable("dt = 0 accepted".into()),
    }
}
