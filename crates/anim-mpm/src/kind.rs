//! The `mpm` scene kind: anim-mpm's presets and scene-file parameters, and [`MpmRun`], the
//! [`Checkpoint`] and [`View`] of a scene's simulation, so that the command line, `cargo xtask`
//! and the Python bindings run its scenes through [`anim_core::scene`] without knowing the crate.
//!
//! | preset | scene | run |
//! | --- | --- | --- |
//! | `mpm` | `three-materials`: jelly, snow and water blocks falling together, 2D, 128^2 cells | 120 frames of 40 x 0.5 ms |
//! | `dam-break-2d-mpm` | `dam-break-2d`: Martin & Moyce's dam break, 64^2 cells, with the surge front against the experiment | 35 frames of 64 x 0.156 ms |
//! | `dam-break` | `dam-break-3d`: a water column collapsing in a tank, 48^3 cells | 100 frames of 16 x 1 ms |
//! | `snowball` | `snowball`: a snowball hitting a wall: it flattens, rebounds and falls to the floor, 64^3 cells | 100 frames of 16 x 0.5 ms |
//!
//! **Bodies.** Instead of a `preset`, a scene file may bring its own matter: `[[scene.bodies]]`
//! tables ([`BodySpec`]), each a box, a sphere or a closed OBJ surface filled with particles,
//! with its material (elastic, snow, fluid or sand), placement and initial velocity, and the
//! scene-wide `resolution`, `dim`, `particles_per_cell`, `transfer`, `kernel`, `gravity`,
//! `obstacles` (planes, boxes, spheres), `obstacle_meshes` (closed OBJ surfaces, 3D; level-set
//! colliders, [`crate::mesh_collider`]), `boundary` (on the obstacles) and `wall` (on the
//! domain's walls) ([`MpmSceneParams`], [`crate::bodies`]). Such a scene is framed by the
//! domain's walls; mesh obstacles are drawn as their surfaces.
//!
//! ```
//! use anim_core::scene::BuildContext;
//!
//! let params = serde_json::json!({
//!     "resolution": 16,
//!     "obstacles": [{ "sphere": { "center": [0.5, 0.3, 0.5], "radius": 0.1 } }],
//!     "boundary": { "separate": { "friction": 0.3 } },
//!     "bodies": [
//!         { "shape": { "box": { "center": [0.5, 0.6, 0.5], "half_extents": [0.1, 0.1, 0.1] } },
//!           "material": { "snow": {} } },
//!         { "shape": { "sphere": { "center": [0.3, 0.7, 0.5], "radius": 0.08 } },
//!           "material": { "elastic": { "young": 2e4 } }, "velocity": [1.0, 0.0, 0.0] },
//!     ],
//! });
//! let mut scene = (anim_mpm::KIND.build)(&params, &BuildContext::default())?;
//! scene.step(1e-3)?;
//! assert_eq!(scene.method(), "3D MLS-MPM, quadratic B-splines, CFL substeps");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! **Frames.** One point per particle in the current (block-sorted) order of the particles,
//! with its velocity, widened from `f32` to `f64`; 2D scenes lie in the `z = 0` plane
//! ([`Context::planar`]). The scenes keep their own frame, the unit box with **y up** (gravity
//! along `-y` by default), which is the frame of every view's frames: nothing is turned. The
//! [`Context`] draws particles as discs of half a cell, the domain's walls (their inner faces,
//! [`MpmParams::wall_nodes`] cells in) as a [`Prop::Tank`], box colliders as
//! [`Prop::Cuboid`]s and sphere colliders as [`Prop::Sphere`]s.
//!
//! **Reference.** The `dam-break-2d` scene carries a [`SurgeFront`]: its
//! [`View::reference_error`] is the rms relative error of the surge front against Martin &
//! Moyce at the table's times passed so far (`None` before the first, `T = 0.41`).
//!
//! ```
//! use anim_core::scene::{BuildContext, Frame};
//!
//! let mpm = (anim_mpm::KIND.presets)().into_iter().find(|p| p.name == "mpm").expect("preset");
//! let quick = mpm.quick_params.as_ref().expect("a quick version");
//! let mut scene = (anim_mpm::KIND.build)(quick, &BuildContext::default())?;
//! scene.step(mpm.run.dt)?;
//! let mut frame = Frame::default();
//! scene.frame(&mut frame);
//! assert_eq!(scene.method(), "2D MLS-MPM, quadratic B-splines, CFL substeps");
//! assert!(frame.points.chunks_exact(3).all(|p| p[2] == 0.0));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::bodies::{self, BodySpec};
use crate::mesh_collider::ObstacleMesh;
use crate::scenes::{self, MpmScene, SurgeFront};
use crate::{Boundary, Kernel, MpmError, MpmParams, MpmSimulation, OutOfDomain, Particles, Shape, Transfer};
use anim_core::scene::study::{self, Candidate, Family, Point, StudyAdapter, Tolerance};
use anim_core::scene::{
    BuildContext, BuildError, Checkpoint, CheckpointError, Context, DynScene, Frame, MeshProp, Preset, Prop,
    RunDefaults, SceneKind, Simulated, Up, View, params, saved_field,
};
use anim_core::solver::{Solver, StepClock, StepReport};
use serde::{Deserialize, Serialize};

