//! `anim`: runs a scene and writes its frames, a preview and a metrics summary.
//!
//! ```text
//! anim run                      # the embedded default scene (a hanging cloth)
//! anim run scene.toml           # a scene file
//! anim run kepler               # a built-in scene by name
//! anim run cloth --out out --frames 60 --format obj --stride 2
//! anim list                     # the built-in scenes (also `anim scenes`)
//! anim run smoke-plume-3d --resolution 48   # a fluid on a finer grid
//! anim run dam-break-2d --frames 20   # an APIC particle fluid (anim-flip)
//! anim run kepler --tolerance 1e-3   # the cheapest measured method meeting a relative error
//! anim run cloth --checkpoint-every 50   # also keep out/checkpoint.anim current
//! anim resume anim-out/cloth/checkpoint.anim   # continue from it, bit for bit
//! ```
//!
//! Every run writes into its output folder: the frames in the scene's natural format (VTK `.vtu`
//! with a `.pvd` series for meshes, VTK `.vti` image data with a `.pvd` for fluid grids (cell
//! fields `density` and `velocity`), `frames.csv` for systems of a few unknowns) or the one asked
//! for, `preview.gif` (and `preview.png`, the last frame; fluids show their density), and
//! `metrics.json`.

use anim_cli::scene::{self, SceneFile};
use anim_cli::tolerance;
use anim_cli::view::{Geometry, OutputFormat, Snapshot, View};
use anim_core::scene::{DynScene, Frame};
use anim_io::FrameWriter;
use anim_io::preview::{Canvas, GifWriter};
use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde::Serialize;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant};

#[derive(Parser)]
#[command(
    name = "anim",
    version,
    about = "Physically based animation: run a scene, write its frames and metrics"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scene file, or a built-in scene by name, or the default scene when none is given.
    Run(RunArgs),
    /// Continue a run from a checkpoint written with `--checkpoint-every`: the frames after it are
    /// bit for bit those of an uninterrupted run.
    Resume(ResumeArgs),
    /// List the built-in scenes (`--kinds`: the scene kinds a scene file can name).
    #[command(visible_alias = "scenes")]
    List(ListArgs),
}

#[derive(clap::Args)]
struct ListArgs {
    /// List the registered scene kinds, with their crate and what they simulate.
    #[arg(long)]
    kinds: bool,
}

#[derive(clap::Args)]
struct ResumeArgs {
    /// The checkpoint file (`<out>/checkpoint.anim`).
    checkpoint: PathBuf,
    /// Output folder (default: the one the checkpointed run wrote to).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Total number of frames of the run (default: the checkpointed run's).
    #[arg(long)]
    frames: Option<usize>,
    /// No progress bar or summary on the terminal.
    #[arg(long)]
    quiet: bool,
}

#[derive(clap::Args)]
struct RunArgs {
    /// A scene file (TOML) or the name of a built-in scene (see `anim list`).
    scene: Option<String>,
    /// Output folder (default: `anim-out/<scene name>`).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Override the number of frames.
    #[arg(long)]
    frames: Option<usize>,
    /// Override the time step in seconds.
    #[arg(long, allow_hyphen_values = true)]
    dt: Option<f64>,
    /// Frame file format (default: the scene's natural one; fluid grids: vti or none).
    #[arg(long, value_enum)]
    format: Option<OutputFormat>,
    /// Override the resolution of a preset scene that has one (cloth, MPM, FEM, particle fluids
    /// and fluid grids: cells or particles across).
    #[arg(long)]
    resolution: Option<usize>,
    /// Write every N-th frame to files.
    #[arg(long, default_value_t = 1)]
    stride: usize,
    /// Skinning method for skinned-character scenes (`lbs`, `dqs` or `both`; default: the
    /// scene's): the same as `--set method=<choice>`.
    #[arg(long, value_parser = ["lbs", "dqs", "both"])]
    skinning: Option<String>,
    /// Set a parameter of the scene's `[scene]` table, `KEY=VALUE` with a TOML value
    /// (`--set resolution=48`, `--set integrator=rk4`, `--set 'transfer={flip=0.9}'`); repeatable.
    /// The scene's kind checks it like a field of the file.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
    /// Skip the GIF/PNG preview.
    #[arg(long)]
    no_preview: bool,
    /// Preview width in pixels (height is 3/4 of it).
    #[arg(long, default_value_t = 320)]
    preview_width: u32,
    /// No progress bar or summary on the terminal.
    #[arg(long)]
    quiet: bool,
    /// Every N frames, replace `<out>/checkpoint.anim` (atomically) with the run's state;
    /// `anim resume` continues from it.
    #[arg(long)]
    checkpoint_every: Option<usize>,
    /// The accuracy the run needs instead of a method: the method (integrator, solver, time
    /// step, resolution, pressure tolerance, PBD iterations and substeps, MPM transfer and kernel)
    /// comes from the report's measured work-precision studies (oscillator, Kepler, FEM beam,
    /// hanging cloth, lid-driven cavity, smoke plume, PBD cloth, MPM dam break), and
    /// the run's error on the study's measure is printed at the end where the scene has a
    /// reference.
    #[arg(long, allow_hyphen_values = true)]
    tolerance: Option<f64>,
}

