//! Ready-to-run rigid-body scenes: the model, its initial state, the time step and the stepper
//! that suit it, and the frames to draw as line segments.
//!
//! | scene | what | stepper | why |
//! | --- | --- | --- | --- |
//! | [`panda_swing`] | the Franka Panda (fingers locked) released from a forward-leaning pose with zero joint torques: it falls and swings under gravity, stopped by its joint limits | RK4, `dt = 1e-3` s | smooth motion between limit contacts; the limit penalty (`k = 1000`) has frequencies up to about 300 rad/s, well inside RK4's stability region at this step, and four ABA calls cost about 8 µs a step |
//! | [`pendulum_chain`] | a planar chain of 32 (default) thin rods hinged end to end, released horizontal | RK4, `dt = 5e-4` s | the falling chain whips its tip; in the work-precision study RK4 reaches every tip accuracy below 1e-2 m at the least cost (about 5e-8 m after 1 s at this step), while the implicit midpoint rule needs steps about ten times smaller for the same accuracy and symplectic Euler far smaller still; over the 4 s the energy stays within 6e-3 J of its start, for 50 J of kinetic energy |
//! | [`t_handle`] | a T-shaped handle spinning in free fall about its intermediate principal axis: it flips every few seconds (the Dzhanibekov effect) | free-body midpoint, `dt = 1e-3` s | conserves energy and angular momentum to rounding, so the flips are the physics and not drift |
//!
//! All scenes are z-up; gravity is `(0, 0, -9.81)` except in the T-handle's free fall (zero).
//! Each scene reports its energy every step ([`StepReport::energy`](anim_core::solver::StepReport)).
//!
//! ```
//! use anim_core::solver::Solver;
//! use anim_rigid::scenes;
//!
//! let scene = scenes::by_name("t-handle").expect("a built-in scene")?;
//! let segments = scene.segments.clone();
//! let (mut sim, mut state) = scene.into_simulation()?;
//! let report = sim.step(&mut state, 1e-3)?;
//! assert!(report.energy.is_some());
//! let mut lines = Vec::new();
//! let (model, data) = sim.system_mut().model_and_data();
//! scenes::segment_points(model, data, &state.q, &segments, &mut lines);
//! assert_eq!(lines.len(), 2); // the bar and the stem
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use anim_core::glam::{DMat3, DVec3};
use anim_core::lie::Se3;
use thiserror::Error;

use crate::config;
use crate::data::Data;
use crate::kinematics::forward_kinematics;
use crate::model::{
    Axis, FrameIndex, FrameKind, Inertia, JointLimits, JointType, Model, ModelBuilder, ModelError,
};
use crate::sim::{RigidIntegrator, RigidSimulation, RigidState, SimError, SimParams};
use crate::urdf::{UrdfError, UrdfOptions, parse_urdf};

/// The Franka Panda URDF (example-robot-data 6.0.0), embedded so the scene needs no files.
const PANDA_URDF: &str = include_str!("../testdata/panda.urdf");

