//! The runnable form of a scene: one [`Runner`] per kind of system, so that the run loop, the
//! frame writers and the preview treat every crate's scenes alike.

use crate::scene::{Scene, SceneError, SkinningChoice};
use crate::view::{Geometry, Snapshot, frame_box};
use anim_core::integrate::systems::{HarmonicOscillator, KeplerOrbit};
use anim_core::integrate::{MechanicalSystem, Simulation, State};
use anim_core::solver::{Solver, StepReport};
use anim_io::FrameFormat;
use anim_pbd::PbdSimulation;
use anim_rigid::sim::{RigidSimulation, RigidState};
use anim_skin::scenes::SkinScene;
use anim_skin::{CharacterData, SkinningMethod};
use anim_springs::{SpringSimulation, scenes as spring_scenes};
use std::path::Path;

/// What the run loop needs from a scene.
pub trait Runner {
    /// The kind of system ("kepler-orbit", "springs/hanging-cloth", ...).
    fn system(&self) -> String;
    /// The method: integrator and, for implicit ones, linear solver.
    fn method(&self) -> String;
    /// The integrated state.
    fn state(&self) -> &State;
    /// Advances by `dt`.
    fn step(&mut self, dt: f64) -> Result<StepReport, String>;
    /// The MAC fluid and its state, for grid fluid scenes run by the MAC solver.
    fn mac(&self) -> Option<(&anim_fluid::mac::MacFluid, &anim_fluid::mac::MacState)> {
        None
    }
    /// Error of the current state against an exact solution, where one exists.
    fn exact_error(&self) -> Option<f64> {
        None
    }
    /// The run's error so far on the measure of the report study whose problem the scene is,
    /// where the scene carries the study's reference (the MPM dam break: the rms relative
    /// surge-front error against Martin & Moyce at the table's times passed so far).
    fn study_error(&self) -> Option<f64> {
        None
    }
    /// The frame format that suits the scene.
    fn natural_format(&self) -> OutputFormat;
    /// How the scene is drawn and written (fixed for the run).
    fn geometry(&self) -> Geometry;
    /// Everything the run carries from one step to the next (state, integrator memory), for
    /// checkpoints: a runner built from the same scene and given this continues bit for bit.
    fn save(&self) -> serde_json::Value;
    /// Restores what [`Runner::save`] of a runner of the same scene returned.
    fn restore(&mut self, saved: &serde_json::Value) -> Result<(), String>;
    /// Copies the current state out for the writer.
    fn snapshot(&self, energy: Option<f64>, out: &mut Snapshot) {
        let s = self.state();
        out.t = s.t;
        out.x.clone_from(&s.x);
        out.v.clone_from(&s.v);
        out.energy = energy;
        out.error = self.exact_error();
    }
}

/// Frame formats the command line offers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum OutputFormat {
    /// One CSV of the whole state per frame row (`frames.csv`): for systems of a few unknowns.
    Csv,
    /// VTK unstructured grids and a `.pvd` series (ParaView).
    Vtu,
    /// Binary PLY per frame (Blender, Houdini, MeshLab).
    Ply,
    /// OBJ per frame (any DCC tool).
    Obj,
    /// VTK image data per frame and a `.pvd` series (ParaView): the fields of grid scenes.
    Vti,
    /// No frame files (metrics and preview only).
    None,
}

impl OutputFormat {
    /// The anim-io format, for the mesh formats.
    #[must_use]
    pub fn frame_format(self) -> Option<FrameFormat> {
        match self {
            OutputFormat::Vtu => Some(FrameFormat::Vtu),
            OutputFormat::Ply => Some(FrameFormat::Ply),
            OutputFormat::Obj => Some(FrameFormat::Obj),
            OutputFormat::Vti => Some(FrameFormat::Vti),
            OutputFormat::Csv | OutputFormat::None => None,
        }
    }
}