/// The built-in scenes, one a line: name, description, and which one is the default.
fn builtin_listing() -> String {
    let mut out = String::new();
    for (name, description) in scene::builtins() {
        let default = if name == scene::DEFAULT_SCENE { " [default]" } else { "" };
        out.push_str(&format!("{name:<18} {description}{default}\n"));
    }
    out
}

fn main() -> ExitCode {
    use clap::{CommandFactory, FromArgMatches};
    // `anim run --help` ends with the list of built-in scenes.
    let listing = format!("Built-in scenes:\n{}", builtin_listing());
    let command = Cli::command().mut_subcommand("run", |run| run.after_help(listing));
    let cli = match Cli::from_arg_matches(&command.get_matches()) {
        Ok(cli) => cli,
        Err(e) => e.exit(),
    };
    match cli.command {
        Command::List(args) if args.kinds => {
            for k in &anim::KINDS {
                println!("{:<20} {:<13} {}", k.kind, k.crate_name, k.summary);
            }
            ExitCode::SUCCESS
        }
        Command::List(_) => {
            print!("{}", builtin_listing());
            ExitCode::SUCCESS
        }
        Command::Run(args) => finish(fresh(&args).and_then(execute)),
        Command::Resume(args) => finish(resumed(&args).and_then(execute)),
    }
}

