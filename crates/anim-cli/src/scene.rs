//! Scene files: a TOML description of what to simulate and how long.
//!
//! ```toml
//! name = "kepler"
//!
//! [run]
//! dt = 0.01          # seconds per step
//! frames = 300       # frames written
//! steps_per_frame = 5
//!
//! [scene]
//! kind = "kepler-orbit"
//! eccentricity = 0.5
//! integrator = "velocity-verlet"   # or { beta-blend = { beta = 0.5 } }
//! ```
//!
//! `kind` names a registered scene kind (`anim list --kinds`); the other fields of `[scene]` are
//! that kind's parameters, read by the crate that implements it with unknown fields refused (a
//! typo never silently falls back to a default). Every error names the file and the field, with
//! its line where the file has one. The built-in scenes are the registered presets, written as
//! scene files.

use anim_core::scene::{BuildContext, BuildError, DynScene, Preset, RunDefaults, SceneKind};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// A scene file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// Scene name, used for the output folder.
    pub name: String,
    /// Time stepping and output: `dt` (s, > 0), `frames` (>= 1), `steps_per_frame` (>= 1,
    /// default 1).
    pub run: RunDefaults,
    /// What is simulated.
    pub scene: SceneSpec,
}

/// The `[scene]` table: a registered kind and its parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SceneSpec {
    /// The scene kind (`"springs"`, `"kepler-orbit"`, ...).
    pub kind: String,
    /// The kind's parameters, as the file gives them.
    #[serde(flatten)]
    pub params: serde_json::Map<String, serde_json::Value>,
}

impl SceneSpec {
    /// The parameters as one JSON value.
    #[must_use]
    pub fn params_value(&self) -> serde_json::Value {
        serde_json::Value::Object(self.params.clone())
    }

    /// The registered kind, if any.
    #[must_use]
    pub fn registered(&self) -> Option<&'static SceneKind> {
        anim::kind(&self.kind)
    }

    /// `KIND/PRESET` where the parameters name a preset (or a file), `KIND/robot` for a robot
    /// table, else `KIND`.
    #[must_use]
    pub fn system(&self) -> String {
        match self.params.get("preset").or_else(|| self.params.get("file")).and_then(|v| v.as_str()) {
            Some(p) => format!("{}/{p}", self.kind),
            None if self.params.contains_key("robot") => format!("{}/robot", self.kind),
            None => self.kind.clone(),
        }
    }
}

/// A scene that could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read.
    #[error("{path}: cannot read scene file: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The file is not valid TOML or does not match the scene format.
    #[error("{path}:{line}:{column}: {message}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// A value is out of its valid range.
    #[error("{path}: field `{field}`: {message}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// Dotted field path, e.g. `run.dt`.
        field: String,
        /// What is wrong.
        message: String,
    },
}

impl SceneError {
    /// An out-of-range value found after parsing.
    #[must_use]
    pub fn invalid(path: &Path, field: impl Into<String>, message: impl Into<String>) -> Self {
        SceneError::Invalid { path: path.to_path_buf(), field: field.into(), message: message.into() }
    }
}

/// The scene run when no scene is named: the most telling one the workspace has.
pub const DEFAULT_SCENE: &str = "cloth";

/// The built-in scene `name`: the registered preset of that name as a scene file.
#[must_use]
pub fn builtin(name: &str) -> Option<SceneFile> {
    anim::preset(name).map(|(kind, preset)| from_preset(kind, &preset))
}

/// A preset as a scene file.
#[must_use]
pub fn from_preset(kind: &SceneKind, preset: &Preset) -> SceneFile {
    let params = match &preset.params {
        serde_json::Value::Object(map) => map.clone(),
        _ => serde_json::Map::new(),
    };
    SceneFile {
        name: preset.name.to_string(),
        run: preset.run,
        scene: SceneSpec { kind: kind.kind.to_string(), params },
    }
}

/// The built-in scenes: `(name, description)` in registry order.
#[must_use]
pub fn builtins() -> Vec<(&'static str, &'static str)> {
    anim::presets().into_iter().map(|(_, p)| (p.name, p.description)).collect()
}

