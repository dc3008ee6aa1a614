//! anim-core's own scenes: the reference systems with exact solutions
//! ([`HarmonicOscillator`], [`KeplerOrbit`]) under any integrator, as two scene kinds.
//!
//! | kind | preset | what | reference |
//! | --- | --- | --- | --- |
//! | `harmonic-oscillator` | `oscillator` | a lightly damped oscillator, implicit midpoint | the exact damped solution |
//! | `kepler-orbit` | `kepler` | a planet on an `e = 0.5` ellipse, velocity Verlet, about 3 orbits | Kepler's equation |
//!
//! [`View::reference_error`] is the Euclidean distance of `(x, v)` from the exact solution.
//!
//! For `--tolerance` both kinds map the report's ODE studies ([`Tolerance`]): `core-oscillator`
//! (`m = k = 1`, times in units of `1/omega`) and `core-kepler` (`e = 0.5`, `a = mu = 1`) give
//! the integrator and `dt`, the step scaled by `(H / T)^(2/p)` when the run is longer than the
//! study's horizon; the run's error on the studies' measures is [`oscillator_error`] and
//! [`kepler_error`].

use super::checkpoint::{Checkpoint, CheckpointError, saved_state};
use super::dynamic::{DynScene, Simulated};
use super::preset::{BuildContext, BuildError, Preset, RunDefaults, SceneKind, params};
use super::study::{self, Candidate, Family, Point, StudyAdapter, Tolerance};
use super::view::{Context, Frame, Prop, View};
use crate::integrate::systems::{HarmonicOscillator, KeplerOrbit};
use crate::integrate::{IntegrateError, IntegratorKind, MechanicalSystem, Simulation, State};
use crate::solver::{Solver, StepReport};
use serde::{Deserialize, Serialize};

/// The scene kinds of anim-core, for the workspace registry.
pub const KINDS: [SceneKind; 2] = [
    SceneKind {
        kind: "harmonic-oscillator",
        crate_name: "anim-core",
        summary: "a damped harmonic oscillator m x'' = -k x - c x' with its exact solution",
        presets: oscillator_presets,
        build: build_oscillator,
        tolerance: Some(Tolerance { adapter: oscillator_adapter, error: oscillator_table_error }),
    },
    SceneKind {
        kind: "kepler-orbit",
        crate_name: "anim-core",
        summary: "a planet on an ellipse around a fixed sun (a = mu = 1), exact by Kepler's equation",
        presets: kepler_presets,
        build: build_kepler,
        tolerance: Some(Tolerance { adapter: kepler_adapter, error: kepler_table_error }),
    },
];

/// Scene-file parameters of a `harmonic-oscillator` scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OscillatorParams {
    /// Mass (> 0).
    pub mass: f64,
    /// Stiffness (> 0).
    pub stiffness: f64,
    /// Damping (>= 0). Default 0.
    #[serde(default)]
    pub damping: f64,
    /// Initial position.
    pub x0: f64,
    /// Initial velocity.
    pub v0: f64,
    /// Integrator.
    pub integrator: IntegratorKind,
}

/// Scene-file parameters of a `kepler-orbit` scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KeplerParams {
    /// Eccentricity in `[0, 1)`.
    pub eccentricity: f64,
    /// Integrator.
    pub integrator: IntegratorKind,
}

fn oscillator_presets() -> Vec<Preset> {
    vec![Preset {
        name: "oscillator",
        description: "a lightly damped harmonic oscillator, implicit midpoint",
        run: RunDefaults::new(0.01, 500, 2),
        params: serde_json::json!({
            "mass": 1.0, "stiffness": 40.0, "damping": 0.2, "x0": 1.0, "v0": 0.0,
            "integrator": "implicit-midpoint",
        }),
        quick_params: None,
    }]
}

