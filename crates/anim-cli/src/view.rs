//! What a scene looks like, apart from how it is stepped: its [`Geometry`] (fixed for the run)
//! and per-frame [`Snapshot`]s. A [`View`] turns the two into frame files and preview images; it
//! is `Send`, so the run loop hands snapshots to a writer thread and keeps stepping.
//!
//! Scenes are y up (anim-core's view contract): a 3-D scene is seen from the front (`+z`), a
//! little from the left and from above, y up on the picture; a 2-D scene (the xy plane) is drawn
//! as it is, orthographic, x right and y up. The camera of a 3-D or 2-D particle scene frames
//! everything the run's points reached ([`View::see`] on every frame, then [`View::camera`]),
//! the obstacles and the ground; the region the context names is the fallback of a run that
//! saw no finite point (its guess of the motion, widened sideways and downward, would leave
//! most of the picture empty once the motion is known).

use anim_core::scene::{Context, DynScene, Frame, MeshProp, Prop};
use anim_io::preview::{Camera, Canvas, Colors, MeshStyle, Shading};
use anim_io::{DataArray, FrameFormat, FrameWriter, ImageData, UnstructuredGrid};

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

/// The state at one frame, copied out of the simulation.
#[derive(Debug, Clone, Default)]
pub struct Snapshot {
    /// Simulated time.
    pub t: f64,
    /// Positions (flat); for a [`Geometry::Grid`], the density per cell.
    pub x: Vec<f64>,
    /// Velocities (flat); for a [`Geometry::Grid`], the velocity per cell (3 components).
    pub v: Vec<f64>,
    /// Total energy, where defined.
    pub energy: Option<f64>,
    /// Error against an exact solution, where one exists.
    pub error: Option<f64>,
    /// Coordinates per point of `x` (not a grid).
    pub point_dim: usize,
    /// Every named field of the frame (not a grid's), for the browser viewer.
    pub fields: Vec<anim_core::scene::Field>,
    /// The props that move with the scene, where they are at this frame ([`Frame::props`]).
    pub props: Vec<Prop>,
}

impl Snapshot {
    /// The scene's current frame: for a grid, its first field (the density) as `x` and its
    /// velocity as `v`; otherwise the points as `x` and the velocity field as `v`. `frame` is
    /// scratch reused from call to call.
    pub fn fill(&mut self, scene: &dyn DynScene, frame: &mut Frame, grid: bool, energy: Option<f64>) {
        scene.frame(frame);
        self.t = frame.time;
        self.x.clear();
        self.v.clear();
        let velocity = frame.fields.iter().find(|f| f.name == "velocity");
        if grid {
            if let Some(density) = frame.fields.iter().find(|f| f.name != "velocity") {
                self.x.extend_from_slice(&density.values);
            }
        } else {
            self.x.extend_from_slice(&frame.points);
            // Reuse the buffers of the previous frame's fields.
            self.fields.truncate(frame.fields.len());
            for (k, f) in frame.fields.iter().enumerate() {
                match self.fields.get_mut(k) {
                    Some(mine) => mine.clone_from(f),
                    None => self.fields.push(f.clone()),
                }
            }
        }
        if let Some(v) = velocity {
            self.v.extend_from_slice(&v.values);
        }
        self.props.clone_from(&frame.props);
        self.energy = energy;
        self.error = scene.reference_error();
    }
}

