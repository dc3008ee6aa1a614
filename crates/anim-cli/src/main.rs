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
//! `metrics.json`. Ctrl-C finishes the frame being stepped and then the folder (`"status":
//! "interrupted"` in the metrics, exit status 130); a second Ctrl-C quits at once.

use anim_cli::run::{self, ResumeArgs, RunArgs};
use anim_cli::scene;
use clap::{Parser, Subcommand};
use std::process::ExitCode;

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
            for k in anim::kinds() {
                println!("{:<20} {:<13} {}", k.kind, k.crate_name, k.summary);
            }
            ExitCode::SUCCESS
        }
        Command::List(_) => {
            print!("{}", builtin_listing());
            ExitCode::SUCCESS
        }
        Command::Run(args) => finish(run::stop_on_interrupt().and_then(|()| run::run(&args))),
        Command::Resume(args) => finish(run::stop_on_interrupt().and_then(|()| run::resume(&args))),
    }
}

/// Exit status 0 for a finished run, 130 (as a shell reports SIGINT) for one stopped by Ctrl-C,
/// 1 for any other error.
fn finish(result: Result<(), String>) -> ExitCode {
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            if run::interrupted() { ExitCode::from(130) } else { ExitCode::FAILURE }
        }
    }
}
