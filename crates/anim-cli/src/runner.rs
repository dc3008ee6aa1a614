//! The runnable form of a scene: one [`Runner`] per kind of system, so that the run loop, the
//! frame writers and the preview treat every crate's scenes alike.

use crate::scene::{Scene, SceneError};
use anim_core::integrate::systems::{HarmonicOscillator, KeplerOrbit};
use anim_core::integrate::{MechanicalSystem, Simulation, State};
use anim_core::solver::{Solver, StepReport};
use anim_io::preview::{Camera, Canvas, Colors, MeshStyle};
use anim_io::{DataArray, FrameFormat, FrameWriter, UnstructuredGrid};
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
    /// Error of the current state against an exact solution, where one exists.
    fn exact_error(&self) -> Option<f64> {
        None
    }
    /// The frame format that suits the scene.
    fn natural_format(&self) -> OutputFormat;
    /// Writes the current state as one frame of a mesh/particle sequence.
    fn write_frame(&self, frames: &mut FrameWriter) -> Result<(), String>;
    /// A camera that keeps the whole motion in view, chosen from the initial state.
    fn camera(&self, aspect: f64) -> Camera;
    /// Draws the current state.
    fn draw(&mut self, canvas: &mut Canvas, camera: &Camera) -> Result<(), String>;
}

/// Frame formats the command line offers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
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
            OutputFormat::Csv | OutputFormat::None => None,
        }
    }
}