/// How a scene is drawn and written; fixed for the run.
#[derive(Debug, Clone)]
pub enum Geometry {
    /// A point moving in the plane (1 or 2 coordinates), with its trail; `sun` draws the
    /// attracting centre at the origin, otherwise a spring from the left edge.
    Planar {
        /// Region shown.
        extent: ([f64; 2], [f64; 2]),
        /// Whether to draw a sun at the origin (else a wall spring).
        sun: bool,
    },
    /// 3-D particles (flat `x = [x0, y0, z0, x1, ...]`) with optional surface triangles and
    /// springs drawn as lines.
    Particles {
        /// Surface triangles (drawn shaded when present).
        triangles: Vec<[usize; 3]>,
        /// Tetrahedra of a volume mesh: what `.vtu` frames hold (their boundary is `triangles`,
        /// what the other formats and the preview show).
        tetrahedra: Vec<[usize; 4]>,
        /// Line segments (springs), drawn when there is no surface.
        edges: Vec<[usize; 2]>,
        /// Points the scene holds in place (pins, clamps, attachments), marked dark.
        pins: Vec<usize>,
        /// Particle disc radius in world units (0: none drawn).
        radius: f64,
        /// Height of a ground plane `y = h`, if any.
        ground: Option<f64>,
        /// What surrounds the bodies: spheres, boxes and capsules (colliders) drawn solid, a
        /// tank's walls drawn as its edges.
        obstacles: Vec<Prop>,
        /// Obstacles of triangles (the user's closed surfaces), drawn solid.
        meshes: Vec<MeshProp>,
        /// The region the context names ([`Context::bounds`]): what the picture frames when no
        /// point was seen; otherwise the points of the whole run and the obstacles are.
        frame_box: ([f64; 3], [f64; 3]),
        /// A 2-D scene in the xy plane ([`Context::planar`]), drawn as such.
        planar: bool,
    },
    /// Fields on a regular grid of cells (a fluid): the snapshot's `x` holds the density per
    /// cell and `v` the velocity per cell, x fastest, then y, then z. Frames are `.vti` image
    /// data (cell fields `density` and `velocity`); the preview shows the density through
    /// viridis, a 3D grid as its maximum along z (the view axis, y up).
    Grid {
        /// Cells along x, y, z (1 along z in 2D).
        dims: [usize; 3],
        /// 2 or 3.
        dim: usize,
        /// Cell size (the grid's corner is at the origin).
        spacing: f64,
        /// Density shown as the ends of the colour scale (fixed for the run).
        range: (f64, f64),
        /// The grid's lower corner.
        origin: [f64; 3],
        /// Colliders in the grid (a sphere the smoke rises around), drawn over the field.
        obstacles: Vec<Prop>,
        /// Obstacles of triangles (the user's closed surfaces), drawn over the field.
        meshes: Vec<MeshProp>,
    },
}

impl Geometry {
    /// How a scene with `context` is drawn and written: an image grid's fields, a system of a
    /// few unknowns in the plane (with the attractor or anchor the context names), or points in
    /// 3-D with their triangles or lines, the ground and the obstacles of the context.
    #[must_use]
    pub fn from_context(context: &Context) -> Self {
        if let Some(image) = &context.image {
            return Geometry::Grid {
                dims: image.dims,
                dim: image.dim,
                spacing: image.spacing,
                range: image.range,
                origin: image.origin,
                obstacles: context
                    .props
                    .iter()
                    .filter(|p| matches!(p, Prop::Sphere { .. } | Prop::Cuboid { .. } | Prop::Capsule { .. }))
                    .copied()
                    .collect(),
                meshes: context.mesh_props.clone(),
            };
        }
        let bounds = context.bounds.unwrap_or(([-1.0; 3], [1.0; 3]));
        if context.point_dim < 3 {
            let sun = context.props.iter().any(|p| matches!(p, Prop::Attractor { .. }));
            return Geometry::Planar {
                extent: ([bounds.0[0], bounds.0[1]], [bounds.1[0], bounds.1[1]]),
                sun,
            };
        }
        let mut ground = None;
        let mut obstacles = Vec::new();
        for prop in &context.props {
            match *prop {
                Prop::Ground { height } => ground = Some(height),
                Prop::Sphere { .. } | Prop::Cuboid { .. } | Prop::Capsule { .. } | Prop::Tank { .. } => {
                    obstacles.push(*prop);
                }
                _ => {}
            }
        }
        Geometry::Particles {
            triangles: context.triangles.clone(),
            tetrahedra: context.tetrahedra.clone(),
            edges: context.lines.clone(),
            pins: context.pins.clone(),
            radius: context.point_radius,
            ground,
            obstacles,
            meshes: context.mesh_props.clone(),
            frame_box: bounds,
            planar: context.planar,
        }
    }