fn kepler_presets() -> Vec<Preset> {
    vec![Preset {
        name: "kepler",
        description: "a planet on an e = 0.5 ellipse, velocity Verlet, about 3 orbits",
        run: RunDefaults::new(0.005, 400, 10),
        params: serde_json::json!({ "eccentricity": 0.5, "integrator": "velocity-verlet" }),
        quick_params: None,
    }]
}

fn positive(field: &str, x: f64) -> Result<(), BuildError> {
    if x > 0.0 && x.is_finite() {
        Ok(())
    } else {
        Err(BuildError::invalid(field, format!("must be a positive finite number, got {x}")))
    }
}

fn finite(field: &str, x: f64) -> Result<(), BuildError> {
    if x.is_finite() { Ok(()) } else { Err(BuildError::invalid(field, format!("must be finite, got {x}"))) }
}

fn build_oscillator(
    value: &serde_json::Value,
    _: &BuildContext<'_>,
) -> Result<Box<dyn DynScene>, BuildError> {
    let p: OscillatorParams = params(value)?;
    positive("mass", p.mass)?;
    positive("stiffness", p.stiffness)?;
    if !(p.damping.is_finite() && p.damping >= 0.0) {
        return Err(BuildError::invalid(
            "damping",
            format!("must be a non-negative finite number, got {}", p.damping),
        ));
    }
    finite("x0", p.x0)?;
    finite("v0", p.v0)?;
    p.integrator.validate().map_err(|m| BuildError::invalid("integrator", m))?;
    Ok(Simulated::new(ExactSystem::oscillator(&p), State::new(vec![p.x0], vec![p.v0])).boxed())
}

fn build_kepler(value: &serde_json::Value, _: &BuildContext<'_>) -> Result<Box<dyn DynScene>, BuildError> {
    let p: KeplerParams = params(value)?;
    if !(0.0..1.0).contains(&p.eccentricity) {
        return Err(BuildError::invalid(
            "eccentricity",
            format!("must lie in [0, 1), got {}", p.eccentricity),
        ));
    }
    p.integrator.validate().map_err(|m| BuildError::invalid("integrator", m))?;
    let (scene, state) = ExactSystem::kepler(&p);
    Ok(Simulated::new(scene, state).boxed())
}

/// Which reference system, with what its exact solution needs.
#[derive(Debug, Clone, Copy)]
enum Exact {
    Oscillator { system: HarmonicOscillator, x0: f64, v0: f64 },
    Kepler(KeplerOrbit),
}

/// A reference system of a few unknowns under an integrator, with its exact solution: the
/// solver of both anim-core kinds.
pub struct ExactSystem {
    sim: Simulation<dyn MechanicalSystem + Send>,
    method: String,
    exact: Exact,
    /// The plane region the motion stays in.
    extent: ([f64; 2], [f64; 2]),
}

impl ExactSystem {
    fn oscillator(p: &OscillatorParams) -> Self {
        let system = HarmonicOscillator::damped(p.mass, p.stiffness, p.damping);
        let a = p.x0.abs().max(1e-3);
        Self {
            sim: Simulation::new(Box::new(system), p.integrator.build(1)),
            method: p.integrator.label(),
            exact: Exact::Oscillator { system, x0: p.x0, v0: p.v0 },
            extent: ([-1.5 * a, -0.3 * a], [1.5 * a, 0.3 * a]),
        }
    }

    fn kepler(p: &KeplerParams) -> (Self, State) {
        let e = p.eccentricity;
        let system = KeplerOrbit::ellipse(e);
        let (x0, v0) = system.initial();
        let b = (1.0 - e * e).sqrt();
        let scene = Self {
            sim: Simulation::new(Box::new(system), p.integrator.build(2)),
            method: p.integrator.label(),
            exact: Exact::Kepler(system),
            extent: ([-1.0 - e - 0.1, -b - 0.1], [1.0 - e + 0.1, b + 0.1]),
        };
        (scene, State::new(x0.to_vec(), v0.to_vec()))
    }
}