/// The `mpm` scene kind of anim-mpm, for the workspace registry.
pub const KIND: SceneKind = SceneKind {
    kind: "mpm",
    crate_name: "anim-mpm",
    summary: "the material point method (APIC, MLS-MPM) in 2D and 3D: elastic, snow and fluid matter",
    presets,
    build,
    tolerance: Some(Tolerance { adapter: tolerance_adapter, error: study::reference_error }),
};

/// Scene-file parameters of an `mpm` scene (the `[scene]` table without `kind`): a `preset`, or
/// `bodies` of the user's own with the scene-wide fields around them (see [`crate::bodies`]).
/// `resolution`, `transfer`, `kernel` and `particles_per_cell` apply to both; `dim`,
/// `gravity`, `obstacles`, `obstacle_meshes`, `boundary` and `wall` only to bodies.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MpmSceneParams {
    /// The scene: `"three-materials"` or `"dam-break-2d"` in 2D, `"dam-break-3d"`,
    /// `"snowball"`, or the peer benchmarks `"benchmark-2d"` and `"benchmark-3d"` (see
    /// [`scenes`]). Absent when the scene has `bodies`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preset: Option<String>,
    /// Grid cells per axis, at least 8 (and at most what the grid's `u32` block keys address:
    /// [`crate::max_resolution`]); absent: the preset's default, 64 for bodies. No more than the
    /// memory holds: the scene's estimate ([`crate::memory`]) is checked against the memory
    /// available before the grid or a particle is made.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub resolution: Option<usize>,
    /// Particle-grid transfer, `"mls-mpm"` or `"apic"`; absent: the scene's (MLS-MPM).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transfer: Option<Transfer>,
    /// Interpolation kernel, `"quadratic"` or `"cubic"` B-splines; absent: the scene's
    /// (quadratic).
    #[serde(default, skip_serializing_if = "Option::is_none", with = "kernel_name")]
    pub kernel: Option<Kernel>,
    /// Particles per cell and axis, 1 to 8 (of the presets, `dam-break-2d` only; absent: 2).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub particles_per_cell: Option<usize>,
    /// Bodies: dimension of the scene, 2 (shapes in the x-y plane) or 3; absent: 3.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dim: Option<usize>,
    /// Bodies: gravity (m/s^2; the first `dim` components are used); absent: `(0, -9.81, 0)`,
    /// the crate's y up.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gravity: Option<[f64; 3]>,
    /// Bodies: fixed obstacles, anim-core's [`Shape`] spelling: `plane`, `box` and `sphere`
    /// (a disk in 2D); a capsule is refused. Absent: none (the domain's walls remain).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub obstacles: Vec<Shape>,
    /// Bodies (3D): fixed obstacles from closed OBJ surfaces ([`ObstacleMesh`]: `{ mesh =
    /// "x.obj", scale, rotate, translate }`, the file relative to the scene file), level-set
    /// colliders sampled on the grid ([`crate::mesh_collider`]), with the `boundary` condition.
    /// Absent: none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub obstacle_meshes: Vec<ObstacleMesh>,
    /// Bodies: the boundary condition on the obstacles ([`Boundary`]): `"sticky"`, `"slip"`,
    /// `{ separate = { friction = 0.3 } }` or `"separate-frictionless"`; absent:
    /// separate-frictionless.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub boundary: Option<Boundary>,
    /// Bodies: the boundary condition on the domain's walls, as `boundary`; absent:
    /// separate-frictionless.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wall: Option<Boundary>,
    /// The bodies (`[[scene.bodies]]` tables), each a [`BodySpec`]; the alternative to `preset`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub bodies: Vec<BodySpec>,
}

