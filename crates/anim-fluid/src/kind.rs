//! The `fluid` scene kind: the grid-fluid presets of [`scenes`] registered with anim-core's
//! scene contracts ([`anim_core::scene`]), so the `anim` command line, `cargo xtask` and the
//! Python bindings build, step, checkpoint and draw them without knowing this crate.
//!
//! | preset | what | solver |
//! | --- | --- | --- |
//! | `smoke-box-2d` | smoke rising from a source in a closed 128 x 128 box | Stam's stable fluids (`f32`, 20 Gauss-Seidel sweeps) |
//! | `smoke-plume-3d` | hot smoke rising around a sphere, open top | 3D MAC grid, MacCormack + MGPCG |
//! | `lid-driven-cavity` | the Re = 100 cavity stirring bands of dye | 2D MAC grid, MacCormack + MGPCG |
//!
//! Without `preset`, a scene file is a smoke scene of the user's own ([`crate::smoke`]): the MAC
//! solver on a box of the file's `size` and `resolution` (2D or 3D), smoke from its `sources`
//! around its `obstacles` (collider shapes) and `obstacle_meshes` (closed OBJ surfaces), with the plume's
//! settings as defaults ([`FluidSceneParams`] lists every field).
//!
//! A scene is the [`FluidScene`] itself stepped as a [`Solver`] whose state is the run's clock:
//! the sum of the steps' `dt` in `f64` (Stam's solver keeps its own time in sums of the
//! `f32` step). Its frames have no points: the fields `"density"` (1 per cell) and
//! `"velocity"` (3 per cell, at the cell centres), x fastest, on the [`ImageGrid`] of the
//! context, in the grid's own axes (y up, as the solvers and the image). The cavity's
//! [`View::reference_error`] is the largest distance from Ghia, Ghia and Shin's (1982)
//! centreline velocities.
//!
//! ```
//! use anim_core::scene::Frame;
//!
//! let preset = (anim_fluid::KIND.presets)().remove(2);
//! assert_eq!(preset.name, "lid-driven-cavity");
//! let params = preset.quick_params.expect("a coarse version");
//! let mut scene = (anim_fluid::KIND.build)(&params, &Default::default())?;
//! scene.step(preset.run.dt)?;
//! let mut frame = Frame::default();
//! scene.frame(&mut frame);
//! let cells = 16 * 16;
//! assert_eq!(frame.field("density").map(|f| f.values.len()), Some(cells));
//! assert_eq!(frame.field("velocity").map(|f| f.values.len()), Some(3 * cells));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::advection::{Advection, Splitting};
use crate::error::FluidError;
use crate::mac::{MacFluid, MacState};
use crate::pressure::PressureMethod;
use crate::scenes::{self, FluidScene, FluidSim};
use crate::smoke::{self, ObstacleMesh, SourceSpec};
use anim_core::geometry::Shape;
use anim_core::scene::study::{self, Candidate, Family, Point, StudyAdapter, Tolerance};
use anim_core::scene::{
    BuildContext, BuildError, Checkpoint, CheckpointError, Context, DynScene, Frame, ImageGrid, Preset, Prop,
    RunDefaults, SceneKind, Simulated, View, params, saved_field,
};
use anim_core::solver::{Solver, StepReport};
use serde::{Deserialize, Serialize};
use serde_json::json;

/// The `fluid` scene kind of anim-fluid, for the workspace registry.
pub const KIND: SceneKind = SceneKind {
    kind: "fluid",
    crate_name: "anim-fluid",
    summary: "grid fluids: Stam's stable fluids and the MAC solver in 2D and 3D, density and velocity per cell",
    presets,
    build,
    tolerance: Some(Tolerance { adapter: tolerance_adapter, error: tolerance_error }),
};

/// The iteration cap of a pressure solve whose solver or tolerance a scene file sets (the
/// report's pressure study's cap); the presets' own settings keep their cap.
pub const PRESSURE_MAX_ITERATIONS: usize = 200_000;

