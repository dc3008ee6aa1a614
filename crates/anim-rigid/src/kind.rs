//! The `rigid` scene kind: the built-in rigid-body [`scenes`] as an anim-core
//! [`SceneKind`], with their presets, their scene-file parameters ([`RigidParams`]) and the
//! solver the run loop drives ([`RigidSegments`]).
//!
//! | preset | scene | run |
//! | --- | --- | --- |
//! | `panda` | [`panda_swing`](crate::scenes::panda_swing): the Franka Panda swinging under gravity with zero torque (RK4) | 100 frames of 30 steps of 1 ms |
//! | `chain` | [`pendulum_chain`](crate::scenes::pendulum_chain): a 32-link pendulum chain (RK4) | 100 frames of 60 steps of 0.5 ms |
//! | `t-handle` | [`t_handle`](crate::scenes::t_handle): a spinning T-handle flipping about its intermediate axis (free-body midpoint) | 120 frames of 200 steps of 1 ms |
//!
//! A scene file may instead give a `robot` table ([`RobotSpec`]): a
//! URDF file of the user's, its base, locked joints, initial joint positions and velocities,
//! damping, PD servos and a torque schedule.
//!
//! A scene is drawn as the line segments its [`RigidScene::segments`] name: frame `k` holds the
//! two end points of every segment (segment `s` joins points `2 s` and `2 s + 1`) and their
//! velocities by finite difference over the last step. The bodies work z up (gravity along
//! `-z`, the URDF's and the scene file's coordinates); frames and context are turned y up, the
//! frame of every view ([`anim_core::scene::turn_z_up`]).
//!
//! ```
//! use anim_core::scene::{BuildContext, Frame};
//!
//! let preset = (anim_rigid::KIND.presets)().into_iter().find(|p| p.name == "t-handle").expect("a preset");
//! let mut scene = (anim_rigid::KIND.build)(&preset.params, &BuildContext::default())?;
//! scene.step(preset.run.dt)?;
//! let mut frame = Frame::default();
//! scene.frame(&mut frame);
//! assert_eq!(frame.points.len(), 2 * 2 * 3); // the bar and the stem, two ends each
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use anim_core::glam::DVec3;
use anim_core::integrate::State;
use anim_core::scene::{
    BuildContext, BuildError, Checkpoint, CheckpointError, Context, DynScene, Frame, Preset, RunDefaults,
    SceneKind, Simulated, Up, View, params, saved_field, saved_state,
};
use anim_core::solver::{Solver, StepReport};
use serde::{Deserialize, Serialize};

use crate::data::Data;
use crate::model::{FrameIndex, JointType, Model};
use crate::robot::{RobotSpec, TorqueSchedule};
use crate::scenes::{self, RigidScene};
use crate::sim::{RigidSimulation, RigidState, SimError};

/// The `rigid` scene kind of anim-rigid, for the workspace registry.
pub const KIND: SceneKind = SceneKind {
    kind: "rigid",
    crate_name: "anim-rigid",
    summary: "articulated and free rigid bodies without contact, drawn as line segments",
    presets,
    build,
    tolerance: None,
};

/// Scene-file parameters of a `rigid` scene (the `[scene]` table without `kind`): a built-in
/// `preset`, or a `robot` table ([`RobotSpec`]) bringing the user's URDF.
///
/// ```toml
/// [scene]
/// kind = "rigid"
///
/// [scene.robot]
/// urdf = "panda.urdf"            # relative to the scene file
/// locked = { panda_finger_joint1 = 0.0, panda_finger_joint2 = 0.0 }
/// q0 = { panda_joint2 = 0.5, panda_joint4 = -2.0 }
/// servo = { kp = 400.0, kd = 40.0, target = { panda_joint1 = 1.0 } }
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RigidParams {
    /// The built-in scene: `"panda-swing"`, `"pendulum-chain"` or `"t-handle"`
    /// ([`scenes::NAMES`]); give this or `robot`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preset: Option<String>,
    /// A robot from a URDF file; give this or `preset`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub robot: Option<RobotSpec>,
}

fn presets() -> Vec<Preset> {
    let preset = |name, description, run, scene: &str| Preset {
        name,
        description,
        run,
        params: serde_json::json!({ "preset": scene }),
        quick_params: None,
    };
    vec![
        preset(
            "panda",
            "the Franka Panda swinging under gravity with zero torque (RK4)",
            RunDefaults::new(0.001, 100, 30),
            "panda-swing",
        ),
        preset(
            "chain",
            "a 32-link pendulum chain (RK4)",
            RunDefaults::new(0.0005, 100, 60),
            "pendulum-chain",
        ),
        preset(
            "t-handle",
            "a spinning T-handle flipping about its intermediate axis (free-body midpoint)",
            RunDefaults::new(0.001, 120, 200),
            "t-handle",
        ),
    ]
}