    /// The frame format that suits the geometry: image data for grids, a CSV table for a few
    /// unknowns, VTK unstructured grids otherwise.
    #[must_use]
    pub fn natural_format(&self) -> OutputFormat {
        match self {
            Geometry::Grid { .. } => OutputFormat::Vti,
            Geometry::Planar { .. } => OutputFormat::Csv,
            Geometry::Particles { .. } => OutputFormat::Vtu,
        }
    }

    /// Whether frames of this geometry can be written in `format`: grids as `vti` (or none),
    /// everything else in any format but `vti`.
    #[must_use]
    pub fn accepts(&self, format: OutputFormat) -> bool {
        match self {
            Geometry::Grid { .. } => matches!(format, OutputFormat::Vti | OutputFormat::None),
            _ => format != OutputFormat::Vti,
        }
    }

    /// Width over height of the picture the geometry wants (a grid's cross-section), if any.
    #[must_use]
    pub fn aspect(&self) -> Option<f64> {
        match self {
            Geometry::Grid { dims, .. } => Some(dims[0] as f64 / dims[1].max(1) as f64),
            _ => None,
        }
    }
}

/// The direction a 3-D scene is seen along: toward `-z` (from the front), a little to the
/// right and down (from the left and above).
const VIEW_DIRECTION: [f64; 3] = [0.55, -0.45, -1.0];

/// The world's up, y.
const UP: [f64; 3] = [0.0, 1.0, 0.0];

/// Frame files and preview images from snapshots.
pub struct View {
    geometry: Geometry,
    /// The 2-D picture of a 3-D grid.
    projection: Vec<f64>,
    trail: Vec<[f64; 3]>,
    positions: Vec<[f64; 3]>,
    velocities: Vec<[f64; 3]>,
    vertices: Vec<usize>,
    /// The pins' positions in the frame drawn, scratch.
    pinned: Vec<[f64; 3]>,
    /// The bounding box of every finite point seen so far ([`View::see`]).
    seen: Option<([f64; 3], [f64; 3])>,
    /// The region the last [`View::camera`] framed (the ground is drawn under it).
    framed: ([f64; 3], [f64; 3]),
    /// What the points or cells are coloured by, and the ends of its colour scale.
    paint: Paint,
    range: (f64, f64),
    /// Colours per point and per segment, scratch.
    colors: Vec<[u8; 3]>,
    segment_colors: Vec<[u8; 3]>,
}

fn triples(flat: &[f64], out: &mut Vec<[f64; 3]>) {
    out.clear();
    out.extend(flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]));
}

fn planar(flat: &[f64]) -> [f64; 3] {
    [flat.first().copied().unwrap_or(0.0), flat.get(1).copied().unwrap_or(0.0), 0.0]
}

fn io<T>(r: Result<T, anim_io::IoError>) -> Result<T, String> {
    r.map_err(|e| e.to_string())
}

impl View {
    /// A view of `geometry`.
    pub fn new(geometry: Geometry) -> Self {
        Self {
            geometry,
            projection: Vec::new(),
            trail: Vec::new(),
            positions: Vec::new(),
            velocities: Vec::new(),
            vertices: Vec::new(),
            pinned: Vec::new(),
            seen: None,
            framed: ([-1.0; 3], [1.0; 3]),
            paint: Paint::Plain,
            range: (0.0, 1.0),
            colors: Vec::new(),
            segment_colors: Vec::new(),
        }
    }

    /// Colours the points (or a grid's cells) by `paint` over `range` in the pictures drawn
    /// from now on: [`View::draw`] then takes the painted values per point, or a grid's
    /// snapshot holds them in place of its density.
    pub fn paint(&mut self, paint: Paint, range: (f64, f64)) {
        self.paint = paint;
        self.range = range;
    }

