//! A run of a scene: from the command line's arguments or a checkpoint to frames, a preview,
//! `metrics.json` and checkpoints. Every scene is a [`DynScene`] built through the registry.

use crate::output::{Output, ViewerSpec};
use crate::scene::{self, SceneFile};
use crate::tolerance;
use crate::view::{Geometry, OutputFormat, Paint, Snapshot};
use anim_core::scene::{DynScene, Frame};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// `anim resume`: continue a checkpointed run.
#[derive(clap::Args)]
pub struct ResumeArgs {
    /// The checkpoint file (`<out>/checkpoint.anim`).
    pub checkpoint: PathBuf,
    /// Output folder (default: the one the checkpointed run wrote to).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Total number of frames of the run (default: the checkpointed run's).
    #[arg(long)]
    pub frames: Option<usize>,
    /// No progress bar or summary on the terminal.
    #[arg(long)]
    pub quiet: bool,
}

/// `anim run`: run a scene file, a built-in scene or the default scene.
#[derive(clap::Args)]
pub struct RunArgs {
    /// A scene file (TOML) or the name of a built-in scene (see `anim list`).
    pub scene: Option<String>,
    /// Output folder (default: `anim-out/<scene name>`).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Override the number of frames.
    #[arg(long)]
    pub frames: Option<usize>,
    /// Override the time step in seconds.
    #[arg(long, allow_hyphen_values = true)]
    pub dt: Option<f64>,
    /// Frame file format (default: the scene's natural one; fluid grids: vti or none).
    #[arg(long, value_enum)]
    pub format: Option<OutputFormat>,
    /// Override the resolution of a preset scene that has one (cloth, MPM, FEM, particle fluids
    /// and fluid grids: cells or particles across).
    #[arg(long)]
    pub resolution: Option<usize>,
    /// Write every N-th frame to files.
    #[arg(long, default_value_t = 1)]
    pub stride: usize,
    /// Skinning method for skinned-character scenes (`lbs`, `dqs` or `both`; default: the
    /// scene's): the same as `--set method=<choice>`.
    #[arg(long, value_parser = ["lbs", "dqs", "both"])]
    pub skinning: Option<String>,
    /// Set a parameter of the scene's `[scene]` table, `KEY=VALUE` with a TOML value
    /// (`--set resolution=48`, `--set integrator=rk4`, `--set 'transfer={flip=0.9}'`); repeatable.
    /// The scene's kind checks it like a field of the file.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Skip the GIF/PNG preview.
    #[arg(long)]
    pub no_preview: bool,
    /// Skip the browser viewer (`viewer.html` and `viewer/` beside the frames).
    #[arg(long)]
    pub no_viewer: bool,
    /// Preview size in pixels, `WIDTHxHEIGHT` (each 16 to 4096); a grid scene's preview keeps
    /// the grid's proportions within it.
    #[arg(long, value_name = "WxH", default_value = "640x480", value_parser = crate::output::parse_preview_size)]
    pub preview_size: (u32, u32),
    /// What the preview colours the points (or a grid's cells) by: `speed`, a field of the
    /// scene's frames (`material`, `strain`, `velocity`, `density`, ...) or `none`. Default:
    /// `material` where a scene has several, a grid's density, otherwise the bodies' colours.
    #[arg(long, value_name = "FIELD")]
    pub color_by: Option<String>,
    /// No progress bar or summary on the terminal.
    #[arg(long)]
    pub quiet: bool,
    /// Every N frames, replace `<out>/checkpoint.anim` (atomically) with the run's state;
    /// `anim resume` continues from it.
    #[arg(long)]
    pub checkpoint_every: Option<usize>,
    /// The accuracy the run needs instead of a method: the method (integrator, solver, time
    /// step, resolution, pressure tolerance, PBD iterations and substeps, MPM transfer and kernel)
    /// comes from the report's measured work-precision studies (oscillator, Kepler, FEM beam,
    /// hanging cloth, lid-driven cavity, smoke plume, PBD cloth, MPM dam break), and
    /// the run's error on the study's measure is printed at the end where the scene has a
    /// reference.
    #[arg(long, allow_hyphen_values = true)]
    pub tolerance: Option<f64>,
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
    /// Steps over the run's wall-clock time (stepping and the output it could not hide).
    steps_per_second: f64,
    /// Steps over the time spent stepping alone.
    stepping_steps_per_second: f64,
    /// The axis that points up in the frames and the preview: `"y"`.
    up: &'static str,
    energy_initial: Option<f64>,
    energy_final: Option<f64>,
    /// `(energy_final - energy_initial) / energy_scale`.
    relative_energy_change: Option<f64>,
    /// The energy in play: the largest over the run of kinetic + |gravitational - initial
    /// gravitational| + |elastic| (see `energy_scale_is`).
    energy_scale: Option<f64>,
    /// What `energy_scale` is, in words.
    energy_scale_is: Option<&'static str>,
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
    /// What the scene's reading skipped or ignored ([`anim_core::scene::Context::notes`]).
    notes: Vec<String>,
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
    /// Whether the run writes the browser viewer (checkpoints written before it existed: yes).
    #[serde(default = "yes")]
    viewer: bool,
    /// The preview's height; absent in checkpoints of runs from before `--preview-size`, whose
    /// previews were 3/4 as high as wide.
    #[serde(default)]
    preview_height: Option<u32>,
    /// What the preview colours by (`--color-by`); absent: the scene's default.
    #[serde(default)]
    color_by: Option<String>,
    checkpoint_every: Option<usize>,
    /// Frames completed.
    frame: usize,
    steps: u64,
    /// Times of the frame files written so far.
    written_times: Vec<f64>,
    energy_initial: Option<f64>,
    /// The energy scale so far and the gravitational energy it is measured from.
    #[serde(default)]
    energy_scale: EnergyScale,
    max_error: Option<f64>,
    newton_iterations: usize,
    runner: serde_json::Value,
}