fn build(value: &serde_json::Value, context: &BuildContext<'_>) -> Result<Box<dyn DynScene>, BuildError> {
    let p: RigidParams = params(value)?;
    let (scene, schedule) = match (&p.preset, &p.robot) {
        (Some(name), None) => match scenes::by_name(name) {
            Some(Ok(scene)) => (scene, TorqueSchedule::default()),
            Some(Err(e)) => return Err(BuildError::invalid("preset", e.to_string())),
            None => {
                return Err(BuildError::invalid(
                    "preset",
                    format!("unknown preset `{name}` (one of {})", scenes::NAMES.join(", ")),
                ));
            }
        },
        (None, Some(robot)) => robot.build(&context.resolve(&robot.urdf)).map_err(|e| {
            BuildError::invalid(format!("robot.{}", e.field()).trim_end_matches('.'), e.to_string())
        })?,
        (Some(_), Some(_)) => {
            return Err(BuildError::invalid(
                "robot",
                "give a built-in `preset` or a `robot` table, not both",
            ));
        }
        (None, None) => {
            return Err(BuildError::invalid(
                "preset",
                format!(
                    "give a built-in `preset` (one of {}) or a `robot` table with a `urdf` file",
                    scenes::NAMES.join(", ")
                ),
            ));
        }
    };
    let field = if p.robot.is_some() { "robot" } else { "preset" };
    let (mut solver, state) =
        RigidSegments::new(scene).map_err(|e| BuildError::invalid(field, e.to_string()))?;
    solver.schedule = schedule;
    Ok(Simulated::new(solver, state).boxed())
}

/// A [`RigidSimulation`] drawn as the segments of its scene: after every step, the world end
/// points of the segments (a display state of `6 x segments` coordinates) and their velocities
/// by finite difference over the step's `dt`. The state it steps is the scene's
/// [`RigidState`]; the display is kept here, saved in checkpoints with the simulation's memory.
#[derive(Debug, Clone)]
pub struct RigidSegments {
    sim: RigidSimulation,
    method: String,
    /// Forward-kinematics buffers of the display (the simulation keeps its own).
    data: Data,
    segments: Vec<(FrameIndex, FrameIndex)>,
    /// The segments' end points at the last refresh.
    points: Vec<[DVec3; 2]>,
    /// End points (flat, 3 per point, two points per segment), their velocities and the time.
    display: State,
    /// Applied torques over time (empty: the simulation's own constant torques).
    schedule: TorqueSchedule,
}

impl RigidSegments {
    /// The simulation of `scene` with its stepper and the scene's initial state; the display
    /// starts at the initial end points with zero velocities.
    ///
    /// # Errors
    /// [`SimError`] when the scene's parameters, stepper or state are invalid.
    pub fn new(scene: RigidScene) -> Result<(Self, RigidState), SimError> {
        let method = format!("{:?}", scene.integrator).to_lowercase();
        let segments = scene.segments.clone();
        let data = Data::new(&scene.model);
        let (sim, state) = scene.into_simulation()?;
        let n = 6 * segments.len();
        let mut solver = Self {
            sim,
            method,
            data,
            segments,
            points: Vec::new(),
            display: State::new(vec![0.0; n], vec![0.0; n]),
            schedule: TorqueSchedule::default(),
        };
        solver.refresh(&state, 0.0);
        Ok((solver, state))
    }

    /// The simulation.
    #[must_use]
    pub fn simulation(&self) -> &RigidSimulation {
        &self.sim
    }

    /// Drives the applied torques by `schedule` from the next step on (see
    /// [`TorqueSchedule::at`]); an empty schedule leaves the simulation's torques as they are.
    ///
    /// # Errors
    /// [`SimError::BadParameter`] when the schedule's torques are not this model's `nv`.
    pub fn set_schedule(&mut self, schedule: TorqueSchedule) -> Result<(), SimError> {
        if let Some(tau) = schedule.at(0.0, 0.0)
            && tau.len() != self.sim.model().nv()
        {
            return Err(SimError::BadParameter {
                name: "torque schedule",
                value: format!("{} torques", tau.len()),
                requirement: "must have one torque per velocity (nv)",
            });
        }
        self.schedule = schedule;
        Ok(())
    }

    /// The display state: segment end points, their velocities, the time.
    #[must_use]
    pub fn display(&self) -> &State {
        &self.display
    }

    /// Segment end points of `state` into the display (velocities by difference over `dt`).
    fn refresh(&mut self, state: &RigidState, dt: f64) {
        scenes::segment_points(self.sim.model(), &mut self.data, &state.q, &self.segments, &mut self.points);
        for (k, p) in self.points.iter().flatten().enumerate() {
            for (c, value) in p.to_array().into_iter().enumerate() {
                let i = 3 * k + c;
                self.display.v[i] = if dt > 0.0 { (value - self.display.x[i]) / dt } else { 0.0 };
                self.display.x[i] = value;
            }
        }
        self.display.t = state.t;
    }

    /// The display points that never move: those carried by the universe through fixed joints,
    /// or sitting on the origin of a revolute or spherical joint that is itself fixed that way
    /// (the base of an arm, the hinge of a chain).
    fn pins(&self) -> Vec<usize> {
        let model = self.sim.model();
        let fixed = |f: FrameIndex| fixed_in_world(model, f);
        let mut pins = Vec::new();
        for (s, &(a, b)) in self.segments.iter().enumerate() {
            for (end, f) in [a, b].into_iter().enumerate() {
                if fixed(f) {
                    pins.push(2 * s + end);
                }
            }
        }
        pins
    }
}