    /// Takes in the points of a snapshot of a particle scene: the camera frames every finite
    /// point seen ([`View::camera`]). Other geometries have fixed pictures.
    pub fn see(&mut self, s: &Snapshot) {
        if !matches!(self.geometry, Geometry::Particles { .. }) {
            return;
        }
        let mut take = |p: [f64; 3]| {
            if p.iter().all(|c| c.is_finite()) {
                let (lo, hi) = self.seen.get_or_insert((p, p));
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
        };
        for p in s.x.chunks_exact(3) {
            take([p[0], p[1], p[2]]);
        }
        // The moving props are part of the picture too.
        for prop in &s.props {
            if let Some((lo, hi)) = extent(prop) {
                take(lo);
                take(hi);
            }
        }
    }

    /// The region a particle scene's picture frames: every point seen, a particle's radius
    /// around them, the obstacles (spheres, boxes, capsules, tanks, meshes) and the ground's
    /// height; the context's region when no point was seen.
    fn region(&self) -> ([f64; 3], [f64; 3]) {
        let Geometry::Particles { frame_box, radius, ground, obstacles, meshes, .. } = &self.geometry else {
            return self.framed;
        };
        let Some((a, b)) = self.seen else { return *frame_box };
        let (mut lo, mut hi) = (a.map(|v| v - radius), b.map(|v| v + radius));
        let mut take = |p: [f64; 3], r: f64| {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k] - r);
                hi[k] = hi[k].max(p[k] + r);
            }
        };
        for (corner, other) in obstacles.iter().filter_map(extent) {
            take(corner, 0.0);
            take(other, 0.0);
        }
        for p in meshes.iter().flat_map(|m| &m.positions) {
            take(*p, 0.0);
        }
        if let Some(y) = *ground {
            lo[1] = lo[1].min(y);
            hi[1] = hi[1].max(y);
        }
        (lo, hi)
    }

    /// Width over height of the picture the geometry wants, if any ([`Geometry::aspect`]).
    #[must_use]
    pub fn aspect(&self) -> Option<f64> {
        self.geometry.aspect()
    }

    /// Writes the snapshot as the next frame of a mesh/particle sequence (or, for a grid, of a
    /// `vti` sequence).
    pub fn write_frame(&mut self, frames: &mut FrameWriter, s: &Snapshot) -> Result<(), String> {
        match &self.geometry {
            Geometry::Planar { .. } => {
                let p = [planar(&s.x)];
                let v = [planar(&s.v)];
                let grid =
                    UnstructuredGrid::new(&p).vertices(&[0]).point_field(DataArray::vectors("velocity", &v));
                io(frames.write(s.t, &grid)).map(|_| ())
            }
            Geometry::Particles { triangles, tetrahedra, edges, .. } => {
                triples(&s.x, &mut self.positions);
                triples(&s.v, &mut self.velocities);
                if self.vertices.len() != self.positions.len() {
                    self.vertices = (0..self.positions.len()).collect();
                }
                let mut grid = UnstructuredGrid::new(&self.positions)
                    .point_field(DataArray::vectors("velocity", &self.velocities));
                // Every other field of the frame (material ids, strain), as it is.
                for f in s.fields.iter().filter(|f| f.name != "velocity") {
                    grid = grid.point_field(DataArray::new(f.name, f.components, f.values.as_slice()));
                }
                grid = if !tetrahedra.is_empty() && frames.format() == FrameFormat::Vtu {
                    grid.tetrahedra(tetrahedra)
                } else if !triangles.is_empty() {
                    grid.triangles(triangles)
                } else if frames.format() == FrameFormat::Ply || edges.is_empty() {
                    grid.vertices(&self.vertices)
                } else {
                    grid.lines(edges)
                };
                io(frames.write(s.t, &grid)).map(|_| ())
            }
            Geometry::Grid { dims, dim, spacing, origin, .. } => {
                let h = *spacing;
                let image = if *dim == 2 {
                    ImageData::from_cells_2d([dims[0], dims[1]], [origin[0], origin[1]], [h; 2])
                } else {
                    ImageData::from_cells_3d(*dims, *origin, [h; 3])
                };
                let image = image
                    .cell_field(DataArray::scalars("density", &s.x))
                    .cell_field(DataArray::vectors("velocity", s.v.as_chunks::<3>().0));
                io(frames.write_image(s.t, &image)).map(|_| ())
            }
        }
    }

    /// A camera that keeps the whole motion in view, for an image of width over height
    /// `aspect`: for particles, everything seen so far ([`View::see`]) and the context's region,
    /// from the front and above (y up), or face on for a 2-D scene.
    pub fn camera(&mut self, aspect: f64) -> Camera {
        match &self.geometry {
            Geometry::Planar { extent, .. } => Camera::xy_plane(extent.0, extent.1, aspect),
            Geometry::Particles { planar, .. } => {
                let planar = *planar;
                let (lo, hi) = self.region();
                self.framed = (lo, hi);
                if planar {
                    Camera::xy_plane([lo[0], lo[1]], [hi[0], hi[1]], aspect)
                } else {
                    Camera::fitting(lo, hi, VIEW_DIRECTION, UP, aspect)
                }
            }
            Geometry::Grid { dims, spacing, origin, .. } => Camera::xy_plane(
                [origin[0], origin[1]],
                [origin[0] + dims[0] as f64 * spacing, origin[1] + dims[1] as f64 * spacing],
                aspect,
            ),
        }
    }

    /// Draws the snapshot; `painted` holds the painted field's value per point of a particle
    /// scene ([`View::paint`], [`Paint::values`]; empty for the bodies' own colours).
    pub fn draw(
        &mut self,
        canvas: &mut Canvas,
        camera: &Camera,
        s: &Snapshot,
        painted: &[f64],
    ) -> Result<(), String> {
        match &self.geometry {
            Geometry::Planar { extent, sun } => {
                let p = planar(&s.x);
                if self.trail.len() < 4096 {
                    self.trail.push(p);
                }
                let segments: Vec<[usize; 2]> = (1..self.trail.len()).map(|i| [i - 1, i]).collect();
                io(canvas.draw_lines(camera, &self.trail, &segments, 1.5, Colors::Uniform([150, 150, 170])))?;
                let scale = (extent.1[0] - extent.0[0]).max(extent.1[1] - extent.0[1]);
                if *sun {
                    io(canvas.draw_particles(
                        camera,
                        &[[0.0, 0.0, -0.1]],
                        0.06 * scale,
                        Colors::Uniform([240, 180, 40]),
                    ))?;
                } else {
                    let anchor = [extent.0[0], 0.0, 0.0];
                    io(canvas.draw_lines(
                        camera,
                        &[anchor, p],
                        &[[0, 1]],
                        2.0,
                        Colors::Uniform([90, 90, 90]),
                    ))?;
                }
                io(canvas.draw_particles(camera, &[p], 0.03 * scale, Colors::Uniform([60, 110, 200])))
            }
            Geometry::Particles {
                triangles, edges, pins, radius, ground, obstacles, meshes, planar, ..
            } => {
                triples(&s.x, &mut self.positions);
                for prop in obstacles.iter().chain(&s.props) {
                    draw_obstacle(canvas, camera, prop)?;
                }
                for mesh in meshes {
                    io(canvas.draw_mesh(camera, &mesh.positions, &mesh.triangles, &OBSTACLE_STYLE))?;
                }
                let (lo, hi) = self.framed;
                if let Some(y) = ground.filter(|_| !planar) {
                    // A floor under the framed region (not beyond it: corners behind the
                    // camera would clip the whole quad).
                    let quad = [[lo[0], y, lo[2]], [hi[0], y, lo[2]], [hi[0], y, hi[2]], [lo[0], y, hi[2]]];
                    let style = MeshStyle {
                        color: [200, 200, 195],
                        back_color: [200, 200, 195],
                        ..MeshStyle::default()
                    };
                    io(canvas.draw_mesh(camera, &quad, &[[0, 1, 2], [0, 2, 3]], &style))?;
                }
                let by_field = !painted.is_empty() && painted.len() == self.positions.len();
                if by_field {
                    self.paint.colors(painted, self.range, &mut self.colors);
                }
                let size = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
                if !triangles.is_empty() {
                    if by_field {
                        io(canvas.draw_mesh_colored(
                            camera,
                            &self.positions,
                            triangles,
                            &self.colors,
                            Shading::Smooth,
                        ))?;
                    } else {
                        io(canvas.draw_mesh(camera, &self.positions, triangles, &MeshStyle::default()))?;
                    }
                } else {
                    let colors = if by_field {
                        self.segment_colors.clear();
                        self.segment_colors.extend(edges.iter().map(|e| self.colors[e[0]]));
                        Colors::PerItem(&self.segment_colors)
                    } else {
                        Colors::Uniform([70, 70, 90])
                    };
                    let width = line_width(edges.len(), canvas.height());
                    io(canvas.draw_lines(camera, &self.positions, edges, width, colors))?;
                    if *radius > 0.0 {
                        let colors = if by_field {
                            Colors::PerItem(&self.colors)
                        } else {
                            Colors::Uniform([200, 90, 60])
                        };
                        io(canvas.draw_particles(camera, &self.positions, *radius, colors))?;
                    }
                }
                // Pins: dark beads a little larger than the particles, over the body.
                self.pinned.clear();
                self.pinned.extend(pins.iter().filter_map(|&i| self.positions.get(i).copied()));
                if !self.pinned.is_empty() {
                    let bead = (1.6 * radius).max(0.011 * size);
                    io(canvas.draw_particles(camera, &self.pinned, bead, Colors::Uniform(PIN)))?;
                }
                Ok(())
            }
            Geometry::Grid { dims, dim, range, obstacles, meshes, .. } => {
                let [nx, ny, nz] = *dims;
                if s.x.len() != nx * ny * nz {
                    return Err(format!("{} values for a {nx} x {ny} x {nz} grid", s.x.len()));
                }
                let range = if self.paint == Paint::Plain { *range } else { self.range };
                if *dim == 2 {
                    io(canvas.draw_scalar_field(&s.x, nx, ny, Some(range)))?;
                } else {
                    // Maximum along z: what looking through the smoke along the view axis shows.
                    self.projection.clear();
                    self.projection.extend_from_slice(&s.x[..nx * ny]);
                    for layer in s.x.chunks_exact(nx * ny).skip(1) {
                        for (p, &d) in self.projection.iter_mut().zip(layer) {
                            *p = p.max(d);
                        }
                    }
                    io(canvas.draw_scalar_field(&self.projection, nx, ny, Some(range)))?;
                }
                // The obstacles the fluid flows around, seen along the same axis.
                for prop in obstacles {
                    draw_obstacle(canvas, camera, prop)?;
                }
                for mesh in meshes {
                    io(canvas.draw_mesh(camera, &mesh.positions, &mesh.triangles, &OBSTACLE_STYLE))?;
                }
                Ok(())
            }
        }
    }
}

/// The colour of pins: near black, apart from every body's colour.
const PIN: [u8; 3] = [35, 35, 45];

/// The width in pixels of `segments` line segments on a picture `height` pixels high: a few
/// links (a robot's, a pendulum chain's) drawn as bars, a rope's hundred as a cord, a
/// network of thousands of springs as threads.
fn line_width(segments: usize, height: u32) -> f64 {
    let h = f64::from(height);
    if segments <= 40 {
        (h / 70.0).max(2.0)
    } else if segments <= 400 {
        (h / 140.0).max(1.5)
    } else {
        (h / 400.0).max(1.0)
    }
}

mod paint;
mod props;
#[cfg(test)]
mod tests;

pub use paint::{MATERIAL, Paint, SPEED};
use props::{OBSTACLE_STYLE, draw_obstacle, extent};