/// The scene-file names of the [`Kernel`]s, `"quadratic"` and `"cubic"`, for an optional field.
mod kernel_name {
    use crate::Kernel;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    #[derive(Serialize, Deserialize)]
    #[serde(rename_all = "lowercase")]
    enum Name {
        Quadratic,
        Cubic,
    }

    #[allow(clippy::ref_option)]
    pub fn serialize<S: Serializer>(kernel: &Option<Kernel>, s: S) -> Result<S::Ok, S::Error> {
        kernel
            .map(|k| match k {
                Kernel::Quadratic => Name::Quadratic,
                Kernel::Cubic => Name::Cubic,
            })
            .serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Kernel>, D::Error> {
        Ok(Option::<Name>::deserialize(d)?.map(|n| match n {
            Name::Quadratic => Kernel::Quadratic,
            Name::Cubic => Kernel::Cubic,
        }))
    }
}

fn presets() -> Vec<Preset> {
    let preset = |name, description, run, params: serde_json::Value, quick: usize| {
        let mut quick_params = params.clone();
        quick_params["resolution"] = serde_json::json!(quick);
        Preset { name, description, run, params, quick_params: Some(quick_params) }
    };
    // Quick versions: the coarsest grids whose walls leave room for the scenes' matter (the
    // three blocks reach 0.1 m from the sides, inside the walls below 18 cells; the 0.6 m column
    // of the 3D dam break needs 12 cells or more; 16 gives the snowball 137 particles).
    vec![
        preset(
            "mpm",
            "MLS-MPM in 2D: a jelly block, a snow block and water falling together",
            RunDefaults::new(0.0005, 120, 40),
            serde_json::json!({ "preset": "three-materials" }),
            32,
        ),
        preset(
            "dam-break-2d-mpm",
            "MLS-MPM in 2D: Martin & Moyce's dam break (0.2 x 0.4 m column), surge front vs the experiment",
            RunDefaults::new(0.00015625, 35, 64),
            serde_json::json!({ "preset": "dam-break-2d", "resolution": 64 }),
            16,
        ),
        preset(
            "dam-break",
            "MLS-MPM in 3D: a water column collapsing in a tank",
            RunDefaults::new(0.001, 100, 16),
            serde_json::json!({ "preset": "dam-break-3d" }),
            16,
        ),
        preset(
            "snowball",
            "MLS-MPM in 3D: a snowball flattening against a wall, rebounding and falling to the floor",
            RunDefaults::new(0.0005, 100, 16),
            serde_json::json!({ "preset": "snowball" }),
            16,
        ),
    ]
}

fn build(value: &serde_json::Value, context: &BuildContext<'_>) -> Result<Box<dyn DynScene>, BuildError> {
    let p: MpmSceneParams = params(value)?;
    if !p.bodies.is_empty() {
        if p.preset.is_some() {
            return Err(BuildError::invalid("preset", "give a `preset` or `[[scene.bodies]]`, not both"));
        }
        return Ok(match bodies::build(&p, context)? {
            MpmScene::Two(s) => {
                Simulated::new(MpmRun::new(s.sim, &s.state, None).framed_by_walls(), s.state).boxed()
            }
            MpmScene::Three(s) => {
                Simulated::new(MpmRun::new(s.sim, &s.state, None).framed_by_walls(), s.state).boxed()
            }
        });
    }
    let Some(preset) = p.preset.as_deref() else {
        return Err(BuildError::invalid(
            "preset",
            format!("give a `preset` (one of {}) or `[[scene.bodies]]` tables", scenes::NAMES.join(", ")),
        ));
    };
    let bodies_only = [
        ("dim", p.dim.is_some()),
        ("gravity", p.gravity.is_some()),
        ("obstacles", !p.obstacles.is_empty()),
        ("obstacle_meshes", !p.obstacle_meshes.is_empty()),
        ("boundary", p.boundary.is_some()),
        ("wall", p.wall.is_some()),
    ];
    if let Some((field, _)) = bodies_only.iter().find(|(_, given)| *given) {
        return Err(BuildError::invalid(
            *field,
            format!("applies to `[[scene.bodies]]`; the preset {preset} sets its own"),
        ));
    }
    if let Some(k) = p.particles_per_cell {
        if !(1..=8).contains(&k) {
            return Err(BuildError::invalid(
                "particles_per_cell",
                format!("must lie in [1, 8] (per axis), got {k}"),
            ));
        }
        if preset != "dam-break-2d" && scenes::NAMES.contains(&preset) {
            return Err(BuildError::invalid(
                "particles_per_cell",
                format!("{preset} places its own particles; only dam-break-2d takes particles_per_cell"),
            ));
        }
    }
    crate::memory::check_preset(preset, p.resolution, p.particles_per_cell)?;
    let found = scenes::by_name_with(preset, p.resolution, p.particles_per_cell).ok_or_else(|| {
        BuildError::invalid(
            "preset",
            format!("unknown preset `{preset}` (one of {})", scenes::NAMES.join(", ")),
        )
    })?;
    let mut scene = found.map_err(|e| BuildError::invalid("resolution", e.to_string()))?;
    if p.transfer.is_some() || p.kernel.is_some() {
        let params = match &scene {
            MpmScene::Two(s) => s.sim.params(),
            MpmScene::Three(s) => s.sim.params(),
        };
        let transfer = p.transfer.unwrap_or(params.transfer);
        let kernel = p.kernel.unwrap_or(params.kernel);
        let field = if p.transfer.is_some() { "transfer" } else { "kernel" };
        scene.set_method(transfer, kernel).map_err(|e| BuildError::invalid(field, e.to_string()))?;
    }
    Ok(match scene {
        MpmScene::Two(s) => {
            let front = (s.name == "dam-break-2d").then(|| SurgeFront::new(s.sim.params(), &s.state));
            Simulated::new(MpmRun::new(s.sim, &s.state, front), s.state).boxed()
        }
        MpmScene::Three(s) => Simulated::new(MpmRun::new(s.sim, &s.state, None), s.state).boxed(),
    })
}

/// A scene's simulation as the run loop steps, checkpoints and draws it: the
/// [`MpmSimulation`] (which keeps the step count and the simulated time), and for the
/// `dam-break-2d` scene the [`SurgeFront`] observed after every step.
#[derive(Debug, Clone)]
pub struct MpmRun<const D: usize> {
    sim: MpmSimulation<D>,
    /// The dam break's surge front at Martin & Moyce's times (`dam-break-2d` only).
    front: Option<SurgeFront>,
    /// Particles of the scene when built, for checking checkpoints.
    particles: usize,
    /// Whether the view frames the domain between its walls (scenes of bodies) instead of the
    /// initial particles.
    walls_framed: bool,
}

impl<const D: usize> MpmRun<D> {
    /// `sim` stepping `particles` (the scene's initial ones), with the dam break's `front`
    /// tracker where the scene has one.
    #[must_use]
    pub fn new(sim: MpmSimulation<D>, particles: &Particles<D>, front: Option<SurgeFront>) -> Self {
        Self { sim, front, particles: particles.len(), walls_framed: false }
    }

