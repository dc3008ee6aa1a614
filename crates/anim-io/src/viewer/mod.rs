//! A browser viewer of a run: `viewer.html` beside the run's frames, with the frames in a
//! compact binary layout under `viewer/`.
//!
//! The page is self-contained: three.js (MIT, r170, vendored under `vendor/three/` of this
//! crate) is embedded in it, so it opens from the folder with no network and no server, by a
//! double click. It has orbit controls, play and pause, a time slider, colouring by any field of
//! the frames, and the scene's context (ground, colliders, tank walls, mesh obstacles, pins).
//!
//! | file | content |
//! | --- | --- |
//! | `viewer.html` | the page, three.js and the viewer's code; written once when the run starts |
//! | `viewer/context.js` | `ANIM.context(JSON)`: what the frames are drawn with (the scene's static context, as given) |
//! | `viewer/f00000.js` ... | `ANIM.frame(k, header, data)`: one frame; `data` is base64 of little-endian parts, each padded to 4 bytes, named in `header.parts` as `[name, components, "f32"]` (points, then per-point fields) or `[name, 1, "u8", lo, hi]` (a cell field quantised over `[lo, hi]`); `header.props`, where present, the props that move with the scene |
//! | `viewer/index.js` | `ANIM.index({"frames": [[t, file], ...]})`: the frames present, rewritten (atomically) after every frame, so a run that stops early leaves a page that shows what it wrote |
//!
//! Frames are loaded as classic scripts rather than fetched: browsers refuse `fetch` of files
//! beside a page opened from disk, but run its scripts.
//!
//! ```
//! use anim_io::viewer::{Viewer, ViewerField};
//!
//! # fn main() -> Result<(), anim_io::IoError> {
//! let dir = std::env::temp_dir().join(format!("anim-io-viewer-doc-{}", std::process::id()));
//! let context = serde_json::json!({ "point_dim": 3, "point_radius": 0.05 });
//! let mut viewer = Viewer::create(&dir, "falling points", &context, false)?;
//! for step in 0..3 {
//!     let t = step as f64 * 0.1;
//!     let x = [0.0, -4.9 * t * t, 0.0, 1.0, -4.9 * t * t, 0.0];
//!     let v = [0.0, -9.8 * t, 0.0, 0.0, -9.8 * t, 0.0];
//!     viewer.frame(step, t, &x, 3, &[ViewerField::points("velocity", 3, &v)])?;
//! }
//! let page = viewer.finish()?;
//! assert!(page.ends_with("viewer.html") && dir.join("viewer/f00002.js").is_file());
//! # std::fs::remove_dir_all(&dir).unwrap();
//! # Ok(())
//! # }
//! ```

use crate::IoError;
use base64::Engine;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// three.js r170, the ES module build, as published on the npm registry.
const THREE: &str = include_str!("../../vendor/three/three.module.min.js");
/// three.js r170's orbit controls (`examples/jsm/controls/OrbitControls.js`).
const ORBIT: &str = include_str!("../../vendor/three/OrbitControls.js");
/// The page around the viewer's code.
const PAGE: &str = include_str!("viewer.html");
/// The viewer's code (an ES module importing `three` and `three/orbit`).
const CODE: &str = include_str!("viewer.js");

/// One field of a frame as the viewer receives it.
#[derive(Debug, Clone, Copy)]
pub struct ViewerField<'a> {
    /// Its name (`"velocity"`, `"density"`).
    pub name: &'a str,
    /// Components per point (1 for a scalar, 3 for a vector); 1 for a cell field.
    pub components: usize,
    /// The values, `components` per point or one per cell.
    pub values: &'a [f64],
    /// For a cell field (an image grid's), the values at the ends of its colour scale: the
    /// values are stored as bytes over this range. `None` for a point field, stored as `f32`.
    pub range: Option<(f64, f64)>,
}

impl<'a> ViewerField<'a> {
    /// A field with `components` values per point.
    #[must_use]
    pub fn points(name: &'a str, components: usize, values: &'a [f64]) -> Self {
        ViewerField { name, components, values, range: None }
    }

    /// A scalar per cell of an image grid, shown over `range`.
    #[must_use]
    pub fn cells(name: &'a str, values: &'a [f64], range: (f64, f64)) -> Self {
        ViewerField { name, components: 1, values, range: Some(range) }
    }
}

/// The writer of a run's browser viewer (see the [module documentation](self)).
#[derive(Debug)]
pub struct Viewer {
    /// The run's folder (`viewer.html` is here).
    dir: PathBuf,
    /// `dir/viewer`.
    data: PathBuf,
    /// Time and file name of every frame listed so far.
    frames: Vec<(f64, String)>,
    /// Scratch: the binary frame, its base64 and the script around it.
    bytes: Vec<u8>,
    text: String,
}