/// Builds the runner of a scene; `base` is the scene file's folder, for relative paths.
pub fn build(
    scene: &Scene,
    file_path: &Path,
    skinning: Option<SkinningChoice>,
) -> Result<Box<dyn Runner>, SceneError> {
    let file = file_path;
    Ok(match *scene {
        Scene::HarmonicOscillator { mass, stiffness, damping, x0, v0, integrator } => {
            let sys = HarmonicOscillator::damped(mass, stiffness, damping);
            let exact = move |t: f64| {
                let (x, v) = sys.exact(x0, v0, t);
                [x, v]
            };
            let state = State::new(vec![x0], vec![v0]);
            Box::new(OdeRunner {
                name: "harmonic-oscillator",
                sim: Simulation::new(Box::new(sys), integrator.build(1)),
                method: integrator.label(),
                state,
                exact: Box::new(move |s: &State| {
                    let e = exact(s.t);
                    ((s.x[0] - e[0]).powi(2) + (s.v[0] - e[1]).powi(2)).sqrt()
                }),
                extent: (
                    [-1.5 * x0.abs().max(1e-3), -0.3 * x0.abs().max(1e-3)],
                    [1.5 * x0.abs().max(1e-3), 0.3 * x0.abs().max(1e-3)],
                ),
            })
        }
        Scene::KeplerOrbit { eccentricity, integrator } => {
            let sys = KeplerOrbit::ellipse(eccentricity);
            let (x0, v0) = sys.initial();
            let b = (1.0 - eccentricity * eccentricity).sqrt();
            Box::new(OdeRunner {
                name: "kepler-orbit",
                sim: Simulation::new(Box::new(sys), integrator.build(2)),
                method: integrator.label(),
                state: State::new(x0.to_vec(), v0.to_vec()),
                exact: Box::new(move |s: &State| {
                    let (x, v) = sys.exact(s.t);
                    let e = [x[0], x[1], v[0], v[1]];
                    s.x.iter().chain(&s.v).zip(e).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt()
                }),
                extent: ([-1.0 - eccentricity - 0.1, -b - 0.1], [1.0 - eccentricity + 0.1, b + 0.1]),
            })
        }
        Scene::Skinning { ref preset, ref file, method } => {
            let scene = match (preset, file) {
                (Some(p), None) if p == "twisted-cylinder" => anim_skin::scenes::twisted_cylinder(None)
                    .map_err(|e| SceneError::invalid(file_path, "scene.preset", e.to_string()))?,
                (Some(p), None) => {
                    return Err(SceneError::invalid(
                        file_path,
                        "scene.preset",
                        format!("unknown preset `{p}` (one of {})", anim_skin::scenes::NAMES.join(", ")),
                    ));
                }
                (None, Some(f)) => {
                    let path = file_path.parent().map_or_else(|| f.clone(), |dir| dir.join(f));
                    anim_skin::scenes::from_gltf(&path)
                        .map_err(|e| SceneError::invalid(file_path, "scene.file", e.to_string()))?
                }
                _ => {
                    return Err(SceneError::invalid(
                        file_path,
                        "scene.preset",
                        "give exactly one of `preset` and `file`".into(),
                    ));
                }
            };
            let default = if preset.is_some() { SkinningChoice::Both } else { SkinningChoice::Dqs };
            let runner = SkinRunner::new(scene, skinning.or(method).unwrap_or(default))
                .map_err(|e| SceneError::invalid(file_path, "scene.method", e))?;
            Box::new(runner)
        }
        Scene::Rigid { ref preset } => {
            let scene = preset_scene(
                file,
                "scene.preset",
                preset,
                &anim_rigid::scenes::NAMES,
                anim_rigid::scenes::by_name(preset),
            )?;
            Box::new(RigidRunner::new(scene).map_err(|e| SceneError::invalid(file, "scene.preset", e))?)
        }
        Scene::Pbd { ref preset, resolution, method, iterations, substeps } => {
            let mut s = preset_scene(
                file,
                "scene.resolution",
                preset,
                &anim_pbd::scenes::NAMES,
                anim_pbd::scenes::by_name(preset, resolution),
            )?;
            if let Some(m) = method {
                s.params.method = m;
            }
            if let Some(i) = iterations {
                s.params.iterations = i;
            }
            if let Some(k) = substeps {
                s.params.substeps = k;
            }
            let method = format!(
                "{} / {}, {} iteration{} x {} substep{}",
                format!("{:?}", s.params.method).to_lowercase(),
                format!("{:?}", s.params.solver).to_lowercase(),
                s.params.iterations,
                if s.params.iterations == 1 { "" } else { "s" },
                s.params.substeps,
                if s.params.substeps == 1 { "" } else { "s" },
            );
            let name = format!("pbd/{}", s.name);
            let (sim, state) =
                s.into_simulation().map_err(|e| SceneError::invalid(file, "scene.preset", e.to_string()))?;
            Box::new(PbdRunner { name, method, sim, state })
        }
        Scene::Fem { ref preset, resolution, element, integrator, linear_solver } => {
            let mut scene = preset_scene(
                file,
                "scene.resolution",
                preset,
                &anim_fem::scenes::NAMES,
                anim_fem::scenes::by_name_with_order(preset, resolution, element.unwrap_or_default()),
            )?;
            if let Some(i) = integrator {
                scene.params.integrator = i;
            }
            if let Some(l) = linear_solver {
                scene.params.linear_solver = l;
            }
            let name = format!("fem/{}", scene.name);
            let (sim, state) = scene
                .into_simulation()
                .map_err(|e| SceneError::invalid(file, "scene.preset", e.to_string()))?;
            Box::new(FemRunner { name, sim, state })
        }
        Scene::Mpm { ref preset, resolution, transfer, kernel, particles_per_cell } => {
            if particles_per_cell.is_some()
                && preset != "dam-break-2d"
                && anim_mpm::scenes::NAMES.contains(&preset.as_str())
            {
                return Err(SceneError::invalid(
                    file,
                    "scene.particles_per_cell",
                    format!("{preset} places its own particles; only dam-break-2d takes particles_per_cell"),
                ));
            }
            let mut scene = preset_scene(
                file,
                "scene.resolution",
                preset,
                &anim_mpm::scenes::NAMES,
                anim_mpm::scenes::by_name_with(preset, resolution, particles_per_cell),
            )?;
            if transfer.is_some() || kernel.is_some() {
                let params = match &scene {
                    anim_mpm::scenes::MpmScene::Two(s) => s.sim.params(),
                    anim_mpm::scenes::MpmScene::Three(s) => s.sim.params(),
                };
                let t = transfer.map_or(params.transfer, |t| t.transfer());
                let k = kernel.map_or(params.kernel, |k| k.kernel());
                let field = if transfer.is_some() { "scene.transfer" } else { "scene.kernel" };
                scene.set_method(t, k).map_err(|e| SceneError::invalid(file, field, e.to_string()))?;
            }
            Box::new(MpmRunner::new(scene))
        }
        Scene::Fluid {
            ref preset,
            resolution,
            pressure_solver,
            pressure_tolerance,
            advection,
            splitting,
        } => {
            let limit = if preset == "smoke-plume-3d" { 128 } else { 2048 };
            if let Some(r) = resolution
                && r > limit
            {
                return Err(SceneError::invalid(
                    file,
                    "scene.resolution",
                    format!("{preset} takes at most {limit} cells across, got {r}"),
                ));
            }
            let mut scene = preset_scene(
                file,
                "scene.resolution",
                preset,
                &anim_fluid::scenes::NAMES,
                anim_fluid::scenes::by_name(preset, resolution),
            )?;
            let fields = [
                ("scene.pressure_solver", pressure_solver.is_some()),
                ("scene.pressure_tolerance", pressure_tolerance.is_some()),
                ("scene.advection", advection.is_some()),
                ("scene.splitting", splitting.is_some()),
            ];
            if let Some(&(field, _)) = fields.iter().find(|(_, set)| *set) {
                let anim_fluid::scenes::FluidSim::Mac(fluid, _) = &mut scene.sim else {
                    return Err(SceneError::invalid(
                        file,
                        field,
                        format!(
                            "{preset} runs the seed's solver (20 Gauss-Seidel sweeps, linear advection), which has no pressure, advection or splitting settings"
                        ),
                    ));
                };
                if pressure_solver.is_some() || pressure_tolerance.is_some() {
                    let p = fluid.params();
                    let (method, tol) = (
                        pressure_solver.map_or(p.pressure, |s| s.0),
                        pressure_tolerance.unwrap_or(p.pressure_tolerance),
                    );
                    let field = if pressure_solver.is_some() {
                        "scene.pressure_solver"
                    } else {
                        "scene.pressure_tolerance"
                    };
                    fluid
                        .set_pressure(method, tol, PRESSURE_MAX_ITERATIONS)
                        .map_err(|e| SceneError::invalid(file, field, e.to_string()))?;
                }
                if let Some(a) = advection {
                    fluid.set_advection(a.advection());
                }
                if let Some(s) = splitting {
                    fluid.set_splitting(s.splitting());
                }
            }
            Box::new(FluidRunner::new(scene))
        }
        Scene::Flip { ref preset, resolution, transfer } => {
            let limit = if preset.ends_with("3d") { 128 } else { 1024 };
            if let Some(r) = resolution
                && r > limit
            {
                return Err(SceneError::invalid(
                    file,
                    "scene.resolution",
                    format!("{preset} takes at most {limit} cells across, got {r}"),
                ));
            }
            let scene = preset_scene(
                file,
                "scene.resolution",
                preset,
                &anim_flip::scenes::NAMES,
                anim_flip::scenes::by_name(preset, resolution, transfer.map(|t| t.transfer())),
            )?;
            Box::new(FlipRunner::new(scene))
        }
        Scene::Springs { ref preset, resolution, integrator, linear_solver } => {
            let mut s = preset_scene(
                file,
                "scene.resolution",
                preset,
                &spring_scenes::NAMES,
                spring_scenes::by_name(preset, resolution),
            )?;
            if let Some(i) = integrator {
                s.integrator = i;
            }
            if let Some(l) = linear_solver {
                s.linear_solver = l;
            }
            let method = if s.integrator.is_implicit() {
                format!("{} / {}", s.integrator.label(), s.linear_solver.name())
            } else {
                s.integrator.label()
            };
            let name = format!("springs/{}", s.name);
            let (sim, state) = s
                .into_simulation()
                .map_err(|e| SceneError::invalid(file, "scene.integrator", e.to_string()))?;
            Box::new(SpringRunner::new(name, method, sim, state))
        }
    })
}

/// The iteration cap of a pressure solve whose solver or tolerance a scene file sets (the report's
/// pressure study's cap).
pub const PRESSURE_MAX_ITERATIONS: usize = 200_000;

/// The scene a crate's `by_name` found for `preset`: an unknown name is an error on
/// `scene.preset` listing the known ones; a build error is reported on `field`.
fn preset_scene<T, E: std::fmt::Display>(
    file: &Path,
    field: &'static str,
    preset: &str,
    names: &[&str],
    found: Option<Result<T, E>>,
) -> Result<T, SceneError> {
    match found {
        Some(Ok(scene)) => Ok(scene),
        Some(Err(e)) => Err(SceneError::invalid(file, field, e.to_string())),
        None => Err(SceneError::invalid(
            file,
            "scene.preset",
            format!("unknown preset `{preset}` (one of {})", names.join(", ")),
        )),
    }
}

/// Field `key` of a saved runner, deserialised.
fn field<T: serde::de::DeserializeOwned>(saved: &serde_json::Value, key: &str) -> Result<T, String> {
    let value = saved.get(key).ok_or_else(|| format!("the checkpoint has no `{key}`"))?;
    T::deserialize(value).map_err(|e| format!("`{key}`: {e}"))
}

/// The saved state under `key`, checked against the size of `current`.
fn saved_state(saved: &serde_json::Value, key: &str, current: &State) -> Result<State, String> {
    let state: State = field(saved, key)?;
    if state.x.len() != current.x.len() || state.v.len() != current.v.len() {
        return Err(format!(
            "`{key}` has {} positions and {} velocities; this scene has {}",
            state.x.len(),
            state.v.len(),
            current.x.len()
        ));
    }
    Ok(state)
}

/// A system of a few unknowns with an exact solution, drawn in the plane.
struct OdeRunner {
    name: &'static str,
    sim: Simulation<dyn MechanicalSystem + Send>,
    method: String,
    state: State,
    exact: Box<dyn Fn(&State) -> f64>,
    /// Plane region shown by the preview.
    extent: ([f64; 2], [f64; 2]),
}

impl Runner for OdeRunner {
    fn system(&self) -> String {
        self.name.to_string()
    }

    fn method(&self) -> String {
        self.method.clone()
    }

    fn state(&self) -> &State {
        &self.state
    }

    fn step(&mut self, dt: f64) -> Result<StepReport, String> {
        self.sim.step(&mut self.state, dt).map_err(|e| e.to_string())
    }

    fn save(&self) -> serde_json::Value {
        serde_json::json!({ "state": self.state, "integrator": self.sim.memory() })
    }

    fn restore(&mut self, saved: &serde_json::Value) -> Result<(), String> {
        let state = saved_state(saved, "state", &self.state)?;
        let memory = saved.get("integrator").ok_or("the checkpoint has no `integrator`")?;
        self.sim.restore_memory(memory).map_err(|e| e.to_string())?;
        self.state = state;
        Ok(())
    }

    fn exact_error(&self) -> Option<f64> {
        Some((self.exact)(&self.state))
    }

    fn natural_format(&self) -> OutputFormat {
        OutputFormat::Csv
    }

