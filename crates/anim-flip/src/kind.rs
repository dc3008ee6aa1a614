//! The `flip` scene kind: the presets of [`scenes::by_name`], or fluid bodies of the scene
//! file's own ([`crate::body`]), registered with anim-core's scene contracts
//! ([`anim_core::scene`]), so the `anim` command line, `cargo xtask` and the Python bindings
//! build, step, checkpoint and draw them without knowing this crate.
//!
//! | preset | what | cells across the 1 m tank |
//! | --- | --- | --- |
//! | `dam-break-2d` | a 0.25 x 0.5 m water column collapsing in a tank | 64 |
//! | `dam-break-3d` | a water column collapsing in the corner of a tank | 32 |
//! | `drop-2d`, `drop-3d` | a disk (ball) of water falling into a pool | 64, 32 |
//! | `sloshing-tank` | water in a 2D tank shaken at its first sloshing frequency | 64 |
//!
//! Instead of `preset`, a scene file may give `[[scene.bodies]]`: boxes, spheres, capsules or
//! closed OBJ surfaces (`mesh`) filled with fluid, placed (`scale`, `rotate`, `translate`) and
//! moving (`velocity`), in a tank whose inside is `[0, 1]` m along each axis, with `dim`,
//! `resolution`, `transfer`, `gravity`, and solid `obstacles` (shapes) and `obstacle_meshes`
//! (closed OBJ surfaces). Scene-file coordinates are the crate's own, **y up**. See
//! [`FlipSceneParams`] and [`crate::body`]; such a scene is a [`body::BodyScene`].
//!
//! A preset scene is the [`FlipSimulation`] itself, a [`Solver`](anim_core::solver::Solver) of
//! its [`Particles`]. anim-flip works y up, the frame of every view's frames: a fluid point
//! `(x, y, z)` is written as it is, a 2D one `(x, y)` at `(x, y, 0)` (2D scenes lie in the
//! plane z = 0, [`Context::planar`]). The sloshing tank is simulated in its own frame; its
//! frames are in the world frame, the tank's displacement added to the positions and its
//! velocity to the velocities. The context has the tank's inner walls at rest as a
//! [`Prop::Tank`] and, as its bounds, the region the moving tank sweeps.
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
//! // Every particle in the plane z = 0, above the tank's floor (y up).
//! assert!(frame.points.chunks_exact(3).all(|p| p[2] == 0.0 && p[1] > 0.0));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::body::{self, FluidBody, ObstacleMesh};
use crate::particles::Particles;
use crate::scenes::{self, FlipScene};
use crate::sim::FlipSimulation;
use crate::transfer::Transfer;
use anim_core::geometry::Shape;
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
    summary: "an incompressible particle fluid (PIC, FLIP, APIC on a MAC grid) in 2D and 3D: dam breaks, drops, a sloshing tank, or bodies of fluid from shapes and closed surfaces",
    presets,
    build,
    tolerance: None,
};

/// Scene-file parameters of a `flip` scene: a preset of [`scenes::NAMES`] and what a file may
/// change in it, or fluid bodies of the file's own in a 1 m tank with obstacles ([`crate::body`]).
/// Give `preset` or `bodies`; `dim`, `gravity`, `obstacles` and `obstacle_meshes` belong to
/// bodies only. Coordinates are y up.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FlipSceneParams {
    /// The preset's name: `"dam-break-2d"`, `"dam-break-3d"`, `"drop-2d"`, `"drop-3d"` or
    /// `"sloshing-tank"`. Give this or `bodies`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preset: Option<String>,
    /// Cells across the 1 m tank: at least 4 (what the solid border and the kernel need), and
    /// no more than the memory holds: the scene's estimate ([`crate::memory`]) is checked
    /// against the memory available before the grid or a particle is made. Default: the preset's (64 in 2D, 32 in 3D); for
    /// bodies the same, across the tank's inside (the walls are outside it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub resolution: Option<usize>,
    /// Grid-to-particle transfer: `"apic"`, `"pic"`, or `{ flip = 0.97 }` (FLIP blended with
    /// PIC, the blend in `[0, 1]`). Default APIC.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transfer: Option<Transfer>,
    /// Fluid bodies ([`FluidBody`]: a shape or a closed OBJ mesh, placed, with a velocity), in
    /// the tank's inside `[0, 1]` m along each axis. Give this or `preset`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub bodies: Vec<FluidBody>,
    /// 2 or 3 (a scene of bodies; a 2D one is the plane z = 0). Default 3.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dim: Option<usize>,
    /// Gravity (m/s^2; a scene of bodies), y up. Default `[0, -9.81, 0]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gravity: Option<[f64; 3]>,
    /// Obstacles (a scene of bodies), in the [`Shape`] spelling (plane, sphere, box,
    /// capsule): the cells whose centres are inside one are solid. Default none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub obstacles: Vec<Shape>,
    /// Obstacles from closed OBJ surfaces ([`ObstacleMesh`]; a scene of bodies): the cells whose
    /// centres are inside one are solid. Default none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub obstacle_meshes: Vec<ObstacleMesh>,
}

impl FlipSceneParams {
    /// The preset at `resolution` cells across (the preset's own when `None`).
    #[must_use]
    pub fn preset(name: &str, resolution: Option<usize>) -> Self {
        Self { preset: Some(name.into()), resolution, ..Self::default() }
    }