impl Solver for ExactSystem {
    type State = State;
    type Error = IntegrateError;

    fn step(&mut self, state: &mut State, dt: f64) -> Result<StepReport, IntegrateError> {
        self.sim.step(state, dt)
    }
}

impl Checkpoint for ExactSystem {
    const VERSION: u32 = 1;

    fn time(&self, state: &State) -> f64 {
        state.t
    }

    fn save(&self, state: &State) -> serde_json::Value {
        serde_json::json!({ "state": state, "integrator": self.sim.memory() })
    }

    fn restore(&mut self, state: &mut State, saved: &serde_json::Value) -> Result<(), CheckpointError> {
        let restored = saved_state(saved, "state", state)?;
        let memory =
            saved.get("integrator").ok_or_else(|| CheckpointError::Missing { field: "integrator".into() })?;
        // The integrator's memory is checked and taken whole, or not at all.
        self.sim.restore_memory(memory).map_err(|e| CheckpointError::invalid("integrator", e.to_string()))?;
        *state = restored;
        Ok(())
    }

    fn provoke_overflow(&mut self, state: &mut State) -> Option<String> {
        // Both: a position alone gives a vanishing pull, a velocity alone a finite drift.
        state.x[0] = f64::MAX;
        state.v[0] = f64::MAX;
        Some("position and velocity 0 set to f64::MAX".into())
    }
}

impl View for ExactSystem {
    fn method(&self) -> String {
        self.method.clone()
    }

    fn context(&self, state: &State) -> Context {
        let (lo, hi) = self.extent;
        let mut context = Context {
            point_dim: state.x.len(),
            bounds: Some(([lo[0], lo[1], 0.0], [hi[0], hi[1], 0.0])),
            ..Context::default()
        };
        context.props.push(match self.exact {
            Exact::Kepler(_) => Prop::Attractor { at: [0.0; 3] },
            Exact::Oscillator { .. } => Prop::Anchor { at: [lo[0], 0.0, 0.0], point: 0 },
        });
        context
    }

    fn frame(&self, state: &State, out: &mut Frame) {
        out.time = state.t;
        out.points.clone_from(&state.x);
        out.field_mut("velocity", state.v.len()).extend_from_slice(&state.v);
    }

    fn reference_error(&self, s: &State) -> Option<f64> {
        Some(match self.exact {
            Exact::Oscillator { system, x0, v0 } => {
                let (x, v) = system.exact(x0, v0, s.t);
                ((s.x[0] - x).powi(2) + (s.v[0] - v).powi(2)).sqrt()
            }
            Exact::Kepler(system) => {
                let (x, v) = system.exact(s.t);
                let e = [x[0], x[1], v[0], v[1]];
                s.x.iter().chain(&s.v).zip(e).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt()
            }
        })
    }
}

/// The integrator a table label names.
#[must_use]
pub fn integrator(label: &str) -> Option<IntegratorKind> {
    IntegratorKind::ALL.into_iter().find(|k| k.label() == label)
}

/// The ODE studies on a scene: times in units of `1/omega` (`unit` is the scene's `omega` over
/// the study's), the study's horizon and the run's length.
struct OdeAdapter {
    unit: f64,
    horizon: f64,
    duration: f64,
}

impl StudyAdapter for OdeAdapter {
    fn candidate(&self, method: &str, point: &Point) -> Result<Candidate, String> {
        let Self { unit, horizon, duration } = *self;
        let kind = integrator(method).ok_or_else(|| study::unknown_method(method))?;
        let factor = study::horizon_factor(horizon / unit, duration, kind.order());
        let mut note = Vec::new();
        if unit != 1.0 {
            note.push(format!("1/omega = {:.4}", 1.0 / unit));
        }
        if factor != 1.0 {
            note.push(format!("run length (H/T)^(2/p) = {factor:.4}"));
        }
        let mut settings = serde_json::Map::new();
        settings.insert("integrator".into(), serde_json::to_value(kind).map_err(|e| e.to_string())?);
        Ok(Candidate {
            settings,
            summary: format!("integrator = {}", kind.label()),
            dt: Some(point.param / unit * factor),
            cost: 1.0 / factor,
            dt_swept: true,
            note: note.join(" x "),
        })
    }
}