    /// The same run viewed as a scene of bodies: framing the domain between its walls, where
    /// all its matter stays, with the bottom wall drawn as the ground in 3D when gravity points
    /// down along -y (see [`View::context`]).
    #[must_use]
    pub fn framed_by_walls(mut self) -> Self {
        self.walls_framed = true;
        self
    }

    /// The simulation.
    #[must_use]
    pub fn simulation(&self) -> &MpmSimulation<D> {
        &self.sim
    }

    /// The surge-front tracker, for the dam break.
    #[must_use]
    pub fn surge_front(&self) -> Option<&SurgeFront> {
        self.front.as_ref()
    }

    /// The checks of a restored particle state beyond its array lengths: the scene's particle
    /// count (or fewer, where particles leaving the domain are removed), known materials,
    /// finite values.
    fn check(&self, p: &Particles<D>) -> Result<(), String> {
        p.check_lengths().map_err(|e| e.to_string())?;
        let removing = self.sim.params().out_of_domain == OutOfDomain::Remove;
        if p.len() > self.particles || (!removing && p.len() != self.particles) {
            return Err(format!("{} particles; this scene has {}", p.len(), self.particles));
        }
        let materials = self.sim.materials().len();
        if let Some(m) = p.material.iter().find(|&&m| usize::from(m) >= materials) {
            return Err(format!("material {m}; this scene has {materials}"));
        }
        if let Some(id) = p.id.iter().find(|&&id| id as usize >= self.particles) {
            return Err(format!("particle id {id}; this scene has {} particles", self.particles));
        }
        let values = p.x.iter().chain(&p.v).chain(&p.c).chain(&p.f).chain(&p.plastic);
        if let Some(bad) = values.chain(&p.mass).chain(&p.volume).find(|v| !v.is_finite()) {
            return Err(format!("holds the non-finite value {bad}"));
        }
        Ok(())
    }
}

impl<const D: usize> Solver for MpmRun<D> {
    type State = Particles<D>;
    type Error = MpmError;