/// Builds the runner of a scene; `base` is the scene file's folder, for relative paths.
pub fn build(scene: &Scene, file: &Path) -> Result<Box<dyn Runner>, SceneError> {
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
                trail: Vec::new(),
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
                trail: Vec::new(),
                extent: ([-1.0 - eccentricity - 0.1, -b - 0.1], [1.0 - eccentricity + 0.1, b + 0.1]),
            })
        }
        Scene::Springs { ref preset, resolution, integrator, linear_solver } => {
            let mut s = match spring_scenes::by_name(preset, resolution) {
                Some(Ok(s)) => s,
                Some(Err(e)) => return Err(SceneError::invalid(file, "scene.resolution", e.to_string())),
                None => {
                    return Err(SceneError::invalid(
                        file,
                        "scene.preset",
                        format!("unknown preset `{preset}` (one of {})", spring_scenes::NAMES.join(", ")),
                    ));
                }
            };
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

/// A system of a few unknowns with an exact solution, drawn in the plane.
struct OdeRunner {
    name: &'static str,
    sim: Simulation<dyn MechanicalSystem + Send>,
    method: String,
    state: State,
    exact: Box<dyn Fn(&State) -> f64>,
    /// Past positions in the plane, for the preview.
    trail: Vec<[f64; 3]>,
    /// Plane region shown by the preview.
    extent: ([f64; 2], [f64; 2]),
}

impl OdeRunner {
    fn point(&self) -> [f64; 3] {
        [self.state.x[0], self.state.x.get(1).copied().unwrap_or(0.0), 0.0]
    }
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

    fn exact_error(&self) -> Option<f64> {
        Some((self.exact)(&self.state))
    }

    fn natural_format(&self) -> OutputFormat {
        OutputFormat::Csv
    }

    fn write_frame(&self, frames: &mut FrameWriter) -> Result<(), String> {
        let p = [self.point()];
        let v = [[self.state.v[0], self.state.v.get(1).copied().unwrap_or(0.0), 0.0]];
        let grid = UnstructuredGrid::new(&p).vertices(&[0]).point_field(DataArray::vectors("velocity", &v));
        frames.write(self.state.t, &grid).map(|_| ()).map_err(|e| e.to_string())
    }

    fn camera(&self, aspect: f64) -> Camera {
        Camera::top_down_2d(self.extent.0, self.extent.1, aspect)
    }

    fn draw(&mut self, canvas: &mut Canvas, camera: &Camera) -> Result<(), String> {
        let p = self.point();
        if self.trail.len() < 4096 {
            self.trail.push(p);
        }
        let segments: Vec<[usize; 2]> = (1..self.trail.len()).map(|i| [i - 1, i]).collect();
        let e = |r: Result<(), anim_io::IoError>| r.map_err(|e| e.to_string());
        e(canvas.draw_lines(camera, &self.trail, &segments, 1.5, Colors::Uniform([150, 150, 170])))?;
        let scale = (self.extent.1[0] - self.extent.0[0]).max(self.extent.1[1] - self.extent.0[1]);
        if self.name == "kepler-orbit" {
            e(canvas.draw_particles(
                camera,
                &[[0.0, 0.0, -0.1]],
                0.06 * scale,
                Colors::Uniform([240, 180, 40]),
            ))?;
        } else {
            // The spring from the wall at the left edge to the mass.
            let anchor = [self.extent.0[0], 0.0, 0.0];
            e(canvas.draw_lines(camera, &[anchor, p], &[[0, 1]], 2.0, Colors::Uniform([90, 90, 90])))?;
        }
        e(canvas.draw_particles(camera, &[p], 0.03 * scale, Colors::Uniform([60, 110, 200])))
    }
}

/// A spring network: cloth drawn as a shaded mesh, ropes and lattices as springs and particles.
struct SpringRunner {
    name: String,
    method: String,
    sim: SpringSimulation,
    state: State,
    positions: Vec<[f64; 3]>,
    edges: Vec<[usize; 2]>,
    vertices: Vec<usize>,
    /// The region the preview shows, from the initial state.
    frame_box: ([f64; 3], [f64; 3]),
}

impl SpringRunner {
    fn new(name: String, method: String, sim: SpringSimulation, state: State) -> Self {
        let network = sim.network();
        let edges = network.springs().iter().map(|s| [s.i, s.j]).collect();
        let vertices = (0..network.num_particles()).collect();
        let mut runner = Self {
            name,
            method,
            sim,
            state,
            positions: Vec::new(),
            edges,
            vertices,
            frame_box: ([0.0; 3], [0.0; 3]),
        };
        runner.refresh();
        runner.frame_box = runner.initial_frame_box();
        runner
    }

    /// The initial bounding box widened sideways by a third of its size and extended down along
    /// gravity (-z) by its size (or to the ground): where the motion of the built-in scenes stays.
    fn initial_frame_box(&self) -> ([f64; 3], [f64; 3]) {
        let (mut lo, mut hi) = ([f64::MAX; 3], [f64::MIN; 3]);
        for p in &self.positions {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let size = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max).max(1e-3);
        for k in 0..2 {
            lo[k] -= size / 3.0;
            hi[k] += size / 3.0;
        }
        lo[2] = (hi[2] - 1.3 * size).min(lo[2]);
        if let Some(z) = self.ground() {
            lo[2] = z;
        }
        (lo, hi)
    }

    fn refresh(&mut self) {
        self.sim.network().positions_into(&self.state.x, &mut self.positions);
    }

    fn has_surface(&self) -> bool {
        !self.sim.network().triangles().is_empty()
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
        let report = self.sim.step(&mut self.state, dt).map_err(|e| e.to_string())?;
        self.refresh();
        Ok(report)
    }

    fn natural_format(&self) -> OutputFormat {
        OutputFormat::Vtu
    }

    fn write_frame(&self, frames: &mut FrameWriter) -> Result<(), String> {
        let n = self.positions.len();
        let v: Vec<[f64; 3]> =
            (0..n).map(|i| [self.state.v[3 * i], self.state.v[3 * i + 1], self.state.v[3 * i + 2]]).collect();
        let mut grid = UnstructuredGrid::new(&self.positions).point_field(DataArray::vectors("velocity", &v));
        let triangles = self.sim.network().triangles();
        grid = if self.has_surface() {
            grid.triangles(triangles)
        } else if frames.format() == FrameFormat::Ply {
            grid.vertices(&self.vertices)
        } else {
            grid.lines(&self.edges)
        };
        frames.write(self.state.t, &grid).map(|_| ()).map_err(|e| e.to_string())
    }

    fn camera(&self, aspect: f64) -> Camera {
        let _ = aspect;
        let (lo, hi) = self.frame_box;
        Camera::framing(lo, hi, [0.55, 1.0, -0.45], [0.0, 0.0, 1.0])
    }

    fn draw(&mut self, canvas: &mut Canvas, camera: &Camera) -> Result<(), String> {
        let e = |r: Result<(), anim_io::IoError>| r.map_err(|e| e.to_string());
        if let Some(z) = self.ground() {
            // A floor under the framed region (not beyond it: corners behind the camera would
            // clip the whole quad).
            let (lo, hi) = self.frame_box;
            let quad = [[lo[0], lo[1], z], [hi[0], lo[1], z], [hi[0], hi[1], z], [lo[0], hi[1], z]];
            let style =
                MeshStyle { color: [200, 200, 195], back_color: [200, 200, 195], ..MeshStyle::default() };
            e(canvas.draw_mesh(camera, &quad, &[[0, 1, 2], [0, 2, 3]], &style))?;
        }
        if self.has_surface() {
            e(canvas.draw_mesh(
                camera,
                &self.positions,
                self.sim.network().triangles(),
                &MeshStyle::default(),
            ))
        } else {
            e(canvas.draw_lines(camera, &self.positions, &self.edges, 1.0, Colors::Uniform([70, 70, 90])))?;
            let radius = 0.15 * self.mean_spring_length();
            e(canvas.draw_particles(camera, &self.positions, radius, Colors::Uniform([200, 90, 60])))
        }
    }
}

impl SpringRunner {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene;

    fn runner_of(name: &str) -> Box<dyn Runner> {
        let text = scene::builtin(name).unwrap();
        let file = scene::parse(text, Path::new(name)).unwrap();
        build(&file.scene, Path::new(name)).unwrap()
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
            runner.write_frame(&mut frames).unwrap();
            assert_eq!(frames.sequence().frames().len(), 1, "{name}");
            let mut canvas = Canvas::new(64, 48, [255, 255, 255]);
            let camera = runner.camera(64.0 / 48.0);
            runner.draw(&mut canvas, &camera).unwrap();
            let drawn = canvas.pixels().iter().filter(|p| **p != [255, 255, 255]).count();
            assert!(drawn > 20, "{name}: only {drawn} pixels drawn");
        }
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn unknown_preset_and_bad_resolution_name_their_fields() {
        let text = scene::builtin("cloth").unwrap().replace("hanging-cloth", "flying-carpet");
        let file = scene::parse(&text, Path::new("s.toml")).unwrap();
        let msg = build(&file.scene, Path::new("s.toml")).err().unwrap().to_string();
        assert!(
            msg.contains("s.toml") && msg.contains("`scene.preset`") && msg.contains("flying-carpet"),
            "{msg}"
        );
        let text = scene::builtin("cloth").unwrap().replace("resolution = 32", "resolution = 1");
        let file = scene::parse(&text, Path::new("s.toml")).unwrap();
        let msg = build(&file.scene, Path::new("s.toml")).err().unwrap().to_string();
        assert!(msg.contains("`scene.resolution`"), "{msg}");
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