    fn geometry(&self) -> Geometry {
        Geometry::Planar { extent: self.extent, sun: self.name == "kepler-orbit" }
    }
}

/// A skinned character posed at the run's time; with two methods, LBS is drawn left of DQS.
struct SkinRunner {
    name: String,
    scene: SkinScene,
    methods: Vec<(SkinningMethod, CharacterData, f64)>,
    state: State,
    triangles: Vec<[usize; 3]>,
    scratch: Vec<[f64; 3]>,
}

impl SkinRunner {
    fn new(scene: SkinScene, choice: SkinningChoice) -> Result<Self, String> {
        let methods = match choice {
            SkinningChoice::Lbs => vec![SkinningMethod::Lbs],
            SkinningChoice::Dqs => vec![SkinningMethod::Dqs],
            SkinningChoice::Both => vec![SkinningMethod::Lbs, SkinningMethod::Dqs],
        };
        let mut data = scene.data();
        scene.pose(&mut data, 0.0, SkinningMethod::Lbs).map_err(|e| e.to_string())?;
        let mut rest = Vec::new();
        data.positions(&mut rest);
        let (mut lo, mut hi) = (f64::MAX, f64::MIN);
        for p in &rest {
            lo = lo.min(p[0]);
            hi = hi.max(p[0]);
        }
        let width = if hi > lo { hi - lo } else { 1.0 };
        let count = methods.len() as f64;
        let methods: Vec<(SkinningMethod, CharacterData, f64)> = methods
            .into_iter()
            .enumerate()
            .map(|(k, m)| (m, scene.data(), (k as f64 - 0.5 * (count - 1.0)) * 1.4 * width))
            .collect();
        let base: Vec<[usize; 3]> =
            scene.character.triangles().iter().map(|t| t.map(|i| i as usize)).collect();
        let n = rest.len();
        let triangles =
            (0..methods.len()).flat_map(|k| base.iter().map(move |t| t.map(|i| i + k * n))).collect();
        let dof = 3 * n * methods.len();
        let mut runner = Self {
            name: format!("skinning/{}", scene.name),
            scene,
            methods,
            state: State::new(vec![0.0; dof], vec![0.0; dof]),
            triangles,
            scratch: Vec::new(),
        };
        runner.pose_all(0.0)?;
        Ok(runner)
    }

    /// Poses every method at `t` into the state (velocities by difference with the last pose).
    fn pose_all(&mut self, t: f64) -> Result<(), String> {
        let dt = t - self.state.t;
        let mut at = 0;
        for (method, data, offset) in &mut self.methods {
            self.scene.pose(data, t, *method).map_err(|e| e.to_string())?;
            data.positions(&mut self.scratch);
            for p in &self.scratch {
                let q = [p[0] + *offset, p[1], p[2]];
                for k in 0..3 {
                    self.state.v[at + k] = if dt > 0.0 { (q[k] - self.state.x[at + k]) / dt } else { 0.0 };
                    self.state.x[at + k] = q[k];
                }
                at += 3;
            }
        }
        self.state.t = t;
        Ok(())
    }
}

impl Runner for SkinRunner {
    fn system(&self) -> String {
        self.name.clone()
    }

    fn method(&self) -> String {
        self.methods
            .iter()
            .map(|(m, _, _)| format!("{m:?}").to_lowercase())
            .collect::<Vec<_>>()
            .join(" beside ")
    }

    fn state(&self) -> &State {
        &self.state
    }

    fn step(&mut self, dt: f64) -> Result<StepReport, String> {
        let t = self.state.t + dt;
        self.pose_all(t)?;
        Ok(StepReport::at_time(t))
    }

    fn save(&self) -> serde_json::Value {
        // The pose is a function of time; positions and velocities are kept so that the next
        // step's finite-difference velocities continue exactly.
        serde_json::json!({ "state": self.state })
    }

    fn restore(&mut self, saved: &serde_json::Value) -> Result<(), String> {
        self.state = saved_state(saved, "state", &self.state)?;
        Ok(())
    }

    fn natural_format(&self) -> OutputFormat {
        OutputFormat::Obj
    }

    fn geometry(&self) -> Geometry {
        Geometry::Particles {
            triangles: self.triangles.clone(),
            edges: Vec::new(),
            radius: 0.0,
            ground: None,
            spheres: Vec::new(),
            frame_box: frame_box(&self.state.x, None, false),
        }
    }
}

/// A position-based-dynamics model: cloth and soft bodies drawn as shaded surfaces, ropes as
/// segments and particles.
struct PbdRunner {
    name: String,
    method: String,
    sim: PbdSimulation,
    state: State,
}

impl Runner for PbdRunner {
    fn system(&self) -> String {
        self.name.clone()
    }

    fn method(&self) -> String {
        self.method.clone()
    }

    fn state(&self) -> &State {
        &self.state
    }

    fn step(&mut self, dt: f64) -> Result<StepReport, String> {
        self.sim.step(&mut self.state, dt).map_err(|e| e.to_string())
    }

    fn save(&self) -> serde_json::Value {
        serde_json::json!({ "state": self.state, "simulation": self.sim.memory() })
    }

    fn restore(&mut self, saved: &serde_json::Value) -> Result<(), String> {
        let state = saved_state(saved, "state", &self.state)?;
        let memory = saved.get("simulation").ok_or("the checkpoint has no `simulation`")?;
        self.sim.restore_memory(memory).map_err(|e| e.to_string())?;
        self.state = state;
        Ok(())
    }

    fn natural_format(&self) -> OutputFormat {
        OutputFormat::Vtu
    }

    fn geometry(&self) -> Geometry {
        let model = self.sim.model();
        let mut triangles = model.triangles().to_vec();
        if triangles.is_empty() && !model.tets().is_empty() {
            let positions = self.state.x.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
            let mesh = anim_io::TetMesh { positions, tets: model.tets().to_vec() };
            triangles = mesh.boundary_triangles();
        }
        let (mut ground, mut spheres) = (None, Vec::new());
        for c in model.colliders().iter().filter(|c| c.body.is_none()) {
            match c.shape {
                anim_pbd::Shape::Plane { point, normal: [0.0, 0.0, 1.0] } => ground = Some(point[2]),
                anim_pbd::Shape::Sphere { center, radius } => spheres.push((center, radius)),
                _ => {}
            }
        }
        let edges = model.edges().to_vec();
        let mean = if edges.is_empty() {
            0.01
        } else {
            edges
                .iter()
                .map(|[i, j]| {
                    let (a, b) = (&self.state.x[3 * i..3 * i + 3], &self.state.x[3 * j..3 * j + 3]);
                    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
                })
                .sum::<f64>()
                / edges.len() as f64
        };
        Geometry::Particles {
            triangles,
            edges,
            radius: 0.2 * mean,
            ground,
            spheres,
            frame_box: frame_box(&self.state.x, ground, true),
        }
    }
}

/// A tetrahedral finite element body (anim-fem), drawn as its boundary surface.
struct FemRunner {
    name: String,
    sim: anim_fem::sim::FemSimulation,
    state: State,
}

impl Runner for FemRunner {
    fn system(&self) -> String {
        self.name.clone()
    }

    fn method(&self) -> String {
        let p = self.sim.params();
        let method = format!("{} / {}", p.integrator.name(), p.linear_solver.name());
        match self.sim.model().order() {
            anim_fem::model::ElementOrder::Linear => method,
            order => format!("{method} / {}", order.name()),
        }
    }

    fn state(&self) -> &State {
        &self.state
    }

    fn step(&mut self, dt: f64) -> Result<StepReport, String> {
        self.sim.step(&mut self.state, dt).map_err(|e| e.to_string())
    }

    fn save(&self) -> serde_json::Value {
        serde_json::json!({ "state": self.state, "simulation": self.sim.memory() })
    }

    fn restore(&mut self, saved: &serde_json::Value) -> Result<(), String> {
        let state = saved_state(saved, "state", &self.state)?;
        let memory = saved.get("simulation").ok_or("the checkpoint has no `simulation`")?;
        self.sim.restore_memory(memory).map_err(|e| e.to_string())?;
        self.state = state;
        Ok(())
    }

    fn natural_format(&self) -> OutputFormat {
        OutputFormat::Vtu
    }

    fn geometry(&self) -> Geometry {
        let model = self.sim.model();
        let (mut ground, mut spheres) = (None, Vec::new());
        for o in model.obstacles() {
            match *o {
                anim_fem::boundary::Obstacle::Plane { normal: [0.0, 0.0, 1.0], offset } => {
                    ground = Some(offset)
                }
                anim_fem::boundary::Obstacle::Sphere { center, radius } => spheres.push((center, radius)),
                _ => {}
            }
        }
        Geometry::Particles {
            triangles: model.surface().to_vec(),
            edges: Vec::new(),
            radius: 0.0,
            ground,
            spheres,
            frame_box: frame_box(&self.state.x, ground, true),
        }
    }
}