fn finish(result: Result<(), String>) -> ExitCode {
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Loads the scene named on the command line: a file if one exists at that path, else a
/// built-in scene of that name. Returns the scene, the path errors should name and the file's
/// text (none for a built-in scene).
fn resolve(arg: Option<&str>) -> Result<(SceneFile, PathBuf, Option<String>), String> {
    let arg = arg.unwrap_or(scene::DEFAULT_SCENE);
    let path = Path::new(arg);
    // A folder of that name (such as a run's output) is not a scene file.
    if path.is_file() {
        let text =
            std::fs::read_to_string(path).map_err(|e| format!("{arg}: cannot read scene file: {e}"))?;
        let file = scene::parse(&text, path).map_err(|e| e.to_string())?;
        return Ok((file, path.to_path_buf(), Some(text)));
    }
    match scene::builtin(arg) {
        Some(file) => Ok((file, PathBuf::from(format!("<built-in scene {arg}>")), None)),
        None => Err(format!(
            "{arg}: no such scene file, and no built-in scene of that name (built-in: {})",
            scene::builtins().iter().map(|b| b.0).collect::<Vec<_>>().join(", ")
        )),
    }
}

/// `KEY=VALUE` of `--set` as a parameter: the value read as TOML, or as a string when it is
/// not TOML (`--set method=dqs`).
fn set_param(file: &mut SceneFile, arg: &str) -> Result<(), String> {
    let (key, value) = arg.split_once('=').ok_or_else(|| format!("--set {arg}: expected KEY=VALUE"))?;
    let key = key.trim();
    if key.is_empty() || key == "kind" {
        return Err(format!("--set {arg}: KEY must name a parameter of the scene (not `kind`)"));
    }
    let value = match toml::from_str::<toml::Table>(&format!("v = {value}")) {
        Ok(mut t) => {
            t.remove("v").map_or(serde_json::Value::Null, |v| serde_json::to_value(v).unwrap_or_default())
        }
        Err(_) => serde_json::Value::String(value.to_string()),
    };
    file.scene.params.insert(key.to_string(), value);
    Ok(())
}

#[derive(Serialize)]
struct Metrics {
    scene: String,
    system: String,
    method: String,
    status: String,
    dt: f64,
    steps: u64,
    frames: usize,
    format: OutputFormat,
    simulated_seconds: f64,
    wall_seconds: f64,
    step_seconds: f64,
    output_seconds: f64,
    output_fraction: f64,
    writer_busy_seconds: f64,
    steps_per_second: f64,
    energy_initial: Option<f64>,
    energy_final: Option<f64>,
    relative_energy_change: Option<f64>,
    max_error_vs_exact: Option<f64>,
    /// `--tolerance` asked for.
    tolerance: Option<f64>,
    /// The run's final error on the measure of the cheapest-method table (relative).
    tolerance_error_final: Option<f64>,
    /// Its largest value over the frames.
    tolerance_error_max: Option<f64>,
    newton_iterations: usize,
    resumed_from_frame: Option<usize>,
    checkpoints_written: usize,
    files: Vec<String>,
}

/// The checkpoint of a run: the scene and output settings it was started with, how far it got,
/// and the scene's checkpoint ([`DynScene::save`]). Written as `<out>/checkpoint.anim` (kind
/// [`CHECKPOINT_KIND`]).
#[derive(Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct RunCheckpoint {
    scene: SceneFile,
    /// The path scene errors and relative file names refer to.
    origin: PathBuf,
    out: PathBuf,
    format: OutputFormat,
    stride: usize,
    preview_width: Option<u32>,
    checkpoint_every: Option<usize>,
    /// Frames completed.
    frame: usize,
    steps: u64,
    /// Times of the frame files written so far.
    written_times: Vec<f64>,
    energy_initial: Option<f64>,
    max_error: Option<f64>,
    newton_iterations: usize,
    runner: serde_json::Value,
}

/// Version 2: the scene is a registered kind with its parameters, the runner a [`DynScene`]
/// checkpoint.
const CHECKPOINT_KIND: &str = "anim-run-2";
const CHECKPOINT_FILE: &str = "checkpoint.anim";

/// A run ready to go: fresh from a scene, or resumed from a checkpoint.
struct Session {
    file: SceneFile,
    origin: PathBuf,
    out: PathBuf,
    format: OutputFormat,
    stride: usize,
    preview_width: Option<u32>,
    checkpoint_every: Option<usize>,
    quiet: bool,
    runner: Box<dyn DynScene>,
    /// How the scene is drawn and written.
    geometry: Geometry,
    start_frame: usize,
    steps: u64,
    written_times: Vec<f64>,
    energy_initial: Option<f64>,
    max_error: Option<f64>,
    newton_iterations: usize,
    resumed: bool,
    /// The `--tolerance` asked for, if any.
    tolerance: Option<f64>,
}

/// What the writer thread produces: the files written and its own busy time.
type WriterResult = Result<(Vec<String>, f64), String>;

/// Frame files, CSV rows and the preview, written on a thread of their own so that the run
/// loop keeps stepping while a frame is encoded. Snapshots travel through a bounded channel: a
/// writer that falls behind slows the run instead of piling up memory.
struct Output {
    sender: Option<std::sync::mpsc::SyncSender<(usize, Snapshot)>>,
    returned: std::sync::mpsc::Receiver<Snapshot>,
    worker: Option<std::thread::JoinHandle<WriterResult>>,
    spare: Vec<Snapshot>,
    /// The scene's frame, scratch reused from frame to frame.
    frame: Frame,
    grid: bool,
}