/// The oscillator study on an oscillator scene: its times are scene times times `omega`.
fn oscillator_adapter(
    value: &serde_json::Value,
    run: &RunDefaults,
    family: &Family,
) -> Result<Box<dyn StudyAdapter>, String> {
    let p: OscillatorParams = params(value).map_err(study::unreadable)?;
    let unit = (p.stiffness / p.mass).sqrt();
    Ok(Box::new(OdeAdapter { unit, horizon: study::horizon(family)?, duration: study::duration(run) }))
}

/// The Kepler study on a Kepler scene: the study and scene share `a = mu = 1`.
fn kepler_adapter(
    value: &serde_json::Value,
    run: &RunDefaults,
    family: &Family,
) -> Result<Box<dyn StudyAdapter>, String> {
    let _: KeplerParams = params(value).map_err(study::unreadable)?;
    Ok(Box::new(OdeAdapter { unit: 1.0, horizon: study::horizon(family)?, duration: study::duration(run) }))
}

/// The state a scene's frame shows.
fn state_of(scene: &dyn DynScene) -> State {
    let mut frame = Frame::default();
    scene.frame(&mut frame);
    let v = frame.field("velocity").map(|f| f.values.clone()).unwrap_or_default();
    State { t: frame.time, x: frame.points, v }
}

fn oscillator_table_error(value: &serde_json::Value, scene: &dyn DynScene, _: Option<f64>) -> Option<f64> {
    oscillator_error(&params(value).ok()?, &state_of(scene))
}

fn kepler_table_error(value: &serde_json::Value, scene: &dyn DynScene, _: Option<f64>) -> Option<f64> {
    kepler_error(&params(value).ok()?, &state_of(scene))
}

/// The oscillator study's error of `state`: `|(x - x_e, (v - v_e)/omega)| / |(x0, v0/omega)|`
/// against the exact solution (`None` for an empty state).
#[must_use]
pub fn oscillator_error(p: &OscillatorParams, state: &State) -> Option<f64> {
    let omega = (p.stiffness / p.mass).sqrt();
    let (xe, ve) = HarmonicOscillator::damped(p.mass, p.stiffness, p.damping).exact(p.x0, p.v0, state.t);
    let scale = p.x0.hypot(p.v0 / omega);
    let (dx, dv) = (state.x.first()? - xe, (state.v.first()? - ve) / omega);
    Some(dx.hypot(dv) / scale.max(f64::MIN_POSITIVE))
}