/// A material-point-method scene (anim-mpm): particles drawn as discs, 2D scenes in the z = 0
/// plane. The particle order changes every step (the simulation sorts them by grid block) and
/// particles may leave, so the display state is refreshed from the particles after each step.
struct MpmRunner {
    name: String,
    scene: anim_mpm::scenes::MpmScene,
    display: State,
    /// The dam break's surge front at Martin & Moyce's times (the `dam-break-2d` preset only).
    front: Option<anim_mpm::scenes::SurgeFront>,
}

impl MpmRunner {
    fn new(scene: anim_mpm::scenes::MpmScene) -> Self {
        let front = match &scene {
            anim_mpm::scenes::MpmScene::Two(s) if s.name == "dam-break-2d" => {
                Some(anim_mpm::scenes::SurgeFront::new(s.sim.params(), &s.state))
            }
            _ => None,
        };
        let mut runner = Self {
            name: format!("mpm/{}", scene.name()),
            scene,
            display: State::new(Vec::new(), Vec::new()),
            front,
        };
        runner.refresh();
        runner
    }

    /// Positions and velocities as 3-vectors in `f64` for the writers.
    fn refresh(&mut self) {
        fn copy<const D: usize>(from: &anim_mpm::Particles<D>, x: &mut Vec<f64>, v: &mut Vec<f64>) {
            x.clear();
            v.clear();
            for (p, u) in from.x.chunks_exact(D).zip(from.v.chunks_exact(D)) {
                for k in 0..3 {
                    x.push(p.get(k).map_or(0.0, |c| f64::from(*c)));
                    v.push(u.get(k).map_or(0.0, |c| f64::from(*c)));
                }
            }
        }
        let d = &mut self.display;
        match &self.scene {
            anim_mpm::scenes::MpmScene::Two(s) => copy(&s.state, &mut d.x, &mut d.v),
            anim_mpm::scenes::MpmScene::Three(s) => copy(&s.state, &mut d.x, &mut d.v),
        }
        d.t = self.scene.time();
    }
}

impl Runner for MpmRunner {
    fn system(&self) -> String {
        self.name.clone()
    }

    fn method(&self) -> String {
        let params = match &self.scene {
            anim_mpm::scenes::MpmScene::Two(s) => s.sim.params(),
            anim_mpm::scenes::MpmScene::Three(s) => s.sim.params(),
        };
        let transfer = match params.transfer {
            anim_mpm::Transfer::Apic => "APIC",
            anim_mpm::Transfer::Mls => "MLS-MPM",
        };
        let kernel = crate::scene::MpmKernel::of(params.kernel).name();
        format!("{}D {transfer}, {kernel} B-splines, CFL substeps", self.scene.dim())
    }

    fn study_error(&self) -> Option<f64> {
        self.front.as_ref().and_then(|f| f.errors()).map(|(_, rms)| rms)
    }

    fn state(&self) -> &State {
        &self.display
    }

    fn step(&mut self, dt: f64) -> Result<StepReport, String> {
        let report = match &mut self.scene {
            anim_mpm::scenes::MpmScene::Two(s) => s.sim.step(&mut s.state, dt),
            anim_mpm::scenes::MpmScene::Three(s) => s.sim.step(&mut s.state, dt),
        }
        .map_err(|e| e.to_string())?;
        if let (Some(front), anim_mpm::scenes::MpmScene::Two(s)) = (&mut self.front, &self.scene) {
            front.observe(s.sim.time(), s.sim.params(), &s.state);
        }
        self.refresh();
        Ok(report)
    }

    fn save(&self) -> serde_json::Value {
        match &self.scene {
            anim_mpm::scenes::MpmScene::Two(s) => serde_json::json!({
                "dim": 2,
                "particles": s.state,
                "simulation": s.sim.memory(),
                "surge_front": self.front,
            }),
            anim_mpm::scenes::MpmScene::Three(s) => {
                serde_json::json!({ "dim": 3, "particles": s.state, "simulation": s.sim.memory() })
            }
        }
    }

    fn restore(&mut self, saved: &serde_json::Value) -> Result<(), String> {
        let dim: usize = field(saved, "dim")?;
        if dim != self.scene.dim() {
            return Err(format!("a {dim}D checkpoint for a {}D scene", self.scene.dim()));
        }
        let memory = saved.get("simulation").ok_or("the checkpoint has no `simulation`")?;
        fn restore<const D: usize>(
            s: &mut anim_mpm::scenes::Scene<D>,
            saved: &serde_json::Value,
            memory: &serde_json::Value,
        ) -> Result<(), String> {
            let particles: anim_mpm::Particles<D> = field(saved, "particles")?;
            particles.check_lengths().map_err(|e| format!("`particles`: {e}"))?;
            s.sim.restore_memory(memory).map_err(|e| e.to_string())?;
            s.state = particles;
            Ok(())
        }
        match &mut self.scene {
            anim_mpm::scenes::MpmScene::Two(s) => restore(s, saved, memory)?,
            anim_mpm::scenes::MpmScene::Three(s) => restore(s, saved, memory)?,
        }
        if self.front.is_some() {
            self.front = Some(field(saved, "surge_front")?);
        }
        self.refresh();
        Ok(())
    }

    fn natural_format(&self) -> OutputFormat {
        OutputFormat::Vtu
    }

    fn geometry(&self) -> Geometry {
        let params = match &self.scene {
            anim_mpm::scenes::MpmScene::Two(s) => s.sim.params(),
            anim_mpm::scenes::MpmScene::Three(s) => s.sim.params(),
        };
        let cell = params.size / params.resolution as f64;
        Geometry::Particles {
            triangles: Vec::new(),
            edges: Vec::new(),
            radius: 0.5 * cell,
            ground: None,
            spheres: Vec::new(),
            frame_box: frame_box(&self.display.x, None, true),
        }
    }
}

/// A particle fluid (anim-flip): particles drawn as discs. anim-flip has y up; the display state
/// (frames and preview) has z up like the CLI's other scenes: a fluid point `(x, y, z)` is shown
/// at `(x, -z, y)`, a 2D one `(x, y)` at `(x, 0, y)`, so 2D scenes lie in the y = 0 plane and
/// face the camera. Positions and velocities are in the world frame (a moving tank's
/// displacement and velocity added), refreshed after each step.
struct FlipRunner {
    name: String,
    scene: anim_flip::scenes::FlipScene,
    display: State,
}

impl FlipRunner {
    fn new(scene: anim_flip::scenes::FlipScene) -> Self {
        let mut runner = Self {
            name: format!("flip/{}", scene.name()),
            scene,
            display: State::new(Vec::new(), Vec::new()),
        };
        runner.refresh();
        runner
    }

    /// Positions and velocities as world-frame, z-up 3-vectors for the writers.
    fn refresh(&mut self) {
        fn copy<const D: usize>(s: &anim_flip::scenes::Preset<D>, d: &mut State) {
            let t = s.sim.time();
            let (axis, dx, dv) = s
                .sim
                .params()
                .tank_motion
                .map_or((0, 0.0, 0.0), |m| (m.axis, m.displacement(t), m.velocity(t)));
            d.x.clear();
            d.v.clear();
            for (p, u) in s.particles.x.iter().zip(&s.particles.v) {
                let mut x = *p;
                let mut v = *u;
                x[axis] += dx;
                v[axis] += dv;
                d.x.extend(z_up(&x));
                d.v.extend(z_up(&v));
            }
            d.t = t;
        }
        match &self.scene {
            anim_flip::scenes::FlipScene::Two(s) => copy(s, &mut self.display),
            anim_flip::scenes::FlipScene::Three(s) => copy(s, &mut self.display),
        }
    }
}

impl Runner for FlipRunner {
    fn system(&self) -> String {
        self.name.clone()
    }

    fn method(&self) -> String {
        let (dim, p) = match &self.scene {
            anim_flip::scenes::FlipScene::Two(s) => (2, s.sim.params().transfer),
            anim_flip::scenes::FlipScene::Three(s) => (3, s.sim.params().transfer),
        };
        format!("{dim}D {} on a MAC grid, MGPCG pressure, CFL substeps", p.name())
    }

    fn state(&self) -> &State {
        &self.display
    }

    fn step(&mut self, dt: f64) -> Result<StepReport, String> {
        let report = match &mut self.scene {
            anim_flip::scenes::FlipScene::Two(s) => s.sim.step(&mut s.particles, dt),
            anim_flip::scenes::FlipScene::Three(s) => s.sim.step(&mut s.particles, dt),
        }
        .map_err(|e| e.to_string())?;
        self.refresh();
        Ok(report)
    }