/// The writer thread's state.
struct Writer {
    dir: PathBuf,
    stride: usize,
    view: View,
    frames: Option<FrameWriter>,
    csv: Option<std::io::BufWriter<std::fs::File>>,
    gif: Option<(GifWriter, Canvas, anim_io::preview::Camera, usize)>,
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
        if let Some((gif, canvas, camera, every)) = &mut self.gif
            && index.is_multiple_of(*every)
        {
            canvas.clear();
            self.view.draw(canvas, camera, s)?;
            gif.push(canvas).map_err(|e| e.to_string())?;
        }
        Ok(())
    }

    fn finish(self) -> Result<Vec<String>, String> {
        let mut files = Vec::new();
        if let Some(frames) = &self.frames {
            let n = frames.sequence().frames().len();
            match frames.finish().map_err(|e| e.to_string())? {
                Some(pvd) => files.push(format!("{} ({n} frames)", pvd.display())),
                None => files.push(format!(
                    "{} ({n} .{} frames)",
                    self.dir.join("frames").display(),
                    frames.format().extension()
                )),
            }
        }
        if let Some(mut csv) = self.csv {
            csv.flush().map_err(|e| e.to_string())?;
            files.push(self.dir.join("frames.csv").display().to_string());
        }
        if let Some((gif, canvas, _, _)) = self.gif {
            let png = self.dir.join("preview.png");
            canvas.save_png(&png).map_err(|e| e.to_string())?;
            let path = gif.finish().map_err(|e| e.to_string())?;
            files.push(path.display().to_string());
            files.push(png.display().to_string());
        }
        Ok(files)
    }
}

impl Output {
    /// The writer of a run; `continuing` holds the times of the frame files an earlier part of
    /// the run wrote (resumed runs continue the numbering and append to `frames.csv`).
    fn new(
        dir: &Path,
        format: OutputFormat,
        stride: usize,
        preview: Option<(u32, usize)>,
        (geometry, dof): (&Geometry, usize),
        continuing: Option<&[f64]>,
    ) -> Result<Self, String> {
        let grid = matches!(geometry, Geometry::Grid { .. });
        let view = View::new(geometry.clone());
        let mut writer = Writer { dir: dir.to_path_buf(), stride, view, frames: None, csv: None, gif: None };
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
        if let Some((width, every)) = preview {
            // A grid is shown at its own proportions; everything else at 4:3.
            let height = match writer.view.aspect() {
                Some(a) => (f64::from(width) / a).round().clamp(16.0, 4096.0) as u32,
                None => (width * 3 / 4).max(1),
            };
            let path = dir.join("preview.gif");
            let gif = GifWriter::create(&path, width, height, 4, true).map_err(|e| e.to_string())?;
            let camera = writer.view.camera(f64::from(width) / f64::from(height));
            writer.gif = Some((gif, Canvas::new(width, height, [248, 248, 250]), camera, every));
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
        })
    }

    /// Queues frame `index` of the scene's current state.
    fn frame(&mut self, index: usize, runner: &dyn DynScene, energy: Option<f64>) -> Result<(), String> {
        self.spare.extend(self.returned.try_iter());
        let mut snapshot = self.spare.pop().unwrap_or_default();
        snapshot.fill(runner, &mut self.frame, self.grid, energy);
        let sent = self.sender.as_ref().map(|s| s.send((index, snapshot)));
        match sent {
            Some(Ok(())) => Ok(()),
            // The writer stopped early: its error is reported by `finish`.
            _ => Err("the frame writer stopped".into()),
        }
    }

    /// Waits for the writer and returns the files written and the writer's busy time.
    fn finish(mut self) -> WriterResult {
        drop(self.sender.take());
        match self.worker.take().map(std::thread::JoinHandle::join) {
            Some(Ok(result)) => result,
            Some(Err(_)) => Err("the frame writer panicked".into()),
            None => Err("the frame writer was not started".into()),
        }
    }
}