/// The scale a run's energy change is measured against: the largest over the run of the energy
/// in play, [`anim_core::solver::EnergyParts::scale`] from the first step's gravitational
/// energy where the solver reports the parts, else the largest `|energy|`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, serde::Deserialize)]
struct EnergyScale {
    /// The first step's gravitational energy (solvers that report the parts).
    gravity0: Option<f64>,
    /// The largest energy in play so far.
    largest: Option<f64>,
    /// Whether the scale came from the parts.
    from_parts: bool,
}

impl EnergyScale {
    /// Takes a step's report into account.
    fn add(&mut self, report: &anim_core::solver::StepReport) {
        let now = match (report.energy_parts, report.energy) {
            (Some(parts), _) => {
                let g0 = *self.gravity0.get_or_insert(parts.gravity);
                self.from_parts = true;
                parts.scale(g0)
            }
            (None, Some(e)) => e.abs(),
            (None, None) => return,
        };
        if now.is_finite() {
            self.largest = Some(self.largest.map_or(now, |m| m.max(now)));
        }
    }

    /// `change` relative to the scale; `None` when the scale is 0 (nothing in play).
    fn relative(&self, change: f64) -> Option<f64> {
        self.largest.filter(|&s| s > 0.0).map(|s| change / s)
    }

    /// What the scale is, in words.
    fn meaning(&self) -> &'static str {
        if self.from_parts {
            "largest over the run of kinetic + |gravitational change| + |elastic| energy"
        } else {
            "the largest |total energy| over the run"
        }
    }
}

