//! The output of a run: frame files, CSV rows and the preview, written on a thread of their own
//! so that the run loop keeps stepping while a frame is encoded.
//!
//! The preview frames whole run: the writer keeps the points of the frames it will draw (as
//! `f32`, at most [`PREVIEW_BYTES`]) and the bounding box of every frame's points, and draws the
//! GIF and the last frame's PNG when the run ends, with a camera built then.

use crate::view::{Geometry, OutputFormat, Paint, SPEED, Snapshot, View};
use anim_core::scene::{DynScene, Frame};
use anim_io::FrameWriter;
use anim_io::preview::{Canvas, GifWriter};
use anim_io::viewer::{Viewer, ViewerField};

/// The most memory the points of the preview's frames may take until the run ends (`f32`
/// each): a scene too large for about 100 of them keeps fewer.
pub(crate) const PREVIEW_BYTES: usize = 256 << 20;

/// The stride of the preview's frames for a run of `frames` frames of `values` numbers each:
/// about 100 frames whatever the run's length, fewer when that many would not fit in
/// [`PREVIEW_BYTES`].
pub(crate) fn preview_every(frames: usize, values: usize) -> usize {
    let fit = (PREVIEW_BYTES / (4 * values.max(1))).max(1);
    frames.div_ceil(100).max(frames.div_ceil(fit)).max(1)
}

/// `--preview-size WxH`: the width and height in pixels, each in `[16, 4096]`.
///
/// # Errors
/// Not two numbers joined by `x`, or a side out of that range, named with the value.
pub(crate) fn parse_preview_size(arg: &str) -> Result<(u32, u32), String> {
    let size =
        arg.split_once(['x', 'X']).and_then(|(w, h)| Some((w.trim().parse().ok()?, h.trim().parse().ok()?)));
    match size {
        Some((w, h)) if (16..=4096).contains(&w) && (16..=4096).contains(&h) => Ok((w, h)),
        Some(_) => Err(format!("{arg}: width and height must each lie in [16, 4096] pixels")),
        None => Err(format!("{arg}: expected WIDTHxHEIGHT in pixels, such as 640x480")),
    }
}

/// The size of a preview of at most `width x height` pixels: that size, or for a picture of
/// width over height `aspect` (a grid's cross-section) the largest of those proportions that
/// fits in it (at least 16 pixels a side).
pub(crate) fn preview_size((width, height): (u32, u32), aspect: Option<f64>) -> (u32, u32) {
    match aspect.filter(|a| a.is_finite() && *a > 0.0) {
        Some(a) if f64::from(width) / f64::from(height) > a => {
            ((f64::from(height) * a).round().clamp(16.0, f64::from(width)) as u32, height)
        }
        Some(a) => (width, (f64::from(width) / a).round().clamp(16.0, f64::from(height)) as u32),
        None => (width, height),
    }
}

/// The animated preview: the frames it will draw, kept until the run ends.
struct Preview {
    gif: GifWriter,
    canvas: Canvas,
    /// Every `every`-th frame is drawn.
    every: usize,
    /// The kept frames' values (positions, or a grid's density), one after another.
    kept: Vec<f32>,
    /// The number of values of each kept frame.
    lengths: Vec<usize>,
    /// What the points are coloured by ([`Paint::Plain`]: nothing kept); a grid keeps the
    /// painted field in `kept` in place of its density.
    paint: Paint,
    /// The painted field's value per point of each kept frame of a particle scene.
    painted: Vec<f32>,
    /// The smallest and largest painted value kept.
    range: (f64, f64),
    /// Scratch for one frame's painted values.
    scratch: Vec<f64>,
    /// The moving props of each kept frame (none for most scenes).
    props: Vec<Vec<anim_core::scene::Prop>>,
}

