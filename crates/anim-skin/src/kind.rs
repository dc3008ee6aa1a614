//! The `skinning` scene kind: a skinned character posed over time, as anim-core
//! [`SceneKind`], with its preset, its scene-file parameters ([`SkinParams`]) and the solver
//! the run loop drives ([`SkinPlayback`]).
//!
//! | preset | scene | run |
//! | --- | --- | --- |
//! | `twist` | [`twisted_cylinder`](crate::scenes::twisted_cylinder) twisted 180 degrees: LBS's candy-wrapper collapse beside DQS | 100 frames of 20 ms |
//!
//! A scene is the built-in cylinder (`preset`) or any skinned glTF 2.0 file (`file`, relative
//! to the scene file's folder), posed by linear blend skinning, dual-quaternion skinning or
//! both side by side (`method`). Nothing is integrated: the pose is a function of time, and a
//! step poses the character at the new time. The frame holds the posed vertices of every
//! method (the first method's left of the next, 1.4 widths apart along `x`) and their
//! velocities by finite difference from the previous pose.
//!
//! ```
//! use anim_core::scene::{BuildContext, Frame};
//!
//! let preset = (anim_skin::KIND.presets)().remove(0);
//! let mut scene = (anim_skin::KIND.build)(&preset.params, &BuildContext::default())?;
//! scene.step(preset.run.dt)?;
//! let mut frame = Frame::default();
//! scene.frame(&mut frame);
//! assert_eq!(scene.method(), "lbs beside dqs");
//! assert_eq!(frame.points.len(), 2 * 3 * (32 * 41 + 2)); // two cylinders of 1314 vertices
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use anim_core::integrate::State;
use anim_core::scene::{
    BuildContext, BuildError, Checkpoint, CheckpointError, Context, DynScene, Frame, Preset, RunDefaults,
    SceneKind, Simulated, Up, View, params, saved_state,
};
use anim_core::solver::{Solver, StepReport};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

use crate::SkinError;
use crate::character::CharacterData;
use crate::scenes::{self, SkinScene};
use crate::skinning::SkinningMethod;

/// The `skinning` scene kind of anim-skin, for the workspace registry.
pub const KIND: SceneKind = SceneKind {
    kind: "skinning",
    crate_name: "anim-skin",
    summary: "a skinned character posed over time by linear blend or dual-quaternion skinning",
    presets,
    build,
    tolerance: None,
};

/// Which skinning a scene shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SkinningChoice {
    /// Linear blend skinning (`"lbs"`).
    Lbs,
    /// Dual-quaternion skinning (`"dqs"`).
    Dqs,
    /// Both, side by side: LBS left, DQS right (`"both"`).
    Both,
}

impl SkinningChoice {
    /// Every choice, in a fixed order.
    pub const ALL: [SkinningChoice; 3] = [SkinningChoice::Lbs, SkinningChoice::Dqs, SkinningChoice::Both];

    /// Its scene-file spelling: `"lbs"`, `"dqs"` or `"both"`.
    #[must_use]
    pub const fn label(self) -> &'static str {
        match self {
            SkinningChoice::Lbs => "lbs",
            SkinningChoice::Dqs => "dqs",
            SkinningChoice::Both => "both",
        }
    }

    /// The methods shown, left to right.
    #[must_use]
    pub fn methods(self) -> &'static [SkinningMethod] {
        match self {
            SkinningChoice::Lbs => &[SkinningMethod::Lbs],
            SkinningChoice::Dqs => &[SkinningMethod::Dqs],
            SkinningChoice::Both => &[SkinningMethod::Lbs, SkinningMethod::Dqs],
        }
    }
}

impl std::fmt::Display for SkinningChoice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.label())
    }
}

impl std::str::FromStr for SkinningChoice {
    type Err = String;

    /// The scene-file spelling ([`SkinningChoice::label`]).
    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|c| c.label() == s)
            .ok_or_else(|| format!("unknown skinning `{s}` (one of lbs, dqs, both)"))
    }
}

/// Scene-file parameters of a `skinning` scene (the `[scene]` table without `kind`). Exactly
/// one of `preset` and `file`. A file must hold at least one skinned triangle mesh (a mesh on a
/// node with a skin, with `JOINTS_0`/`WEIGHTS_0`); without an animation it is shown in its rest
/// pose at every frame, and after its first animation's last key it holds the last pose.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SkinParams {
    /// A built-in character: `"twisted-cylinder"` ([`scenes::NAMES`]). Default: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preset: Option<String>,
    /// A skinned glTF 2.0 file (`.gltf` or `.glb`), relative to the scene file's folder
    /// ([`BuildContext::resolve`]); its first animation is played. Default: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<PathBuf>,
    /// `"lbs"`, `"dqs"` or `"both"` (side by side). Default: `"both"` for a preset, `"dqs"` for
    /// a file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub method: Option<SkinningChoice>,
}

