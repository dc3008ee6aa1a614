//! A robot of the user's own, from a URDF file, as a ready-to-run scene: the fixed or floating
//! base, joints locked at a position, the initial joint positions and velocities by joint name,
//! joint damping and limits, proportional-derivative servos towards target positions, and a
//! schedule of applied joint torques. [`RobotSpec`] is also the `robot` table of a `rigid`
//! scene file (`crate::kind`, feature `serde`).
//!
//! ```
//! use anim_rigid::robot::RobotSpec;
//!
//! # #[cfg(feature = "serde")] {
//! let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("testdata");
//! let spec: RobotSpec = serde_json::from_value(serde_json::json!({
//!     "urdf": "panda.urdf",
//!     "locked": { "panda_finger_joint1": 0.0, "panda_finger_joint2": 0.0 },
//!     "q0": { "panda_joint2": 0.5 },
//!     "servo": { "kp": 400.0, "kd": 40.0, "target": { "panda_joint2": 0.5, "panda_joint4": -1.5 } },
//! }))?;
//! let (scene, schedule) = spec.build(&dir.join(&spec.urdf))?;
//! assert_eq!(scene.model.nv(), 7);
//! assert_eq!(scene.state.q[1], 0.5);
//! assert!(schedule.is_empty());
//! # }
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Units are SI: metres, radians, seconds, newtons and newton-metres. The URDF's own frames are
//! kept (anim's scenes are z-up, as URDF robots are by convention).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anim_core::glam::{DQuat, DVec3};
#[cfg(feature = "serde")]
use anim_core::scene::is_default;
use thiserror::Error;

use crate::config;
use crate::model::{FrameIndex, FrameKind, Joint, JointType, Model};
use crate::scenes::RigidScene;
use crate::sim::{RigidIntegrator, RigidState, Servo, SimError, SimParams};
use crate::urdf::{UrdfError, UrdfOptions, load_urdf, rpy_to_matrix};

/// How the robot's root link is attached to the world.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum Base {
    /// The root link is the world: an arm bolted to the floor.
    #[default]
    Fixed,
    /// The root link is a free body (a free joint of 6 degrees of freedom), for legged robots
    /// and anything thrown.
    Floating,
}

/// Proportional-derivative servos on named joints: the torque `kp (target - q) - kd q̇` on each.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct ServoSpec {
    /// Proportional gain (N·m/rad, or N/m on a prismatic joint), finite and `>= 0`.
    pub kp: f64,
    /// Derivative gain (N·m·s/rad, or N·s/m), finite and `>= 0`.
    pub kd: f64,
    /// Target position of each servoed joint, by joint name (rad or m).
    pub target: BTreeMap<String, f64>,
}

/// One entry of a torque schedule: from time `from` on (until the next entry), the joints named
/// get these torques and every other joint none.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct TorqueKey {
    /// Start time (s), finite and `>= 0`; entries in increasing order.
    pub from: f64,
    /// Applied torque per joint name (N·m, or N on a prismatic joint).
    pub joints: BTreeMap<String, f64>,
}

#[cfg(feature = "serde")]
fn default_limit_stiffness() -> f64 {
    SimParams::default().limit_stiffness
}

#[cfg(feature = "serde")]
fn default_limit_damping() -> f64 {
    SimParams::default().limit_damping
}

