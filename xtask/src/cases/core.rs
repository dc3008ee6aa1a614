//! anim-core: integrators on the harmonic oscillator and the Kepler orbit, Lie-group identities,
//! the 3x3 SVD.

use crate::registry::{
    Check, ConformanceCase, Ctx, Judge, Outcome, Point, Registry, Series, StabilityCase, Study, StudyResult,
    median_seconds,
};
use anim_core::glam::{DMat3, DVec3, Mat3};
use anim_core::integrate::study::{advance, fit_order};
use anim_core::integrate::systems::{HarmonicOscillator, KeplerOrbit};
use anim_core::integrate::{
    IntegrateError, Integrator, IntegratorKind, NewtonParams, SecondOrderSystem, State,
};
use anim_core::lie::{Se3, Twist, so3};
use anim_core::linalg::{LinearSolverKind, svd3, svd3_f32};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::PI;

const CRATE: &str = "anim-core";

pub fn register(r: &mut Registry) {
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "oscillator convergence order",
        run: Box::new(oscillator_orders),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "kepler convergence order",
        run: Box::new(kepler_orders),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "energy behaviour over 1e5 steps",
        run: Box::new(energy_behaviour),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "SO(3)/SE(3) exp-log identities",
        run: Box::new(lie_identities),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "3x3 SVD reconstruction",
        run: Box::new(svd_checks),
    });

    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "explicit Euler, stiff oscillator omega*dt = 100",
        expected: || Outcome::Diverged(String::new()),
        run: |_| stiff_oscillator(IntegratorKind::ExplicitEuler),
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "symplectic Euler, stiff oscillator omega*dt = 100",
        expected: || Outcome::Diverged(String::new()),
        run: |_| stiff_oscillator(IntegratorKind::SymplecticEuler),
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "backward Euler, stiff oscillator omega*dt = 100",
        expected: || Outcome::Stable(String::new()),
        run: |_| stiff_oscillator(IntegratorKind::BackwardEuler),
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "implicit midpoint, stiff oscillator omega*dt = 100",
        expected: || Outcome::Stable(String::new()),
        run: |_| stiff_oscillator(IntegratorKind::ImplicitMidpoint),
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "symplectic-Euler stability bound omega*dt < 2 over 6 decades of k",
        expected: || Outcome::Stable(String::new()),
        run: |_| stability_bound(IntegratorKind::SymplecticEuler, 2.0),
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "velocity-Verlet stability bound omega*dt < 2 over 6 decades of k",
        expected: || Outcome::Stable(String::new()),
        run: |_| stability_bound(IntegratorKind::VelocityVerlet, 2.0),
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "RK4 stability bound omega*dt < 2.8284 over 6 decades of k",
        expected: || Outcome::Stable(String::new()),
        run: |_| stability_bound(IntegratorKind::Rk4, 2.0 * 2f64.sqrt()),
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "force returning NaN",
        expected: || Outcome::Diverged(String::new()),
        run: |_| nan_force(),
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "time step dt = 0",
        expected: || Outcome::Rejected(String::new()),
        run: |_| zero_dt(),
    });

    r.studies.push(Study {
        crate_name: CRATE,
        name: "integrators on the harmonic oscillator",
        run: oscillator_study,
    });
    r.studies.push(Study { crate_name: CRATE, name: "integrators on the Kepler orbit", run: kepler_study });
}

fn theory_order(kind: IntegratorKind) -> f64 {
    f64::from(kind.order())
}

fn build(kind: IntegratorKind, dof: usize) -> Box<dyn Integrator<dyn MechanicalDyn> + Send> {
    kind.build_with(dof, NewtonParams::with_tolerance(1e-13), LinearSolverKind::Cg)
}

/// Object-safe alias so the oscillator and the orbit share one builder.
pub trait MechanicalDyn: anim_core::integrate::MechanicalSystem {}
impl<T: anim_core::integrate::MechanicalSystem> MechanicalDyn for T {}

/// Runs `kind` on the unit oscillator for `periods` periods in `steps` steps; returns the error
/// of (x, v) against the exact solution.
fn oscillator_run(kind: IntegratorKind, steps: usize, periods: f64) -> f64 {
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

fn kepler_run(kind: IntegratorKind, steps: usize, orbits: f64) -> f64 {
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
                metric: format!(
                    "order (error {} at finest dt)",
                    crate::registry::fmt_num(*errs.last().unwrap_or(&f64::NAN))
                ),
                measured: fit_order(&dts, &errs),
                reference: theory_order(kind),
                tolerance: 0.15,
                judge: Judge::Near,
                source,
            }
        })
        .collect()
}

fn oscillator_orders(ctx: &Ctx) -> Vec<Check> {
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

fn kepler_orders(ctx: &Ctx) -> Vec<Check> {
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
            first = first.max(err);
        } else if i >= steps - steps / 10 {
            last = last.max(err);
        }
    }
    (first, last)
}