fn presets() -> Vec<Preset> {
    vec![Preset {
        name: "twist",
        description: "a cylinder twisted 180 degrees: LBS's candy-wrapper collapse beside DQS",
        run: RunDefaults::new(0.02, 100, 1),
        params: serde_json::json!({ "preset": "twisted-cylinder", "method": "both" }),
        quick_params: None,
    }]
}

fn build(value: &serde_json::Value, context: &BuildContext<'_>) -> Result<Box<dyn DynScene>, BuildError> {
    let p: SkinParams = params(value)?;
    let scene = match (&p.preset, &p.file) {
        (Some(name), None) if name == "twisted-cylinder" => {
            scenes::twisted_cylinder(None).map_err(|e| BuildError::invalid("preset", e.to_string()))?
        }
        (Some(name), None) => {
            return Err(BuildError::invalid(
                "preset",
                format!("unknown preset `{name}` (one of {})", scenes::NAMES.join(", ")),
            ));
        }
        #[cfg(not(feature = "gltf"))]
        (None, Some(file)) => {
            return Err(BuildError::invalid(
                "file",
                format!(
                    "{}: reading glTF files needs anim-skin's `gltf` feature, which this build lacks",
                    context.resolve(file).display()
                ),
            ));
        }
        #[cfg(feature = "gltf")]
        (None, Some(file)) => {
            let path = context.resolve(file);
            let scene = scenes::from_gltf(&path).map_err(|e| BuildError::invalid("file", e.to_string()))?;
            if scene.character.meshes.is_empty() {
                let skipped = if scene.warnings.is_empty() {
                    String::new()
                } else {
                    format!(" (skipped: {})", scene.warnings.join("; "))
                };
                return Err(BuildError::invalid(
                    "file",
                    format!(
                        "{}: no skinned mesh: a skinning scene poses the triangle meshes of nodes \
                         with a skin{skipped}",
                        path.display()
                    ),
                ));
            }
            scene
        }
        _ => return Err(BuildError::invalid("preset", "give exactly one of `preset` and `file`")),
    };
    let default = if p.preset.is_some() { SkinningChoice::Both } else { SkinningChoice::Dqs };
    let (solver, state) = SkinPlayback::new(scene, p.method.unwrap_or(default))
        .map_err(|e| BuildError::invalid("method", e.to_string()))?;
    Ok(Simulated::new(solver, state).boxed())
}

/// Why a step of a [`SkinPlayback`] failed; the state is then unchanged.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PlaybackError {
    /// The time step is not a positive finite number.
    #[error("anim-skin: time step must be positive and finite, got {dt}")]
    BadTimeStep {
        /// The step given.
        dt: f64,
    },
    /// A method could not pose the character at the new time (DQS on a scaled joint).
    #[error("anim-skin: {method:?} pose at t = {t}: {error}")]
    Pose {
        /// The method.
        method: SkinningMethod,
        /// The time posed.
        t: f64,
        /// Why.
        error: SkinError,
    },
}

/// A [`SkinScene`] played over time with one or more skinning methods side by side: the state
/// is the posed vertices of every method (flat, 3 per vertex, method by method), their
/// velocities by finite difference from the previous pose, and the time.
///
/// Nothing is integrated: a step poses the clip at the new time, so
/// [`Checkpoint::provoke_overflow`] has nothing to overflow and returns `None`.
#[derive(Debug, Clone)]
pub struct SkinPlayback {
    scene: SkinScene,
    /// Each method with its posing buffers and its offset along `x`.
    methods: Vec<(SkinningMethod, CharacterData, f64)>,
    /// The character's triangles, repeated per method on its vertices.
    triangles: Vec<[usize; 3]>,
    /// Posed positions of one method.
    scratch: Vec<[f64; 3]>,
}