/// A fresh run of the scene named on the command line.
fn fresh(args: &RunArgs) -> Result<Session, String> {
    let (mut file, origin, text) = resolve(args.scene.as_deref())?;
    if let Some(f) = args.frames {
        if f == 0 {
            return Err("--frames must be at least 1".into());
        }
        file.run.frames = f;
    }
    if let Some(dt) = args.dt {
        if !(dt > 0.0 && dt.is_finite()) {
            return Err(format!("--dt must be a positive finite number, got {dt}"));
        }
        file.run.dt = dt;
    }
    if args.stride == 0 {
        return Err("--stride must be at least 1".into());
    }
    if args.preview_width < 16 || args.preview_width > 4096 {
        return Err(format!("--preview-width must lie in [16, 4096], got {}", args.preview_width));
    }
    if args.checkpoint_every == Some(0) {
        return Err("--checkpoint-every must be at least 1".into());
    }
    if let Some(r) = args.resolution {
        file.scene.params.insert("resolution".into(), r.into());
    }
    if let Some(choice) = &args.skinning {
        file.scene.params.insert("method".into(), choice.clone().into());
    }
    for arg in &args.set {
        set_param(&mut file, arg)?;
    }
    if let Some(tol) = args.tolerance {
        if args.dt.is_some() {
            return Err("give --dt or --tolerance, not both (--tolerance picks the step)".into());
        }
        let choice = tolerance::choose(&mut file, tol, &tolerance::table()?)?;
        if let Some(r) = args.resolution {
            // The scene had resolution r before the pick (set above); putting it back changes
            // the scene only if the pick chose another.
            let mut asked = file.scene.clone();
            asked.params.insert("resolution".into(), r.into());
            if asked != file.scene {
                return Err(format!(
                    "give --resolution or --tolerance, not both: on {} the resolution is part of the method \
                     --tolerance picks ({})",
                    file.name, choice.settings
                ));
            }
        }
        if !args.quiet {
            println!(
                "--tolerance {tol:e}: picked {} ({}) because {}",
                choice.method, choice.settings, choice.why
            );
        }
    }
    let runner = scene::build(&file, &origin, text.as_deref()).map_err(|e| {
        let e = e.to_string();
        match args.resolution {
            Some(r) if e.contains("unknown field `resolution`") => {
                format!("--resolution {r}: a {} scene has no resolution", file.scene.kind)
            }
            Some(r) if e.contains("`scene.resolution`") => format!("--resolution {r}: {e}"),
            _ => e,
        }
    })?;
    let geometry = Geometry::from_context(&runner.context());
    let format = args.format.unwrap_or_else(|| geometry.natural_format());
    if !geometry.accepts(format) {
        return Err(if format == OutputFormat::Vti {
            format!(
                "--format vti: {} is not a grid scene (vti frames hold grid fields); it writes {} frames",
                file.name,
                format_name(geometry.natural_format())
            )
        } else {
            format!(
                "--format {}: {} is a grid scene: its frames are vti (or none)",
                format_name(format),
                file.name
            )
        });
    }
    let out = args.out.clone().unwrap_or_else(|| Path::new("anim-out").join(&file.name));
    Ok(Session {
        file,
        origin,
        out,
        format,
        stride: args.stride,
        preview_width: (!args.no_preview).then_some(args.preview_width),
        checkpoint_every: args.checkpoint_every,
        quiet: args.quiet,
        runner,
        geometry,
        start_frame: 0,
        steps: 0,
        written_times: Vec::new(),
        energy_initial: None,
        max_error: None,
        newton_iterations: 0,
        resumed: false,
        tolerance: args.tolerance,
    })
}

/// The command-line spelling of a frame format.
fn format_name(format: OutputFormat) -> String {
    use clap::ValueEnum;
    format.to_possible_value().map_or_else(|| format!("{format:?}"), |v| v.get_name().to_string())
}