/// The Kepler study's error of `state`: `|x - x_e|` against Kepler's equation (`None` for a
/// state of fewer than two coordinates).
#[must_use]
pub fn kepler_error(p: &KeplerParams, state: &State) -> Option<f64> {
    let (xe, _) = KeplerOrbit::ellipse(p.eccentricity).exact(state.t);
    Some((state.x.first()? - xe[0]).hypot(state.x.get(1)? - xe[1]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Frame;

    fn scene(kind: &str) -> (Box<dyn DynScene>, Preset) {
        let k = KINDS.iter().find(|k| k.kind == kind).expect("kind");
        let preset = (k.presets)().remove(0);
        ((k.build)(&preset.params, &BuildContext::default()).expect("build"), preset)
    }

    #[test]
    fn the_oscillator_follows_its_exact_solution_and_the_error_says_how_far() {
        let (mut s, preset) = scene("harmonic-oscillator");
        assert_eq!(s.reference_error(), Some(0.0));
        for _ in 0..200 {
            s.step(preset.run.dt).expect("step");
        }
        // Implicit midpoint lags in phase by omega^3 dt^2 t / 12 = 4.22e-3 rad at omega =
        // sqrt(40), dt = 0.01, t = 2 s; the error is then dominated by the velocity's,
        // phase lag x omega x amplitude e^(-c t / 2m) = 4.22e-3 x 6.32 x 0.819 = 0.0218.
        let e = s.reference_error().expect("exact");
        assert!((e / 0.0218 - 1.0).abs() < 0.1, "{e}");
        let mut f = Frame::default();
        s.frame(&mut f);
        assert_eq!((f.points.len(), f.field("velocity").map(|v| v.values.len())), (1, Some(1)));
        // The library's exact solution against the closed form written out here.
        let HarmonicOscillatorCheck { x, v } = HarmonicOscillatorCheck::at(f.time);
        let d = ((f.points[0] - x).powi(2) + (f.field("velocity").expect("v").values[0] - v).powi(2)).sqrt();
        assert!((d - e).abs() < 1e-12, "{d} {e}");
    }

    /// The preset's exact solution, written out: `x = e^(-zeta w t) (cos(w_d t) + zeta w / w_d sin(w_d t))`.
    struct HarmonicOscillatorCheck {
        x: f64,
        v: f64,
    }

    impl HarmonicOscillatorCheck {
        fn at(t: f64) -> Self {
            let (m, k, c) = (1.0f64, 40.0f64, 0.2f64);
            let gamma = c / (2.0 * m);
            let wd = (k / m - gamma * gamma).sqrt();
            let (s, co) = (wd * t).sin_cos();
            let decay = (-gamma * t).exp();
            let x = decay * (co + gamma / wd * s);
            let v = decay * (-(wd + gamma * gamma / wd) * s);
            Self { x, v }
        }
    }

    #[test]
    fn a_checkpoint_resumes_bit_for_bit_and_a_foreign_one_is_refused() {
        for kind in ["harmonic-oscillator", "kepler-orbit"] {
            let (mut a, preset) = scene(kind);
            let dt = preset.run.dt;
            for _ in 0..7 {
                a.step(dt).expect("step");
            }
            let text = a.save().to_string();
            for _ in 0..9 {
                a.step(dt).expect("step");
            }
            let (mut b, _) = scene(kind);
            b.restore(&serde_json::from_str(&text).expect("json")).expect("restore");
            for _ in 0..9 {
                b.step(dt).expect("step");
            }
            assert_eq!(a.save(), b.save(), "{kind}");
            assert_eq!(a.time().to_bits(), b.time().to_bits(), "{kind}");
        }
        let (oscillator, _) = scene("harmonic-oscillator");
        let (mut kepler, _) = scene("kepler-orbit");
        let before = kepler.save();
        let err = kepler.restore(&oscillator.save()).expect_err("another scene");
        assert!(err.to_string().contains("1 positions and 1 velocities; this scene has 2 and 2"), "{err}");
        let mut old = before.clone();
        old["version"] = serde_json::json!(0);
        assert_eq!(kepler.restore(&old), Err(CheckpointError::Version { found: 0, expected: 1 }));
        assert_eq!(kepler.save(), before);
    }

    #[test]
    fn an_overflow_fails_the_step_and_leaves_the_scene_as_it_was() {
        let (mut s, preset) = scene("kepler-orbit");
        s.step(preset.run.dt).expect("step");
        assert!(s.provoke_overflow().is_some());
        let before = s.save();
        let err = s.step(preset.run.dt).expect_err("overflow");
        assert!(err.to_string().contains("non-finite"), "{err}");
        assert_eq!(s.save(), before);
    }

    #[test]
    fn bad_parameters_name_their_field() {
        let k = &KINDS[0];
        let mut p = (k.presets)()[0].params.clone();
        p["mass"] = serde_json::json!(-1.0);
        let err = (k.build)(&p, &BuildContext::default()).err().expect("refused");
        assert_eq!(err.to_string(), "field `mass`: must be a positive finite number, got -1");
        p["mas"] = serde_json::json!(1.0);
        let err = (k.build)(&p, &BuildContext::default()).err().expect("refused");
        assert!(err.to_string().starts_with("field `mas`: unknown field `mas`, expected one of"), "{err}");
        let p = serde_json::json!({ "eccentricity": 0.5, "integrator": "rk5" });
        let err = (KINDS[1].build)(&p, &BuildContext::default()).err().expect("refused");
        assert!(err.to_string().starts_with("field `integrator`: unknown variant `rk5`"), "{err}");
        let k = &KINDS[1];
        let p = serde_json::json!({ "eccentricity": 1.0, "integrator": "rk4" });
        let err = (k.build)(&p, &BuildContext::default()).err().expect("refused");
        assert_eq!(err.to_string(), "field `eccentricity`: must lie in [0, 1), got 1");
    }
    #[test]
    fn the_ode_error_is_zero_on_the_exact_solution() {
        // Independent of the runner: the exact state at t gives zero, a shifted one its shift.
        let p: OscillatorParams = params(&oscillator_presets()[0].params).expect("params");
        let (xe, ve) = HarmonicOscillator::damped(p.mass, p.stiffness, p.damping).exact(p.x0, p.v0, 0.7);
        let mut s = State::new(vec![xe], vec![ve]);
        s.t = 0.7;
        assert_eq!(oscillator_error(&p, &s), Some(0.0));
        s.x[0] += 1e-3;
        let e = oscillator_error(&p, &s).expect("an error");
        assert!((e - 1e-3 / p.x0.hypot(p.v0 / (p.stiffness / p.mass).sqrt())).abs() < 1e-15);
        let k: KeplerParams = params(&kepler_presets()[0].params).expect("params");
        let (xe, ve) = KeplerOrbit::ellipse(0.5).exact(1.3);
        let mut s = State::new(xe.to_vec(), ve.to_vec());
        s.t = 1.3;
        assert_eq!(kepler_error(&k, &s), Some(0.0));
    }

    #[test]
    fn the_oscillator_step_is_in_units_of_one_over_omega_and_shrinks_over_long_runs() {
        let f = study::family("o", "harmonic-oscillator", Some(100.0), &[], &[]);
        let p = oscillator_presets().remove(0);
        let adapter = (KINDS[0].tolerance.expect("mapped").adapter)(&p.params, &p.run, &f).expect("adapter");
        let pt = Point { param: 0.5, seconds: 1e-5, error: 1e-3 };
        // k = 40, m = 1: omega = sqrt(40); 1000 steps of 0.01 s = 63 time units, inside 100.
        let c = adapter.candidate("rk4", &pt).expect("runs");
        assert_eq!(c.dt, Some(0.5 / 40f64.sqrt()));
        assert_eq!(c.summary, "integrator = rk4");
        assert_eq!(c.note, format!("1/omega = {:.4}", 1.0 / 40f64.sqrt()));
        // Kepler: a 20 s run against a horizon of 5 shrinks RK4's step by (1/4)^(1/2).
        let f = study::family("k", "kepler-orbit", Some(5.0), &[], &[]);
        let p = kepler_presets().remove(0);
        let adapter = (KINDS[1].tolerance.expect("mapped").adapter)(&p.params, &p.run, &f).expect("adapter");
        let c = adapter.candidate("rk4", &Point { param: 0.1, ..pt }).expect("runs");
        assert!((c.dt.expect("a step") - 0.05).abs() < 1e-15);
        assert!((c.cost - 2.0).abs() < 1e-12);
        assert_eq!(adapter.candidate("rk5", &pt).unwrap_err(), "`rk5` is not a method this build knows");
        assert_eq!(integrator("velocity-verlet"), Some(IntegratorKind::VelocityVerlet));
    }
}