    /// The simulation's step, then the surge front's observation.
    fn step(&mut self, state: &mut Particles<D>, dt: f64) -> Result<StepReport, MpmError> {
        let report = self.sim.step(state, dt)?;
        if let Some(front) = &mut self.front {
            front.observe(self.sim.time(), self.sim.params(), state);
        }
        Ok(report)
    }
}

impl<const D: usize> Checkpoint for MpmRun<D> {
    const VERSION: u32 = 1;

    fn time(&self, _: &Particles<D>) -> f64 {
        self.sim.time()
    }

    /// `{"dim", "particles", "simulation"}` and, in 2D, `"surge_front"` (`null` for the
    /// scenes without one).
    fn save(&self, state: &Particles<D>) -> serde_json::Value {
        if D == 2 {
            serde_json::json!({
                "dim": D,
                "particles": state,
                "simulation": self.sim.memory(),
                "surge_front": self.front,
            })
        } else {
            serde_json::json!({ "dim": D, "particles": state, "simulation": self.sim.memory() })
        }
    }

    fn restore(
        &mut self,
        state: &mut Particles<D>,
        saved: &serde_json::Value,
    ) -> Result<(), CheckpointError> {
        let dim: usize = saved_field(saved, "dim")?;
        if dim != D {
            return Err(CheckpointError::invalid("dim", format!("a {dim}D checkpoint for a {D}D scene")));
        }
        let memory =
            saved.get("simulation").ok_or_else(|| CheckpointError::Missing { field: "simulation".into() })?;
        StepClock::from_memory(memory).map_err(|e| CheckpointError::invalid("simulation", e))?;
        let particles: Particles<D> = saved_field(saved, "particles")?;
        self.check(&particles).map_err(|e| CheckpointError::invalid("particles", e))?;
        let front = match self.front {
            Some(_) => Some(
                saved_field::<SurgeFront>(saved, "surge_front")?
                    .checked()
                    .map_err(|e| CheckpointError::invalid("surge_front", e))?,
            ),
            None => None,
        };
        // Everything is checked: commit.
        self.sim.restore_memory(memory).map_err(|e| CheckpointError::invalid("simulation", e.to_string()))?;
        *state = particles;
        self.front = front;
        Ok(())
    }