/// A run continued from a checkpoint: the scene is rebuilt from the checkpoint's copy and the
/// runner's state restored.
fn resumed(args: &ResumeArgs) -> Result<Session, String> {
    let (header, ckpt): (_, RunCheckpoint) =
        anim_io::read_checkpoint(&args.checkpoint).map_err(|e| e.to_string())?;
    if header.kind != CHECKPOINT_KIND {
        return Err(format!(
            "{}: a checkpoint of kind `{}`, not of an `anim run` (`{CHECKPOINT_KIND}`)",
            args.checkpoint.display(),
            header.kind
        ));
    }
    let mut file = ckpt.scene;
    if let Some(f) = args.frames {
        if f <= ckpt.frame {
            return Err(format!("--frames {f}: the checkpoint is already at frame {}", ckpt.frame));
        }
        file.run.frames = f;
    }
    let mut runner = scene::build(&file, &ckpt.origin, None).map_err(|e| e.to_string())?;
    runner.restore(&ckpt.runner).map_err(|e| format!("{}: {e}", args.checkpoint.display()))?;
    let geometry = Geometry::from_context(&runner.context());
    Ok(Session {
        file,
        origin: ckpt.origin,
        out: args.out.clone().unwrap_or(ckpt.out),
        format: ckpt.format,
        stride: ckpt.stride,
        preview_width: ckpt.preview_width,
        checkpoint_every: ckpt.checkpoint_every,
        quiet: args.quiet,
        runner,
        geometry,
        start_frame: ckpt.frame,
        steps: ckpt.steps,
        written_times: ckpt.written_times,
        energy_initial: ckpt.energy_initial,
        max_error: ckpt.max_error,
        newton_iterations: ckpt.newton_iterations,
        resumed: true,
        tolerance: None,
    })
}

impl Session {
    /// Writes `<out>/checkpoint.anim` for the frames completed so far (`frame` of them).
    fn checkpoint(&self, frame: usize) -> Result<PathBuf, String> {
        let ckpt = RunCheckpoint {
            scene: self.file.clone(),
            origin: self.origin.clone(),
            out: self.out.clone(),
            format: self.format,
            stride: self.stride,
            preview_width: self.preview_width,
            checkpoint_every: self.checkpoint_every,
            frame,
            steps: self.steps,
            written_times: self.written_times.clone(),
            energy_initial: self.energy_initial,
            max_error: self.max_error,
            newton_iterations: self.newton_iterations,
            runner: self.runner.save(),
        };
        let path = self.out.join(CHECKPOINT_FILE);
        anim_io::write_checkpoint(&path, CHECKPOINT_KIND, &ckpt).map_err(|e| e.to_string())?;
        Ok(path)
    }
}