impl Preview {
    /// Keeps a frame: its points (or a grid's painted cells) and painted values.
    fn keep(&mut self, s: &Snapshot, grid: bool) {
        self.scratch.clear();
        if grid {
            match &self.paint {
                Paint::Field(name) if name == SPEED => {
                    Paint::Field(name.clone()).values(&[], &s.v, &mut self.scratch);
                }
                _ => self.scratch.extend_from_slice(&s.x),
            }
            self.kept.extend(self.scratch.iter().map(|&v| v as f32));
            self.lengths.push(self.scratch.len());
        } else {
            self.kept.extend(s.x.iter().map(|&v| v as f32));
            self.lengths.push(s.x.len());
            self.paint.values(&s.fields, &s.v, &mut self.scratch);
            self.painted.extend(self.scratch.iter().map(|&v| v as f32));
        }
        self.props.push(s.props.clone());
        for &v in self.scratch.iter().filter(|v| v.is_finite()) {
            self.range = (self.range.0.min(v), self.range.1.max(v));
        }
    }
}
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// What the writer thread produces: the files written and its own busy time.
pub(crate) type WriterResult = Result<(Vec<String>, f64), String>;

/// Frame files, CSV rows and the preview, written on a thread of their own so that the run
/// loop keeps stepping while a frame is encoded. Snapshots travel through a bounded channel: a
/// writer that falls behind slows the run instead of piling up memory.
pub(crate) struct Output {
    sender: Option<std::sync::mpsc::SyncSender<(usize, Snapshot)>>,
    returned: std::sync::mpsc::Receiver<Snapshot>,
    worker: Option<std::thread::JoinHandle<WriterResult>>,
    spare: Vec<Snapshot>,
    /// The scene's frame, scratch reused from frame to frame.
    frame: Frame,
    grid: bool,
    /// Coordinates per point of the scene's frames.
    point_dim: usize,
}

/// The writer thread's state.
struct Writer {
    dir: PathBuf,
    stride: usize,
    view: View,
    frames: Option<FrameWriter>,
    csv: Option<std::io::BufWriter<std::fs::File>>,
    preview: Option<Preview>,
    viewer: Option<RunViewer>,
    /// Whether the scene is a grid of cells.
    grid: bool,
    /// A grid's shown field and the fixed ends of its colour scale.
    grid_range: Option<(&'static str, (f64, f64))>,
}

/// The browser viewer of a run.
struct RunViewer {
    page: Viewer,
    /// The name and colour range of a grid's cell field (a grid scene).
    cells: Option<(&'static str, (f64, f64))>,
}

/// What the browser viewer of a run is made from.
pub(crate) struct ViewerSpec<'a> {
    /// The page's title (the scene's name).
    pub title: &'a str,
    /// The scene's static context.
    pub context: &'a anim_core::scene::Context,
    /// Whether the run continues an earlier one (the index keeps its frames).
    pub resume: bool,
}

impl Writer {
    fn frame(&mut self, index: usize, s: &Snapshot) -> Result<(), String> {
        if index.is_multiple_of(self.stride) {
            if let Some(frames) = &mut self.frames {
                self.view.write_frame(frames, s)?;
            }
            if let Some(csv) = &mut self.csv {
                let values: Vec<String> = s.x.iter().chain(&s.v).map(|v| format!("{v:e}")).collect();
                let opt = |v: Option<f64>| v.map(|v| format!("{v:e}")).unwrap_or_default();
                writeln!(csv, "{index},{:e},{},{},{}", s.t, values.join(","), opt(s.energy), opt(s.error))
                    .map_err(|e| e.to_string())?;
            }
        }
        if let Some(RunViewer { page: viewer, cells }) = &mut self.viewer
            && index.is_multiple_of(self.stride)
        {
            let result = match cells {
                Some((name, range)) => {
                    viewer.frame(index, s.t, &[], 3, &[ViewerField::cells(name, &s.x, *range)])
                }
                None => {
                    let fields: Vec<ViewerField<'_>> = s
                        .fields
                        .iter()
                        .map(|f| ViewerField::points(f.name, f.components, &f.values))
                        .collect();
                    let props = if s.props.is_empty() {
                        serde_json::Value::Null
                    } else {
                        serde_json::to_value(&s.props).map_err(|e| format!("viewer frame {index}: {e}"))?
                    };
                    viewer.frame_with_props(index, s.t, &s.x, s.point_dim, &fields, &props)
                }
            };
            result.map_err(|e| e.to_string())?;
        }
        if let Some(preview) = &mut self.preview {
            self.view.see(s);
            if index.is_multiple_of(preview.every) {
                preview.keep(s, self.grid);
            }
        }
        Ok(())
    }