/// The default of a flag that older checkpoints lack.
fn yes() -> bool {
    true
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
    /// The preview's size in pixels, or none.
    preview_size: Option<(u32, u32)>,
    /// `--color-by`, checked against the scene's frames when the run starts.
    color_by: Option<String>,
    viewer: bool,
    checkpoint_every: Option<usize>,
    quiet: bool,
    runner: Box<dyn DynScene>,
    /// How the scene is drawn and written.
    geometry: Geometry,
    /// The context's notes ([`anim_core::scene::Context::notes`]).
    notes: Vec<String>,
    start_frame: usize,
    steps: u64,
    written_times: Vec<f64>,
    energy_initial: Option<f64>,
    energy_scale: EnergyScale,
    max_error: Option<f64>,
    newton_iterations: usize,
    resumed: bool,
    /// The `--tolerance` asked for, if any.
    tolerance: Option<f64>,
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
    let mut default_scene = None;
    if let Some(tol) = args.tolerance {
        if args.dt.is_some() {
            return Err("give --dt or --tolerance, not both (--tolerance picks the step)".into());
        }
        default_scene = Some(file.clone());
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
    let mut runner = runner;
    if let Some(default) = default_scene
        && !args.quiet
    {
        compare_with_default(&default, &file, &origin, runner.as_mut())?;
    }
    let context = runner.context();
    let geometry = Geometry::from_context(&context);
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
        viewer: !args.no_viewer,
        preview_size: (!args.no_preview).then_some(args.preview_size),
        color_by: args.color_by.clone(),
        checkpoint_every: args.checkpoint_every,
        quiet: args.quiet,
        runner,
        geometry,
        notes: context.notes,
        start_frame: 0,
        steps: 0,
        written_times: Vec::new(),
        energy_initial: None,
        energy_scale: EnergyScale::default(),
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
    let context = runner.context();
    let geometry = Geometry::from_context(&context);
    Ok(Session {
        file,
        origin: ckpt.origin,
        out: args.out.clone().unwrap_or(ckpt.out),
        format: ckpt.format,
        stride: ckpt.stride,
        preview_size: ckpt.preview_width.map(|w| (w, ckpt.preview_height.unwrap_or((w * 3 / 4).max(1)))),
        color_by: ckpt.color_by,
        viewer: ckpt.viewer,
        checkpoint_every: ckpt.checkpoint_every,
        quiet: args.quiet,
        runner,
        geometry,
        notes: context.notes,
        start_frame: ckpt.frame,
        steps: ckpt.steps,
        written_times: ckpt.written_times,
        energy_initial: ckpt.energy_initial,
        energy_scale: ckpt.energy_scale,
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
            preview_width: self.preview_size.map(|s| s.0),
            preview_height: self.preview_size.map(|s| s.1),
            color_by: self.color_by.clone(),
            viewer: self.viewer,
            checkpoint_every: self.checkpoint_every,
            frame,
            steps: self.steps,
            written_times: self.written_times.clone(),
            energy_initial: self.energy_initial,
            energy_scale: self.energy_scale,
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
    if !s.quiet {
        for note in &s.notes {
            println!("note: {note}");
        }
    }
    let mut first = Frame::default();
    let dof = {
        let mut snap = Snapshot::default();
        snap.fill(s.runner.as_ref(), &mut first, false, None);
        snap.x.len()
    };
    let context = s.runner.context();
    // Checked before anything is written.
    let paint = Paint::choose(s.color_by.as_deref(), &context, &first)?;
    std::fs::create_dir_all(&out)
        .map_err(|e| format!("{}: cannot create output folder: {e}", out.display()))?;
    let run = s.file.run;
    let continuing = s.resumed.then_some(s.written_times.as_slice());
    let preview = s.preview_size.map(|size| (size, run.frames, paint));
    let context = s.viewer.then_some(context);
    let viewer =
        context.as_ref().map(|context| ViewerSpec { title: &s.file.name, context, resume: s.resumed });
    let mut output = Output::new(&out, s.format, s.stride, preview, (&s.geometry, dof), continuing, viewer)?;
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
    let mut interrupted = None;
    'frames: for frame in s.start_frame..run.frames {
        if interrupts() > 0 {
            interrupted = Some(frame);
            break;
        }
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
                    s.energy_scale.add(&report);
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
        let stopping = interrupts() > 0 && frame + 1 < run.frames;
        if let Some(every) = s.checkpoint_every
            && ((frame + 1).is_multiple_of(every) || stopping)
            && frame + 1 < run.frames
        {
            s.checkpoint(frame + 1)?;
            checkpoints += 1;
        }
        if stopping {
            interrupted = Some(frame + 1);
            break;
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
        status: match (&failure, interrupted) {
            (Some(f), _) => format!("diverged at {f}"),
            (None, Some(_)) => "interrupted".into(),
            (None, None) => "completed".into(),
        },
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
        steps_per_second: steps_here as f64 / wall.max(1e-12),
        stepping_steps_per_second: steps_here as f64 / step_seconds.max(1e-12),
        up: anim_io::frames::UP,
        energy_initial: energy0,
        energy_final: energy,
        relative_energy_change: energy0.zip(energy).and_then(|(e0, e)| s.energy_scale.relative(e - e0)),
        energy_scale: s.energy_scale.largest,
        energy_scale_is: s.energy_scale.largest.map(|_| s.energy_scale.meaning()),
        max_error_vs_exact: s.max_error,
        tolerance: s.tolerance,
        tolerance_error_final: table_error.map(|e| e.0),
        tolerance_error_max: table_error.map(|e| e.1),
        newton_iterations: s.newton_iterations,
        resumed_from_frame: s.resumed.then_some(s.start_frame),
        checkpoints_written: checkpoints,
        files,
        notes: s.notes.clone(),
    };
    let metrics_path = out.join("metrics.json");
    anim_io::metrics::write_json(&metrics_path, &metrics).map_err(|e| e.to_string())?;
    if !s.quiet {
        if let Some(f) = metrics.resumed_from_frame {
            println!("resumed at frame {f} (step {first_step})");
        }
        println!(
            "{}: {} steps of {} s with {} in {:.2} s ({:.0} steps/s, {:.0} stepping alone); output {:.0}% of the time",
            metrics.scene,
            steps_here,
            metrics.dt,
            metrics.method,
            wall,
            metrics.steps_per_second,
            metrics.stepping_steps_per_second,
            100.0 * metrics.output_fraction
        );
        match (metrics.relative_energy_change, metrics.energy_scale) {
            (Some(d), Some(scale)) => {
                println!(
                    "  energy change {d:.3e} relative to the energy in play, {scale:.3e} ({})",
                    s.energy_scale.meaning()
                )
            }
            (None, Some(_)) => {
                println!("  energy change: not measured (nothing moved, was lifted or deformed)")
            }
            _ => {}
        }
        if let Some(e) = metrics.max_error_vs_exact {
            println!("  max error against the exact solution {e:.3e}");
        }
        match (s.tolerance, table_error) {
            (Some(tol), Some((last, max))) => println!(
                "  error on the table's measure: final {last:.3e}, max over the frames {max:.3e}; tolerance {tol:e} {}",
                if last <= tol { "met" } else { "NOT met" }
            ),
            (Some(_), None) => println!(
                "  error on the table's measure: not measured (this scene carries no reference for it; the \
                 study's error at the picked point is the estimate)"
            ),
            _ => {}
        }
        for f in &metrics.files {
            println!("  wrote {f}");
        }
        if checkpoints > 0 {
            println!("  wrote {} ({checkpoints} times)", out.join(CHECKPOINT_FILE).display());
        }
        println!("  wrote {}", metrics_path.display());
    }
    match (failure, interrupted) {
        (Some(f), _) => {
            Err(format!("simulation diverged at {f} (frames up to the failure and metrics were written)"))
        }
        (None, Some(done)) => Err(format!(
            "interrupted after frame {done} of {} (its frames, preview and metrics were written{})",
            run.frames,
            if s.checkpoint_every.is_some() { ", and a checkpoint to resume from" } else { "" }
        )),
        (None, None) => Ok(()),
    }
}

/// Seconds a frame of `runner` takes, measured on its first steps after one untimed step (which
/// pays one-time setup such as a factorisation's analysis): at most a frame's steps, and no
/// more once 0.2 s have passed. The runner is then restored to where it was (its checkpoint
/// contract: bit for bit), whether or not the measurement succeeded; the time is `None` when a
/// step failed.
///
/// # Errors
/// The restore failed: the runner is not where the run must start.
fn seconds_per_frame(
    runner: &mut dyn DynScene,
    dt: f64,
    steps_per_frame: usize,
) -> Result<Option<f64>, String> {
    let saved = runner.save();
    let measured = (|| {
        runner.step(dt).ok()?;
        let start = Instant::now();
        let mut steps = 0;
        while steps < steps_per_frame && (steps == 0 || start.elapsed() < Duration::from_millis(200)) {
            runner.step(dt).ok()?;
            steps += 1;
        }
        Some(start.elapsed().as_secs_f64() / steps as f64 * steps_per_frame as f64)
    })();
    runner
        .restore(&saved)
        .map_err(|e| format!("--tolerance: the scene could not be put back after timing a few steps: {e}"))?;
    Ok(measured)
}

/// Prints how the cost of a frame with the method `--tolerance` picked compares with the
/// scene's own method (both measured here, on a few steps), and a warning when the pick is more
/// than 5 times slower. `runner` is left where it was.
///
/// # Errors
/// `runner` could not be put back after timing ([`seconds_per_frame`]).
fn compare_with_default(
    default: &SceneFile,
    picked: &SceneFile,
    origin: &Path,
    runner: &mut dyn DynScene,
) -> Result<(), String> {
    let base = match scene::build(default, origin, None) {
        Ok(mut d) => seconds_per_frame(d.as_mut(), default.run.dt, default.run.steps_per_frame)?,
        Err(_) => None,
    };
    let measured = match base {
        Some(base) => {
            seconds_per_frame(runner, picked.run.dt, picked.run.steps_per_frame)?.map(|pick| (pick, base))
        }
        None => None,
    };
    match measured {
        Some((pick, base)) if pick > 5.0 * base => eprintln!(
            "warning: --tolerance: a frame with the picked method takes about {:.0}x the time of the scene's \
             own method ({} against {} per frame, measured on a few steps)",
            pick / base,
            seconds(pick),
            seconds(base)
        ),
        Some((pick, base)) => println!(
            "--tolerance: a frame takes {} with the picked method, {} with the scene's own (measured on a few steps)",
            seconds(pick),
            seconds(base)
        ),
        None => {
            println!("--tolerance: the cost against the scene's own method was not measured (a step failed)")
        }
    }
    Ok(())
}

/// A duration for people: `1.2 s`, `35 ms`, `120 us`.
fn seconds(s: f64) -> String {
    if s >= 1.0 {
        format!("{s:.1} s")
    } else if s >= 1e-3 {
        format!("{:.0} ms", s * 1e3)
    } else {
        format!("{:.0} us", s * 1e6)
    }
}

/// How many interrupt signals (Ctrl-C) the process has had since
/// [`stop_on_interrupt`] was called.
static INTERRUPTS: AtomicUsize = AtomicUsize::new(0);

fn interrupts() -> usize {
    INTERRUPTS.load(Ordering::Relaxed)
}

/// Whether the process was interrupted (Ctrl-C) during a run.
#[must_use]
pub fn interrupted() -> bool {
    interrupts() > 0
}

/// Makes Ctrl-C (SIGINT, and SIGTERM) end a run cleanly: the frame being stepped is finished,
/// then the folder is completed as after the last frame (the frame series and its `.pvd`, the
/// preview of the frames so far, `metrics.json` with `"status": "interrupted"`, and a
/// checkpoint to resume from when `--checkpoint-every` was given), and [`run`] returns an error
/// saying so. A second Ctrl-C quits at once (exit status 130); a signal within
/// [`SAME_INTERRUPT`] of the first is the same interrupt delivered twice (`timeout -s INT` sends
/// it to the process and to its process group), not a second Ctrl-C.
///
/// # Errors
/// The handler could not be installed (one was installed before).
pub fn stop_on_interrupt() -> Result<(), String> {
    static FIRST: std::sync::OnceLock<Instant> = std::sync::OnceLock::new();
    ctrlc::set_handler(|| {
        let first = *FIRST.get_or_init(Instant::now);
        if INTERRUPTS.fetch_add(1, Ordering::Relaxed) == 0 {
            eprintln!("\ninterrupted: finishing the current frame and the output folder (Ctrl-C again to quit at once)");
        } else if first.elapsed() >= SAME_INTERRUPT {
            std::process::exit(130);
        }
    })
    .map_err(|e| format!("cannot handle Ctrl-C: {e}"))
}

/// How soon after the first an interrupt signal counts as the same one.
pub const SAME_INTERRUPT: Duration = Duration::from_millis(300);

/// Runs the scene `args` names and writes its output.
///
/// # Errors
/// A message naming the flag, file, field or step that failed; a run that diverges writes its
/// frames up to the failure and its metrics first.
pub fn run(args: &RunArgs) -> Result<(), String> {
    fresh(args).and_then(|s| anim_core::par::on_worker(|| execute(s)))
}

/// Continues the run checkpointed in `args.checkpoint`.
///
/// # Errors
/// As [`run`], and for a checkpoint that cannot be read or restored.
pub fn resume(args: &ResumeArgs) -> Result<(), String> {
    resumed(args).and_then(|s| anim_core::par::on_worker(|| execute(s)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use anim_core::scene::{CheckpointError, Context, StepError};
    use anim_core::solver::StepReport;

    /// A scene whose state is a step count and whose step fails once it reaches `fail_at`.
    struct Counter {
        steps: u32,
        fail_at: u32,
    }

    #[derive(Debug, thiserror::Error)]
    #[error("step {0} fails")]
    struct Fails(u32);

    impl DynScene for Counter {
        fn step(&mut self, _: f64) -> Result<StepReport, StepError> {
            if self.steps >= self.fail_at {
                return Err(StepError::new(Fails(self.steps)));
            }
            self.steps += 1;
            Ok(StepReport::at_time(f64::from(self.steps)))
        }
        fn time(&self) -> f64 {
            f64::from(self.steps)
        }
        fn save(&self) -> serde_json::Value {
            self.steps.into()
        }
        fn restore(&mut self, saved: &serde_json::Value) -> Result<(), CheckpointError> {
            self.steps = saved.as_u64().and_then(|s| u32::try_from(s).ok()).unwrap_or(0);
            Ok(())
        }
        fn method(&self) -> String {
            "counter".into()
        }
        fn context(&self) -> Context {
            Context::default()
        }
        fn frame(&self, _: &mut Frame) {}
        fn reference_error(&self) -> Option<f64> {
            None
        }
        fn provoke_overflow(&mut self) -> Option<String> {
            None
        }
    }

    /// Timing a few steps leaves the scene where it was, whether the steps succeed or one of
    /// them fails (the run then starts from the scene's own start, not from where the failing
    /// measurement stopped).
    #[test]
    fn timing_a_frame_puts_the_scene_back_even_when_a_step_fails() {
        for (start, fail_at, measured) in [(0, 100, true), (2, 4, false), (3, 3, false)] {
            let mut scene = Counter { steps: start, fail_at };
            let time = seconds_per_frame(&mut scene, 0.1, 10).unwrap();
            assert_eq!((time.is_some(), scene.steps), (measured, start), "start {start}, fail at {fail_at}");
        }
    }
}