fn execute(mut s: Session) -> Result<(), String> {
    let out = s.out.clone();
    std::fs::create_dir_all(&out)
        .map_err(|e| format!("{}: cannot create output folder: {e}", out.display()))?;
    let run = s.file.run;
    // At most about 100 preview frames, whatever the run's length.
    let preview = s.preview_width.map(|w| (w, run.frames.div_ceil(100)));
    let continuing = s.resumed.then_some(s.written_times.as_slice());
    let dof = {
        let mut snap = Snapshot::default();
        snap.fill(s.runner.as_ref(), &mut Frame::default(), false, None);
        snap.x.len()
    };
    let mut output = Output::new(&out, s.format, s.stride, preview, (&s.geometry, dof), continuing)?;
    let writes_files = s.format.frame_format().is_some();

    let first_step = s.steps;
    let total_steps = (run.frames * run.steps_per_frame) as u64;
    let bar = ProgressBar::with_draw_target(Some(total_steps), ProgressDrawTarget::hidden());
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} steps, {elapsed} elapsed, eta {eta}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar.set_position(s.steps);
    let start = Instant::now();
    let mut bar_shown = false;
    let mut energy = None;
    let mut step_seconds = 0.0;
    let mut failure = None;
    let mut checkpoints = 0usize;
    let mut table_error: Option<(f64, f64)> = None;
    let mut max_residual: Option<f64> = None;
    'frames: for frame in s.start_frame..run.frames {
        let t_step = Instant::now();
        for _ in 0..run.steps_per_frame {
            match s.runner.step(run.dt) {
                Ok(report) => {
                    s.newton_iterations += report.iterations;
                    if let Some(r) = report.residual {
                        max_residual = Some(max_residual.map_or(r, |m: f64| m.max(r)));
                    }
                    energy = report.energy;
                    if s.energy_initial.is_none() {
                        s.energy_initial = energy;
                    }
                }
                Err(e) => {
                    failure = Some(format!("step {}: {e}", s.steps));
                    break 'frames;
                }
            }
            s.steps += 1;
        }
        step_seconds += t_step.elapsed().as_secs_f64();
        if let Some(e) = s.runner.reference_error() {
            s.max_error = Some(s.max_error.map_or(e, |m: f64| m.max(e)));
        }
        if s.tolerance.is_some()
            && let Some(e) = tolerance::table_error(&s.file.scene, s.runner.as_ref(), max_residual)
        {
            table_error = Some((e, table_error.map_or(e, |(_, m)| m.max(e))));
        }
        if let Err(e) = output.frame(frame, s.runner.as_ref(), energy) {
            failure = Some(format!("frame {frame}: {e}"));
            break;
        }
        if writes_files && frame.is_multiple_of(s.stride) {
            s.written_times.push(s.runner.time());
        }
        if let Some(every) = s.checkpoint_every
            && (frame + 1).is_multiple_of(every)
            && frame + 1 < run.frames
        {
            s.checkpoint(frame + 1)?;
            checkpoints += 1;
        }
        if !s.quiet && !bar_shown && start.elapsed() > Duration::from_secs(1) {
            bar.set_draw_target(ProgressDrawTarget::stderr());
            bar_shown = true;
        }
        bar.set_position(s.steps);
    }
    bar.finish_and_clear();
    let (files, writer_seconds) = output.finish()?;
    let wall = start.elapsed().as_secs_f64();
    // What output added to the run: everything that was not stepping (the writer overlaps
    // with stepping; what it could not hide shows here).
    let output_seconds = (wall - step_seconds).max(0.0);
    let steps_here = s.steps - first_step;
    let energy0 = s.energy_initial;
    let metrics = Metrics {
        scene: s.file.name.clone(),
        system: s.file.scene.system(),
        method: s.runner.method(),
        status: failure.clone().map_or_else(|| "completed".into(), |f| format!("diverged at {f}")),
        dt: run.dt,
        steps: s.steps,
        frames: run.frames,
        format: s.format,
        simulated_seconds: s.runner.time(),
        wall_seconds: wall,
        step_seconds,
        output_seconds,
        output_fraction: output_seconds / wall.max(1e-12),
        writer_busy_seconds: writer_seconds,
        steps_per_second: steps_here as f64 / step_seconds.max(1e-12),
        energy_initial: energy0,
        energy_final: energy,
        relative_energy_change: energy0.zip(energy).map(|(e0, e)| (e - e0) / e0.abs().max(f64::MIN_POSITIVE)),
        max_error_vs_exact: s.max_error,
        tolerance: s.tolerance,
        tolerance_error_final: table_error.map(|e| e.0),
        tolerance_error_max: table_error.map(|e| e.1),
        newton_iterations: s.newton_iterations,
        resumed_from_frame: s.resumed.then_some(s.start_frame),
        checkpoints_written: checkpoints,
        files,
    };
    let metrics_path = out.join("metrics.json");
    anim_io::metrics::write_json(&metrics_path, &metrics).map_err(|e| e.to_string())?;
    if !s.quiet {
        if let Some(f) = metrics.resumed_from_frame {
            println!("resumed at frame {f} (step {first_step})");
        }
        println!(
            "{}: {} steps of {} s with {} in {:.2} s ({:.0} steps/s); output {:.0}% of the time",
            metrics.scene,
            steps_here,
            metrics.dt,
            metrics.method,
            wall,
            metrics.steps_per_second,
            100.0 * metrics.output_fraction
        );
        if let Some(d) = metrics.relative_energy_change {
            println!("  relative energy change {d:.3e}");
        }
        if let Some(e) = metrics.max_error_vs_exact {
            println!("  max error against the exact solution {e:.3e}");
        }
        if let (Some(tol), Some((last, max))) = (s.tolerance, table_error) {
            println!(
                "  error on the table's measure: final {last:.3e}, max over the frames {max:.3e}; tolerance {tol:e} {}",
                if last <= tol { "met" } else { "NOT met" }
            );
        }
        for f in &metrics.files {
            println!("  wrote {f}");
        }
        if checkpoints > 0 {
            println!("  wrote {} ({checkpoints} times)", out.join(CHECKPOINT_FILE).display());
        }
        println!("  wrote {}", metrics_path.display());
    }
    match failure {
        Some(f) => {
            Err(format!("simulation diverged at {f} (frames up to the failure and metrics were written)"))
        }
        None => Ok(()),
    }
}