/// A robot scene: a URDF file and what to do with it. Every field but `urdf` has a default.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct RobotSpec {
    /// The URDF file (in a scene file: relative to the scene file's folder). Its `<visual>` and
    /// `<collision>` meshes are not read: the robot is drawn as segments between its joints.
    pub urdf: PathBuf,
    /// `"fixed"` (default) or `"floating"`.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "is_default"))]
    pub base: Base,
    /// A floating base's initial position (m); default the origin. Only with `base = "floating"`.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Option::is_none"))]
    pub base_position: Option<[f64; 3]>,
    /// A floating base's initial orientation as URDF roll, pitch, yaw (rad); default none. Only
    /// with `base = "floating"`.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Option::is_none"))]
    pub base_rpy: Option<[f64; 3]>,
    /// Moving joints locked at a position (rad or m), by name: they become fixed (a gripper's
    /// fingers, say).
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "BTreeMap::is_empty"))]
    pub locked: BTreeMap<String, f64>,
    /// Initial positions of one-degree-of-freedom joints, by name (rad or m); the others start
    /// at zero.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "BTreeMap::is_empty"))]
    pub q0: BTreeMap<String, f64>,
    /// Initial velocities of one-degree-of-freedom joints, by name (rad/s or m/s); the others
    /// start at rest.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "BTreeMap::is_empty"))]
    pub v0: BTreeMap<String, f64>,
    /// Viscous damping of every joint but the floating base (N·m·s/rad); default 0.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "is_default"))]
    pub damping: f64,
    /// Stiffness of the joint-limit penalty (N·m/rad); default 1000.
    #[cfg_attr(feature = "serde", serde(default = "default_limit_stiffness"))]
    pub limit_stiffness: f64,
    /// Damping of the joint-limit penalty, active beyond a limit (N·m·s/rad); default 5.
    #[cfg_attr(feature = "serde", serde(default = "default_limit_damping"))]
    pub limit_damping: f64,
    /// The time stepper; default `"rk4"`.
    #[cfg_attr(feature = "serde", serde(default = "default_integrator"))]
    pub integrator: RigidIntegrator,
    /// Proportional-derivative servos; default none.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Option::is_none"))]
    pub servo: Option<ServoSpec>,
    /// A schedule of applied torques; default none.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Vec::is_empty"))]
    pub torque: Vec<TorqueKey>,
}

#[cfg(feature = "serde")]
fn default_integrator() -> RigidIntegrator {
    RigidIntegrator::Rk4
}

/// Why a robot scene could not be built: the URDF, or a field of [`RobotSpec`].
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum RobotError {
    /// The URDF did not load (the error names its file, line and element).
    #[error(transparent)]
    Urdf(#[from] UrdfError),
    /// A field names no suitable joint or holds a bad value.
    #[error("{message}")]
    Invalid {
        /// The field of [`RobotSpec`], dotted (`q0.panda_joint9`, `servo.kp`, `torque[1].from`).
        field: String,
        /// What is wrong.
        message: String,
    },
    /// The simulation refused the parameters or the state.
    #[error(transparent)]
    Sim(#[from] SimError),
}

impl RobotError {
    /// The field of [`RobotSpec`] at fault (`urdf` for the file itself; empty when the
    /// simulation refused the whole).
    #[must_use]
    pub fn field(&self) -> &str {
        match self {
            RobotError::Urdf(_) => "urdf",
            RobotError::Invalid { field, .. } => field,
            RobotError::Sim(_) => "",
        }
    }

    fn invalid(field: impl Into<String>, message: impl Into<String>) -> Self {
        RobotError::Invalid { field: field.into(), message: message.into() }
    }
}

/// Applied joint torques over time, held constant over each step: a step from `t` to `t + dt`
/// gets the torques of the last entry starting at or before its middle `t + dt/2` (none before
/// the first), so an entry starting on a step boundary takes effect exactly there whatever the
/// rounding of `t`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TorqueSchedule {
    /// `(from, torques of length nv)`, `from` strictly increasing.
    keys: Vec<(f64, Vec<f64>)>,
    zero: Vec<f64>,
}

impl TorqueSchedule {
    /// A schedule of `(from, torques)` entries for a model of `nv` velocities.
    ///
    /// # Errors
    /// [`SimError::BadParameter`] for a start time that is negative, non-finite or not after the
    /// previous one, or torques of the wrong length or non-finite.
    pub fn new(keys: Vec<(f64, Vec<f64>)>, nv: usize) -> Result<Self, SimError> {
        let mut last = f64::NEG_INFINITY;
        for (from, torque) in &keys {
            if !(from.is_finite() && *from >= 0.0 && *from > last) {
                return Err(SimError::BadParameter {
                    name: "torque schedule",
                    value: from.to_string(),
                    requirement: "start times must be finite, >= 0 and increasing",
                });
            }
            last = *from;
            if torque.len() != nv || torque.iter().any(|x| !x.is_finite()) {
                return Err(SimError::BadParameter {
                    name: "torque schedule",
                    value: format!("{} entries at t = {from}", torque.len()),
                    requirement: "torques must be nv finite values",
                });
            }
        }
        Ok(Self { keys, zero: vec![0.0; nv] })
    }

    /// Whether the schedule has no entry (no torque is ever applied by it).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.keys.is_empty()
    }

    /// The torques of the step from `t` to `t + dt`; `None` for an empty schedule.
    #[must_use]
    pub fn at(&self, t: f64, dt: f64) -> Option<&[f64]> {
        if self.keys.is_empty() {
            return None;
        }
        let middle = t + 0.5 * dt;
        let k = self.keys.partition_point(|(from, _)| *from <= middle);
        Some(if k == 0 { &self.zero } else { &self.keys[k - 1].1 })
    }
}