/// Why a scene could not be built.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum SceneError {
    /// The embedded URDF did not load.
    #[error(transparent)]
    Urdf(#[from] UrdfError),
    /// The model could not be built.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// The simulation rejected the parameters or state.
    #[error(transparent)]
    Sim(#[from] SimError),
    /// A scene parameter out of its range.
    #[error("scene parameter '{name}' = {value}: {requirement}")]
    BadParameter {
        /// The parameter.
        name: &'static str,
        /// Its value, as text.
        value: String,
        /// What it must satisfy.
        requirement: &'static str,
    },
}

/// A scene: model, forces, initial state, how to step it and what to draw.
#[derive(Debug, Clone)]
pub struct RigidScene {
    /// Short name ("panda-swing").
    pub name: &'static str,
    /// One-line description.
    pub description: &'static str,
    /// The model.
    pub model: Model,
    /// Forces and solver settings.
    pub params: SimParams,
    /// Initial state.
    pub state: RigidState,
    /// Suggested time step (s).
    pub dt: f64,
    /// Suggested simulated duration (s).
    pub duration: f64,
    /// Suggested stepper.
    pub integrator: RigidIntegrator,
    /// Pairs of frames drawn as line segments (see [`segment_points`]).
    pub segments: Vec<(FrameIndex, FrameIndex)>,
}

impl RigidScene {
    /// The simulation with the scene's stepper, and the initial state.
    ///
    /// # Errors
    /// [`SimError`] if the parameters, stepper or state were changed to invalid ones.
    pub fn into_simulation(self) -> Result<(RigidSimulation, RigidState), SimError> {
        let sim = RigidSimulation::new(self.model, self.params, self.integrator)?;
        let state = sim.initial_state(self.state.q, self.state.v)?;
        Ok((sim, state))
    }

    /// Number of steps of `dt` covering `duration`.
    #[must_use]
    pub fn steps(&self) -> usize {
        (self.duration / self.dt).round().max(1.0) as usize
    }
}

/// The built-in scene names.
pub const NAMES: [&str; 3] = ["panda-swing", "pendulum-chain", "t-handle"];

/// Builds a scene by name (see [`NAMES`]) at its default size; `None` for an unknown name.
#[must_use]
pub fn by_name(name: &str) -> Option<Result<RigidScene, SceneError>> {
    Some(match name {
        "panda-swing" => panda_swing(),
        "pendulum-chain" => pendulum_chain(None),
        "t-handle" => t_handle(),
        _ => return None,
    })
}

/// The world position of every joint origin (universe first) at `q`, into `out` (cleared).
///
/// # Panics
/// When `q` or `data` does not match `model`.
#[track_caller]
pub fn joint_positions(model: &Model, data: &mut Data, q: &[f64], out: &mut Vec<DVec3>) {
    forward_kinematics(model, data, q);
    out.clear();
    out.extend(data.world_placements.iter().map(|m| m.translation));
}

/// The world end points of the segments `segments` (pairs of frames) at `q`, into `out`
/// (cleared): what a renderer draws as lines.
///
/// # Panics
/// When `q` or `data` does not match `model`, or a frame index is out of range.
#[track_caller]
pub fn segment_points(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    segments: &[(FrameIndex, FrameIndex)],
    out: &mut Vec<[DVec3; 2]>,
) {
    forward_kinematics(model, data, q);
    let at = |data: &Data, f: FrameIndex| {
        let frame = model.frame(f);
        data.world_placements[frame.parent_joint].transform_point(frame.placement.translation)
    };
    out.clear();
    out.extend(segments.iter().map(|&(a, b)| [at(data, a), at(data, b)]));
}

fn frame(model: &Model, name: &str) -> Result<FrameIndex, SceneError> {
    model.frame_id(name).ok_or(SceneError::BadParameter {
        name: "frame",
        value: name.to_string(),
        requirement: "must exist in the scene's model",
    })
}

/// The Franka Panda (fingers locked at 0, 7 DoF, fixed base) released at rest from a pose
/// leaning forward, with zero joint torques: gravity makes it fall and swing; its joint limits
/// (penalty `k = 1000` N·m/rad, `c = 5` N·m·s/rad) stop the shoulder and elbow. RK4 at
/// `dt = 1e-3` s for 5 s.
///
/// # Errors
/// [`SceneError`] if the embedded URDF does not load (it does).
pub fn panda_swing() -> Result<RigidScene, SceneError> {
    let options =
        UrdfOptions::default().lock_joint("panda_finger_joint1", 0.0).lock_joint("panda_finger_joint2", 0.0);
    let model = parse_urdf(PANDA_URDF, &options)?;
    let q = vec![0.3, 0.9, -0.2, -1.0, 0.4, 1.6, 0.8];
    let v = vec![0.0; model.nv()];
    let mut chain = vec![frame(&model, "universe")?];
    for k in 1..=7 {
        chain.push(frame(&model, &format!("panda_joint{k}"))?);
    }
    chain.push(frame(&model, "panda_hand_tcp")?);
    let segments = chain.windows(2).map(|w| (w[0], w[1])).collect();
    Ok(RigidScene {
        name: "panda-swing",
        description: "the Franka Panda falls and swings under gravity with zero joint torques (RK4)",
        model,
        params: SimParams::default(),
        state: RigidState::new(q, v),
        dt: 1e-3,
        duration: 5.0,
        integrator: RigidIntegrator::Rk4,
        segments,
    })
}

/// A planar chain of thin uniform rods of length `link_length` and the given masses (root
/// first), hinged end to end about the world `y` axis; joint `k` sits at the end of rod `k - 1`
/// and, at `q = 0`, every rod points along `+x`. A frame `tip` marks the free end. No joint
/// limits (continuous joints), gravity `-z`.
///
/// # Errors
/// [`SceneError::BadParameter`] for an empty chain, a non-positive length or mass.
pub fn pendulum_chain_model(masses: &[f64], link_length: f64) -> Result<Model, SceneError> {
    if masses.is_empty() || masses.len() > 10_000 {
        return Err(SceneError::BadParameter {
            name: "links",
            value: masses.len().to_string(),
            requirement: "must lie in [1, 10000]",
        });
    }
    if !(link_length > 0.0) || !link_length.is_finite() {
        return Err(SceneError::BadParameter {
            name: "link_length",
            value: link_length.to_string(),
            requirement: "must be positive and finite",
        });
    }
    if let Some(m) = masses.iter().find(|m| !(**m > 0.0) || !m.is_finite()) {
        return Err(SceneError::BadParameter {
            name: "link mass",
            value: m.to_string(),
            requirement: "must be positive and finite",
        });
    }
    let mut b = ModelBuilder::new("pendulum-chain");
    let mut parent = 0;
    for (k, &m) in masses.iter().enumerate() {
        let placement = if k == 0 { Se3::IDENTITY } else { Se3::from_translation(DVec3::X * link_length) };
        let j = b.add_joint(
            parent,
            &format!("hinge{}", k + 1),
            JointType::Revolute(Axis::Y),
            placement,
            JointLimits::UNBOUNDED,
        )?;
        // A thin rod along +x: I = m L² / 12 about y and z through its centre.
        let i = m * link_length * link_length / 12.0;
        let rod =
            Inertia::new(m, DVec3::X * (0.5 * link_length), DMat3::from_diagonal(DVec3::new(0.0, i, i)));
        b.append_body(j, &rod, &Se3::IDENTITY)?;
        parent = j;
    }
    b.add_frame("tip", FrameKind::Operational, parent, Se3::from_translation(DVec3::X * link_length))?;
    Ok(b.build())
}

/// The segments of a chain built by [`pendulum_chain_model`]: joint to joint, then to the tip.
fn chain_segments(model: &Model) -> Result<Vec<(FrameIndex, FrameIndex)>, SceneError> {
    let mut points = Vec::with_capacity(model.njoints() + 1);
    for j in 1..model.njoints() {
        points.push(frame(model, &model.joint(j).name)?);
    }
    points.push(frame(model, "tip")?);
    Ok(points.windows(2).map(|w| (w[0], w[1])).collect())
}

/// A planar pendulum chain of `links` rods (default 32), each 0.1 m long and 0.1 kg, released at
/// rest horizontal: it falls, folds and whips. RK4 at `dt = 5e-4` s for 4 s.
///
/// # Errors
/// [`SceneError::BadParameter`] for `links` outside `[1, 10000]`.
pub fn pendulum_chain(links: Option<usize>) -> Result<RigidScene, SceneError> {
    let n = links.unwrap_or(32);
    let model = pendulum_chain_model(&vec![0.1; n], 0.1)?;
    let segments = chain_segments(&model)?;
    let state = RigidState::new(vec![0.0; model.nq()], vec![0.0; model.nv()]);
    Ok(RigidScene {
        name: "pendulum-chain",
        description: "a planar chain of 32 rods falls from horizontal and whips (RK4)",
        model,
        params: SimParams::default(),
        state,
        dt: 5e-4,
        duration: 4.0,
        integrator: RigidIntegrator::Rk4,
        segments,
    })
}

/// Inertia of a solid cylinder of mass `m`, radius `r`, length `l` about its centre, axis `axis`.
fn cylinder(m: f64, r: f64, l: f64, axis: usize) -> DMat3 {
    let along = 0.5 * m * r * r;
    let across = m * (3.0 * r * r + l * l) / 12.0;
    let mut d = DVec3::splat(across);
    d[axis] = along;
    DMat3::from_diagonal(d)
}

/// The T-handle of [`t_handle`]: a free body whose frame sits at its centre of mass with its
/// axes principal; a bar along `x` (0.2 m, 0.2 kg) and a stem along `+y` from the bar's middle
/// (0.15 m, 0.15 kg), both solid cylinders of radius 1 cm. Frames `bar_left`, `bar_right`,
/// `junction` and `stem_end` mark the shape. Returns the model and its principal moments
/// `(I_x, I_y, I_z)`.
///
/// # Errors
/// Never in practice (the geometry is fixed); [`SceneError::Model`] if the builder rejects it.
pub fn t_handle_model() -> Result<(Model, DVec3), SceneError> {
    let (mb, lb, ms, ls, r) = (0.2, 0.2, 0.15, 0.15, 0.01);
    // Centre of mass on the stem axis, measured from the junction.
    let yc = ms * 0.5 * ls / (mb + ms);
    let bar = Inertia::new(mb, DVec3::new(0.0, -yc, 0.0), cylinder(mb, r, lb, 0));
    let stem = Inertia::new(ms, DVec3::new(0.0, 0.5 * ls - yc, 0.0), cylinder(ms, r, ls, 1));
    let body = bar.merged(&stem);
    let mut b = ModelBuilder::new("t-handle");
    b.gravity(DVec3::ZERO)?;
    let j = b.add_joint(0, "handle", JointType::Free, Se3::IDENTITY, JointLimits::UNBOUNDED)?;
    b.append_body(j, &body, &Se3::IDENTITY)?;
    let at = |p: DVec3| Se3::from_translation(p);
    b.add_frame("bar_left", FrameKind::Operational, j, at(DVec3::new(-0.5 * lb, -yc, 0.0)))?;
    b.add_frame("bar_right", FrameKind::Operational, j, at(DVec3::new(0.5 * lb, -yc, 0.0)))?;
    b.add_frame("junction", FrameKind::Operational, j, at(DVec3::new(0.0, -yc, 0.0)))?;
    b.add_frame("stem_end", FrameKind::Operational, j, at(DVec3::new(0.0, ls - yc, 0.0)))?;
    let model = b.build();
    let moments = DVec3::new(body.rotational.x_axis.x, body.rotational.y_axis.y, body.rotational.z_axis.z);
    Ok((model, moments))
}

/// The axis (0, 1, 2 for x, y, z) of the intermediate principal moment.
fn intermediate_axis(moments: DVec3) -> usize {
    let mut idx = [0, 1, 2];
    idx.sort_by(|&a, &b| moments[a].total_cmp(&moments[b]));
    idx[1]
}

/// A T-handle spinning at 10 rad/s about its intermediate principal axis, nudged by 0.01 rad/s
/// about the other two, floating without gravity 1 m above the origin: the spin axis flips
/// over and back every few seconds (the Dzhanibekov effect, the instability of rotation about
/// the intermediate axis). The free-body midpoint stepper at `dt = 1e-3` s for 20 s.
///
/// # Errors
/// Never in practice; see [`t_handle_model`].
pub fn t_handle() -> Result<RigidScene, SceneError> {
    let (model, moments) = t_handle_model()?;
    let axis = intermediate_axis(moments);
    let mut w = DVec3::splat(0.01);
    w[axis] = 10.0;
    let mut q = config::neutral(&model);
    q[2] = 1.0;
    let v = vec![0.0, 0.0, 0.0, w.x, w.y, w.z];
    let segments = vec![
        (frame(&model, "bar_left")?, frame(&model, "bar_right")?),
        (frame(&model, "junction")?, frame(&model, "stem_end")?),
    ];
    Ok(RigidScene {
        name: "t-handle",
        description: "a T-handle spinning about its intermediate axis flips over and back (Dzhanibekov effect)",
        model,
        params: SimParams::default(),
        state: RigidState::new(q, v),
        dt: 1e-3,
        duration: 20.0,
        integrator: RigidIntegrator::FreeBodyMidpoint,
        segments,
    })
}

/// The period of the body angular velocity of a torque-free rigid body (Euler's top), from its
/// principal moments `moments` and body angular velocity `omega` in the principal axes:
/// `T = 4 K(k) / p` with the complete elliptic integral `K` (Landau & Lifshitz, *Mechanics*,
/// §37). For `L² > 2E I₂` (`I₁ < I₂ < I₃` sorted),
/// `p² = (I₃ - I₂)(L² - 2E I₁)/(I₁ I₂ I₃)`, `k² = (I₂ - I₁)(2E I₃ - L²)/((I₃ - I₂)(L² - 2E I₁))`;
/// for `L² < 2E I₂` the roles of `I₁` and `I₃` swap. The component along the intermediate axis
/// changes sign twice per period: a flip and a flip back.
///
/// `None` for equal moments, a body at rest, or motion on the separatrix (`L² = 2E I₂`, an
/// infinite period).
#[must_use]
pub fn euler_top_period(moments: DVec3, omega: DVec3) -> Option<f64> {
    let mut idx = [0, 1, 2];
    idx.sort_by(|&a, &b| moments[a].total_cmp(&moments[b]));
    let (i1, i2, i3) = (moments[idx[0]], moments[idx[1]], moments[idx[2]]);
    if !(i1 > 0.0 && i1 < i2 && i2 < i3) {
        return None;
    }
    let two_e: f64 = (0..3).map(|a| moments[a] * omega[a] * omega[a]).sum();
    let l2: f64 = (0..3).map(|a| (moments[a] * omega[a]).powi(2)).sum();
    let (p2, k2) = if l2 > two_e * i2 {
        (
            (i3 - i2) * (l2 - two_e * i1) / (i1 * i2 * i3),
            (i2 - i1) * (two_e * i3 - l2) / ((i3 - i2) * (l2 - two_e * i1)),
        )
    } else if l2 < two_e * i2 {
        (
            (i2 - i1) * (two_e * i3 - l2) / (i1 * i2 * i3),
            (i3 - i2) * (l2 - two_e * i1) / ((i2 - i1) * (two_e * i3 - l2)),
        )
    } else {
        return None;
    };
    if !(p2 > 0.0) || !(0.0..1.0).contains(&k2) {
        return None;
    }
    // K(k) = π / (2 AGM(1, √(1 - k²))).
    let (mut a, mut b) = (1.0_f64, (1.0 - k2).sqrt());
    for _ in 0..60 {
        let (an, bn) = (0.5 * (a + b), (a * b).sqrt());
        a = an;
        b = bn;
        if (a - b).abs() <= 1e-16 * a {
            break;
        }
    }
    let k = std::f64::consts::PI / (2.0 * a);
    Some(4.0 * k / p2.sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_scene_builds_and_starts_at_rest_or_spinning() {
        for name in NAMES {
            let scene = by_name(name).expect("known").expect("builds");
            assert_eq!(scene.name, name);
            assert_eq!(scene.state.q.len(), scene.model.nq());
            assert!(scene.steps() > 100);
            assert!(!scene.segments.is_empty());
        }
        assert!(by_name("nope").is_none());
        assert!(pendulum_chain(Some(0)).is_err());
        assert!(pendulum_chain_model(&[1.0, -1.0], 0.1).is_err());
    }

    #[test]
    fn t_handle_spins_about_its_intermediate_axis() {
        let (model, m) = t_handle_model().expect("builds");
        assert_eq!(model.nv(), 6);
        let axis = intermediate_axis(m);
        let mut sorted = [m.x, m.y, m.z];
        sorted.sort_by(f64::total_cmp);
        assert_eq!(m[axis], sorted[1]);
        assert!(sorted[0] < sorted[1] && sorted[1] < sorted[2]);
        // The body frame is at the centre of mass with principal axes.
        let i = model.inertias()[1];
        assert!(i.com.length() < 1e-15);
        assert_eq!(i.rotational.x_axis.y, 0.0);
    }

    #[test]
    fn euler_period_matches_the_small_oscillation_limit() {
        // Spin about the largest axis with a tiny wobble: p → ω₃ √((I₃-I₁)(I₃-I₂)/(I₁I₂)), k → 0,
        // so T → 2π / p.
        let m = DVec3::new(1.0, 2.0, 3.0);
        let w3 = 5.0;
        let t = euler_top_period(m, DVec3::new(1e-6, 0.0, w3)).expect("a period");
        let p = w3 * ((3.0 - 1.0) * (3.0 - 2.0) / (1.0 * 2.0_f64)).sqrt();
        assert!((t - 2.0 * std::f64::consts::PI / p).abs() < 1e-9 * t, "{t}");
        assert!(euler_top_period(DVec3::splat(1.0), DVec3::X).is_none());
    }
}
