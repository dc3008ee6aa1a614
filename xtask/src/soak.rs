//! `cargo xtask stability --long`: soak runs. Each crate's hard case runs for `10^5` steps or
//! ten minutes of wall time, whichever comes first, checking finiteness at every step (the
//! solvers' own guards) and an energy bound or invariant on a fixed stride. Then every registered
//! preset (`anim::presets()`, so a new preset gets its row without any edit here) runs for
//! [`PRESET_BUDGET`] (`10^4` steps or one minute: 29 presets stay within half an hour) through
//! anim-core's `DynScene`: every step checked by its solver's guard (a
//! `StepError` is a detected divergence), every value of its frame checked finite every
//! [`FRAME_STRIDE`] steps, and its checkpoint saved and restored into it (a restore refuses a
//! non-finite or damaged value) every [`CHECKPOINT_STRIDE`] steps and at the end. With `--quick`
//! the presets run their quick parameters for [`QUICK_PRESET_BUDGET`]. The table goes to the
//! terminal and to `<out>/soak.md` (default `docs/report/`), which the report links.
//!
//! A soak case is stable when it reaches its step count or its time budget without an error and
//! without breaking its bound; anything else is a failure and `stability --long` exits 1.

use crate::registry::{Budget, Outcome, Soak, drive, finish, fmt_num, rejected};
use anim_core::scene::{BuildContext, DynScene, Frame, Preset, SceneKind};
use std::fmt::Write as _;
use std::time::{Duration, Instant};

/// Steps between the checks that every value of a preset's frame is finite.
pub const FRAME_STRIDE: u64 = 10;
/// Steps between the checks of a preset's checkpoint.
pub const CHECKPOINT_STRIDE: u64 = 1000;
/// A preset row's budget: `10^4` steps or one minute of wall time.
pub const PRESET_BUDGET: Budget = Budget { steps: 10_000, wall: Duration::from_secs(60) };
/// A preset row's budget with `--quick` (the hard cases keep `Budget::new(true)`).
pub const QUICK_PRESET_BUDGET: Budget = Budget { steps: 200, wall: Duration::from_secs(3) };

/// A row of the table: crate, case, bound checked, what the run did.
struct Row {
    crate_name: &'static str,
    name: String,
    bound: String,
    soak: Soak,
}

/// The first non-finite value of `frame`, named.
fn non_finite(frame: &Frame) -> Option<String> {
    if !frame.time.is_finite() {
        return Some(format!("the frame's time is {}", frame.time));
    }
    if let Some(i) = frame.points.iter().position(|v| !v.is_finite()) {
        return Some(format!("point coordinate {i} is {}", frame.points[i]));
    }
    frame.fields.iter().find_map(|f| {
        let i = f.values.iter().position(|v| !v.is_finite())?;
        Some(format!("value {i} of field `{}` is {}", f.name, f.values[i]))
    })
}

/// Saves the checkpoint and restores it into the scene, which must then save the same text (so
/// it continues bit for bit): the restore checks sizes and finiteness, and a non-finite number
/// is saved as `null`, which no restore reads.
fn checkpoint_restores(scene: &mut dyn DynScene) -> Result<(), String> {
    let saved = scene.save();
    scene.restore(&saved).map_err(|e| format!("its checkpoint does not restore: {e}"))?;
    let (again, before): (String, String) = (scene.save().to_string(), saved.to_string());
    if again != before {
        return Err("restored from its checkpoint, it saves a different one".into());
    }
    Ok(())
}

/// Soaks `preset` (quick parameters when `quick`) for `budget`.
fn soak_preset(kind: &SceneKind, preset: &Preset, quick: bool, budget: Budget) -> Soak {
    let mut scene = match (kind.build)(preset.params_for(quick), &BuildContext::default()) {
        Ok(s) => s,
        Err(e) => return rejected(budget, e),
    };
    let dt = preset.run.dt;
    let mut frame = Frame::default();
    let driven = drive(budget, dt, |k| {
        scene.step(dt).map_err(|e| format!("step {k}: {e}"))?;
        if k.is_multiple_of(FRAME_STRIDE) {
            scene.frame(&mut frame);
            if let Some(what) = non_finite(&frame) {
                return Err(format!("step {k}: {what}"));
            }
        }
        if k.is_multiple_of(CHECKPOINT_STRIDE) {
            checkpoint_restores(scene.as_mut()).map_err(|e| format!("step {k}: {e}"))?;
        }
        Ok(())
    });
    let mut soak = match driven {
        Err(soak) => soak,
        Ok(clock) => {
            scene.frame(&mut frame);
            let end = match non_finite(&frame) {
                Some(what) => Err(what),
                None => checkpoint_restores(scene.as_mut()),
            };
            match end {
                Ok(()) => finish(&clock, dt, true, format!("finite to t = {} s", fmt_num(scene.time()))),
                Err(e) => finish(&clock, dt, false, format!("at the end, step {}: {e}", clock.steps)),
            }
        }
    };
    soak.simulated = scene.time();
    soak
}