impl Viewer {
    /// Starts the viewer of a run in `dir`: writes `dir/viewer.html` (titled `title`) and
    /// `dir/viewer/context.js` holding `context`, the scene's static context as JSON (the
    /// page reads `point_dim`, `lines`, `triangles`, `tetrahedra`, `pins`, `point_radius`,
    /// `props`, `mesh_props`, `bounds` and `image` where present). When `resume` (a run
    /// continued from a checkpoint), the frames an index already in `dir` lists stay listed
    /// where their files are present; otherwise the index starts empty.
    ///
    /// # Errors
    /// [`IoError::Io`] when a file cannot be written; [`IoError::InvalidData`] when `context`
    /// does not serialise.
    pub fn create(
        dir: impl AsRef<Path>,
        title: &str,
        context: &serde_json::Value,
        resume: bool,
    ) -> Result<Self, IoError> {
        let dir = dir.as_ref().to_path_buf();
        let data = dir.join("viewer");
        std::fs::create_dir_all(&data).map_err(|e| IoError::io(&data, e))?;
        let context =
            serde_json::to_string(context).map_err(|e| IoError::data("viewer context", e.to_string()))?;
        write_atomic(&data.join("context.js"), &format!("ANIM.context({context});\n"))?;
        let page = page(title);
        let html = dir.join("viewer.html");
        write_atomic(&html, &page)?;
        let mut frames = if resume { listed(&data.join("index.js")) } else { Vec::new() };
        frames.retain(|(_, file)| data.join(file).is_file());
        let viewer = Viewer { dir, data, frames, bytes: Vec::new(), text: String::new() };
        viewer.write_index()?;
        Ok(viewer)
    }