/// Parses scene text; `path` names the source in errors. The kind's parameters are checked when
/// the scene is built ([`build`]).
///
/// # Errors
/// [`SceneError::Parse`] with line and column, or [`SceneError::Invalid`] naming the field.
pub fn parse(text: &str, path: &Path) -> Result<SceneFile, SceneError> {
    let scene: SceneFile = toml::from_str(text).map_err(|e| {
        let start = e.span().map_or(0, |s| s.start);
        let start =
            unknown_field(e.message()).and_then(|name| field_offset(text, start, name)).unwrap_or(start);
        let (line, column) = line_col(text, start);
        SceneError::Parse { path: path.to_path_buf(), line, column, message: e.message().trim().to_string() }
    })?;
    validate(&scene).map_err(|(field, message)| SceneError::invalid(path, field, message))?;
    if scene.scene.registered().is_none() {
        let kinds: Vec<&str> = anim::kinds().map(|k| k.kind).collect();
        let at = table_header(text, "scene").and_then(|s| field_offset(text, s, "kind")).unwrap_or(0);
        let (line, column) = line_col(text, at);
        return Err(SceneError::Parse {
            path: path.to_path_buf(),
            line,
            column,
            message: format!("unknown scene kind `{}` (one of {})", scene.scene.kind, kinds.join(", ")),
        });
    }
    Ok(scene)
}

/// Loads a scene file from disk.
///
/// # Errors
/// [`SceneError`] naming the file.
pub fn load(path: &Path) -> Result<SceneFile, SceneError> {
    let text = std::fs::read_to_string(path)
        .map_err(|source| SceneError::Io { path: path.to_path_buf(), source })?;
    parse(&text, path)
}

/// Builds the scene of `file` through its registered kind. `origin` is the file (or the
/// built-in scene's name) errors name; relative file names in the parameters are read from its
/// folder. `text`, the file's text where there is one, lets an error give the field's line.
///
/// # Errors
/// [`SceneError`] naming the field (and its line, with `text`) that the kind refused.
pub fn build(file: &SceneFile, origin: &Path, text: Option<&str>) -> Result<Box<dyn DynScene>, SceneError> {
    let Some(kind) = file.scene.registered() else {
        return Err(SceneError::invalid(
            origin,
            "scene.kind",
            format!("unknown scene kind `{}`", file.scene.kind),
        ));
    };
    let base = origin.parent().filter(|p| !p.as_os_str().is_empty());
    let context = BuildContext { base };
    (kind.build)(&file.scene.params_value(), &context).map_err(|e| build_error(e, origin, text))
}

/// A kind's refusal as a scene-file error: with the field's line where the text has it.
fn build_error(e: BuildError, origin: &Path, text: Option<&str>) -> SceneError {
    let (field, message) = match e {
        BuildError::Schema { field, message } => (field, message),
        BuildError::Invalid { field, message } => (field, message),
        BuildError::Memory { field, message, .. } => (field, message),
        other => (String::new(), other.to_string()),
    };
    let at = text.and_then(|t| locate(t, &field));
    let key = field.split(['.', '[']).next().unwrap_or_default();
    match (text, at) {
        (Some(t), Some(at)) if !key.is_empty() => {
            let (line, column) = line_col(t, at);
            SceneError::Parse {
                path: origin.to_path_buf(),
                line,
                column,
                message: format!("field `scene.{field}`: {message}"),
            }
        }
        _ if field.is_empty() => SceneError::invalid(origin, "scene", message),
        _ => SceneError::invalid(origin, format!("scene.{field}"), message),
    }
}