    fn finish(mut self) -> Result<Vec<String>, String> {
        let mut files = Vec::new();
        if let Some(frames) = &self.frames {
            // The frames in this folder (a run resumed into a new folder has only its own).
            let sequence = frames.sequence();
            let n = sequence.frames().iter().filter(|(_, f)| sequence.dir().join(f).is_file()).count();
            match frames.finish().map_err(|e| e.to_string())? {
                Some(pvd) => files.push(format!("{} ({n} frames)", pvd.display())),
                None => files.push(format!(
                    "{} ({n} .{} frames)",
                    self.dir.join("frames").display(),
                    frames.format().extension()
                )),
            }
        }
        if let Some(RunViewer { page: viewer, .. }) = self.viewer {
            let n = viewer.len();
            let page = viewer.finish().map_err(|e| e.to_string())?;
            files.push(format!("{} ({n} frames)", page.display()));
        }
        if let Some(mut csv) = self.csv {
            csv.flush().map_err(|e| e.to_string())?;
            files.push(self.dir.join("frames.csv").display().to_string());
        }
        if let Some(Preview { mut gif, mut canvas, kept, lengths, paint, painted, range, props, .. }) =
            self.preview.take()
        {
            // The camera of the whole run, now that it has been seen.
            let camera = self.view.camera(f64::from(canvas.width()) / f64::from(canvas.height()));
            // The colour scale: the grid's own for its density, the kept values' otherwise
            // (from zero for a speed).
            let range = match (&self.grid_range, &paint) {
                (Some((shown, r)), Paint::Field(name)) if name == shown => *r,
                _ if range.0 > range.1 => (0.0, 1.0),
                (_, Paint::Field(name)) if name == SPEED => (0.0, range.1),
                _ => range,
            };
            let caption = paint.caption(range);
            self.view.paint(paint, range);
            let mut snapshot = Snapshot::default();
            let mut values = Vec::new();
            let (mut at, mut at_painted) = (0, 0);
            for (n, props) in lengths.into_iter().zip(props) {
                snapshot.props = props;
                snapshot.x.clear();
                snapshot.x.extend(kept[at..at + n].iter().map(|&v| f64::from(v)));
                at += n;
                values.clear();
                if !self.grid && !painted.is_empty() {
                    let points = n / 3;
                    values.extend(painted[at_painted..at_painted + points].iter().map(|&v| f64::from(v)));
                    at_painted += points;
                }
                canvas.clear();
                self.view.draw(&mut canvas, &camera, &snapshot, &values)?;
                gif.push(&canvas).map_err(|e| e.to_string())?;
            }
            let png = self.dir.join("preview.png");
            canvas.save_png(&png).map_err(|e| e.to_string())?;
            let path = gif.finish().map_err(|e| e.to_string())?;
            let coloured = caption.map(|c| format!(" (coloured by {c})")).unwrap_or_default();
            files.push(format!("{}{coloured}", path.display()));
            files.push(format!("{}{coloured}", png.display()));
        }
        Ok(files)
    }
}

impl Output {
    /// The writer of a run; `preview` the preview's largest size, the run's number of frames
    /// and what the preview colours by; `continuing` holds the times of the frame files an earlier part of the run wrote
    /// (resumed runs continue the numbering and append to `frames.csv`).
    pub(crate) fn new(
        dir: &Path,
        format: OutputFormat,
        stride: usize,
        preview: Option<((u32, u32), usize, Paint)>,
        (geometry, dof): (&Geometry, usize),
        continuing: Option<&[f64]>,
        viewer: Option<ViewerSpec<'_>>,
    ) -> Result<Self, String> {
        let grid = matches!(geometry, Geometry::Grid { .. });
        let view = View::new(geometry.clone());
        let mut writer = Writer {
            dir: dir.to_path_buf(),
            stride,
            view,
            frames: None,
            csv: None,
            preview: None,
            viewer: None,
            grid,
            grid_range: None,
        };
        let point_dim = viewer.as_ref().map_or(3, |spec| spec.context.point_dim);
        if let Some(spec) = viewer {
            let json = serde_json::to_value(spec.context).map_err(|e| format!("viewer context: {e}"))?;
            let page = Viewer::create(dir, spec.title, &json, spec.resume).map_err(|e| e.to_string())?;
            let cells = spec.context.image.map(|g| (g.shown, g.range));
            writer.viewer = Some(RunViewer { page, cells });
        }
        if let Some(f) = format.frame_format() {
            let frames = FrameWriter::continuing(dir.join("frames"), f, continuing.unwrap_or(&[]));
            writer.frames = Some(frames.map_err(|e| e.to_string())?);
        }
        if format == OutputFormat::Csv && continuing.is_some() {
            let path = dir.join("frames.csv");
            let file = std::fs::OpenOptions::new()
                .append(true)
                .open(&path)
                .map_err(|e| format!("{}: cannot append to the run's frames: {e}", path.display()))?;
            writer.csv = Some(std::io::BufWriter::new(file));
        } else if format == OutputFormat::Csv {
            let path = dir.join("frames.csv");
            let file = std::fs::File::create(&path).map_err(|e| format!("{}: {e}", path.display()))?;
            let mut csv = std::io::BufWriter::new(file);
            let n = dof;
            let header: Vec<String> =
                (0..n).map(|i| format!("x{i}")).chain((0..n).map(|i| format!("v{i}"))).collect();
            writeln!(csv, "frame,t,{},energy,error_vs_exact", header.join(","))
                .map_err(|e| format!("{}: {e}", path.display()))?;
            writer.csv = Some(csv);
        }
        if let Some((size, frames, paint)) = preview {
            // A grid is shown at its own proportions; everything else at the size asked for.
            let (width, height) = preview_size(size, writer.view.aspect());
            let path = dir.join("preview.gif");
            let gif = GifWriter::create(&path, width, height, 4, true).map_err(|e| e.to_string())?;
            // What a kept frame holds: a grid's painted value per cell, or the coordinates and
            // the painted value per point.
            let values = match geometry {
                Geometry::Grid { dims, range, .. } => {
                    writer.grid_range = Some(("density", *range));
                    dims.iter().product()
                }
                _ if paint == Paint::Plain => dof,
                _ => dof + dof / 3,
            };
            let every = preview_every(frames, values);
            writer.preview = Some(Preview {
                gif,
                canvas: Canvas::new(width, height, [248, 248, 250]),
                every,
                // Sized once: growing by doubling would hold twice the budget for a moment.
                kept: Vec::with_capacity(
                    frames.div_ceil(every).min(PREVIEW_BYTES / 4 / values.max(1)).max(1) * values,
                ),
                lengths: Vec::new(),
                paint,
                painted: Vec::new(),
                range: (f64::INFINITY, f64::NEG_INFINITY),
                scratch: Vec::new(),
                props: Vec::new(),
            });
        }
        let (sender, receiver) = std::sync::mpsc::sync_channel::<(usize, Snapshot)>(4);
        let (give_back, returned) = std::sync::mpsc::channel::<Snapshot>();
        let worker = std::thread::Builder::new()
            .name("anim-writer".into())
            .spawn(move || {
                let mut busy = 0.0;
                let mut result = Ok(());
                for (index, snapshot) in receiver {
                    let start = Instant::now();
                    if result.is_ok() {
                        result = writer.frame(index, &snapshot);
                    }
                    busy += start.elapsed().as_secs_f64();
                    // Hand the buffers back for reuse; the run may already have ended.
                    let _ = give_back.send(snapshot);
                }
                result?;
                let start = Instant::now();
                let files = writer.finish()?;
                Ok((files, busy + start.elapsed().as_secs_f64()))
            })
            .map_err(|e| format!("cannot start the writer thread: {e}"))?;
        Ok(Output {
            sender: Some(sender),
            returned,
            worker: Some(worker),
            spare: Vec::new(),
            frame: Frame::default(),
            grid,
            point_dim,
        })
    }