/// Scene-file parameters of a `fluid` scene: a preset of [`scenes::NAMES`] and what a file may
/// change in it, or, without `preset`, a smoke scene of the user's own ([`crate::smoke`]): the
/// MAC solver on a box of `size` with buoyant smoke from `sources` around `obstacles`, its
/// settings defaulting to the `smoke-plume-3d` preset's. Unset fields keep the preset's value.
///
/// The fields from `dim` on belong to a smoke scene of the user's own; a preset refuses them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FluidSceneParams {
    /// The preset's name: `"smoke-box-2d"`, `"smoke-plume-3d"` or `"lid-driven-cavity"`.
    /// Default: none, a smoke scene of the user's own (which then needs `sources`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preset: Option<String>,
    /// Cells across the domain, at least 2. Default: the preset's (128, 32, 64). For a smoke
    /// scene of the user's own, the cells along x (the other sides take cells of the same
    /// size); default 32. No more than the memory holds: the scene's estimate
    /// ([`crate::memory`]) is checked against the memory available before the grid is made.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub resolution: Option<usize>,
    /// Pressure solver of the MAC scenes (`"jacobi"`, `"rb-gauss-seidel"`, `"cg"`,
    /// `"mgpcg"`). Default: the preset's (MGPCG). Setting it or the tolerance lets the solve
    /// take up to [`PRESSURE_MAX_ITERATIONS`] iterations.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pressure_solver: Option<PressureMethod>,
    /// Relative residual `max|b - A p| / max|b|` the pressure solve stops at, > 0 (MAC scenes).
    /// Default: the preset's (1e-5 for the plume and a smoke scene of the user's own, 1e-8 for
    /// the cavity).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pressure_tolerance: Option<f64>,
    /// Advection scheme of the MAC scenes (`"sl-linear"`, `"sl-monotone-cubic"`, `"bfecc"`,
    /// `"maccormack"`). Default: the preset's (MacCormack).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub advection: Option<Advection>,
    /// How a MAC step splits advection from projection (`"advect-project"`, Stam's order,
    /// or `"reflection"`, advection-reflection). Default: the preset's (advect-project).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub splitting: Option<Splitting>,
    /// 2 or 3 (a smoke scene of the user's own). Default 3.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dim: Option<usize>,
    /// The domain's size (m), `[x, y, z]` (`[x, y]` in 2D), from the origin, y up: `resolution`
    /// cells along x and as many cells of the same size along y and z as cover the size. Default
    /// the plume's `[1, 1.5, 1]` (`[1, 1.5]` in 2D).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub size: Option<Vec<f64>>,
    /// Buoyancy weight of density `alpha` in `f = (-alpha rho + beta (T - T_amb)) e_y`, finite.
    /// Default the plume's 0.05.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub buoyancy_density: Option<f64>,
    /// Buoyancy weight of temperature `beta`, finite. Default the plume's 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub buoyancy_temperature: Option<f64>,
    /// Ambient temperature `T_amb`, finite (the initial temperature everywhere). Default 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ambient_temperature: Option<f64>,
    /// Vorticity confinement strength `eps`, >= 0. Default the plume's 2.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vorticity_confinement: Option<f64>,
    /// Kinematic viscosity (m²/s), >= 0 (an implicit solve per step when positive). Default 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub viscosity: Option<f64>,
    /// Whether the top (the high y side) is open (pressure 0 beyond it, smoke leaves); the other
    /// walls are no-slip. Default true (the plume's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub open_top: Option<bool>,
    /// Where smoke comes from: at least one [`SourceSpec`] (a shape or a closed OBJ surface,
    /// with its density, temperature and velocity).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sources: Option<Vec<SourceSpec>>,
    /// Solids the smoke flows around, collider shapes in the `anim_core::geometry::Shape`
    /// spelling (`{ sphere = { center, radius } }`, `box`, `capsule`, `plane`); each must cover
    /// a cell centre. Default none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub obstacles: Option<Vec<Shape>>,
    /// Solids the smoke flows around, closed OBJ surfaces placed by `scale`, `rotate`,
    /// `translate` ([`ObstacleMesh`]); each must cover a cell centre. Default none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub obstacle_meshes: Option<Vec<ObstacleMesh>>,
}