    /// Checks the parameters and builds the preset.
    ///
    /// # Errors
    /// [`BuildError::Memory`] of `resolution` for a scene past the memory available;
    /// [`BuildError::Invalid`] naming the field: no preset or bodies as well, a field of bodies
    /// only, an unknown preset, a FLIP blend outside `[0, 1]`, a resolution the simulation
    /// refuses.
    pub fn scene(&self) -> Result<FlipScene, BuildError> {
        let Some(preset) = self.preset.as_deref() else {
            return Err(self.neither());
        };
        if !self.bodies.is_empty() {
            return Err(BuildError::invalid("bodies", "give a built-in `preset` or `bodies`, not both"));
        }
        let only_bodies = [
            ("dim", self.dim.is_some()),
            ("gravity", self.gravity.is_some()),
            ("obstacles", !self.obstacles.is_empty()),
            ("obstacle_meshes", !self.obstacle_meshes.is_empty()),
        ];
        if let Some((field, _)) = only_bodies.iter().find(|(_, given)| *given) {
            return Err(BuildError::invalid(
                *field,
                format!("belongs to a scene of `bodies`; the preset `{preset}` sets its own"),
            ));
        }
        let unknown = || {
            BuildError::invalid(
                "preset",
                format!("unknown preset `{preset}` (one of {})", scenes::NAMES.join(", ")),
            )
        };
        if !scenes::NAMES.contains(&preset) {
            return Err(unknown());
        }
        self.check_transfer()?;
        crate::memory::check_preset(preset, self.resolution)?;
        scenes::by_name(preset, self.resolution, self.transfer)
            .ok_or_else(unknown)?
            .map_err(|e| BuildError::invalid("resolution", e.to_string()))
    }

    /// Builds the scene of [`bodies`](Self::bodies) ([`crate::body::build`]), in 2D or 3D as
    /// [`dim`](Self::dim) says; `context` resolves the mesh files.
    ///
    /// # Errors
    /// [`BuildError::Invalid`] naming the field: no bodies, a preset as well, a `dim` other
    /// than 2 or 3, a FLIP blend outside `[0, 1]`, and the refusals of [`crate::body`].
    pub fn bodies_scene(&self, context: &BuildContext<'_>) -> Result<Box<dyn DynScene>, BuildError> {
        if self.bodies.is_empty() {
            return Err(self.neither());
        }
        if self.preset.is_some() {
            return Err(BuildError::invalid("bodies", "give a built-in `preset` or `bodies`, not both"));
        }
        self.check_transfer()?;
        Ok(match self.dim.unwrap_or(3) {
            2 => {
                let (scene, particles) = body::build::<2>(self, context)?;
                Simulated::new(scene, particles).boxed()
            }
            3 => {
                let (scene, particles) = body::build::<3>(self, context)?;
                Simulated::new(scene, particles).boxed()
            }
            d => return Err(BuildError::invalid("dim", format!("must be 2 or 3, got {d}"))),
        })
    }

    fn check_transfer(&self) -> Result<(), BuildError> {
        if let Some(Transfer::Flip(blend)) = self.transfer
            && !(0.0..=1.0).contains(&blend)
        {
            return Err(BuildError::invalid(
                "transfer",
                format!("the FLIP blend must lie in [0, 1], got {blend}"),
            ));
        }
        Ok(())
    }

    /// The refusal of parameters with neither a preset nor bodies.
    fn neither(&self) -> BuildError {
        BuildError::invalid(
            "preset",
            format!(
                "give a built-in `preset` (one of {}) or `[[scene.bodies]]` of fluid",
                scenes::NAMES.join(", ")
            ),
        )
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

fn build(value: &serde_json::Value, context: &BuildContext<'_>) -> Result<Box<dyn DynScene>, BuildError> {
    let p: FlipSceneParams = params(value)?;
    if p.preset.is_none() {
        return p.bodies_scene(context);
    }
    Ok(match p.scene()? {
        FlipScene::Two(s) => Simulated::new(s.sim, s.particles).boxed(),
        FlipScene::Three(s) => Simulated::new(s.sim, s.particles).boxed(),
    })
}

/// A fluid point or vector in the frames' three coordinates: as it is in 3D (both y up),
/// `(x, y) -> (x, y, 0)` in 2D.
pub(crate) fn widened<const D: usize>(p: &[f64; D]) -> [f64; 3] {
    std::array::from_fn(|k| if k < D { p[k] } else { 0.0 })
}

/// The corners `lo` and `hi` of a box in the frames' three coordinates ([`widened`]).
pub(crate) fn widened_box<const D: usize>(lo: &[f64; D], hi: &[f64; D]) -> ([f64; 3], [f64; 3]) {
    (widened(lo), widened(hi))
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
        let tank = widened_box(&lo, &hi);
        let (mut reach_lo, mut reach_hi) = (lo, hi);
        if let Some(m) = self.params().tank_motion {
            // The oscillation's reach (the presets' tanks do not accelerate steadily).
            reach_lo[m.axis] -= m.amplitude;
            reach_hi[m.axis] += m.amplitude;
        }
        let mut context = Context::default();
        context.point_dim = 3;
        context.planar = D == 2;
        context.point_radius = 0.25 * self.grid().h();
        context.props.push(Prop::Tank { lo: tank.0, hi: tank.1 });
        context.bounds = Some(widened_box(&reach_lo, &reach_hi));
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
            out.points.extend(widened(&x));
        }
        let velocity = out.field_mut("velocity", 3);
        for u in &particles.v {
            let mut v = *u;
            v[axis] += dv;
            velocity.extend(widened(&v));
        }
    }
}

#[cfg(test)]
mod tests;