    /// Queues frame `index` of the scene's current state.
    pub(crate) fn frame(
        &mut self,
        index: usize,
        runner: &dyn DynScene,
        energy: Option<f64>,
    ) -> Result<(), String> {
        self.spare.extend(self.returned.try_iter());
        let mut snapshot = self.spare.pop().unwrap_or_default();
        snapshot.fill(runner, &mut self.frame, self.grid, energy);
        snapshot.point_dim = self.point_dim;
        let sent = self.sender.as_ref().map(|s| s.send((index, snapshot)).is_ok());
        match sent {
            Some(true) => Ok(()),
            // The writer stopped early: its error is reported by `finish`.
            _ => Err("the frame writer stopped".into()),
        }
    }

    /// Waits for the writer and returns the files written and the writer's busy time.
    pub(crate) fn finish(mut self) -> WriterResult {
        drop(self.sender.take());
        match self.worker.take().map(std::thread::JoinHandle::join) {
            Some(Ok(result)) => result,
            Some(Err(_)) => Err("the frame writer panicked".into()),
            None => Err("the frame writer was not started".into()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// About 100 preview frames whatever the run's length, and never more kept values than
    /// fit the budget: the frames kept (every `every`-th of `frames`) times their bytes.
    #[test]
    fn the_preview_keeps_about_100_frames_within_its_memory() {
        assert_eq!(preview_every(1, 3), 1);
        assert_eq!(preview_every(100, 3), 1);
        assert_eq!(preview_every(1000, 3), 10);
        for (frames, values) in [(100, 3_000_000), (1000, 3_000_000), (75, 30_000_000), (10, 1 << 30)] {
            let every = preview_every(frames, values);
            let kept = frames.div_ceil(every);
            assert!(kept <= 100, "{frames} frames of {values}: {kept} kept");
            assert!(
                kept == 1 || kept * 4 * values <= PREVIEW_BYTES,
                "{frames} frames of {values}: {kept} kept"
            );
        }
        // 3 million values (a million particles): 22 frames fit, so 100 frames keep every 5th.
        assert_eq!(preview_every(100, 3_000_000), 5);
    }

    #[test]
    fn a_grid_preview_keeps_its_proportions_inside_the_size() {
        assert_eq!(preview_size((640, 480), None), (640, 480));
        assert_eq!(preview_size((640, 480), Some(1.0)), (480, 480));
        assert_eq!(preview_size((640, 480), Some(2.0)), (640, 320));
        assert_eq!(preview_size((640, 480), Some(0.5)), (240, 480));
        assert_eq!(preview_size((640, 480), Some(1e-6)), (16, 480));
        assert_eq!(preview_size((640, 480), Some(f64::NAN)), (640, 480));
    }

    #[test]
    fn preview_sizes_are_read_and_refused_with_the_value() {
        assert_eq!(parse_preview_size("640x480"), Ok((640, 480)));
        assert_eq!(parse_preview_size("16X4096"), Ok((16, 4096)));
        for bad in ["8x8", "0x480", "640x4097"] {
            let e = parse_preview_size(bad).unwrap_err();
            assert_eq!(e, format!("{bad}: width and height must each lie in [16, 4096] pixels"));
        }
        for bad in ["wide", "640", "x480", "640x", "-1x480", "6.5x480"] {
            let e = parse_preview_size(bad).unwrap_err();
            assert_eq!(e, format!("{bad}: expected WIDTHxHEIGHT in pixels, such as 640x480"));
        }
    }
}