    fn save(&self) -> serde_json::Value {
        match &self.scene {
            anim_flip::scenes::FlipScene::Two(s) => {
                serde_json::json!({ "dim": 2, "particles": s.particles, "simulation": s.sim.memory() })
            }
            anim_flip::scenes::FlipScene::Three(s) => {
                serde_json::json!({ "dim": 3, "particles": s.particles, "simulation": s.sim.memory() })
            }
        }
    }

    fn restore(&mut self, saved: &serde_json::Value) -> Result<(), String> {
        let dim: usize = field(saved, "dim")?;
        if dim != self.scene.dim() {
            return Err(format!("a {dim}D checkpoint for a {}D scene", self.scene.dim()));
        }
        let memory = saved.get("simulation").ok_or("the checkpoint has no `simulation`")?;
        fn restore<const D: usize>(
            s: &mut anim_flip::scenes::Preset<D>,
            saved: &serde_json::Value,
            memory: &serde_json::Value,
        ) -> Result<(), String> {
            let particles: anim_flip::Particles<D> = field(saved, "particles")?;
            particles.validate().map_err(|e| format!("`particles`: {e}"))?;
            let mut sim = s.sim.clone();
            sim.restore_memory(memory).map_err(|e| e.to_string())?;
            s.sim = sim;
            s.particles = particles;
            Ok(())
        }
        match &mut self.scene {
            anim_flip::scenes::FlipScene::Two(s) => restore(s, saved, memory)?,
            anim_flip::scenes::FlipScene::Three(s) => restore(s, saved, memory)?,
        }
        self.refresh();
        Ok(())
    }

    fn natural_format(&self) -> OutputFormat {
        OutputFormat::Vtu
    }

    fn geometry(&self) -> Geometry {
        fn tank<const D: usize>(s: &anim_flip::scenes::Preset<D>) -> (f64, [f64; 3], [f64; 3]) {
            let (mut lo, mut hi) = s.sim.fluid_box();
            if let Some(m) = s.sim.params().tank_motion {
                // The oscillation's reach (the presets' tanks do not accelerate steadily).
                lo[m.axis] -= m.amplitude;
                hi[m.axis] += m.amplitude;
            }
            let (a, b) = (z_up(&lo), z_up(&hi));
            (
                s.sim.grid().h(),
                std::array::from_fn(|k| a[k].min(b[k])),
                std::array::from_fn(|k| a[k].max(b[k])),
            )
        }
        let (h, lo, hi) = match &self.scene {
            anim_flip::scenes::FlipScene::Two(s) => tank(s),
            anim_flip::scenes::FlipScene::Three(s) => tank(s),
        };
        Geometry::Particles {
            triangles: Vec::new(),
            edges: Vec::new(),
            radius: 0.25 * h,
            ground: None,
            spheres: Vec::new(),
            frame_box: (lo, hi),
        }
    }
}

/// A y-up fluid vector as the CLI's z-up one: `(x, y, z) -> (x, -z, y)` (a rotation about x),
/// `(x, y) -> (x, 0, y)`.
fn z_up<const D: usize>(p: &[f64; D]) -> [f64; 3] {
    let z = if D == 3 { -p[D - 1] } else { 0.0 };
    [p[0], z, p[1]]
}

/// A grid fluid (anim-fluid). The display state holds the density per cell as positions and
/// the cell-centred velocity as velocities (see [`Geometry::Grid`]), refreshed after every step
/// into the same buffers; its time is the sum of the run's steps.
struct FluidRunner {
    name: String,
    method: String,
    scene: anim_fluid::scenes::FluidScene,
    display: State,
    /// Colour scale of the density pictures.
    range: (f64, f64),
}

impl FluidRunner {
    fn new(scene: anim_fluid::scenes::FluidScene) -> Self {
        use anim_fluid::scenes::FluidSim;
        let method = match &scene.sim {
            FluidSim::Seed(_) => "seed stable fluids (f32, 20 Gauss-Seidel sweeps)".to_string(),
            FluidSim::Mac(f, _) => format!(
                "{}D MAC, {} advection, {} splitting, {} pressure",
                f.dim(),
                f.params().advection.name(),
                f.params().splitting.name(),
                f.params().pressure.name()
            ),
        };
        // The seed's source adds 10 per step where it sits and the closed box keeps it all: in
        // the 128^2 box after 200 steps the density's median is 17, its 99th percentile 50
        // (measured on the scene's frames), so the scale ends at 50. The MAC scenes' densities
        // lie in [0, 1] (sources and dye of 1, a limited advection).
        let range = match &scene.sim {
            FluidSim::Seed(_) => (0.0, 50.0),
            FluidSim::Mac(..) => (0.0, 1.0),
        };
        let mut runner = Self {
            name: format!("fluid/{}", scene.name),
            method,
            scene,
            display: State::new(Vec::new(), Vec::new()),
            range,
        };
        runner.refresh();
        runner
    }

    fn refresh(&mut self) {
        self.scene.density_into(&mut self.display.x);
        self.scene.velocity_into(&mut self.display.v);
    }
}

impl Runner for FluidRunner {
    fn system(&self) -> String {
        self.name.clone()
    }

    fn method(&self) -> String {
        self.method.clone()
    }

    fn state(&self) -> &State {
        &self.display
    }

    fn step(&mut self, dt: f64) -> Result<StepReport, String> {
        let report = self.scene.step_by(dt).map_err(|e| e.to_string())?;
        self.display.t += dt;
        self.refresh();
        Ok(report)
    }

    fn mac(&self) -> Option<(&anim_fluid::mac::MacFluid, &anim_fluid::mac::MacState)> {
        match &self.scene.sim {
            anim_fluid::scenes::FluidSim::Mac(f, s) => Some((f, s)),
            anim_fluid::scenes::FluidSim::Seed(_) => None,
        }
    }

    fn save(&self) -> serde_json::Value {
        serde_json::json!({ "time": self.display.t, "fluid": self.scene.memory() })
    }

    fn restore(&mut self, saved: &serde_json::Value) -> Result<(), String> {
        let time: f64 = field(saved, "time")?;
        if !time.is_finite() {
            return Err(format!("`time`: {time} is not finite"));
        }
        let memory = saved.get("fluid").ok_or("the checkpoint has no `fluid`")?;
        self.scene.restore_memory(memory).map_err(|e| e.to_string())?;
        self.display.t = time;
        self.refresh();
        Ok(())
    }

    fn natural_format(&self) -> OutputFormat {
        OutputFormat::Vti
    }

    fn geometry(&self) -> Geometry {
        Geometry::Grid {
            dims: self.scene.dims(),
            dim: self.scene.dim(),
            spacing: self.scene.cell_size(),
            range: self.range,
        }
    }
}

/// An articulated or free rigid body (anim-rigid), drawn as the segments its scene names; the
/// frame files and the preview see the segments' endpoints as particles.
struct RigidRunner {
    name: String,
    method: String,
    sim: RigidSimulation,
    rigid: RigidState,
    data: anim_rigid::Data,
    segments: Vec<(anim_rigid::model::FrameIndex, anim_rigid::model::FrameIndex)>,
    points: Vec<[anim_core::glam::DVec3; 2]>,
    display: State,
}

impl RigidRunner {
    fn new(scene: anim_rigid::scenes::RigidScene) -> Result<Self, String> {
        let name = format!("rigid/{}", scene.name);
        let method = format!("{:?}", scene.integrator).to_lowercase();
        let segments = scene.segments.clone();
        let data = anim_rigid::Data::new(&scene.model);
        let (sim, rigid) = scene.into_simulation().map_err(|e| e.to_string())?;
        let n = 6 * segments.len();
        let mut runner = Self {
            name,
            method,
            sim,
            rigid,
            data,
            segments,
            points: Vec::new(),
            display: State::new(vec![0.0; n], vec![0.0; n]),
        };
        runner.refresh(0.0);
        Ok(runner)
    }

    /// Segment endpoints into the display state (velocities by difference over `dt`).
    fn refresh(&mut self, dt: f64) {
        anim_rigid::scenes::segment_points(
            self.sim.model(),
            &mut self.data,
            &self.rigid.q,
            &self.segments,
            &mut self.points,
        );
        for (k, p) in self.points.iter().flatten().enumerate() {
            for (c, value) in p.to_array().into_iter().enumerate() {
                let i = 3 * k + c;
                self.display.v[i] = if dt > 0.0 { (value - self.display.x[i]) / dt } else { 0.0 };
                self.display.x[i] = value;
            }
        }
        self.display.t = self.rigid.t;
    }
}

impl Runner for RigidRunner {
    fn system(&self) -> String {
        self.name.clone()
    }

    fn method(&self) -> String {
        self.method.clone()
    }

    fn state(&self) -> &State {
        &self.display
    }

    fn step(&mut self, dt: f64) -> Result<StepReport, String> {
        let report = self.sim.step(&mut self.rigid, dt).map_err(|e| e.to_string())?;
        self.refresh(dt);
        Ok(report)
    }