    /// Sets the deformation gradient of the first particle to `1e30` in every entry: its stress
    /// overflows in the next transfer, which the step reports as [`MpmError::NonFinite`].
    fn provoke_overflow(&mut self, state: &mut Particles<D>) -> Option<String> {
        let id = *state.id.first()?;
        state.f[..D * D].fill(1e30);
        Some(format!("deformation gradient of particle {id} set to 1e30 in every entry"))
    }
}

/// The first three coordinates of a `D`-vector, widened to `f64` (0 beyond `D`).
fn widen<const D: usize>(p: &[f32]) -> [f64; 3] {
    std::array::from_fn(|k| p.get(k).map_or(0.0, |c| f64::from(*c)))
}

impl<const D: usize> View for MpmRun<D> {
    /// `"{D}D {transfer}, {kernel} B-splines, CFL substeps"`.
    fn method(&self) -> String {
        let params = self.sim.params();
        let transfer = match params.transfer {
            Transfer::Apic => "APIC",
            Transfer::Mls => "MLS-MPM",
        };
        let kernel = match params.kernel {
            Kernel::Quadratic => "quadratic",
            Kernel::Cubic => "cubic",
        };
        format!("{D}D {transfer}, {kernel} B-splines, CFL substeps")
    }

    /// Particles as discs of half a cell; the tank of the domain's walls, the colliders; the
    /// region of the particles of `state`, widened sideways by a third of its size and extended
    /// down along -y by its size. A scene of bodies ([`MpmRun::framed_by_walls`]) frames the
    /// tank instead; in 3D with gravity mostly along -y only up to the highest apex a particle
    /// thrown up reaches (plus a cell), with the bottom wall drawn as the ground. The solver
    /// works y up, the frame of views: nothing is turned. A 2D scene lies in the plane z = 0.
    fn context(&self, state: &Particles<D>) -> Context {
        let params = self.sim.params();
        let cell = params.size / params.resolution as f64;
        let mut display = Frame::default();
        self.frame(state, &mut display);
        // `Context` is non-exhaustive: filled field by field.
        let mut context = Context::default();
        context.point_dim = 3;
        context.planar = D == 2;
        context.point_radius = 0.5 * cell;
        let tank = tank(params, D);
        let g = params.gravity;
        let falls_along_y = D == 3 && -g[1] > g[0].abs().max(g[2].abs());
        context.bounds = Some(match tank {
            Prop::Tank { lo, mut hi } if self.walls_framed => {
                if falls_along_y {
                    // Nothing rises above the highest apex of a particle thrown up.
                    let apex = display
                        .points
                        .chunks_exact(3)
                        .zip(state.v.chunks_exact(D))
                        .map(|(x, v)| x[1] + f64::from(v[1].max(0.0)).powi(2) / (-2.0 * g[1]))
                        .fold(lo[1], f64::max);
                    hi[1] = hi[1].min(apex + cell);
                }
                (lo, hi)
            }
            _ => anim_core::scene::frame_box(&display.points, Up::Y, None, true),
        });
        if self.walls_framed && falls_along_y {
            context.props.push(Prop::Ground { height: params.wall_nodes as f64 * params.h() });
        }
        context.props.push(tank);
        context.props.extend(params.colliders.iter().filter_map(|c| collider(c.shape, D)));
        context.mesh_props.extend(self.sim.mesh_colliders().iter().map(|m| MeshProp::from(m.surface())));
        context
    }

    fn frame(&self, state: &Particles<D>, out: &mut Frame) {
        out.time = self.sim.time();
        out.points.clear();
        for p in state.x.chunks_exact(D) {
            out.points.extend_from_slice(&widen::<D>(p));
        }
        let v = out.field_mut("velocity", 3);
        for u in state.v.chunks_exact(D) {
            v.extend_from_slice(&widen::<D>(u));
        }
        // The material's index in the scene (the order of its bodies or the preset's materials).
        out.field_mut("material", 1).extend(state.material.iter().map(|&m| f64::from(m)));
        let strain = out.field_mut("strain", 1);
        strain.extend((0..state.len()).map(|p| state.strain(p)));
    }

