//! The `flip` scene kind: the presets of [`scenes::by_name`] registered with anim-core's scene
//! contracts ([`anim_core::scene`]), so the `anim` command line, `cargo xtask` and the Python
//! bindings build, step, checkpoint and draw them without knowing this crate.
//!
//! | preset | what | cells across the 1 m tank |
//! | --- | --- | --- |
//! | `dam-break-2d` | a 0.25 x 0.5 m water column collapsing in a tank | 64 |
//! | `dam-break-3d` | a water column collapsing in the corner of a tank | 32 |
//! | `drop-2d`, `drop-3d` | a disk (ball) of water falling into a pool | 64, 32 |
//! | `sloshing-tank` | water in a 2D tank shaken at its first sloshing frequency | 64 |
//!
//! A scene is the [`FlipSimulation`] itself, a [`Solver`](anim_core::solver::Solver) of its
//! [`Particles`]. anim-flip has y
//! up; frames have z up like the workspace's other scenes: a fluid point `(x, y, z)` is shown
//! at `(x, -z, y)`, a 2D one `(x, y)` at `(x, 0, y)` (2D scenes lie in the plane y = 0). The
//! sloshing tank is simulated in its own frame; its frames are in the world frame, the tank's
//! displacement added to the positions and its velocity to the velocities. The context has
//! the tank's inner walls at rest as a [`Prop::Tank`] and, as its bounds, the region the
//! moving tank sweeps.
//!
//! ```
//! use anim_core::scene::Frame;
//!
//! let preset = (anim_flip::KIND.presets)().remove(2);
//! assert_eq!(preset.name, "drop-2d");
//! let params = preset.quick_params.expect("a coarse version");
//! let mut scene = (anim_flip::KIND.build)(&params, &Default::default())?;
//! scene.step(preset.run.dt)?;
//! let mut frame = Frame::default();
//! scene.frame(&mut frame);
//! // Every particle in the plane y = 0, z up.
//! assert!(frame.points.chunks_exact(3).all(|p| p[1] == 0.0 && p[2] > 0.0));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::particles::Particles;
use crate::scenes::{self, FlipScene};
use crate::sim::FlipSimulation;
use crate::transfer::Transfer;
use anim_core::scene::{
    BuildContext, BuildError, Checkpoint, CheckpointError, Context, DynScene, Frame, Preset, Prop,
    RunDefaults, SceneKind, Simulated, View, params, saved_field,
};
use serde::{Deserialize, Serialize};
use serde_json::json;

/// The `flip` scene kind of anim-flip, for the workspace registry.
pub const KIND: SceneKind = SceneKind {
    kind: "flip",
    crate_name: "anim-flip",
    summary: "an incompressible particle fluid (PIC, FLIP, APIC on a MAC grid) in 2D and 3D: dam breaks, drops, a sloshing tank",
    presets,
    build,
    tolerance: None,
};

/// Scene-file parameters of a `flip` scene: a preset of [`scenes::NAMES`] and what a file may
/// change in it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FlipSceneParams {
    /// The preset's name: `"dam-break-2d"`, `"dam-break-3d"`, `"drop-2d"`, `"drop-3d"` or
    /// `"sloshing-tank"`.
    pub preset: String,
    /// Cells across the 1 m tank: at most 1024 in 2D, 128 in 3D (at least 4, what the
    /// solid border and the kernel need). Default: the preset's (64 in 2D, 32 in 3D).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub resolution: Option<usize>,
    /// Grid-to-particle transfer: `"apic"`, `"pic"`, or `{ flip = 0.97 }` (FLIP blended with
    /// PIC, the blend in `[0, 1]`). Default APIC.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transfer: Option<Transfer>,
}

impl FlipSceneParams {
    /// The preset at `resolution` cells across (the preset's own when `None`).
    #[must_use]
    pub fn preset(name: &str, resolution: Option<usize>) -> Self {
        Self { preset: name.into(), resolution, transfer: None }
    }