    fn save(&self) -> serde_json::Value {
        serde_json::json!({ "rigid": self.rigid, "simulation": self.sim.memory(), "display": self.display })
    }

    fn restore(&mut self, saved: &serde_json::Value) -> Result<(), String> {
        let rigid: RigidState = field(saved, "rigid")?;
        if rigid.q.len() != self.rigid.q.len() || rigid.v.len() != self.rigid.v.len() {
            return Err(format!(
                "`rigid` has {} coordinates and {} velocities; this model has {} and {}",
                rigid.q.len(),
                rigid.v.len(),
                self.rigid.q.len(),
                self.rigid.v.len()
            ));
        }
        let display = saved_state(saved, "display", &self.display)?;
        let memory = saved.get("simulation").ok_or("the checkpoint has no `simulation`")?;
        self.sim.restore_memory(memory).map_err(|e| e.to_string())?;
        self.rigid = rigid;
        self.display = display;
        Ok(())
    }

    fn natural_format(&self) -> OutputFormat {
        OutputFormat::Vtu
    }

    fn geometry(&self) -> Geometry {
        let edges: Vec<[usize; 2]> = (0..self.segments.len()).map(|k| [2 * k, 2 * k + 1]).collect();
        let longest = self.points.iter().map(|[a, b]| (*a - *b).length()).fold(0.0, f64::max);
        Geometry::Particles {
            triangles: Vec::new(),
            edges,
            radius: 0.06 * longest.max(1e-3),
            ground: None,
            spheres: Vec::new(),
            frame_box: frame_box(&self.display.x, None, true),
        }
    }
}

/// A spring network: cloth drawn as a shaded mesh, ropes and lattices as springs and particles.
struct SpringRunner {
    name: String,
    method: String,
    sim: SpringSimulation,
    state: State,
}

impl SpringRunner {
    fn new(name: String, method: String, sim: SpringSimulation, state: State) -> Self {
        Self { name, method, sim, state }
    }

    fn ground(&self) -> Option<f64> {
        self.sim.network().model().colliders().iter().find_map(|c| match c.shape {
            anim_springs::Shape::Plane { point, normal: [0.0, 0.0, 1.0] } => Some(point[2]),
            _ => None,
        })
    }

    fn mean_spring_length(&self) -> f64 {
        let springs = self.sim.network().springs();
        if springs.is_empty() {
            return 0.01;
        }
        springs.iter().map(|s| s.rest_length).sum::<f64>() / springs.len() as f64
    }
}

impl Runner for SpringRunner {
    fn system(&self) -> String {
        self.name.clone()
    }

    fn method(&self) -> String {
        self.method.clone()
    }

    fn state(&self) -> &State {
        &self.state
    }

    fn step(&mut self, dt: f64) -> Result<StepReport, String> {
        self.sim.step(&mut self.state, dt).map_err(|e| e.to_string())
    }

    fn save(&self) -> serde_json::Value {
        serde_json::json!({ "state": self.state, "simulation": self.sim.memory() })
    }

    fn restore(&mut self, saved: &serde_json::Value) -> Result<(), String> {
        let state = saved_state(saved, "state", &self.state)?;
        let memory = saved.get("simulation").ok_or("the checkpoint has no `simulation`")?;
        self.sim.restore_memory(memory).map_err(|e| e.to_string())?;
        self.state = state;
        Ok(())
    }

    fn natural_format(&self) -> OutputFormat {
        OutputFormat::Vtu
    }