/// Whether frame `f` of `model` stays at one world position whatever the configuration.
fn fixed_in_world(model: &Model, f: FrameIndex) -> bool {
    let frame = model.frame(f);
    let mut joint = frame.parent_joint;
    let mut point = frame.placement.translation;
    while joint != 0 {
        let j = model.joint(joint);
        match j.kind {
            JointType::Fixed => {}
            JointType::Revolute(_) | JointType::Spherical if point == DVec3::ZERO => {}
            _ => return false,
        }
        point = j.placement.transform_point(point);
        joint = j.parent;
    }
    true
}

impl Solver for RigidSegments {
    type State = RigidState;
    type Error = SimError;

    /// Steps the simulation, then moves the display to the new end points. A failed step
    /// changes neither the state, the simulation's memory nor the display.
    fn step(&mut self, state: &mut RigidState, dt: f64) -> Result<StepReport, SimError> {
        if let Some(tau) = self.schedule.at(state.t, dt) {
            // The torques are a function of time: a failed step leaves them to be set again.
            self.sim.system_mut().set_torque(tau)?;
        }
        let report = self.sim.step(state, dt)?;
        self.refresh(state, dt);
        Ok(report)
    }
}

impl Checkpoint for RigidSegments {
    const VERSION: u32 = 1;

    fn time(&self, state: &RigidState) -> f64 {
        state.t
    }

    /// `{"rigid": state, "simulation": memory, "display": display state}`: the display is
    /// saved because the next step's velocities are differences from its positions.
    fn save(&self, state: &RigidState) -> serde_json::Value {
        serde_json::json!({ "rigid": state, "simulation": self.sim.memory(), "display": self.display })
    }

    fn restore(&mut self, state: &mut RigidState, saved: &serde_json::Value) -> Result<(), CheckpointError> {
        let rigid: RigidState = saved_field(saved, "rigid")?;
        if rigid.q.len() != state.q.len() || rigid.v.len() != state.v.len() {
            return Err(CheckpointError::invalid(
                "rigid",
                format!(
                    "{} coordinates and {} velocities; this model has {} and {}",
                    rigid.q.len(),
                    rigid.v.len(),
                    state.q.len(),
                    state.v.len()
                ),
            ));
        }
        if let Some(bad) = rigid.q.iter().chain(&rigid.v).chain([&rigid.t]).find(|x| !x.is_finite()) {
            return Err(CheckpointError::invalid("rigid", format!("holds the non-finite value {bad}")));
        }
        let display = saved_state(saved, "display", &self.display)?;
        if display.t.to_bits() != rigid.t.to_bits() {
            return Err(CheckpointError::invalid(
                "display",
                format!("at time {}, the bodies at {}", display.t, rigid.t),
            ));
        }
        let memory =
            saved.get("simulation").ok_or_else(|| CheckpointError::Missing { field: "simulation".into() })?;
        // Checked whole before anything is taken: the last fallible call.
        self.sim.restore_memory(memory).map_err(|e| CheckpointError::invalid("simulation", e.to_string()))?;
        *state = rigid;
        self.display = display;
        Ok(())
    }

    fn provoke_overflow(&mut self, state: &mut RigidState) -> Option<String> {
        // The first coordinate advances by h v: MAX + h MAX overflows for every stepper (a
        // hinge angle, or the x of a free body), and the accelerations of a tree overflow too.
        state.q[0] = f64::MAX;
        state.v[0] = f64::MAX;
        Some("coordinate and velocity 0 set to f64::MAX".into())
    }
}

impl View for RigidSegments {
    /// The stepper, as `rk4` or `freebodymidpoint`.
    fn method(&self) -> String {
        self.method.clone()
    }

    /// The segments as lines between their end points, drawn as discs of 6% of the longest
    /// segment; the points on fixed joints as pins; the display's bounding box extended down.
    fn context(&self, _: &RigidState) -> Context {
        let lines = (0..self.segments.len()).map(|k| [2 * k, 2 * k + 1]).collect();
        let longest = self.points.iter().map(|[a, b]| (*a - *b).length()).fold(0.0, f64::max);
        let mut context = Context::default();
        context.point_dim = 3;
        context.lines = lines;
        context.pins = self.pins();
        context.point_radius = 0.06 * longest.max(1e-3);
        context.bounds = Some(anim_core::scene::frame_box(&self.display.x, Up::Z, None, true));
        // Built z up, the robot's frame; drawn y up.
        context.turn_z_up();
        context
    }

    fn frame(&self, _: &RigidState, out: &mut Frame) {
        out.time = self.display.t;
        out.points.clone_from(&self.display.x);
        out.field_mut("velocity", 3).extend_from_slice(&self.display.v);
        out.turn_z_up(3, &["velocity"]);
    }
}