/// Byte offset of the line of `field` (a path like `robot.q0` or `bodies[1].material.young`)
/// in a scene file's text: the field's line in `[scene]`, or in its own `[scene.KEY]` table, or
/// in the `[[scene.KEY]]` table of that index; that table's header when the rest of the path is
/// not written on a line of its own.
fn locate(text: &str, field: &str) -> Option<usize> {
    let mut parts = field.splitn(2, '.');
    let head = parts.next().unwrap_or_default();
    let rest = parts.next();
    let (key, index) = match head.split_once('[') {
        Some((key, i)) => (key, i.trim_end_matches(']').parse::<usize>().ok()),
        None => (head, None),
    };
    if key.is_empty() {
        return None;
    }
    let scene = table_header(text, "scene")?;
    if let Some(at) = field_in_table(text, scene, key) {
        return Some(at);
    }
    let table = match index {
        Some(i) => nth_header(text, &format!("[[scene.{key}]]"), i)?,
        None => table_header(text, &format!("scene.{key}"))?,
    };
    let sub = rest.and_then(|r| r.split(['.', '[']).next());
    Some(sub.and_then(|name| field_in_table(text, table, name)).unwrap_or(table))
}

/// Byte offset of the `[name]` table header.
fn table_header(text: &str, name: &str) -> Option<usize> {
    nth_header(text, &format!("[{name}]"), 0)
}

/// Byte offset of the `n`-th (0-based) line that starts with `header`.
fn nth_header(text: &str, header: &str, n: usize) -> Option<usize> {
    let mut offset = 0;
    let mut seen = 0;
    for line in text.split_inclusive('\n') {
        if line.trim_start().starts_with(header) {
            if seen == n {
                return Some(offset);
            }
            seen += 1;
        }
        offset += line.len();
    }
    None
}

/// Whether a line opens a table (`[name]` or `[[name]]`), as opposed to continuing an array.
fn is_header(line: &str) -> bool {
    let rest = line.trim_start().trim_start_matches('[');
    line.trim_start().starts_with('[')
        && rest.starts_with(|c: char| c.is_alphabetic() || c == '"' || c == '\'')
}

/// Byte offset of the line assigning `name` in the table whose header line starts at `header`,
/// before the next table.
fn field_in_table(text: &str, header: usize, name: &str) -> Option<usize> {
    assignment(text, header, name, true)
}

/// Byte offset of the first line assigning `name` (`name = ...`, indented or not; the offset of
/// the key) among the lines of `text` from the one holding byte `from` on; with `table`, `from`
/// is on a table's header line and the search ends at the next table header.
fn assignment(text: &str, from: usize, name: &str, table: bool) -> Option<usize> {
    let mut offset = 0;
    let mut first = true;
    for line in text.split_inclusive('\n') {
        let start = offset;
        offset += line.len();
        if offset <= from {
            continue;
        }
        if table && !first && is_header(line) {
            return None;
        }
        first = false;
        let trimmed = line.trim_start();
        if trimmed.strip_prefix(name).is_some_and(|r| r.trim_start().starts_with('=')) {
            return Some(start + (line.len() - trimmed.len()));
        }
    }
    None
}

/// The name in serde's "unknown field `NAME`" message.
fn unknown_field(message: &str) -> Option<&str> {
    let rest = message.split_once("unknown field `")?.1;
    Some(rest.split_once('`')?.0)
}

/// Byte offset of the first line, from the one holding byte `from` on, that assigns `name`.
fn field_offset(text: &str, from: usize, name: &str) -> Option<usize> {
    assignment(text, from, name, false)
}

fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}

fn validate(s: &SceneFile) -> Result<(), (&'static str, String)> {
    if s.name.is_empty() || s.name.contains(['/', '\\']) || s.name.starts_with('.') {
        return Err(("name", format!("must be a plain non-empty name (used as a folder), got {:?}", s.name)));
    }
    if !(s.run.dt > 0.0 && s.run.dt.is_finite()) {
        return Err(("run.dt", format!("must be a positive finite number, got {}", s.run.dt)));
    }
    if s.run.frames == 0 {
        return Err(("run.frames", "must be at least 1".into()));
    }
    if s.run.steps_per_frame == 0 {
        return Err(("run.steps_per_frame", "must be at least 1".into()));
    }
    Ok(())
}

#[cfg(test)]
mod tests;