    /// Checks the parameters and builds the preset.
    ///
    /// # Errors
    /// [`BuildError::Invalid`] naming the field: an unknown preset, a FLIP blend outside
    /// `[0, 1]`, a resolution above the preset's limit or one the simulation refuses.
    pub fn scene(&self) -> Result<FlipScene, BuildError> {
        let preset = self.preset.as_str();
        let unknown = || {
            BuildError::invalid(
                "preset",
                format!("unknown preset `{preset}` (one of {})", scenes::NAMES.join(", ")),
            )
        };
        if !scenes::NAMES.contains(&preset) {
            return Err(unknown());
        }
        if let Some(Transfer::Flip(blend)) = self.transfer
            && !(0.0..=1.0).contains(&blend)
        {
            return Err(BuildError::invalid(
                "transfer",
                format!("the FLIP blend must lie in [0, 1], got {blend}"),
            ));
        }
        let limit = if preset.ends_with("3d") { 128 } else { 1024 };
        if let Some(r) = self.resolution
            && r > limit
        {
            return Err(BuildError::invalid(
                "resolution",
                format!("{preset} takes at most {limit} cells across, got {r}"),
            ));
        }
        scenes::by_name(preset, self.resolution, self.transfer)
            .ok_or_else(unknown)?
            .map_err(|e| BuildError::invalid("resolution", e.to_string()))
    }
}

fn preset(name: &'static str, description: &'static str, frames: usize, params: serde_json::Value) -> Preset {
    let quick = if name.ends_with("3d") { 8 } else { 16 };
    let mut quick_params = params.clone();
    quick_params["resolution"] = json!(quick);
    Preset {
        name,
        description,
        run: RunDefaults::new(0.02, frames, 1),
        params,
        quick_params: Some(quick_params),
    }
}

fn presets() -> Vec<Preset> {
    vec![
        preset(
            "dam-break-2d",
            "APIC particle fluid in 2D: a 0.25 x 0.5 m water column collapsing in a tank (64 cells/m)",
            100,
            json!({ "preset": "dam-break-2d", "resolution": 64 }),
        ),
        preset(
            "dam-break-3d",
            "APIC particle fluid in 3D: a water column collapsing in the corner of a tank",
            75,
            json!({ "preset": "dam-break-3d", "resolution": 32 }),
        ),
        preset(
            "drop-2d",
            "APIC particle fluid in 2D: a disk of water falling into a pool",
            75,
            json!({ "preset": "drop-2d", "resolution": 64 }),
        ),
        preset(
            "drop-3d",
            "APIC particle fluid in 3D: a ball of water falling into a pool",
            75,
            json!({ "preset": "drop-3d", "resolution": 32 }),
        ),
        preset(
            "sloshing-tank",
            "APIC particle fluid in 2D: water in a tank shaken at its first sloshing frequency",
            250,
            json!({ "preset": "sloshing-tank", "resolution": 64, "transfer": "apic" }),
        ),
    ]
}

fn build(value: &serde_json::Value, _: &BuildContext<'_>) -> Result<Box<dyn DynScene>, BuildError> {
    let p: FlipSceneParams = params(value)?;
    Ok(match p.scene()? {
        FlipScene::Two(s) => Simulated::new(s.sim, s.particles).boxed(),
        FlipScene::Three(s) => Simulated::new(s.sim, s.particles).boxed(),
    })
}

/// A y-up fluid vector as a z-up one: `(x, y, z) -> (x, -z, y)` (a rotation about x),
/// `(x, y) -> (x, 0, y)`.
fn z_up<const D: usize>(p: &[f64; D]) -> [f64; 3] {
    let z = if D == 3 { -p[D - 1] } else { 0.0 };
    [p[0], z, p[1]]
}

/// The corners of the box with corners `lo` and `hi` (y up), z up.
fn box_z_up<const D: usize>(lo: &[f64; D], hi: &[f64; D]) -> ([f64; 3], [f64; 3]) {
    let (a, b) = (z_up(lo), z_up(hi));
    (std::array::from_fn(|k| a[k].min(b[k])), std::array::from_fn(|k| a[k].max(b[k])))
}

/// Saved as `{"dim", "cells", "particles", "simulation"}`: the dimension and grid it belongs
/// to, the particles and the step clock ([`FlipSimulation::memory`]).
impl<const D: usize> Checkpoint for FlipSimulation<D> {
    const VERSION: u32 = 1;

    fn time(&self, _: &Particles<D>) -> f64 {
        FlipSimulation::time(self)
    }