/// Runs the selected soak cases, prints the table, writes `<out>/soak.md`; true when all are
/// stable.
pub fn run(quick: bool, filter: Option<&str>, out: &str) -> bool {
    let start = Instant::now();
    let budget = Budget::new(quick);
    let mut rows = Vec::new();
    let report = |crate_name: &str, name: &str, soak: &Soak| {
        eprintln!(
            "soak: {crate_name} / {name}: {} after {} steps, {:.1} s",
            soak.outcome.kind(),
            soak.steps,
            soak.wall
        );
    };
    for case in crate::cases::all().soak {
        if !crate::suites::selected(filter, case.crate_name, case.name) {
            continue;
        }
        eprintln!("soak: {} / {} ...", case.crate_name, case.name);
        let soak = (case.run)(budget);
        report(case.crate_name, case.name, &soak);
        rows.push(Row {
            crate_name: case.crate_name,
            name: case.name.into(),
            bound: case.bound.into(),
            soak,
        });
    }
    let hard_cases = rows.len();
    let preset_budget = if quick { QUICK_PRESET_BUDGET } else { PRESET_BUDGET };
    let preset_start = Instant::now();
    for (kind, preset) in anim::presets() {
        let quick_params = if quick && preset.quick_params.is_some() { " (quick params)" } else { "" };
        let name = format!("preset {}{quick_params}: {}", preset.name, preset.description);
        if !crate::suites::selected(filter, kind.crate_name, preset.name) {
            continue;
        }
        eprintln!("soak: {} / preset {} ...", kind.crate_name, preset.name);
        let soak = soak_preset(kind, &preset, quick, preset_budget);
        report(kind.crate_name, preset.name, &soak);
        let bound = format!(
            "the solver's guard at every step; frame values finite every {FRAME_STRIDE} steps; checkpoint restores every {CHECKPOINT_STRIDE} steps and at the end"
        );
        rows.push(Row { crate_name: kind.crate_name, name, bound, soak });
    }
    let preset_seconds = preset_start.elapsed().as_secs_f64();
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Long runs (soak)\n\nEach crate's hard case for {} steps or {} s of wall time, whichever comes \
         first (`cargo xtask stability --long{}`). Finiteness is checked by the solvers at every \
         step; the bound is checked on the stride given in the detail. Then every registered preset{} \
         for {} steps or {} s, through the scene interface: its solver's guard at every step, every \
         frame value finite every {FRAME_STRIDE} steps, its checkpoint saved and restored (a restore \
         refuses a non-finite value) every {CHECKPOINT_STRIDE} steps and at the end. Wall times are on \
         the machine that wrote this file, shared with other work.\n",
        budget.steps,
        budget.wall.as_secs(),
        if quick { " --quick" } else { "" },
        if quick { " (its quick parameters)" } else { "" },
        preset_budget.steps,
        preset_budget.wall.as_secs(),
    );
    md.push_str(
        "| crate | case | bound checked | steps | simulated time | wall time | ended by | outcome | detail |\n\
         | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n",
    );
    let mut failed = 0;
    for Row { crate_name, name, bound, soak } in &rows {
        let stable = matches!(soak.outcome, Outcome::Stable(_));
        if !stable {
            failed += 1;
        }
        let _ = writeln!(
            md,
            "| {crate_name} | {} | {} | {} | {} s | {:.1} s | {} | {} | {} |",
            name.replace('|', "/"),
            bound.replace('|', "/"),
            soak.steps,
            fmt_num(soak.simulated),
            soak.wall,
            soak.stopped_by,
            if stable { "stable".to_string() } else { format!("**{}**", soak.outcome.kind()) },
            soak.outcome.detail().replace('|', "/")
        );
    }
    println!("{md}");
    println!(
        "soak: {} stable, {failed} failed ({hard_cases} hard cases, {} presets: {preset_seconds:.0} s); {:.0} s in all",
        rows.len() - failed,
        rows.len() - hard_cases,
        start.elapsed().as_secs_f64()
    );
    // A filtered or quick run prints only; the full run is the one recorded.
    if filter.is_none() && !quick {
        let dir = std::path::Path::new(out);
        if let Err(e) = std::fs::create_dir_all(dir).and_then(|()| std::fs::write(dir.join("soak.md"), &md)) {
            eprintln!("could not write {}: {e}", dir.join("soak.md").display());
            return false;
        }
        eprintln!("wrote {}", dir.join("soak.md").display());
    }
    failed == 0
}