impl FluidSceneParams {
    /// The preset at `resolution` cells across (the preset's own when `None`).
    #[must_use]
    pub fn preset(name: &str, resolution: Option<usize>) -> Self {
        Self { preset: Some(name.into()), resolution, sources: None, ..Self::smoke(Vec::new()) }
    }

    /// A smoke scene of the user's own from `sources`, every other field at its default.
    #[must_use]
    pub fn smoke(sources: Vec<SourceSpec>) -> Self {
        Self {
            preset: None,
            resolution: None,
            pressure_solver: None,
            pressure_tolerance: None,
            advection: None,
            splitting: None,
            dim: None,
            size: None,
            buoyancy_density: None,
            buoyancy_temperature: None,
            ambient_temperature: None,
            vorticity_confinement: None,
            viscosity: None,
            open_top: None,
            sources: Some(sources),
            obstacles: None,
            obstacle_meshes: None,
        }
    }

    /// The fields of a smoke scene of the user's own that are set.
    fn smoke_fields(&self) -> Vec<&'static str> {
        [
            ("dim", self.dim.is_some()),
            ("size", self.size.is_some()),
            ("buoyancy_density", self.buoyancy_density.is_some()),
            ("buoyancy_temperature", self.buoyancy_temperature.is_some()),
            ("ambient_temperature", self.ambient_temperature.is_some()),
            ("vorticity_confinement", self.vorticity_confinement.is_some()),
            ("viscosity", self.viscosity.is_some()),
            ("open_top", self.open_top.is_some()),
            ("sources", self.sources.is_some()),
            ("obstacles", self.obstacles.is_some()),
            ("obstacle_meshes", self.obstacle_meshes.is_some()),
        ]
        .into_iter()
        .filter_map(|(name, set)| set.then_some(name))
        .collect()
    }

    /// Checks the parameters and builds the scene (mesh files relative to the working
    /// directory).
    ///
    /// # Errors
    /// As [`FluidSceneParams::scene_in`].
    pub fn scene(&self) -> Result<FluidScene, BuildError> {
        self.scene_in(&BuildContext::default())
    }

    /// Checks the parameters and builds the scene, reading mesh files relative to `context`.
    ///
    /// # Errors
    /// [`BuildError::Memory`] of `resolution` for a grid past the memory available;
    /// [`BuildError::Invalid`] naming the field: an unknown preset, a resolution the solver
    /// refuses, a tolerance that is not positive and finite, a
    /// MAC setting given to Stam's solver, a smoke scene's field given to a preset; for a smoke
    /// scene of the user's own, a bad size or setting, a source or obstacle that covers no cell,
    /// a source inside obstacles, an OBJ file that does not parse or is not a closed surface
    /// (`sources[k].mesh`, `obstacle_meshes[k].mesh`).
    pub fn scene_in(&self, context: &BuildContext<'_>) -> Result<FluidScene, BuildError> {
        if let Some(tol) = self.pressure_tolerance
            && !(tol > 0.0 && tol.is_finite())
        {
            return Err(BuildError::invalid(
                "pressure_tolerance",
                format!("must be a positive finite number, got {tol}"),
            ));
        }
        let Some(preset) = self.preset.as_deref() else {
            let mut scene = smoke::build(self, context)?;
            self.apply_mac_settings(&mut scene, "a smoke scene")?;
            return Ok(scene);
        };
        if let Some(&field) = self.smoke_fields().first() {
            return Err(BuildError::invalid(
                field,
                format!(
                    "belongs to a smoke scene of your own; preset `{preset}` keeps its own (remove \
                     `preset` to build your own scene with `sources` and obstacles)"
                ),
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
        crate::memory::check_preset(preset, self.resolution, self.splitting)?;
        let mut scene = scenes::by_name(preset, self.resolution)
            .ok_or_else(unknown)?
            .map_err(|e| BuildError::invalid("resolution", e.to_string()))?;
        self.apply_mac_settings(&mut scene, preset)?;
        Ok(scene)
    }

    /// Sets the pressure solver and tolerance, the advection and the splitting the file gives
    /// on the MAC solver of `scene` (`what` names the scene in the refusal of Stam's solver).
    fn apply_mac_settings(&self, scene: &mut FluidScene, what: &str) -> Result<(), BuildError> {
        let fields = [
            ("pressure_solver", self.pressure_solver.is_some()),
            ("pressure_tolerance", self.pressure_tolerance.is_some()),
            ("advection", self.advection.is_some()),
            ("splitting", self.splitting.is_some()),
        ];
        let Some(&(field, _)) = fields.iter().find(|(_, set)| *set) else { return Ok(()) };
        let FluidSim::Mac(fluid, _) = &mut scene.sim else {
            return Err(BuildError::invalid(
                field,
                format!(
                    "{what} runs Stam's solver (20 Gauss-Seidel sweeps, linear advection), which has no pressure, advection or splitting settings"
                ),
            ));
        };
        if self.pressure_solver.is_some() || self.pressure_tolerance.is_some() {
            let p = fluid.params();
            let method = self.pressure_solver.unwrap_or(p.pressure);
            let tol = self.pressure_tolerance.unwrap_or(p.pressure_tolerance);
            let field = if self.pressure_solver.is_some() { "pressure_solver" } else { "pressure_tolerance" };
            fluid
                .set_pressure(method, tol, PRESSURE_MAX_ITERATIONS)
                .map_err(|e| BuildError::invalid(field, e.to_string()))?;
        }
        if let Some(a) = self.advection {
            fluid.set_advection(a);
        }
        if let Some(s) = self.splitting {
            fluid.set_splitting(s);
        }
        Ok(())
    }
}

fn presets() -> Vec<Preset> {
    vec![
        Preset {
            name: "smoke-box-2d",
            description: "Stam's stable fluids (GDC 2003): smoke rising from a source in a closed 128x128 box",
            run: RunDefaults::new(0.1, 100, 2),
            params: json!({ "preset": "smoke-box-2d", "resolution": 128 }),
            quick_params: Some(json!({ "preset": "smoke-box-2d", "resolution": 16 })),
        },
        Preset {
            name: "smoke-plume-3d",
            description: "hot smoke rising around a sphere, 3D MAC grid, MacCormack + MGPCG, open top",
            run: RunDefaults::new(0.046875, 64, 1),
            params: json!({ "preset": "smoke-plume-3d", "resolution": 32 }),
            quick_params: Some(json!({ "preset": "smoke-plume-3d", "resolution": 8 })),
        },
        Preset {
            name: "lid-driven-cavity",
            description: "the Re = 100 lid-driven cavity (64x64 MAC grid) stirring bands of dye",
            run: RunDefaults::new(0.015625, 128, 10),
            params: json!({ "preset": "lid-driven-cavity", "resolution": 64 }),
            quick_params: Some(json!({ "preset": "lid-driven-cavity", "resolution": 16 })),
        },
    ]
}

fn build(value: &serde_json::Value, context: &BuildContext<'_>) -> Result<Box<dyn DynScene>, BuildError> {
    let p: FluidSceneParams = params(value)?;
    Ok(Simulated::new(p.scene_in(context)?, 0.0).boxed())
}

/// A [`FluidScene`] stepped by `dt` per step (the Stam scene applies its source pattern first),
/// with the run's clock as its state: the sum of the steps' `dt`.
impl Solver for FluidScene {
    type State = f64;
    type Error = FluidError;

    fn step(&mut self, time: &mut f64, dt: f64) -> Result<StepReport, FluidError> {
        let mut report = self.step_by(dt)?;
        *time += dt;
        report.time = *time;
        Ok(report)
    }
}

/// Saved as `{"time": t, "fluid": memory}` with [`FluidScene::memory`]: Stam's solver's six arrays,
/// or the MAC state and its warm-start pressure.
impl Checkpoint for FluidScene {
    /// 2: Stam's solver saved under `"stam"` (version 1 named it differently).
    const VERSION: u32 = 2;

    fn time(&self, time: &f64) -> f64 {
        *time
    }

    fn save(&self, time: &f64) -> serde_json::Value {
        json!({ "time": time, "fluid": self.memory() })
    }

    fn restore(&mut self, time: &mut f64, saved: &serde_json::Value) -> Result<(), CheckpointError> {
        let t: f64 = saved_field(saved, "time")?;
        if !t.is_finite() {
            return Err(CheckpointError::invalid("time", format!("{t} is not finite")));
        }
        let memory = saved.get("fluid").ok_or_else(|| CheckpointError::Missing { field: "fluid".into() })?;
        // Checks everything before it changes anything.
        self.restore_memory(memory).map_err(|e| CheckpointError::invalid("fluid", e.to_string()))?;
        *time = t;
        Ok(())
    }

    fn provoke_overflow(&mut self, _: &mut f64) -> Option<String> {
        match &mut self.sim {
            FluidSim::Stam(f) => {
                // The diffusion sums four neighbours: 2 f32::MAX is infinite.
                f.density_mut().fill(f32::MAX);
                Some("the density of every cell set to f32::MAX".into())
            }
            FluidSim::Mac(f, s) => {
                // Neighbouring faces of opposite signs: the net outflow is infinite.
                for values in s.vel.iter_mut().take(f.dim()) {
                    for (k, u) in values.iter_mut().enumerate() {
                        *u = if k % 2 == 0 { f64::MAX } else { -f64::MAX };
                    }
                }
                Some("the face velocities set to +-f64::MAX, alternating".into())
            }
        }
    }
}

impl View for FluidScene {
    fn method(&self) -> String {
        match &self.sim {
            FluidSim::Stam(_) => "Stam's stable fluids (f32, 20 Gauss-Seidel sweeps)".to_string(),
            FluidSim::Mac(f, _) => format!(
                "{}D MAC, {} advection, {} splitting, {} pressure",
                f.dim(),
                f.params().advection.name(),
                f.params().splitting.name(),
                f.params().pressure.name()
            ),
        }
    }

    /// The image grid (origin at 0, the cell size as spacing, the density shown) and, for the
    /// plume, its sphere in the grid's axes; for a smoke scene of the user's own, its shape
    /// obstacles but planes (mesh obstacles have no prop).
    fn context(&self, _: &f64) -> Context {
        // Stam's source adds 10 per step where it sits and the closed box keeps it all: in
        // the 128^2 box after 200 steps the density's median is 17, its 99th percentile 50
        // (measured on the scene's frames), so the scale ends at 50. The MAC scenes' densities
        // lie in [0, 1] (sources and dye of 1, a limited advection).
        let range = match &self.sim {
            FluidSim::Stam(_) => (0.0, 50.0),
            FluidSim::Mac(..) => (0.0, 1.0),
        };
        let mut context = Context::default();
        context.image = Some(ImageGrid {
            dims: self.dims(),
            dim: self.dim(),
            origin: [0.0; 3],
            spacing: self.cell_size(),
            shown: "density",
            range,
        });
        if self.name == "smoke-plume-3d" {
            context.props.push(Prop::Sphere {
                center: scenes::PLUME_SPHERE_CENTRE,
                radius: scenes::PLUME_SPHERE_RADIUS,
            });
        }
        context.props.extend(self.shapes.iter().filter_map(Prop::of_shape));
        context
    }

    fn frame(&self, time: &f64, out: &mut Frame) {
        out.time = *time;
        out.points.clear();
        self.density_into(out.field_mut("density", 1));
        self.velocity_into(out.field_mut("velocity", 3));
    }

    fn reference_error(&self, _: &f64) -> Option<f64> {
        match &self.sim {
            FluidSim::Mac(fluid, state) if self.name == "lid-driven-cavity" => Some(ghia_error(fluid, state)),
            _ => None,
        }
    }
}

/// Ghia, Ghia and Shin (1982), Re = 100: `u` along the vertical centreline, `(y, u)`.
const GHIA_U: &str = include_str!("../testdata/ghia_re100_u.csv");
/// The same for `v` along the horizontal centreline, `(x, v)`.
const GHIA_V: &str = include_str!("../testdata/ghia_re100_v.csv");

/// Ghia's points `(coordinate, value)` strictly inside the cavity.
fn ghia_points(text: &str) -> impl Iterator<Item = (f64, f64)> + '_ {
    text.lines()
        .skip(1)
        .filter_map(|l| {
            let (a, b) = l.split_once(',')?;
            Some((a.trim().parse().ok()?, b.trim().parse().ok()?))
        })
        .filter(|&(c, _)| c > 0.0 && c < 1.0)
}

/// The cavity's error on the Ghia study's measure: the largest `|u(0.5, y) - u_Ghia|` and
/// `|v(x, 0.5) - v_Ghia|` over Ghia's interior points (the unit cavity, Re = 100).
#[must_use]
pub fn ghia_error(fluid: &MacFluid, state: &MacState) -> f64 {
    let u = ghia_points(GHIA_U).map(|(y, u)| (fluid.velocity_at_point(state, [0.5, y, 0.0])[0] - u).abs());
    let v = ghia_points(GHIA_V).map(|(x, v)| (fluid.velocity_at_point(state, [x, 0.5, 0.0])[1] - v).abs());
    u.chain(v).fold(0.0, f64::max)
}

/// A label of the pressure study: `"<solver> N=<n>"`.
#[must_use]
pub fn pressure_label(label: &str) -> Option<(PressureMethod, usize)> {
    let (name, n) = label.split_once(" N=")?;
    Some((pressure_method(name)?, n.parse().ok()?))
}

/// The pressure solver of [`PressureMethod::name`] `name`.
#[must_use]
pub fn pressure_method(name: &str) -> Option<PressureMethod> {
    PressureMethod::ALL.into_iter().find(|m| m.name() == name)
}

/// The settings of a picked pressure solve: the resolution (if picked), the solver and its
/// tolerance, as scene-file parameters and in scene-file terms.
fn pressure_candidate(n: Option<usize>, solver: PressureMethod, tol: f64, dt: Option<f64>) -> Candidate {
    let mut settings = serde_json::Map::new();
    if let Some(n) = n {
        settings.insert("resolution".into(), json!(n));
    }
    settings.insert("pressure_solver".into(), json!(solver));
    settings.insert("pressure_tolerance".into(), json!(tol));
    Candidate {
        settings,
        summary: format!(
            "{}pressure_solver = {}, pressure_tolerance = {tol:e}",
            n.map(|n| format!("resolution = {n}, ")).unwrap_or_default(),
            solver.name()
        ),
        dt,
        cost: 1.0,
        dt_swept: false,
        note: String::new(),
    }
}

/// The `fluid_cavity_ghia` study on the `lid-driven-cavity` scene: the resolution `N` and the
/// pressure solver at the study's pressure tolerance, `dt = 1/N`.
struct CavityAdapter {
    pressure_tolerance: f64,
}

impl StudyAdapter for CavityAdapter {
    fn candidate(&self, method: &str, point: &Point) -> Result<Candidate, String> {
        let solver = pressure_method(method).ok_or_else(|| study::unknown_method(method))?;
        let n = point.param.round();
        if !(2.0..=2048.0).contains(&n) {
            return Err(format!("resolution {n} out of range"));
        }
        let n = n as usize;
        Ok(pressure_candidate(Some(n), solver, self.pressure_tolerance, Some(1.0 / n as f64)))
    }
}

/// The `fluid_pressure_divergence` study on the `smoke-plume-3d` scene: the pressure solver and
/// its tolerance, from the series measured at the grid size (`nearest`) nearest the scene's
/// largest side (`n`).
struct PressureAdapter {
    n: usize,
    nearest: usize,
}

impl StudyAdapter for PressureAdapter {
    fn candidate(&self, method: &str, point: &Point) -> Result<Candidate, String> {
        let Self { n, nearest } = *self;
        let (solver, measured) = pressure_label(method).ok_or_else(|| study::unknown_method(method))?;
        if measured != nearest {
            return Err(format!(
                "measured at N = {measured}; the scene's grid ({n} cells) is nearest N = {nearest}"
            ));
        }
        Ok(pressure_candidate(None, solver, point.param, None))
    }
}

/// The adapter of a `fluid` scene to its study (the registry maps `fluid/lid-driven-cavity` and
/// `fluid/smoke-plume-3d`). The studies measured the presets' own advection and splitting: a
/// scene that sets either is refused (the message, without the `--tolerance: FILE` the picker
/// puts before it, names the fields).
fn tolerance_adapter(
    value: &serde_json::Value,
    _: &RunDefaults,
    family: &Family,
) -> Result<Box<dyn StudyAdapter>, String> {
    let p: FluidSceneParams = params(value).map_err(study::unreadable)?;
    let set: Vec<&str> = [("advection", p.advection.is_some()), ("splitting", p.splitting.is_some())]
        .into_iter()
        .filter_map(|(name, on)| on.then_some(name))
        .collect();
    if !set.is_empty() {
        return Err(format!(
            "sets `{}`, but the {} study measured the preset's own; remove the field or --tolerance",
            set.join("` and `"),
            family.study
        ));
    }
    let Some(preset) = p.preset.as_deref() else {
        return Err(format!(
            "is a smoke scene of its own (no `preset`); the {} study measured the presets only",
            family.study
        ));
    };
    if preset == "lid-driven-cavity" {
        return Ok(Box::new(CavityAdapter {
            pressure_tolerance: study::problem(family, "pressure_tolerance")?,
        }));
    }
    crate::memory::check_preset(preset, p.resolution, p.splitting).map_err(study::unreadable)?;
    let scene = scenes::by_name(preset, p.resolution)
        .ok_or_else(|| format!("--tolerance: unknown fluid preset `{preset}`"))?
        .map_err(study::unreadable)?;
    let n = scene.dims().into_iter().max().unwrap_or(1);
    let sizes: Vec<usize> =
        family.series.iter().filter_map(|s| pressure_label(&s.method).map(|(_, n)| n)).collect();
    let nearest = sizes
        .iter()
        .copied()
        .min_by(|a, b| {
            let d = |m: usize| (m as f64 / n as f64).ln().abs();
            d(*a).total_cmp(&d(*b)).then(a.cmp(b))
        })
        .ok_or_else(|| format!("--tolerance: the {} study measured no grid size", family.study))?;
    Ok(Box::new(PressureAdapter { n, nearest }))
}

/// The run's error on its study's measure: for the smoke plume the largest relative pressure
/// residual of the run's projections (`max_residual`), else the scene's own reference error
/// (Ghia's velocities for the cavity).
fn tolerance_error(
    value: &serde_json::Value,
    scene: &dyn DynScene,
    max_residual: Option<f64>,
) -> Option<f64> {
    let p: FluidSceneParams = params(value).ok()?;
    if p.preset.as_deref() == Some("smoke-plume-3d") { max_residual } else { scene.reference_error() }
}

#[cfg(test)]
mod tests;
