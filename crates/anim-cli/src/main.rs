//! `anim`: runs a scene and writes its frames, a preview and a metrics summary.
//!
//! ```text
//! anim run                      # the embedded default scene (a hanging cloth)
//! anim run scene.toml           # a scene file
//! anim run kepler               # a built-in scene by name
//! anim run cloth --out out --frames 60 --format obj --stride 2
//! anim list                     # the built-in scenes
//! ```
//!
//! Every run writes into its output folder: the frames in the scene's natural format (VTK `.vtu`
//! with a `.pvd` series for meshes, `frames.csv` for systems of a few unknowns) or the one asked
//! for, `preview.gif` (and `preview.png`, the last frame), and `metrics.json`.

mod runner;
mod scene;
mod view;

use anim_io::FrameWriter;
use anim_io::preview::{Canvas, GifWriter};
use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use runner::{OutputFormat, Runner};
use scene::SceneFile;
use serde::Serialize;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant};
use view::{Snapshot, View};

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
    /// List the built-in scenes.
    List,
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
    /// Frame file format (default: the scene's natural one).
    #[arg(long, value_enum)]
    format: Option<OutputFormat>,
    /// Write every N-th frame to files.
    #[arg(long, default_value_t = 1)]
    stride: usize,
    /// Skinning method for skinned-character scenes (default: the scene's).
    #[arg(long, value_enum)]
    skinning: Option<scene::SkinningChoice>,
    /// Skip the GIF/PNG preview.
    #[arg(long)]
    no_preview: bool,
    /// Preview width in pixels (height is 3/4 of it).
    #[arg(long, default_value_t = 320)]
    preview_width: u32,
    /// No progress bar or summary on the terminal.
    #[arg(long)]
    quiet: bool,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::List => {
            for (name, description, _) in scene::BUILTIN {
                let default = if name == scene::DEFAULT_SCENE { " [default]" } else { "" };
                println!("{name:<12} {description}{default}");
            }
            ExitCode::SUCCESS
        }
        Command::Run(args) => match run(&args) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("error: {e}");
                ExitCode::FAILURE
            }
        },
    }
}

