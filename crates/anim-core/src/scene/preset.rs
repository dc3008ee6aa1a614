//! [`SceneKind`] and [`Preset`]: how a crate registers its scenes.

use super::dynamic::DynScene;
use super::study::Tolerance;
use serde::de::DeserializeOwned;
use std::path::Path;

/// How long a preset runs and how often it is written, unless a scene file says otherwise.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunDefaults {
    /// Time step (s), > 0.
    pub dt: f64,
    /// Frames written, >= 1.
    pub frames: usize,
    /// Steps between written frames, >= 1.
    #[serde(default = "one")]
    pub steps_per_frame: usize,
}

/// Whether `value` is its type's default: for `#[serde(skip_serializing_if = "...")]` on
/// scene-file parameters, so a saved scene file lists only what was set.
#[must_use]
pub fn is_default<T: Default + PartialEq>(value: &T) -> bool {
    *value == T::default()
}

fn one() -> usize {
    1
}

impl RunDefaults {
    /// `frames` frames of `steps_per_frame` steps of `dt`.
    #[must_use]
    pub const fn new(dt: f64, frames: usize, steps_per_frame: usize) -> Self {
        Self { dt, frames, steps_per_frame }
    }

    /// Total steps of the run.
    #[must_use]
    pub fn steps(&self) -> usize {
        self.frames * self.steps_per_frame
    }
}

/// A named, ready-to-run scene of a crate: what `anim run NAME` runs and what the workspace's
/// generic suites (determinism, allocation, checkpoints, non-finite guard) run for every crate.
#[derive(Debug, Clone, PartialEq)]
pub struct Preset {
    /// Name, unique across the workspace (`anim run NAME`): lower case, words joined by `-`.
    pub name: &'static str,
    /// One line saying what is seen and by which method.
    pub description: &'static str,
    /// Step and frame counts.
    pub run: RunDefaults,
    /// The scene-file parameters of the preset: the `[scene]` table without `kind`, as the
    /// crate's parameter type serialises it.
    pub params: serde_json::Value,
    /// A smaller version of the same scene for quick suites (a coarser grid, fewer particles),
    /// or `None` when the preset is small already.
    pub quick_params: Option<serde_json::Value>,
}

impl Preset {
    /// The parameters a suite runs the preset with: its `quick_params` when `quick` (and it has
    /// them), else its `params`.
    #[must_use]
    pub fn params_for(&self, quick: bool) -> &serde_json::Value {
        if quick { self.quick_params.as_ref().unwrap_or(&self.params) } else { &self.params }
    }
}

/// What a scene built from a file may need beyond its parameters.
#[derive(Debug, Clone, Default)]
pub struct BuildContext<'a> {
    /// The folder relative file names in the parameters are read from (the scene file's
    /// folder); the working directory when `None`.
    pub base: Option<&'a Path>,
}

impl BuildContext<'_> {
    /// `name` relative to [`BuildContext::base`].
    #[must_use]
    pub fn resolve(&self, name: &Path) -> std::path::PathBuf {
        match self.base {
            Some(base) => base.join(name),
            None => name.to_path_buf(),
        }
    }
}

/// Parameters a scene cannot be built from.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum BuildError {
    /// The parameters do not fit the kind's schema: an unknown field, a missing one, a value of
    /// the wrong type or an unknown name.
    #[error("{}{message}", if field.is_empty() { String::new() } else { format!("field `{field}`: ") })]
    Schema {
        /// Where in the parameters (dotted path, empty for the table itself: an unknown or
        /// missing field, whose name the message gives).
        field: String,
        /// serde's message.
        message: String,
    },
    /// A parameter is out of range, or the scene cannot be built with it.
    #[error("field `{field}`: {message}")]
    Invalid {
        /// The parameter's name (dotted for nested ones).
        field: String,
        /// What is wrong, with the valid range or names.
        message: String,
    },
    /// The scene the parameters ask for needs more memory than is available
    /// ([`MemoryNeed::check`](super::MemoryNeed::check)).
    #[error("field `{field}`: {message}")]
    Memory {
        /// The parameter that sets the size (dotted for nested ones).
        field: String,
        /// What was asked, the estimate with its parts, and the memory available.
        message: String,
        /// The estimate (bytes).
        bytes: f64,
        /// The memory it was checked against (bytes): what was available, or
        /// [`UNKNOWN_LIMIT`](super::UNKNOWN_LIMIT) when that is unknown.
        available: f64,
    },
}

impl BuildError {
    /// An [`BuildError::Invalid`] of `field`.
    #[must_use]
    pub fn invalid(field: impl Into<String>, message: impl Into<String>) -> Self {
        Self::Invalid { field: field.into(), message: message.into() }
    }

    /// The same error, of a field of the table `prefix` (such as `bodies[2]`): its field becomes
    /// `prefix.field`, or `prefix` for the table itself.
    ///
    /// ```
    /// use anim_core::scene::{BuildError, Placement};
    ///
    /// let bad = Placement { scale: 0.0, ..Placement::default() };
    /// let e = bad.check().unwrap_err().within("bodies[2]");
    /// assert_eq!(e.to_string(), "field `bodies[2].scale`: must be positive and finite, got 0");
    /// let table = BuildError::Schema { field: String::new(), message: "unknown field `x`".into() };
    /// assert_eq!(table.within("bodies[0]").to_string(), "field `bodies[0]`: unknown field `x`");
    /// ```
    #[must_use]
    pub fn within(self, prefix: &str) -> Self {
        let join =
            |field: String| if field.is_empty() { prefix.to_string() } else { format!("{prefix}.{field}") };
        match self {
            Self::Schema { field, message } => Self::Schema { field: join(field), message },
            Self::Invalid { field, message } => Self::Invalid { field: join(field), message },
            Self::Memory { field, message, bytes, available } => {
                Self::Memory { field: join(field), message, bytes, available }
            }
        }
    }
}

/// The parameters of a kind, read from their scene-file form.
///
/// # Errors
/// [`BuildError::Schema`] with serde's message and the path of the value it concerns when
/// `value` does not fit `T`.
pub fn params<T: DeserializeOwned>(value: &serde_json::Value) -> Result<T, BuildError> {
    serde_path_to_error::deserialize(value).map_err(|e| {
        let field = e.path().to_string();
        let field = if field == "." { String::new() } else { field };
        BuildError::Schema { field, message: e.into_inner().to_string() }
    })
}

/// A crate's scenes as the registry lists them: one `kind` of scene file, its presets and the
/// builder from its parameters. The command line, `cargo xtask` and the Python bindings walk a
/// list of these and know nothing else about the crate.
#[derive(Debug, Clone, Copy)]
pub struct SceneKind {
    /// The `kind` a scene file names (`"springs"`, `"harmonic-oscillator"`).
    pub kind: &'static str,
    /// The crate that implements it (`"anim-springs"`).
    pub crate_name: &'static str,
    /// One line saying what the kind simulates.
    pub summary: &'static str,
    /// The presets of this kind.
    pub presets: fn() -> Vec<Preset>,
    /// Builds a scene from its parameters (the `[scene]` table without `kind`).
    pub build: BuildFn,
    /// How the report's studies map to this kind's scenes for `--tolerance` (`None`: no study
    /// measured them).
    pub tolerance: Option<Tolerance>,
}

/// The builder of a [`SceneKind`]: parameters in, a scene out.
pub type BuildFn = fn(&serde_json::Value, &BuildContext<'_>) -> Result<Box<dyn DynScene>, BuildError>;