    fn geometry(&self) -> Geometry {
        let network = self.sim.network();
        let ground = self.ground();
        let spheres = network
            .model()
            .colliders()
            .iter()
            .filter_map(|c| match c.shape {
                anim_springs::Shape::Sphere { center, radius } => Some((center, radius)),
                _ => None,
            })
            .collect();
        Geometry::Particles {
            triangles: network.triangles().to_vec(),
            edges: network.springs().iter().map(|s| [s.i, s.j]).collect(),
            radius: 0.15 * self.mean_spring_length(),
            ground,
            spheres,
            frame_box: frame_box(&self.state.x, ground, true),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene;
    use crate::view::View;
    use anim_io::FrameWriter;
    use anim_io::preview::Canvas;

    /// The built-in scene's runner; fluid grids at a small resolution to keep the tests fast.
    fn runner_of(name: &str) -> Box<dyn Runner> {
        let text = scene::builtin(name).unwrap();
        let mut file = scene::parse(text, Path::new(name)).unwrap();
        if let Scene::Fluid { resolution, .. } = &mut file.scene {
            *resolution = Some(if name == "smoke-plume-3d" { 8 } else { 16 });
        }
        if let Scene::Flip { resolution, .. } = &mut file.scene {
            *resolution = Some(if name.ends_with("3d") { 8 } else { 16 });
        }
        build(&file.scene, Path::new(name), None).unwrap()
    }

    #[test]
    fn every_builtin_scene_steps_writes_and_draws() {
        let dir = std::env::temp_dir().join(format!("anim-cli-runner-{}", std::process::id()));
        for (name, _, _) in scene::BUILTIN {
            let mut runner = runner_of(name);
            let x0 = runner.state().x.clone();
            // The scene's own step, small enough for any of them to take a few.
            let text = scene::builtin(name).unwrap();
            let dt = scene::parse(text, Path::new(name)).unwrap().run.dt;
            for _ in 0..3 {
                runner.step(dt).unwrap();
            }
            assert!((runner.state().t - 3.0 * dt).abs() < 1e-12, "{name}");
            assert_ne!(runner.state().x, x0, "{name}: nothing moved");
            let format = runner.natural_format();
            let frame_format = format.frame_format().unwrap_or(FrameFormat::Vtu);
            let mut frames = FrameWriter::new(dir.join(name), frame_format).unwrap();
            let mut view = View::new(runner.geometry());
            let mut snap = Snapshot::default();
            runner.snapshot(None, &mut snap);
            view.write_frame(&mut frames, &snap).unwrap();
            assert_eq!(frames.sequence().frames().len(), 1, "{name}");
            let mut canvas = Canvas::new(64, 48, [255, 255, 255]);
            let camera = view.camera(64.0 / 48.0);
            view.draw(&mut canvas, &camera, &snap).unwrap();
            let drawn = canvas.pixels().iter().filter(|p| **p != [255, 255, 255]).count();
            assert!(drawn > 20, "{name}: only {drawn} pixels drawn");
        }
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn fluid_pressure_settings_reach_the_solver_or_are_refused() {
        let text = scene::builtin("lid-driven-cavity").unwrap().replace(
            "resolution = 64",
            "resolution = 8\npressure_solver = \"rb-gauss-seidel\"\npressure_tolerance = 1e-4",
        );
        let file = scene::parse(&text, Path::new("s.toml")).unwrap();
        let runner = build(&file.scene, Path::new("s.toml"), None).unwrap();
        let (fluid, _) = runner.mac().unwrap();
        let p = fluid.params();
        assert_eq!(
            (p.pressure, p.pressure_tolerance, p.pressure_max_iterations),
            (anim_fluid::pressure::PressureMethod::RedBlackGaussSeidel, 1e-4, PRESSURE_MAX_ITERATIONS)
        );
        assert!(runner.method().contains("rb-gauss-seidel pressure"), "{}", runner.method());
        // Without the fields the preset's own settings stay (MGPCG to 1e-8, 1000 iterations).
        let plain = scene::parse(
            &scene::builtin("lid-driven-cavity").unwrap().replace("64", "8"),
            Path::new("s.toml"),
        );
        let runner = build(&plain.unwrap().scene, Path::new("s.toml"), None).unwrap();
        let p = runner.mac().unwrap().0.params();
        assert_eq!((p.pressure, p.pressure_tolerance), (anim_fluid::pressure::PressureMethod::Mgpcg, 1e-8));
        let text =
            scene::builtin("smoke-box-2d").unwrap().replace("resolution = 128", "pressure_tolerance = 1e-4");
        let file = scene::parse(&text, Path::new("s.toml")).unwrap();
        let msg = build(&file.scene, Path::new("s.toml"), None).err().unwrap().to_string();
        assert!(
            msg.contains("field `scene.pressure_tolerance`: smoke-box-2d runs the seed's solver"),
            "{msg}"
        );
    }

    #[test]
    fn fluid_advection_and_splitting_reach_the_solver_or_are_refused() {
        use anim_fluid::advection::{Advection, Splitting};
        let text = scene::builtin("lid-driven-cavity").unwrap().replace(
            "resolution = 64",
            "resolution = 8\nadvection = \"sl-linear\"\nsplitting = \"reflection\"",
        );
        let file = scene::parse(&text, Path::new("s.toml")).unwrap();
        let mut runner = build(&file.scene, Path::new("s.toml"), None).unwrap();
        let p = runner.mac().unwrap().0.params();
        assert_eq!((p.advection, p.splitting), (Advection::Linear, Splitting::Reflection));
        // The preset's pressure settings stay when only the advection is set.
        assert_eq!((p.pressure, p.pressure_tolerance), (anim_fluid::pressure::PressureMethod::Mgpcg, 1e-8));
        assert!(runner.method().contains("sl-linear advection, reflection splitting"), "{}", runner.method());
        runner.step(0.01).unwrap();
        let plain = scene::builtin("lid-driven-cavity").unwrap().replace("64", "8");
        let runner =
            build(&scene::parse(&plain, Path::new("s.toml")).unwrap().scene, Path::new("s.toml"), None)
                .unwrap();
        let p = runner.mac().unwrap().0.params();
        assert_eq!((p.advection, p.splitting), (Advection::MacCormack, Splitting::AdvectProject));
        for (field, line) in
            [("advection", "advection = \"bfecc\""), ("splitting", "splitting = \"reflection\"")]
        {
            let text = scene::builtin("smoke-box-2d").unwrap().replace("resolution = 128", line);
            let file = scene::parse(&text, Path::new("s.toml")).unwrap();
            let msg = build(&file.scene, Path::new("s.toml"), None).err().unwrap().to_string();
            assert!(
                msg.contains(&format!("field `scene.{field}`: smoke-box-2d runs the seed's solver")),
                "{msg}"
            );
        }
        let bad =
            scene::builtin("lid-driven-cavity").unwrap().replace("resolution = 64", "splitting = \"strang\"");
        let msg = scene::parse(&bad, Path::new("s.toml")).err().unwrap().to_string();
        assert!(msg.contains("unknown variant `strang`") && msg.contains("reflection"), "{msg}");
    }

    #[test]
    fn fem_method_fields_reach_the_simulation() {
        let text = scene::builtin("beam").unwrap().replace(
            "preset = \"cantilever-beam\"",
            "preset = \"cantilever-beam\"\nresolution = 1\nintegrator = \"symplectic-euler\"",
        );
        let file = scene::parse(&text, Path::new("s.toml")).unwrap();
        let mut runner = build(&file.scene, Path::new("s.toml"), None).unwrap();
        // An explicit step has no Newton update to report; the preset's backward Euler has.
        assert_eq!(runner.step(1e-5).unwrap().residual, None);
        let text = scene::builtin("beam")
            .unwrap()
            .replace("preset = \"cantilever-beam\"", "preset = \"cantilever-beam\"\nresolution = 1");
        let file = scene::parse(&text, Path::new("s.toml")).unwrap();
        let mut runner = build(&file.scene, Path::new("s.toml"), None).unwrap();
        let report = runner.step(1e-2).unwrap();
        assert!(report.iterations >= 1 && report.residual.is_some(), "{report:?}");
    }

    #[test]
    fn pbd_method_fields_reach_the_simulation() {
        let text = scene::builtin("pbd-cloth").unwrap().replace(
            "preset = \"hanging-cloth\"",
            "preset = \"hanging-cloth\"\nresolution = 4\nmethod = \"pbd\"\niterations = 3\nsubsteps = 5",
        );
        let file = scene::parse(&text, Path::new("s.toml")).unwrap();
        let mut runner = build(&file.scene, Path::new("s.toml"), None).unwrap();
        assert_eq!(runner.method(), "pbd / gaussseidel, 3 iterations x 5 substeps");
        // Each substep's iterations report into the step's iteration count: 3 x 5.
        assert_eq!(runner.step(1.0 / 60.0).unwrap().iterations, 15);
        let plain = scene::parse(scene::builtin("pbd-cloth").unwrap(), Path::new("s.toml")).unwrap();
        let runner = build(&plain.scene, Path::new("s.toml"), None).unwrap();
        assert_eq!(runner.method(), "xpbd / gaussseidel, 1 iteration x 8 substeps");
    }

    #[test]
    fn mpm_method_fields_reach_the_simulation_and_the_dam_break_measures_its_front() {
        let dam = |fields: &str| {
            let text = scene::builtin("dam-break-2d-mpm").unwrap().replace("resolution = 64", fields);
            let file = scene::parse(&text, Path::new("s.toml")).unwrap();
            build(&file.scene, Path::new("s.toml"), None)
        };
        let runner = dam("resolution = 32\ntransfer = \"apic\"\nkernel = \"cubic\"").unwrap();
        assert_eq!(runner.method(), "2D APIC, cubic B-splines, CFL substeps");
        // The column 0.2 x 0.4 m at h = 1/32 holds floor(6.4 k) x floor(12.8 k) particles.
        for (k, count) in [(2, 12 * 25), (3, 19 * 38)] {
            let runner = dam(&format!("resolution = 32\nparticles_per_cell = {k}")).unwrap();
            assert_eq!(runner.state().x.len(), 3 * count, "{k} per cell");
            assert_eq!(runner.method(), "2D MLS-MPM, quadratic B-splines, CFL substeps");
        }
        let three = scene::builtin("mpm")
            .unwrap()
            .replace("preset = \"three-materials\"", "preset = \"three-materials\"\nparticles_per_cell = 3");
        let file = scene::parse(&three, Path::new("s.toml")).unwrap();
        let msg = build(&file.scene, Path::new("s.toml"), None).err().unwrap().to_string();
        assert!(
            msg.contains(
                "s.toml: field `scene.particles_per_cell`: three-materials places its own particles"
            ),
            "{msg}"
        );
        // The surge-front error appears once the run passes Martin & Moyce's first time,
        // T = 0.41, t = 0.41 / sqrt(2 g / a) = 0.0414 s.
        let mut runner = dam("resolution = 32").unwrap();
        let dt = anim_mpm::scenes::dam_break_2d_dt(32);
        assert_eq!(runner.study_error(), None);
        let first = 0.41 / (2.0 * 9.81 / 0.2f64).sqrt();
        while runner.state().t + dt < first {
            runner.step(dt).unwrap();
        }
        assert_eq!(runner.study_error(), None, "before T = 0.41");
        runner.step(dt).unwrap();
        let e = runner.study_error().unwrap();
        assert!(e.is_finite() && e > 0.0 && e < 1.0, "{e}");
        // Other scenes carry no study reference.
        assert_eq!(runner_of("mpm").study_error(), None);
    }

    #[test]
    fn unknown_preset_and_bad_resolution_name_their_fields() {
        let text = scene::builtin("cloth").unwrap().replace("hanging-cloth", "flying-carpet");
        let file = scene::parse(&text, Path::new("s.toml")).unwrap();
        let msg = build(&file.scene, Path::new("s.toml"), None).err().unwrap().to_string();
        assert!(
            msg.contains("s.toml") && msg.contains("`scene.preset`") && msg.contains("flying-carpet"),
            "{msg}"
        );
        let text = scene::builtin("cloth").unwrap().replace("resolution = 32", "resolution = 1");
        let file = scene::parse(&text, Path::new("s.toml")).unwrap();
        let msg = build(&file.scene, Path::new("s.toml"), None).err().unwrap().to_string();
        assert!(msg.contains("`scene.resolution`"), "{msg}");
    }

    #[test]
    fn every_builtin_scene_resumes_from_its_saved_state_bit_for_bit() {
        for (name, _, text) in scene::BUILTIN {
            let dt = scene::parse(text, Path::new(name)).unwrap().run.dt;
            let mut uninterrupted = runner_of(name);
            for _ in 0..4 {
                uninterrupted.step(dt).unwrap();
            }
            // Through JSON text, as the checkpoint file stores it.
            let saved = serde_json::to_string(&uninterrupted.save()).unwrap();
            for _ in 0..5 {
                uninterrupted.step(dt).unwrap();
            }
            let mut resumed = runner_of(name);
            resumed.restore(&serde_json::from_str(&saved).unwrap()).unwrap();
            for _ in 0..5 {
                resumed.step(dt).unwrap();
            }
            let (a, b) = (uninterrupted.state(), resumed.state());
            let same = |p: &[f64], q: &[f64]| {
                p.len() == q.len() && p.iter().zip(q).all(|(u, w)| u.to_bits() == w.to_bits())
            };
            assert!(same(&a.x, &b.x) && same(&a.v, &b.v) && a.t.to_bits() == b.t.to_bits(), "{name}");
            assert_eq!(uninterrupted.save(), resumed.save(), "{name}");
        }
    }

    #[test]
    fn a_saved_state_of_another_scene_is_refused() {
        let cloth = runner_of("cloth").save();
        for other in ["rope", "kepler", "panda", "drape", "twist", "smoke-box-2d", "lid-driven-cavity"] {
            let msg = runner_of(other).restore(&cloth).unwrap_err();
            assert!(!msg.is_empty(), "{other}");
        }
        // Fluids: another solver, another grid, a damaged field; the runner is unchanged.
        let smoke = runner_of("smoke-box-2d").save();
        let mut plume = runner_of("smoke-plume-3d");
        plume.step(0.05).unwrap();
        let mut other_grid = plume.save();
        other_grid["fluid"]["simulation"]["dims"] = serde_json::json!([8, 12, 9]);
        let cases = [
            ("lid-driven-cavity", smoke, "a seed memory for a scene run by the mac solver"),
            ("smoke-plume-3d", other_grid, "[8, 12, 9] grid"),
            ("smoke-box-2d", serde_json::json!({ "time": 0.0 }), "no `fluid`"),
        ];
        for (name, saved, expect) in cases {
            let mut runner = runner_of(name);
            let before = runner.save();
            let msg = runner.restore(&saved).unwrap_err();
            assert!(msg.contains(expect), "{expect}: {msg}");
            assert_eq!(runner.save(), before, "{expect}");
        }
    }

    #[test]
    fn fluid_frames_are_vti_grids_and_the_preview_shows_the_density() {
        let dir = std::env::temp_dir().join(format!("anim-cli-fluid-{}", std::process::id()));
        for name in ["smoke-box-2d", "smoke-plume-3d"] {
            let mut runner = runner_of(name);
            let dt = if name == "smoke-box-2d" { 0.1 } else { 1.5 / 8.0 };
            for _ in 0..4 {
                runner.step(dt).unwrap();
            }
            let geometry = runner.geometry();
            let Geometry::Grid { dims, .. } = geometry else { panic!("{name}: not a grid") };
            assert!(geometry.accepts(OutputFormat::Vti) && !geometry.accepts(OutputFormat::Csv));
            let mut frames = FrameWriter::new(dir.join(name), FrameFormat::Vti).unwrap();
            let mut view = View::new(geometry);
            let mut snap = Snapshot::default();
            runner.snapshot(None, &mut snap);
            let cells = dims.iter().product::<usize>();
            assert_eq!((snap.x.len(), snap.v.len()), (cells, 3 * cells), "{name}");
            view.write_frame(&mut frames, &snap).unwrap();
            let text = std::fs::read_to_string(dir.join(name).join("frame_00000.vti")).unwrap();
            let extent = format!("0 {} 0 {} 0 {}", dims[0], dims[1], if dims[2] == 1 { 0 } else { dims[2] });
            assert!(text.contains(&format!("WholeExtent=\"{extent}\"")), "{name}: {extent}");
            assert!(text.contains("Name=\"density\"") && text.contains("Name=\"velocity\""));
            // The picture follows the density: the smoke's cells are brighter than empty ones.
            let mut canvas = Canvas::new(40, 40, [255, 255, 255]);
            let camera = view.camera(1.0);
            view.draw(&mut canvas, &camera, &snap).unwrap();
            let (nx, ny) = (dims[0], dims[1]);
            let column_max =
                |i: usize, j: usize| (0..dims[2]).map(|k| snap.x[i + nx * (j + ny * k)]).fold(0.0, f64::max);
            let (mut hi, mut lo) = ((0, 0, 0.0), (0, 0, f64::MAX));
            for j in 0..ny {
                for i in 0..nx {
                    let d = column_max(i, j);
                    if d > hi.2 {
                        hi = (i, j, d);
                    }
                    if d < lo.2 {
                        lo = (i, j, d);
                    }
                }
            }
            assert!(hi.2 > lo.2, "{name}: no smoke");
            let pixel = |(i, j, _): (usize, usize, f64)| {
                let x = ((i as f64 + 0.5) / nx as f64 * 40.0) as u32;
                let y = 39 - ((j as f64 + 0.5) / ny as f64 * 40.0) as u32;
                let p = canvas.pixel(x, y);
                u32::from(p[0]) + u32::from(p[1]) + u32::from(p[2])
            };
            assert!(pixel(hi) > pixel(lo), "{name}: {hi:?} {lo:?}");
        }
        std::fs::remove_dir_all(&dir).ok();
    }

    /// Every particle-fluid preset at a tiny resolution: a few steps keep every value finite and
    /// every particle inside the tank (in the world frame, the tank's displacement added), and
    /// an error of the solver is the step's error.
    #[test]
    fn flip_presets_stay_finite_and_inside_their_tanks() {
        for name in anim_flip::scenes::NAMES {
            let mut runner = runner_of(name);
            let dt = scene::parse(scene::builtin(name).unwrap(), Path::new(name)).unwrap().run.dt;
            for _ in 0..4 {
                runner.step(dt).unwrap();
            }
            let s = runner.state();
            assert!(s.x.iter().chain(&s.v).all(|x| x.is_finite()), "{name}");
            assert!(!s.x.is_empty() && s.v.iter().any(|v| *v != 0.0), "{name}: nothing moves");
            let saved = runner.save();
            let (dim, x) = (saved["dim"].as_u64().unwrap() as usize, &saved["particles"]["x"]);
            let x: Vec<f64> = serde_json::from_value(x.clone()).unwrap();
            let scene =
                anim_flip::scenes::by_name(name, Some(if dim == 3 { 8 } else { 16 }), None).unwrap().unwrap();
            let (lo, hi, shift) = match &scene {
                anim_flip::scenes::FlipScene::Two(p) => {
                    let (lo, hi) = p.sim.fluid_box();
                    let m = p.sim.params().tank_motion;
                    (lo.to_vec(), hi.to_vec(), m.map_or(0.0, |m| m.displacement(s.t)))
                }
                anim_flip::scenes::FlipScene::Three(p) => {
                    let (lo, hi) = p.sim.fluid_box();
                    (lo.to_vec(), hi.to_vec(), 0.0)
                }
            };
            for (k, c) in x.chunks_exact(dim).enumerate() {
                for a in 0..dim {
                    assert!(c[a] >= lo[a] && c[a] <= hi[a], "{name}: particle {k} at {c:?}");
                }
                // The display (world frame, z up) is the tank frame shifted along x, the fluid's
                // y (up) as z and its z as -y.
                let expected = [c[0] + shift, if dim == 3 { -c[2] } else { 0.0 }, c[1]];
                for (a, e) in expected.iter().enumerate() {
                    assert_eq!(s.x[3 * k + a].to_bits(), e.to_bits(), "{name}: particle {k}");
                }
            }
            if name == "sloshing-tank" {
                assert!(shift != 0.0, "the tank does not move");
            }
            // Velocities whose grid sums overflow: the non-finite guard's error is the step's.
            let mut bad = saved.clone();
            let count = bad["particles"]["v"].as_array().unwrap().len();
            bad["particles"]["v"] = serde_json::json!(vec![1e308; count]);
            runner.restore(&bad).unwrap();
            let msg = runner.step(dt).unwrap_err();
            assert!(msg.contains("anim-flip: non-finite"), "{name}: {msg}");
            // A damaged checkpoint is refused and the runner keeps its state.
            let before = runner.save();
            bad["particles"]["x"][0] = serde_json::json!(f64::MAX);
            bad["particles"]["v"][0] = serde_json::Value::Null;
            assert!(runner.restore(&bad).is_err(), "{name}");
            bad["dim"] = serde_json::json!(5 - dim);
            assert!(runner.restore(&bad).unwrap_err().contains("checkpoint for a"), "{name}");
            assert_eq!(runner.save(), before, "{name}");
        }
        // Unknown presets and oversized grids built programmatically name the field.
        let scene = Scene::Flip { preset: "drop-4d".into(), resolution: None, transfer: None };
        let msg = build(&scene, Path::new("s.toml"), None).err().unwrap().to_string();
        assert!(
            msg.contains("`scene.preset`") && msg.contains("drop-4d") && msg.contains("sloshing-tank"),
            "{msg}"
        );
        let scene = Scene::Flip { preset: "drop-3d".into(), resolution: Some(1000), transfer: None };
        let msg = build(&scene, Path::new("s.toml"), None).err().unwrap().to_string();
        assert!(msg.contains("`scene.resolution`") && msg.contains("128"), "{msg}");
        let scene = Scene::Flip { preset: "drop-2d".into(), resolution: Some(2), transfer: None };
        let msg = build(&scene, Path::new("s.toml"), None).err().unwrap().to_string();
        assert!(msg.contains("`scene.resolution`") && msg.contains("cells[0]"), "{msg}");
    }

    #[test]
    fn kepler_runner_reports_the_exact_error() {
        let mut runner = runner_of("kepler");
        assert_eq!(runner.exact_error(), Some(0.0));
        for _ in 0..100 {
            runner.step(0.005).unwrap();
        }
        let err = runner.exact_error().unwrap();
        assert!(err > 0.0 && err < 1e-4, "{err}");
    }
}