    fn save(&self, particles: &Particles<D>) -> serde_json::Value {
        json!({
            "dim": D,
            "cells": self.grid().cells().as_slice(),
            "particles": particles,
            "simulation": self.memory(),
        })
    }

    fn restore(
        &mut self,
        particles: &mut Particles<D>,
        saved: &serde_json::Value,
    ) -> Result<(), CheckpointError> {
        let dim: usize = saved_field(saved, "dim")?;
        if dim != D {
            return Err(CheckpointError::invalid("dim", format!("a {dim}D checkpoint for a {D}D scene")));
        }
        let cells: Vec<usize> = saved_field(saved, "cells")?;
        if cells != self.grid().cells() {
            return Err(CheckpointError::invalid(
                "cells",
                format!("a checkpoint of a {cells:?} grid; this scene's is {:?}", self.grid().cells()),
            ));
        }
        let restored: Particles<D> = saved_field(saved, "particles")?;
        restored.validate().map_err(|e| CheckpointError::invalid("particles", e.to_string()))?;
        if self.params().reseed.is_none() && restored.len() != particles.len() {
            return Err(CheckpointError::invalid(
                "particles",
                format!(
                    "{} particles; this scene has {} and does not reseed",
                    restored.len(),
                    particles.len()
                ),
            ));
        }
        let (lo, hi) = self.fluid_box();
        if let Some(p) = restored.x.iter().position(|x| (0..D).any(|a| !(x[a] >= lo[a] && x[a] <= hi[a]))) {
            return Err(CheckpointError::invalid(
                "particles",
                format!("particle {p} at {:?} lies outside the tank {lo:?} - {hi:?}", restored.x[p]),
            ));
        }
        let memory =
            saved.get("simulation").ok_or_else(|| CheckpointError::Missing { field: "simulation".into() })?;
        // Checks the clock before it sets it; the particles are taken after.
        self.restore_memory(memory).map_err(|e| CheckpointError::invalid("simulation", e.to_string()))?;
        *particles = restored;
        Ok(())
    }

    fn provoke_overflow(&mut self, particles: &mut Particles<D>) -> Option<String> {
        // Grid sums of a few particles' 1e308 overflow in the particle-to-grid transfer.
        for v in &mut particles.v {
            *v = [1e308; D];
        }
        Some("the velocity of every particle set to 1e308".into())
    }
}

impl<const D: usize> View for FlipSimulation<D> {
    fn method(&self) -> String {
        format!("{D}D {} on a MAC grid, MGPCG pressure, CFL substeps", self.params().transfer.name())
    }

    /// Particles drawn as discs of a quarter cell, the tank's inner walls at rest, and as
    /// bounds the region the (moving) tank sweeps.
    fn context(&self, _: &Particles<D>) -> Context {
        let (lo, hi) = self.fluid_box();
        let tank = box_z_up(&lo, &hi);
        let (mut reach_lo, mut reach_hi) = (lo, hi);
        if let Some(m) = self.params().tank_motion {
            // The oscillation's reach (the presets' tanks do not accelerate steadily).
            reach_lo[m.axis] -= m.amplitude;
            reach_hi[m.axis] += m.amplitude;
        }
        let mut context = Context::default();
        context.point_dim = 3;
        context.point_radius = 0.25 * self.grid().h();
        context.props.push(Prop::Tank { lo: tank.0, hi: tank.1 });
        context.bounds = Some(box_z_up(&reach_lo, &reach_hi));
        context
    }

    fn frame(&self, particles: &Particles<D>, out: &mut Frame) {
        let t = FlipSimulation::time(self);
        let (axis, dx, dv) =
            self.params().tank_motion.map_or((0, 0.0, 0.0), |m| (m.axis, m.displacement(t), m.velocity(t)));
        out.time = t;
        out.points.clear();
        for p in &particles.x {
            let mut x = *p;
            x[axis] += dx;
            out.points.extend(z_up(&x));
        }
        let velocity = out.field_mut("velocity", 3);
        for u in &particles.v {
            let mut v = *u;
            v[axis] += dv;
            velocity.extend(z_up(&v));
        }
    }
}

#[cfg(test)]
mod tests;