impl RobotSpec {
    /// The robot of this spec, its URDF read from `urdf` (the caller resolves
    /// [`urdf`](Self::urdf) against its folder), as a scene, with its torque schedule.
    ///
    /// # Errors
    /// [`RobotError::Urdf`] for a URDF that does not load or a locked joint it does not have;
    /// [`RobotError::Invalid`] naming the field for a joint name that is not a moving
    /// one-degree-of-freedom joint of the robot, a non-finite value, a base pose on a fixed base
    /// or a bad schedule; [`RobotError::Sim`] for gains or coefficients the simulation refuses.
    pub fn build(&self, urdf: &Path) -> Result<(RigidScene, TorqueSchedule), RobotError> {
        let mut options = UrdfOptions::default().floating_base(self.base == Base::Floating);
        for (name, &position) in &self.locked {
            finite(&format!("locked.{name}"), position)?;
            options = options.lock_joint(name, position);
        }
        let model = load_urdf(urdf, &options)?;
        let joint = |field: &str, name: &str| one_dof_joint(&model, &self.locked, field, name);

        let mut q = config::neutral(&model);
        let mut v = vec![0.0; model.nv()];
        for (name, &value) in &self.q0 {
            let field = format!("q0.{name}");
            q[joint(&field, name)?.idx_q] = finite(&field, value)?;
        }
        for (name, &value) in &self.v0 {
            let field = format!("v0.{name}");
            v[joint(&field, name)?.idx_v] = finite(&field, value)?;
        }
        self.place_base(&model, &mut q)?;

        let mut servos = Vec::new();
        if let Some(servo) = &self.servo {
            for (name, &target) in &servo.target {
                let field = format!("servo.target.{name}");
                let dof = joint(&field, name)?.idx_v;
                servos.push(Servo { dof, target: finite(&field, target)?, kp: servo.kp, kd: servo.kd });
            }
        }
        let params = SimParams::default()
            .with_damping(self.damping)
            .with_limits(self.limit_stiffness, self.limit_damping)
            .with_servos(servos);
        params.check(&model).map_err(|e| match &e {
            // Name the spec's field: `servos` is its `servo` table; the others keep their names.
            SimError::BadParameter { name, .. } => {
                RobotError::invalid(if *name == "servos" { "servo" } else { name }, e.to_string())
            }
            _ => RobotError::Sim(e),
        })?;

        let mut keys = Vec::with_capacity(self.torque.len());
        for (k, key) in self.torque.iter().enumerate() {
            let mut tau = vec![0.0; model.nv()];
            for (name, &value) in &key.joints {
                let field = format!("torque[{k}].joints.{name}");
                tau[joint(&field, name)?.idx_v] = finite(&field, value)?;
            }
            keys.push((key.from, tau));
        }
        let schedule = TorqueSchedule::new(keys, model.nv())
            .map_err(|e| RobotError::invalid("torque", format!("{e} (entries in order of `from`)")))?;

        let segments = segments(&model);
        let scene = RigidScene {
            name: "robot",
            description: "a robot from a URDF file",
            model,
            params,
            state: RigidState::new(q, v),
            dt: 1e-3,
            duration: 1.0,
            integrator: self.integrator,
            segments,
        };
        Ok((scene, schedule))
    }