    /// Writes frame `index` at time `time`: `points` holds `point_dim` coordinates per point
    /// (1 to 3; the page draws them in 3-D, missing coordinates 0), `fields` the frame's
    /// fields. The index is rewritten to list it.
    ///
    /// # Errors
    /// [`IoError::InvalidData`] when `point_dim` is not 1 to 3 (with points), a field's length
    /// is not its components times the points (cell fields: any length), or a value is not
    /// finite; [`IoError::Io`] when a file cannot be written.
    pub fn frame(
        &mut self,
        index: usize,
        time: f64,
        points: &[f64],
        point_dim: usize,
        fields: &[ViewerField<'_>],
    ) -> Result<(), IoError> {
        self.frame_with_props(index, time, points, point_dim, fields, &serde_json::Value::Null)
    }

    /// [`Viewer::frame`] with the props that move with the scene at this frame: a JSON array
    /// of props as the context lists its fixed ones (`{"Capsule": {"a": [...], "b": [...],
    /// "radius": r}}`, `Sphere`, `Cuboid`), drawn where they are at each frame (the flag's
    /// swaying pole). Anything but a non-empty array adds nothing.
    ///
    /// # Errors
    /// As [`Viewer::frame`].
    pub fn frame_with_props(
        &mut self,
        index: usize,
        time: f64,
        points: &[f64],
        point_dim: usize,
        fields: &[ViewerField<'_>],
        props: &serde_json::Value,
    ) -> Result<(), IoError> {
        let file = frame_file(index);
        let what = || format!("viewer frame {index}");
        if !points.is_empty() && !(1..=3).contains(&point_dim) {
            return Err(IoError::data(what(), format!("points of {point_dim} coordinates (1 to 3 drawn)")));
        }
        let n = if points.is_empty() { 0 } else { points.len() / point_dim };
        if n * point_dim != points.len() {
            return Err(IoError::data(
                what(),
                format!("{} coordinates are not {point_dim} per point", points.len()),
            ));
        }
        self.bytes.clear();
        let mut parts = String::new();
        let finite = |name: &str, values: &[f64]| match values.iter().position(|v| !v.is_finite()) {
            Some(i) => Err(IoError::data(what(), format!("`{name}` value {i} is {}", values[i]))),
            None => Ok(()),
        };
        finite("points", points)?;
        let _ = write!(parts, "[\"points\",3,\"f32\"]");
        for p in points.chunks_exact(point_dim.max(1)) {
            for k in 0..3 {
                let c = p.get(k).copied().unwrap_or(0.0) as f32;
                self.bytes.extend_from_slice(&c.to_le_bytes());
            }
        }
        for f in fields {
            let name = json_string(f.name);
            finite(f.name, f.values)?;
            match f.range {
                None => {
                    if f.values.len() != f.components * n || f.components == 0 {
                        return Err(IoError::data(
                            what(),
                            format!(
                                "field `{}` has {} values, not {} per point for {n} points",
                                f.name,
                                f.values.len(),
                                f.components
                            ),
                        ));
                    }
                    let _ = write!(parts, ",[{name},{},\"f32\"]", f.components);
                    for v in f.values {
                        self.bytes.extend_from_slice(&(*v as f32).to_le_bytes());
                    }
                }
                Some((lo, hi)) => {
                    let (lo, hi) =
                        if lo.is_finite() && hi.is_finite() && hi > lo { (lo, hi) } else { (0.0, 1.0) };
                    let _ = write!(parts, ",[{name},1,\"u8\",{lo:e},{hi:e}]");
                    let scale = 255.0 / (hi - lo);
                    self.bytes
                        .extend(f.values.iter().map(|v| ((v - lo) * scale).round().clamp(0.0, 255.0) as u8));
                    self.bytes.resize(self.bytes.len().next_multiple_of(4), 0);
                }
            }
        }
        self.text.clear();
        let time = if time.is_finite() { time } else { 0.0 };
        let moving = match props {
            serde_json::Value::Array(list) if !list.is_empty() => format!(",\"props\":{props}"),
            _ => String::new(),
        };
        let _ = write!(
            self.text,
            "ANIM.frame({index},{{\"t\":{time:e},\"n\":{n},\"parts\":[{parts}]{moving}}},\""
        );
        base64::engine::general_purpose::STANDARD.encode_string(&self.bytes, &mut self.text);
        self.text.push_str("\");\n");
        let path = self.data.join(&file);
        std::fs::write(&path, &self.text).map_err(|e| IoError::io(&path, e))?;
        self.frames.retain(|(_, f)| *f != file);
        self.frames.push((time, file));
        // File names sort as frame numbers (fixed width, and wider only past 99999).
        self.frames.sort_by(|a, b| (a.1.len(), &a.1).cmp(&(b.1.len(), &b.1)));
        self.write_index()
    }

    /// The page's path; the index lists the frames written (and, for a resumed run, the
    /// earlier ones present in the folder).
    ///
    /// # Errors
    /// [`IoError::Io`] when the index cannot be written.
    pub fn finish(self) -> Result<PathBuf, IoError> {
        self.write_index()?;
        Ok(self.dir.join("viewer.html"))
    }

    /// Number of frames listed.
    #[must_use]
    pub fn len(&self) -> usize {
        self.frames.len()
    }

    /// Whether no frame is listed.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }

    /// Rewrites `viewer/index.js` with the frames whose files are present.
    fn write_index(&self) -> Result<(), IoError> {
        let mut text = String::from("ANIM.index({\"frames\":[");
        let mut first = true;
        for (t, file) in &self.frames {
            if self.data.join(file).is_file() {
                let _ = write!(text, "{}[{t:e},\"{file}\"]", if first { "" } else { "," });
                first = false;
            }
        }
        text.push_str("]});\n");
        write_atomic(&self.data.join("index.js"), &text)
    }
}

/// The frames an index file lists (none when it is absent or unreadable: a new index then
/// lists the frames written from now on).
fn listed(path: &Path) -> Vec<(f64, String)> {
    let Ok(text) = std::fs::read_to_string(path) else { return Vec::new() };
    let json = text.trim().strip_prefix("ANIM.index(").and_then(|t| t.strip_suffix(");"));
    let value: serde_json::Value = json.and_then(|j| serde_json::from_str(j).ok()).unwrap_or_default();
    let entries = value["frames"].as_array().cloned().unwrap_or_default();
    entries
        .iter()
        .filter_map(|e| Some((e[0].as_f64()?, e[1].as_str()?.to_string())))
        .filter(|(_, file)| file.starts_with('f') && file.ends_with(".js") && !file.contains(['/', '\\']))
        .collect()
}

/// The file of frame `index`.
fn frame_file(index: usize) -> String {
    format!("f{index:05}.js")
}

/// The page: three.js and its orbit controls as data URLs of an import map, the viewer's
/// code, and the scripts that load the context and the index.
fn page(title: &str) -> String {
    let b64 = |s: &str| base64::engine::general_purpose::STANDARD.encode(s.as_bytes());
    let imports = format!(
        "{{\"imports\":{{\"three\":\"data:text/javascript;base64,{}\",\"three/orbit\":\"data:text/javascript;base64,{}\"}}}}",
        b64(THREE),
        b64(ORBIT)
    );
    PAGE.replace("{{TITLE}}", &html_escape(title)).replace("{{IMPORTS}}", &imports).replace("{{CODE}}", CODE)
}

/// `s` as a JSON string literal.
fn json_string(s: &str) -> String {
    serde_json::Value::String(s.to_string()).to_string()
}

/// `s` with the characters HTML gives meaning to escaped.
fn html_escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// Writes `text` to `path` through a temporary file and a rename, so a reader never sees half.
fn write_atomic(path: &Path, text: &str) -> Result<(), IoError> {
    let tmp = path.with_extension("tmp");
    std::fs::write(&tmp, text).map_err(|e| IoError::io(&tmp, e))?;
    std::fs::rename(&tmp, path).map_err(|e| IoError::io(path, e))
}

#[cfg(test)]
mod tests;