impl SkinPlayback {
    /// `scene` shown by `choice`, posed at time 0 (zero velocities). With two methods, each is
    /// shifted along `x` by 1.4 times the width of the character's pose at time 0, centred on
    /// the origin.
    ///
    /// # Errors
    /// [`SkinError`] when a method cannot pose the character at time 0 (DQS on scaled joints).
    pub fn new(scene: SkinScene, choice: SkinningChoice) -> Result<(Self, State), SkinError> {
        let methods = choice.methods();
        let mut data = scene.data();
        scene.pose(&mut data, 0.0, SkinningMethod::Lbs)?;
        let mut rest = Vec::new();
        data.positions(&mut rest);
        let (mut lo, mut hi) = (f64::MAX, f64::MIN);
        for p in &rest {
            lo = lo.min(p[0]);
            hi = hi.max(p[0]);
        }
        let width = if hi > lo { hi - lo } else { 1.0 };
        let count = methods.len() as f64;
        let methods: Vec<(SkinningMethod, CharacterData, f64)> = methods
            .iter()
            .enumerate()
            .map(|(k, &m)| (m, scene.data(), (k as f64 - 0.5 * (count - 1.0)) * 1.4 * width))
            .collect();
        let base: Vec<[usize; 3]> =
            scene.character.triangles().iter().map(|t| t.map(|i| i as usize)).collect();
        let n = rest.len();
        let triangles =
            (0..methods.len()).flat_map(|k| base.iter().map(move |t| t.map(|i| i + k * n))).collect();
        let dof = 3 * n * methods.len();
        let mut playback = Self { scene, methods, triangles, scratch: Vec::new() };
        let mut state = State::new(vec![0.0; dof], vec![0.0; dof]);
        playback.pose_all(&mut state, 0.0).map_err(|(_, e)| e)?;
        Ok((playback, state))
    }

    /// The scene played.
    #[must_use]
    pub fn scene(&self) -> &SkinScene {
        &self.scene
    }

    /// Poses every method at `t` into `state` (velocities by difference with its last pose);
    /// `state` is unchanged when a method fails.
    fn pose_all(&mut self, state: &mut State, t: f64) -> Result<(), (SkinningMethod, SkinError)> {
        for (method, data, _) in &mut self.methods {
            self.scene.pose(data, t, *method).map_err(|e| (*method, e))?;
        }
        let dt = t - state.t;
        let mut at = 0;
        for (_, data, offset) in &self.methods {
            data.positions(&mut self.scratch);
            for p in &self.scratch {
                let q = [p[0] + *offset, p[1], p[2]];
                for k in 0..3 {
                    state.v[at + k] = if dt > 0.0 { (q[k] - state.x[at + k]) / dt } else { 0.0 };
                    state.x[at + k] = q[k];
                }
                at += 3;
            }
        }
        state.t = t;
        Ok(())
    }
}

impl Solver for SkinPlayback {
    type State = State;
    type Error = PlaybackError;

    fn step(&mut self, state: &mut State, dt: f64) -> Result<StepReport, PlaybackError> {
        if !(dt > 0.0 && dt.is_finite()) {
            return Err(PlaybackError::BadTimeStep { dt });
        }
        let t = state.t + dt;
        self.pose_all(state, t).map_err(|(method, error)| PlaybackError::Pose { method, t, error })?;
        Ok(StepReport::at_time(t))
    }
}

impl Checkpoint for SkinPlayback {
    const VERSION: u32 = 1;

    fn time(&self, state: &State) -> f64 {
        state.t
    }

    /// `{"state": state}`: the pose is a function of time; positions and velocities are kept so
    /// that the next step's finite-difference velocities continue exactly.
    fn save(&self, state: &State) -> serde_json::Value {
        serde_json::json!({ "state": state })
    }

    fn restore(&mut self, state: &mut State, saved: &serde_json::Value) -> Result<(), CheckpointError> {
        *state = saved_state(saved, "state", state)?;
        Ok(())
    }

    /// `None`: nothing is integrated, the pose is a function of time (the clip's keys are
    /// checked finite when loaded), so no state value can make a step overflow.
    fn provoke_overflow(&mut self, _: &mut State) -> Option<String> {
        None
    }
}

impl View for SkinPlayback {
    /// The methods, left to right: `"lbs"`, `"dqs"` or `"lbs beside dqs"`.
    fn method(&self) -> String {
        self.methods
            .iter()
            .map(|(m, _, _)| format!("{m:?}").to_lowercase())
            .collect::<Vec<_>>()
            .join(" beside ")
    }

    /// The character's triangles on every method's vertices; the pose's bounding box widened
    /// sideways.
    fn context(&self, state: &State) -> Context {
        let mut context = Context::default();
        context.point_dim = 3;
        context.triangles.clone_from(&self.triangles);
        context.bounds = Some(anim_core::scene::frame_box(&state.x, Up::Y, None, false));
        context.notes.clone_from(&self.scene.warnings);
        context
    }

    fn frame(&self, state: &State, out: &mut Frame) {
        out.time = state.t;
        out.points.clone_from(&state.x);
        out.field_mut("velocity", 3).extend_from_slice(&state.v);
    }
}