    /// A floating base's initial pose into `q`; a pose on a fixed base is refused.
    fn place_base(&self, model: &Model, q: &mut [f64]) -> Result<(), RobotError> {
        let floating = model.joints().get(1).filter(|j| matches!(j.kind, JointType::Free));
        let Some(base) = floating else {
            if self.base_position.is_some() || self.base_rpy.is_some() {
                let field = if self.base_position.is_some() { "base_position" } else { "base_rpy" };
                return Err(RobotError::invalid(field, "a base pose needs `base = \"floating\"`"));
            }
            return Ok(());
        };
        let i = base.idx_q;
        if let Some(p) = self.base_position {
            for (c, &x) in p.iter().enumerate() {
                q[i + c] = finite("base_position", x)?;
            }
        }
        if let Some([roll, pitch, yaw]) = self.base_rpy {
            for x in [roll, pitch, yaw] {
                finite("base_rpy", x)?;
            }
            let r = DQuat::from_mat3(&rpy_to_matrix(roll, pitch, yaw)).normalize();
            q[i + 3..i + 7].copy_from_slice(&[r.x, r.y, r.z, r.w]);
        }
        Ok(())
    }
}

fn finite(field: &str, value: f64) -> Result<f64, RobotError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(RobotError::invalid(field, format!("{value} is not finite")))
    }
}

/// The moving one-degree-of-freedom joint `name` of `model`, or an error naming `field` and
/// listing the joints it could have been.
fn one_dof_joint<'m>(
    model: &'m Model,
    locked: &BTreeMap<String, f64>,
    field: &str,
    name: &str,
) -> Result<&'m Joint, RobotError> {
    match model.joint_id(name).map(|j| model.joint(j)) {
        Some(j) if j.nq() == 1 => Ok(j),
        Some(j) => Err(RobotError::invalid(
            field,
            format!(
                "joint `{name}` is a {} joint; only one-degree-of-freedom joints are named here",
                j.kind.name()
            ),
        )),
        None if locked.contains_key(name) => {
            Err(RobotError::invalid(field, format!("joint `{name}` is locked (see `locked`)")))
        }
        None => {
            let names: Vec<&str> =
                model.joints()[1..].iter().filter(|j| j.nq() == 1).map(|j| j.name.as_str()).collect();
            Err(RobotError::invalid(
                field,
                format!("the robot has no moving joint `{name}` (its joints: {})", names.join(", ")),
            ))
        }
    }
}

/// What a robot is drawn as: a segment from each joint to its parent joint, and from each
/// joint to the frames it carries away from its origin (link origins, tool centres); segments
/// of zero length are left out, unless nothing else is left to draw.
fn segments(model: &Model) -> Vec<(FrameIndex, FrameIndex)> {
    // The frame marking each joint's origin: its own joint frame, the universe for joint 0.
    let mut origin = vec![None; model.njoints()];
    for (f, frame) in model.frames().iter().enumerate() {
        let at_origin = frame.placement.translation == DVec3::ZERO;
        let marks = matches!(frame.kind, FrameKind::Joint) || frame.parent_joint == 0;
        if at_origin && marks && origin[frame.parent_joint].is_none() {
            origin[frame.parent_joint] = Some(f);
        }
    }
    let mut out = Vec::new();
    for (j, joint) in model.joints().iter().enumerate().skip(1) {
        if let (Some(a), Some(b)) = (origin[joint.parent], origin[j])
            && joint.placement.translation != DVec3::ZERO
        {
            out.push((a, b));
        }
    }
    // Frames at one place on one joint (a link and the fixed joint merged into it) are drawn once.
    let mut drawn = Vec::new();
    for (f, frame) in model.frames().iter().enumerate() {
        let offset = frame.placement.translation;
        let key = (frame.parent_joint, offset.to_array().map(f64::to_bits));
        if matches!(frame.kind, FrameKind::Joint) || offset == DVec3::ZERO || drawn.contains(&key) {
            continue;
        }
        if let Some(a) = origin[frame.parent_joint] {
            drawn.push(key);
            out.push((a, f));
        }
    }
    // A robot whose frames all sit on its joints (one free body) is drawn as its joint origins,
    // so its frames still hold where it is.
    if out.is_empty() {
        out.extend(origin.iter().skip(1).flatten().map(|&f| (f, f)));
    }
    out
}

#[cfg(test)]
#[cfg(feature = "serde")]
mod tests;