    fn reference_error(&self, _: &Particles<D>) -> Option<f64> {
        self.front.as_ref().and_then(SurgeFront::errors).map(|(_, rms)| rms)
    }
}

/// The domain's walls: the inner faces, [`MpmParams::wall_nodes`] cells in from the sides of
/// `[0, size]^dim` (flat along z in 2D).
fn tank(params: &MpmParams, dim: usize) -> Prop {
    let inset = params.wall_nodes as f64 * params.h();
    let (lo, hi) = (inset, params.size - inset);
    let extent = |k: usize, v: f64| if k < dim { v } else { 0.0 };
    Prop::Tank { lo: std::array::from_fn(|k| extent(k, lo)), hi: std::array::from_fn(|k| extent(k, hi)) }
}

/// A collider's shape at time 0 as a prop (z = 0 in 2D); `None` for planes (and capsules, which
/// a simulation refuses).
fn collider(shape: Shape, dim: usize) -> Option<Prop> {
    let at = |v: [f64; 3], sign: f64, half: [f64; 3]| -> [f64; 3] {
        std::array::from_fn(|k| if k < dim { v[k] + sign * half[k] } else { 0.0 })
    };
    match shape {
        Shape::Box { center, half_extents: half } => {
            Some(Prop::Cuboid { lo: at(center, -1.0, half), hi: at(center, 1.0, half) })
        }
        Shape::Sphere { center, radius } => Some(Prop::Sphere { center: at(center, 0.0, [0.0; 3]), radius }),
        Shape::Plane { .. } | Shape::Capsule { .. } => None,
    }
}

/// The scene-file name of a transfer (`"apic"`, `"mls-mpm"`).
fn transfer_name(transfer: Transfer) -> &'static str {
    match transfer {
        Transfer::Apic => "apic",
        Transfer::Mls => "mls-mpm",
    }
}

/// The scene-file name of a kernel (`"quadratic"`, `"cubic"`).
fn kernel_name_of(kernel: Kernel) -> &'static str {
    match kernel {
        Kernel::Quadratic => "quadratic",
        Kernel::Cubic => "cubic",
    }
}

/// A label of the MPM dam-break study: `"<MLS-MPM|APIC> <quadratic|cubic>, <k>x<k> ppc"`.
#[must_use]
pub fn mpm_label(label: &str) -> Option<(Transfer, Kernel, usize)> {
    let (method, ppc) = label.split_once(", ")?;
    let (transfer, kernel) = method.split_once(' ')?;
    let transfer = match transfer {
        "MLS-MPM" => Transfer::Mls,
        "APIC" => Transfer::Apic,
        _ => return None,
    };
    let kernel = [Kernel::Quadratic, Kernel::Cubic].into_iter().find(|k| kernel_name_of(*k) == kernel)?;
    let (a, b) = ppc.strip_suffix(" ppc")?.split_once('x')?;
    let k: usize = a.parse().ok()?;
    (b.parse::<usize>().ok()? == k).then_some((transfer, kernel, k))
}

/// The `mpm_dam_break` study on the `dam-break-2d` scene: resolution, transfer, kernel and
/// particles per cell, at the study's step `dt = h / 100`.
struct DamBreakAdapter;

impl StudyAdapter for DamBreakAdapter {
    fn candidate(&self, method: &str, point: &Point) -> Result<Candidate, String> {
        let (transfer, kernel, ppc) = mpm_label(method).ok_or_else(|| study::unknown_method(method))?;
        let n = point.param.round();
        if !(8.0..=4096.0).contains(&n) {
            return Err(format!("resolution {n} out of range"));
        }
        let n = n as usize;
        let (t, k) = (transfer_name(transfer), kernel_name_of(kernel));
        let mut settings = serde_json::Map::new();
        settings.insert("resolution".into(), serde_json::json!(n));
        settings.insert("transfer".into(), serde_json::json!(t));
        settings.insert("kernel".into(), serde_json::json!(k));
        settings.insert("particles_per_cell".into(), serde_json::json!(ppc));
        Ok(Candidate {
            settings,
            summary: format!("resolution = {n}, transfer = {t}, kernel = {k}, particles_per_cell = {ppc}"),
            dt: Some(scenes::dam_break_2d_dt(n)),
            cost: 1.0,
            dt_swept: false,
            note: String::new(),
        })
    }
}

/// The adapter of an `mpm` scene to its study (the registry maps `mpm/dam-break-2d`).
fn tolerance_adapter(
    value: &serde_json::Value,
    _: &RunDefaults,
    family: &Family,
) -> Result<Box<dyn StudyAdapter>, String> {
    let p: MpmSceneParams = params(value).map_err(study::unreadable)?;
    if p.preset.as_deref() == Some("dam-break-2d") {
        Ok(Box::new(DamBreakAdapter))
    } else {
        Err(study::unmapped(family))
    }
}