/// Loads the scene named on the command line: a file if one exists at that path, else a
/// built-in scene of that name. Returns the scene and the path errors should name.
fn resolve(arg: Option<&str>) -> Result<(SceneFile, PathBuf), String> {
    let arg = arg.unwrap_or(scene::DEFAULT_SCENE);
    let path = Path::new(arg);
    if path.exists() {
        return scene::load(path).map(|s| (s, path.to_path_buf())).map_err(|e| e.to_string());
    }
    match scene::builtin(arg) {
        Some(text) => {
            let origin = PathBuf::from(format!("<built-in scene {arg}>"));
            scene::parse(text, &origin).map(|s| (s, origin)).map_err(|e| e.to_string())
        }
        None => Err(format!(
            "{arg}: no such scene file, and no built-in scene of that name (built-in: {})",
            scene::BUILTIN.map(|b| b.0).join(", ")
        )),
    }
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
    newton_iterations: usize,
    files: Vec<String>,
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
    fn new(
        dir: &Path,
        format: OutputFormat,
        stride: usize,
        preview: Option<(u32, usize)>,
        runner: &dyn Runner,
    ) -> Result<Self, String> {
        let view = View::new(runner.geometry());
        let mut writer = Writer { dir: dir.to_path_buf(), stride, view, frames: None, csv: None, gif: None };
        if let Some(f) = format.frame_format() {
            writer.frames = Some(FrameWriter::new(dir.join("frames"), f).map_err(|e| e.to_string())?);
        }
        if format == OutputFormat::Csv {
            let path = dir.join("frames.csv");
            let file = std::fs::File::create(&path).map_err(|e| format!("{}: {e}", path.display()))?;
            let mut csv = std::io::BufWriter::new(file);
            let n = runner.state().dof();
            let header: Vec<String> =
                (0..n).map(|i| format!("x{i}")).chain((0..n).map(|i| format!("v{i}"))).collect();
            writeln!(csv, "frame,t,{},energy,error_vs_exact", header.join(","))
                .map_err(|e| format!("{}: {e}", path.display()))?;
            writer.csv = Some(csv);
        }
        if let Some((width, every)) = preview {
            let height = (width * 3 / 4).max(1);
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
        Ok(Output { sender: Some(sender), returned, worker: Some(worker), spare: Vec::new() })
    }

    /// Queues frame `index` of the runner's current state.
    fn frame(&mut self, index: usize, runner: &dyn Runner, energy: Option<f64>) -> Result<(), String> {
        self.spare.extend(self.returned.try_iter());
        let mut snapshot = self.spare.pop().unwrap_or_default();
        runner.snapshot(energy, &mut snapshot);
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

fn run(args: &RunArgs) -> Result<(), String> {
    let (mut file, origin) = resolve(args.scene.as_deref())?;
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
    let mut runner = runner::build(&file.scene, &origin, args.skinning).map_err(|e| e.to_string())?;
    let format = args.format.unwrap_or_else(|| runner.natural_format());
    let out = args.out.clone().unwrap_or_else(|| Path::new("anim-out").join(&file.name));
    std::fs::create_dir_all(&out)
        .map_err(|e| format!("{}: cannot create output folder: {e}", out.display()))?;
    // At most about 100 preview frames, whatever the run's length.
    let preview = (!args.no_preview).then(|| (args.preview_width, file.run.frames.div_ceil(100)));
    let mut output = Output::new(&out, format, args.stride, preview, runner.as_ref())?;

    let total_steps = (file.run.frames * file.run.steps_per_frame) as u64;
    let bar = ProgressBar::with_draw_target(Some(total_steps), ProgressDrawTarget::hidden());
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} steps, {elapsed} elapsed, eta {eta}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let start = Instant::now();
    let mut bar_shown = false;
    let (mut steps, mut max_err, mut newton) = (0u64, None::<f64>, 0usize);
    let (mut energy0, mut energy) = (None, None);
    let mut step_seconds = 0.0;
    let mut failure = None;
    'frames: for frame in 0..file.run.frames {
        let t_step = Instant::now();
        for _ in 0..file.run.steps_per_frame {
            match runner.step(file.run.dt) {
                Ok(report) => {
                    newton += report.iterations;
                    energy = report.energy;
                    if energy0.is_none() {
                        energy0 = energy;
                    }
                }
                Err(e) => {
                    failure = Some(format!("step {steps}: {e}"));
                    break 'frames;
                }
            }
            steps += 1;
        }
        step_seconds += t_step.elapsed().as_secs_f64();
        if let Some(e) = runner.exact_error() {
            max_err = Some(max_err.map_or(e, |m: f64| m.max(e)));
        }
        if let Err(e) = output.frame(frame, runner.as_ref(), energy) {
            failure = Some(format!("frame {frame}: {e}"));
            break;
        }
        if !args.quiet && !bar_shown && start.elapsed() > Duration::from_secs(1) {
            bar.set_draw_target(ProgressDrawTarget::stderr());
            bar_shown = true;
        }
        bar.set_position(steps);
    }
    bar.finish_and_clear();
    let (files, writer_seconds) = output.finish()?;
    let wall = start.elapsed().as_secs_f64();
    // What output added to the run: everything that was not stepping (the writer overlaps
    // with stepping; what it could not hide shows here).
    let output_seconds = (wall - step_seconds).max(0.0);
    let metrics = Metrics {
        scene: file.name.clone(),
        system: runner.system(),
        method: runner.method(),
        status: failure.clone().map_or_else(|| "completed".into(), |f| format!("diverged at {f}")),
        dt: file.run.dt,
        steps,
        frames: file.run.frames,
        format,
        simulated_seconds: runner.state().t,
        wall_seconds: wall,
        step_seconds,
        output_seconds,
        output_fraction: output_seconds / wall.max(1e-12),
        writer_busy_seconds: writer_seconds,
        steps_per_second: steps as f64 / step_seconds.max(1e-12),
        energy_initial: energy0,
        energy_final: energy,
        relative_energy_change: energy0.zip(energy).map(|(e0, e)| (e - e0) / e0.abs().max(f64::MIN_POSITIVE)),
        max_error_vs_exact: max_err,
        newton_iterations: newton,
        files,
    };
    let metrics_path = out.join("metrics.json");
    anim_io::metrics::write_json(&metrics_path, &metrics).map_err(|e| e.to_string())?;
    if !args.quiet {
        println!(
            "{}: {} steps of {} s with {} in {:.2} s ({:.0} steps/s); output {:.0}% of the time",
            metrics.scene,
            steps,
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
        for f in &metrics.files {
            println!("  wrote {f}");
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
