//! The example scene files of `examples/scenes/`, each with the user's own assets: every file
//! gets the scene contracts of the presets (determinism across thread counts, no allocation per
//! step, checkpoint resume, the non-finite guard; see [`super::presets`]) and a run of the `anim`
//! command's own run loop that must write its frames, its preview and its metrics. The
//! contracts step each example at the resolution of its file in both modes (an example has no
//! smaller quick variant: about 30 steps each, the bulk of the suite's time on the examples); the
//! `anim run` writes two frames in quick mode and the file's own frame count in the full suite.
//! A folder without scene files is a failure, not an empty list.

use crate::registry::{Check, ConformanceCase, Ctx, Judge, Registry};
use anim_core::scene::BuildContext;
use std::path::{Path, PathBuf};

const SOURCE: &str = "examples/scenes: the file runs as `anim run FILE.toml` runs it";

/// The folder of the example scene files.
pub fn folder() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/scenes")
}

/// The example scene files, sorted.
fn files() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(folder())
        .map(|dir| dir.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    files.retain(|p| p.extension().is_some_and(|x| x == "toml"));
    files.sort();
    files
}

pub fn register(r: &mut Registry) {
    let files = files();
    if files.is_empty() {
        r.conformance.push(ConformanceCase {
            crate_name: "examples",
            name: "example scenes",
            run: Box::new(|_| {
                failed(
                    "examples",
                    "example scenes".into(),
                    format!("no scene files in {}", folder().display()),
                )
            }),
        });
    }
    for file in files {
        let stem = file.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        let crate_name = anim_cli::scene::load(&file)
            .ok()
            .and_then(|f| f.scene.registered())
            .map_or("examples", |k| k.crate_name);
        let name: &'static str = Box::leak(format!("example scene: {stem}").into_boxed_str());
        r.conformance.push(ConformanceCase {
            crate_name,
            name,
            run: Box::new(move |ctx| example(&file, ctx)),
        });
    }
}

fn failed(crate_name: &'static str, case: String, e: impl std::fmt::Display) -> Vec<Check> {
    vec![Check {
        crate_name,
        case: format!("{case}: {e}"),
        metric: "error".into(),
        measured: f64::NAN,
        reference: 0.0,
        tolerance: 0.0,
        judge: Judge::AtMost,
        source: SOURCE,
    }]
}

fn example(file: &Path, ctx: &Ctx) -> Vec<Check> {
    let stem = file.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    let scene = match anim_cli::scene::load(file) {
        Ok(s) => s,
        Err(e) => return failed("examples", format!("example {stem}"), e),
    };
    let Some(kind) = scene.scene.registered() else {
        return failed("examples", format!("example {stem}"), format!("unknown kind `{}`", scene.scene.kind));
    };
    let base = file.parent();
    let context = BuildContext { base };
    let params = scene.scene.params_value();
    let mut out =
        super::presets::scene_contracts(kind, &format!("example {stem}"), &params, &context, scene.run.dt);
    let frames = if ctx.quick { 2 } else { scene.run.frames };
    out.extend(run(kind.crate_name, file, &stem, frames));
    out
}

/// `anim run FILE --frames N --out DIR`: the frames, preview and metrics it writes.
fn run(crate_name: &'static str, file: &Path, stem: &str, frames: usize) -> Vec<Check> {
    #[derive(clap::Parser)]
    struct Command {
        #[command(flatten)]
        args: anim_cli::run::RunArgs,
    }
    let out = std::env::temp_dir().join(format!("anim-example-{stem}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let argv = [
        "anim".to_string(),
        file.display().to_string(),
        "--frames".into(),
        frames.to_string(),
        "--out".into(),
        out.display().to_string(),
        "--quiet".into(),
        "--preview-size".into(),
        "160x120".into(),
    ];
    let command = match <Command as clap::Parser>::try_parse_from(argv) {
        Ok(c) => c,
        Err(e) => return failed(crate_name, format!("example {stem}: the command line"), e),
    };
    if let Err(e) = anim_cli::run::run(&command.args) {
        return failed(crate_name, format!("example {stem}: anim run"), e);
    }
    let written = std::fs::read_dir(out.join("frames")).map(|d| d.count()).unwrap_or(0);
    let outputs = ["preview.png", "metrics.json"].iter().filter(|f| out.join(f).is_file()).count();
    let _ = std::fs::remove_dir_all(&out);
    let at_least = |case: String, metric: &str, measured: usize, needed: usize| Check {
        crate_name,
        case,
        metric: metric.into(),
        measured: measured as f64,
        reference: needed as f64,
        tolerance: needed as f64,
        judge: Judge::AtLeast,
        source: SOURCE,
    };
    vec![
        at_least(
            format!("example {stem}: anim run, {frames} frames"),
            "frame files written",
            written,
            frames,
        ),
        at_least(format!("example {stem}: anim run"), "of preview.png and metrics.json written", outputs, 2),
    ]
}
