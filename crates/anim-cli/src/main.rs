//! `anim`: runs a scene and writes its frames and a metrics summary.
//!
//! ```text
//! anim run                      # the embedded default scene
//! anim run scene.toml           # a scene file
//! anim run oscillator           # a built-in scene by name
//! anim run scene.toml --out out --frames 100 --dt 0.001
//! anim list                     # the built-in scenes
//! ```

mod scene;

use anim_core::integrate::systems::{HarmonicOscillator, KeplerOrbit};
use anim_core::integrate::{IntegrateError, MechanicalSystem, Simulation, State};
use anim_core::solver::Solver;
use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use scene::{Scene, SceneFile};
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
    Run {
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
        /// No progress bar or summary on the terminal.
        #[arg(long)]
        quiet: bool,
    },
    /// List the built-in scenes.
    List,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::List => {
            for (name, description, _) in scene::BUILTIN {
                let default = if name == scene::DEFAULT_SCENE { " (default)" } else { "" };
                println!("{name:<12} {description}{default}");
            }
            ExitCode::SUCCESS
        }
        Command::Run { scene, out, frames, dt, quiet } => match run(scene.as_deref(), out, frames, dt, quiet)
        {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("error: {e}");
                ExitCode::FAILURE
            }
        },
    }
}

/// Loads the scene named on the command line: a file if one exists at that path, else a
/// built-in scene of that name.
fn resolve(arg: Option<&str>) -> Result<SceneFile, String> {
    let arg = arg.unwrap_or(scene::DEFAULT_SCENE);
    let path = Path::new(arg);
    if path.exists() {
        return scene::load(path).map_err(|e| e.to_string());
    }
    match scene::builtin(arg) {
        Some(text) => {
            scene::parse(text, Path::new(&format!("<built-in scene {arg}>"))).map_err(|e| e.to_string())
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
    system: &'static str,
    integrator: &'static str,
    status: String,
    dt: f64,
    steps: u64,
    frames: usize,
    simulated_seconds: f64,
    wall_seconds: f64,
    steps_per_second: f64,
    energy_initial: Option<f64>,
    energy_final: Option<f64>,
    relative_energy_drift: Option<f64>,
    max_error_vs_exact: Option<f64>,
    newton_iterations: usize,
}

/// The runnable form of a scene: a simulation, its initial state and an optional exact solution.
struct Runnable {
    system: &'static str,
    sim: Simulation<dyn MechanicalSystem + Send>,
    state: State,
    exact: Option<Box<dyn Fn(f64) -> Vec<f64>>>,
}

fn build(scene: &Scene) -> Runnable {
    match *scene {
        Scene::HarmonicOscillator { mass, stiffness, damping, x0, v0, integrator } => {
            let sys = HarmonicOscillator::damped(mass, stiffness, damping);
            Runnable {
                system: "harmonic-oscillator",
                sim: Simulation::new(Box::new(sys), integrator.build(1)),
                state: State::new(vec![x0], vec![v0]),
                exact: Some(Box::new(move |t| {
                    let (x, v) = sys.exact(x0, v0, t);
                    vec![x, v]
                })),
            }
        }
        Scene::KeplerOrbit { eccentricity, integrator } => {
            let sys = KeplerOrbit::ellipse(eccentricity);
            let (x0, v0) = sys.initial();
            Runnable {
                system: "kepler-orbit",
                sim: Simulation::new(Box::new(sys), integrator.build(2)),
                state: State::new(x0.to_vec(), v0.to_vec()),
                exact: Some(Box::new(move |t| {
                    let (x, v) = sys.exact(t);
                    vec![x[0], x[1], v[0], v[1]]
                })),
            }
        }
    }
}

fn run(
    arg: Option<&str>,
    out: Option<PathBuf>,
    frames: Option<usize>,
    dt: Option<f64>,
    quiet: bool,
) -> Result<(), String> {
    let mut file = resolve(arg)?;
    if let Some(f) = frames {
        if f == 0 {
            return Err("--frames must be at least 1".into());
        }
        file.run.frames = f;
    }
    if let Some(dt) = dt {
        if !(dt > 0.0 && dt.is_finite()) {
            return Err(format!("--dt must be a positive finite number, got {dt}"));
        }
        file.run.dt = dt;
    }
    let out = out.unwrap_or_else(|| Path::new("anim-out").join(&file.name));
    std::fs::create_dir_all(&out)
        .map_err(|e| format!("{}: cannot create output folder: {e}", out.display()))?;
    let frames_path = out.join("frames.csv");
    let csv = std::fs::File::create(&frames_path).map_err(|e| format!("{}: {e}", frames_path.display()))?;
    let mut csv = std::io::BufWriter::new(csv);
    let io_err = |e: std::io::Error| format!("{}: {e}", frames_path.display());

    let Runnable { system, mut sim, mut state, exact } = build(&file.scene);
    let n = state.dof();
    let header: Vec<String> =
        (0..n).map(|i| format!("x{i}")).chain((0..n).map(|i| format!("v{i}"))).collect();
    writeln!(csv, "frame,t,{},energy,error_vs_exact", header.join(",")).map_err(io_err)?;

    let energy0 = sim.system_mut().energy(0.0, &state.x, &state.v);
    let total_steps = (file.run.frames * file.run.steps_per_frame) as u64;
    let bar = ProgressBar::with_draw_target(Some(total_steps), ProgressDrawTarget::hidden());
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} steps, {elapsed} elapsed, eta {eta}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let start = Instant::now();
    let mut bar_shown = false;
    let (mut steps, mut max_err, mut newton, mut energy) = (0u64, None::<f64>, 0usize, energy0);
    let mut status = String::from("completed");
    let mut failure: Option<IntegrateError> = None;
    'frames: for frame in 0..file.run.frames {
        for _ in 0..file.run.steps_per_frame {
            match sim.step(&mut state, file.run.dt) {
                Ok(report) => {
                    newton += report.iterations;
                    energy = report.energy;
                }
                Err(e) => {
                    status = format!("diverged at step {steps}: {e}");
                    failure = Some(e);
                    break 'frames;
                }
            }
            steps += 1;
        }
        let err = exact.as_ref().map(|f| {
            let ex = f(state.t);
            state.x.iter().chain(&state.v).zip(&ex).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt()
        });
        if let Some(e) = err {
            max_err = Some(max_err.map_or(e, |m: f64| m.max(e)));
        }
        let values: Vec<String> = state.x.iter().chain(&state.v).map(|v| format!("{v:e}")).collect();
        let opt = |v: Option<f64>| v.map(|v| format!("{v:e}")).unwrap_or_default();
        writeln!(csv, "{frame},{:e},{},{},{}", state.t, values.join(","), opt(energy), opt(err))
            .map_err(io_err)?;
        if !quiet && !bar_shown && start.elapsed() > Duration::from_secs(1) {
            bar.set_draw_target(ProgressDrawTarget::stderr());
            bar_shown = true;
        }
        bar.set_position(steps);
    }
    bar.finish_and_clear();
    csv.flush().map_err(io_err)?;
    let wall = start.elapsed().as_secs_f64();
    let metrics = Metrics {
        scene: file.name.clone(),
        system,
        integrator: sim.integrator_name(),
        status,
        dt: file.run.dt,
        steps,
        frames: file.run.frames,
        simulated_seconds: state.t,
        wall_seconds: wall,
        steps_per_second: steps as f64 / wall.max(1e-12),
        energy_initial: energy0,
        energy_final: energy,
        relative_energy_drift: energy0.zip(energy).map(|(e0, e)| (e - e0) / e0.abs().max(f64::MIN_POSITIVE)),
        max_error_vs_exact: max_err,
        newton_iterations: newton,
    };
    let metrics_path = out.join("metrics.json");
    let json = serde_json::to_string_pretty(&metrics).map_err(|e| e.to_string())?;
    std::fs::write(&metrics_path, json + "\n").map_err(|e| format!("{}: {e}", metrics_path.display()))?;
    if !quiet {
        println!(
            "{}: {} steps of {} with {} in {:.3} s ({:.0} steps/s)",
            metrics.scene, steps, metrics.dt, metrics.integrator, wall, metrics.steps_per_second
        );
        if let Some(d) = metrics.relative_energy_drift {
            println!("  relative energy change {d:.3e}");
        }
        if let Some(e) = metrics.max_error_vs_exact {
            println!("  max error against the exact solution {e:.3e}");
        }
        println!("  wrote {} and {}", frames_path.display(), metrics_path.display());
    }
    match failure {
        Some(e) => {
            Err(format!("simulation diverged: {e} (frames up to the failure and metrics were written)"))
        }
        None => Ok(()),
    }
}