fn energy_behaviour(_ctx: &Ctx) -> Vec<Check> {
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
                    crate::registry::fmt_num(last)
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
                measured: if last.is_finite() { last / first } else { f64::MAX },
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
                crate::registry::fmt_num(last)
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

fn random_unit(rng: &mut ChaCha8Rng) -> DVec3 {
    loop {
        let v =
            DVec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
        let n = v.length();
        if n > 1e-3 && n <= 1.0 {
            return v / n;
        }
    }
}

fn frob(m: DMat3) -> f64 {
    m.to_cols_array().iter().map(|x| x * x).sum::<f64>().sqrt()
}

fn lie_identities(_ctx: &Ctx) -> Vec<Check> {
    let samples = 100_000;
    let mut rng = ChaCha8Rng::seed_from_u64(0x11e);
    let mut exp_log = 0.0f64;
    let mut log_exp = 0.0f64;
    let mut se3_round = 0.0f64;
    for _ in 0..samples {
        let w = random_unit(&mut rng) * rng.random_range(0.0..PI);
        let r = so3::exp(w);
        exp_log = exp_log.max(frob(so3::exp(so3::log(r)) - r));
        if w.length() < PI - 1e-6 {
            log_exp = log_exp.max((so3::log(r) - w).length());
        }
        let xi = Twist::new(
            DVec3::new(rng.random_range(-2.0..2.0), rng.random_range(-2.0..2.0), rng.random_range(-2.0..2.0)),
            w,
        );
        let back = Se3::exp(xi).log();
        se3_round = se3_round.max((back.v - xi.v).length().max((back.w - xi.w).length()));
    }
    let mut edge = 0.0f64;
    let axes = [
        DVec3::X,
        DVec3::Y,
        DVec3::Z,
        DVec3::new(1.0, 1.0, 0.0).normalize(),
        DVec3::new(1.0, -2.0, 3.0).normalize(),
    ];
    for axis in axes {
        for angle in [0.0, 1e-12, 1e-9, 1e-6, 1.0, PI - 1e-6, PI - 1e-9, PI] {
            let r = so3::exp(axis * angle);
            edge = edge.max(frob(so3::exp(so3::log(r)) - r));
        }
    }
    let mk = |case: &str, metric: &str, measured: f64| Check {
        crate_name: CRATE,
        case: case.into(),
        metric: metric.into(),
        measured,
        reference: 0.0,
        tolerance: 1e-12,
        judge: Judge::AtMost,
        source: "group identity",
    };
    vec![
        mk("SO(3) exp(log R) = R, 1e5 random", "max Frobenius error", exp_log),
        mk(
            "SO(3) exp(log R) = R, angles 0, 1e-12, 1e-9, 1e-6, pi-1e-6, pi-1e-9, pi",
            "max Frobenius error",
            edge,
        ),
        mk("SO(3) log(exp w) = w, |w| < pi, 1e5 random", "max |error|", log_exp),
        mk("SE(3) log(exp xi) = xi, 1e5 random", "max |error|", se3_round),
    ]
}

#[derive(Clone, Copy)]
enum Category {
    Random,
    Rank2,
    Rank1,
    Repeated,
    Reflected,
    NearIdentity,
}

const CATEGORIES: [(Category, &str); 6] = [
    (Category::Random, "random"),
    (Category::Rank2, "rank 2"),
    (Category::Rank1, "rank 1"),
    (Category::Repeated, "repeated singular values"),
    (Category::Reflected, "reflected (det < 0)"),
    (Category::NearIdentity, "near identity"),
];

fn sample_matrix(rng: &mut ChaCha8Rng, cat: Category) -> DMat3 {
    let rot = |rng: &mut ChaCha8Rng| so3::exp(random_unit(rng) * rng.random_range(0.0..PI));
    let (u, v) = (rot(rng), rot(rng));
    let mut s =
        DVec3::new(rng.random_range(0.1..3.0), rng.random_range(0.1..3.0), rng.random_range(0.1..3.0));
    match cat {
        Category::Random => {
            return DMat3::from_cols_array(&std::array::from_fn(|_| rng.random_range(-1.0..1.0)));
        }
        Category::Rank2 => s.z = 0.0,
        Category::Rank1 => {
            s.y = 0.0;
            s.z = 0.0
        }
        Category::Repeated => {
            s.y = s.x;
            if rng.random_bool(0.5) {
                s.z = s.x;
            }
        }
        Category::Reflected => s.z = -s.z,
        Category::NearIdentity => {
            return DMat3::IDENTITY
                + DMat3::from_cols_array(&std::array::from_fn(|_| rng.random_range(-1e-6..1e-6)));
        }
    }
    u * DMat3::from_diagonal(s) * v.transpose()
}

fn svd_checks(_ctx: &Ctx) -> Vec<Check> {
    let samples = 20_000;
    let mut rng = ChaCha8Rng::seed_from_u64(0x5_7D);
    let mut checks = Vec::new();
    for (cat, name) in CATEGORIES {
        let (mut e64, mut e32, mut orth, mut bad_det) = (0.0f64, 0.0f64, 0.0f64, 0usize);
        for _ in 0..samples {
            let a = sample_matrix(&mut rng, cat);
            let s = svd3(a);
            let rec = s.u * DMat3::from_diagonal(s.sigma) * s.v.transpose();
            e64 = e64.max(frob(rec - a) / frob(a).max(1e-300));
            orth = orth
                .max(frob(s.u.transpose() * s.u - DMat3::IDENTITY))
                .max(frob(s.v.transpose() * s.v - DMat3::IDENTITY));
            if (s.u.determinant() - 1.0).abs() > 1e-9 || (s.v.determinant() - 1.0).abs() > 1e-9 {
                bad_det += 1;
            }
            let af = a.as_mat3();
            let sf = svd3_f32(af);
            let recf = sf.u * Mat3::from_diagonal(sf.sigma) * sf.v.transpose();
            let errf = (recf - af).to_cols_array().iter().map(|x| x * x).sum::<f32>().sqrt()
                / af.to_cols_array().iter().map(|x| x * x).sum::<f32>().sqrt().max(1e-30);
            e32 = e32.max(f64::from(errf));
        }
        let mk = |metric: &str, measured: f64, tol: f64| Check {
            crate_name: CRATE,
            case: format!("SVD {name}, {samples} samples"),
            metric: metric.into(),
            measured,
            reference: 0.0,
            tolerance: tol,
            judge: Judge::AtMost,
            source: "A = U S V^T, U, V proper rotations",
        };
        checks.push(mk("f64 max relative reconstruction error", e64, 1e-12));
        checks.push(mk("f64 max |U^T U - I|, |V^T V - I|", orth, 1e-12));
        checks.push(mk("f64 count det U or det V != +1", bad_det as f64, 0.0));
        checks.push(mk("f32 max relative reconstruction error", e32, 1e-5));
    }
    checks
}

fn stiff_oscillator(kind: IntegratorKind) -> Outcome {
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
    Outcome::Stable(format!("10^4 steps, energy ratio E/E0 = {}", crate::registry::fmt_num(e / e0)))
}

/// Largest stable omega*dt found by bisection, for k over 6 decades; compares with `theory`.
fn stability_bound(kind: IntegratorKind, theory: f64) -> Outcome {
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

fn nan_force() -> Outcome {
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

fn zero_dt() -> Outcome {
    let mut sys = HarmonicOscillator::new(1.0, 1.0);
    let mut state = State::new(vec![1.0], vec![0.0]);
    let mut integ = build(IntegratorKind::Rk4, 1);
    match integ.step(&mut sys, &mut state, 0.0) {
        Err(e @ IntegrateError::BadTimeStep { .. }) => Outcome::Rejected(e.to_string()),
        Err(e) => Outcome::Diverged(e.to_string()),
        Ok(_) => Outcome::Stable("dt = 0 accepted".into()),
    }
}

fn study(
    ctx: &Ctx,
    title: &str,
    slug: &str,
    error_label: &str,
    steps_for: impl Fn(IntegratorKind) -> Vec<usize>,
    run: impl Fn(IntegratorKind, usize) -> f64,
    horizon: f64,
) -> StudyResult {
    let (batches, min_batch) = if ctx.quick { (3, 0.002) } else { (7, 0.02) };
    let series = IntegratorKind::ALL
        .iter()
        .map(|&kind| {
            let points = steps_for(kind)
                .into_iter()
                .map(|n| {
                    let error = run(kind, n);
                    let seconds = median_seconds(batches, min_batch, || {
                        std::hint::black_box(run(kind, n));
                    });
                    Point { param: horizon / n as f64, seconds, error }
                })
                .collect();
            Series { label: kind.label(), points }
        })
        .collect();
    StudyResult {
        title: title.into(),
        slug: slug.into(),
        error_label: error_label.into(),
        param_label: "dt".into(),
        series,
    }
}

/// Simulated time of the oscillator study (`m = k = 1`, so 10.3 periods), the horizon its
/// cheapest-method table holds for.
pub const OSCILLATOR_HORIZON: f64 = 20.6 * PI;

/// Simulated time of the Kepler study (`a = mu = 1`, period `2 pi`: 1.3 orbits).
pub const KEPLER_HORIZON: f64 = 2.6 * PI;

fn oscillator_study(ctx: &Ctx) -> StudyResult {
    let n = if ctx.quick { 4 } else { 8 };
    study(
        ctx,
        "Harmonic oscillator, 10.3 periods: error of (x, v) against the exact solution",
        "core-oscillator",
        "|(x, v) - exact| at t = 20.6 pi",
        |_| (0..n).map(|i| 100usize << i).collect(),
        |kind, steps| oscillator_run(kind, steps, OSCILLATOR_HORIZON / (2.0 * PI)),
        OSCILLATOR_HORIZON,
    )
}

fn kepler_study(ctx: &Ctx) -> StudyResult {
    let n = if ctx.quick { 4 } else { 8 };
    study(
        ctx,
        "Kepler orbit e = 0.5, 1.3 orbits: position error against Kepler's equation",
        "core-kepler",
        "|x - exact| at t = 2.6 pi",
        |_| (0..n).map(|i| 250usize << i).collect(),
        |kind, steps| kepler_run(kind, steps, KEPLER_HORIZON / (2.0 * PI)),
        KEPLER_HORIZON,
    )
}
