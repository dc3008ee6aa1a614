//! [`View`]: what a scene looks like, apart from how it is stepped.
//!
//! Everything a view gives is in one right-handed world frame with **y up** and gravity along
//! `-y`, as in glTF, three.js and Bevy: every [`Frame`] (points and vector fields) and every
//! part of the [`Context`] (props, mesh props, bounds, image grids). A 2D scene lies in the xy
//! plane (`z = 0`, [`Context::planar`]), x to the right and y up. A crate whose solver works z
//! up (gravity along `-z`) builds its context and frames in its own frame and turns them at the
//! end with [`Context::turn_z_up`] and [`Frame::turn_z_up`]: the rotation
//! `(x, y, z) -> (x, z, -y)` about x ([`turn_z_up`]), which keeps lengths, angles and
//! handedness. Scene files keep each solver's own coordinates.

use crate::geometry::Shape;
use crate::solver::Solver;
use crate::surface::ClosedSurface;

/// The static part of a scene's picture, fixed for the run: the cells that join the points,
/// the props around them (ground, colliders, walls), pinned points and the region the motion
/// stays in. Built once by [`View::context`].
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize)]
#[non_exhaustive]
pub struct Context {
    /// Coordinates per point in a [`Frame`]: 1 or 2 for a system of a few unknowns drawn in the
    /// plane (an oscillator, an orbit), 3 for particles and meshes. 0 for an image grid, whose
    /// frames have no points.
    pub point_dim: usize,
    /// Whether the scene is 2D: its points (3 coordinates each) lie in the xy plane, `z = 0`,
    /// and are drawn as such, looking along `-z` with x to the right and y up.
    pub planar: bool,
    /// Line segments between points (springs, rope links, robot links).
    pub lines: Vec<[usize; 2]>,
    /// Surface triangles (cloth, the boundary of a solid), counter-clockwise seen from outside.
    pub triangles: Vec<[usize; 3]>,
    /// Tetrahedra of a volume mesh.
    pub tetrahedra: Vec<[usize; 4]>,
    /// Points held in place by the scene (pins, clamped vertices, attachments).
    pub pins: Vec<usize>,
    /// Radius of a point when drawn as a disc (particles), in metres; 0 for none.
    pub point_radius: f64,
    /// What surrounds the points: ground, colliders, walls, attractors.
    pub props: Vec<Prop>,
    /// Obstacles of triangles (the user's closed surfaces), drawn solid.
    pub mesh_props: Vec<MeshProp>,
    /// The region the motion of the scene stays in: corners `(lo, hi)`, for framing a picture.
    pub bounds: Option<([f64; 3], [f64; 3])>,
    /// The grid of an image scene (a grid fluid), whose frames hold cell fields and no points.
    pub image: Option<ImageGrid>,
    /// What the user should know about how the scene was read: parts of an input file that
    /// were skipped or ignored (a loader's warnings), one sentence each. The `anim` command
    /// prints them when a run starts and keeps them in its metrics.
    pub notes: Vec<String>,
}

/// A thing in the scene that is not simulated but is part of its picture.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
#[non_exhaustive]
pub enum Prop {
    /// The ground plane `y = height`.
    Ground {
        /// Height of the plane (m).
        height: f64,
    },
    /// A static sphere (a collider).
    Sphere {
        /// Centre (m).
        center: [f64; 3],
        /// Radius (m).
        radius: f64,
    },
    /// A static capsule: the points within `radius` of the segment `a`-`b`.
    Capsule {
        /// One end of the axis (m).
        a: [f64; 3],
        /// The other end (m).
        b: [f64; 3],
        /// Radius (m).
        radius: f64,
    },
    /// An axis-aligned solid box (a collider).
    Cuboid {
        /// Lower corner (m).
        lo: [f64; 3],
        /// Upper corner (m).
        hi: [f64; 3],
    },
    /// The walls of an open-topped tank that holds the scene (a fluid's container), inner
    /// corners.
    Tank {
        /// Lower inner corner (m).
        lo: [f64; 3],
        /// Upper inner corner (m).
        hi: [f64; 3],
    },
    /// A fixed attracting centre (the sun of an orbit).
    Attractor {
        /// Position.
        at: [f64; 3],
    },
    /// A fixed anchor tied to point `point` (the wall end of an oscillator's spring).
    Anchor {
        /// Position of the anchor.
        at: [f64; 3],
        /// The point it is tied to.
        point: usize,
    },
}

/// A fixed obstacle of triangles in the picture (a closed surface from a scene file's
/// `obstacle_meshes`, placed), counter-clockwise seen from outside.
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize)]
pub struct MeshProp {
    /// Vertex positions (m).
    pub positions: Vec<[f64; 3]>,
    /// Triangles, three vertex indices each.
    pub triangles: Vec<[usize; 3]>,
}

impl From<&ClosedSurface> for MeshProp {
    fn from(surface: &ClosedSurface) -> Self {
        MeshProp {
            positions: surface.positions().iter().map(|p| p.to_array()).collect(),
            triangles: surface.triangles().to_vec(),
        }
    }
}

impl Prop {
    /// The prop a collider shape is drawn as: a sphere, capsule or box (a cuboid), in the
    /// shape's own frame (a z-up crate turns its context after, [`Context::turn_z_up`]). Planes
    /// are `None`: the previews draw only the ground ([`ground_height`]).
    #[must_use]
    pub fn of_shape(shape: &Shape) -> Option<Self> {
        match *shape {
            Shape::Sphere { center, radius } => Some(Prop::Sphere { center, radius }),
            Shape::Capsule { a, b, radius } => Some(Prop::Capsule { a, b, radius }),
            Shape::Box { center, half_extents: h } => Some(Prop::Cuboid {
                lo: [center[0] - h[0], center[1] - h[1], center[2] - h[2]],
                hi: [center[0] + h[0], center[1] + h[1], center[2] + h[2]],
            }),
            Shape::Plane { .. } => None,
        }
    }
}

/// The axis that points up in a solver's own frame: y in the frames every view gives and in the
/// y-up solvers (MPM, FLIP, grid fluids), z in the z-up ones (springs, PBD, FEM, rigid bodies).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Up {
    /// `+y` up, gravity along `-y`: the frame of every [`Frame`] and [`Context`].
    Y,
    /// `+z` up, gravity along `-z`: turned y up by [`turn_z_up`](super::turn_z_up).
    Z,
}

impl Up {
    /// The index of the axis: 1 for y, 2 for z.
    #[must_use]
    pub fn axis(self) -> usize {
        match self {
            Up::Y => 1,
            Up::Z => 2,
        }
    }
}

/// The height along `up` of the first plane among `shapes` whose normal points straight up
/// along it (`+y` or `+z`, any length): the ground a preview draws, in the frame of `shapes`.
/// The plane `z = h` of a z-up solver is the ground `y = h` once turned ([`turn_z_up`](super::turn_z_up)).
pub fn ground_height<'a>(shapes: impl IntoIterator<Item = &'a Shape>, up: Up) -> Option<f64> {
    let a = up.axis();
    shapes.into_iter().find_map(|s| match *s {
        Shape::Plane { point, normal } if (0..3).all(|k| k == a || normal[k] == 0.0) && normal[a] > 0.0 => {
            Some(point[a])
        }
        _ => None,
    })
}

/// A regular grid of cells whose fields an image scene writes.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ImageGrid {
    /// Cells along x, y, z (1 along z in 2D).
    pub dims: [usize; 3],
    /// 2 or 3.
    pub dim: usize,
    /// Lower corner of the grid (m).
    pub origin: [f64; 3],
    /// Cell size (m).
    pub spacing: f64,
    /// The name of the scalar field a picture shows (`"density"`).
    pub shown: &'static str,
    /// The values at the ends of the colour scale of that field, fixed for the run.
    pub range: (f64, f64),
}

impl ImageGrid {
    /// Number of cells.
    #[must_use]
    pub fn cells(&self) -> usize {
        self.dims.iter().product()
    }
}

/// One named field of a frame, per point or (for an image grid) per cell, x fastest.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Field {
    /// Its name in the frame files (`"velocity"`, `"density"`).
    pub name: &'static str,
    /// Components per point or cell (1 for a scalar, 3 for a vector).
    pub components: usize,
    /// The values, `components` per point or cell.
    pub values: Vec<f64>,
}

/// A scene at one output time: the points (flat, [`Context::point_dim`] per point) and named
/// fields. Buffers are reused from frame to frame: [`View::frame`] overwrites them in place.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Frame {
    /// Simulated time (s).
    pub time: f64,
    /// Point coordinates, flat.
    pub points: Vec<f64>,
    /// Named fields, in a fixed order per scene (velocity first, where there is one).
    pub fields: Vec<Field>,
    /// Props that move with the scene, where they are at this frame's time (a kinematic body
    /// drawn with the shape it is given, such as the flag's swaying pole); the fixed props are
    /// the context's ([`Context::props`]). Empty for most scenes.
    pub props: Vec<Prop>,
}

impl Frame {
    /// Number of points.
    #[must_use]
    pub fn len(&self, point_dim: usize) -> usize {
        self.points.len().checked_div(point_dim).unwrap_or(0)
    }

    /// The field named `name`, if the frame has one.
    #[must_use]
    pub fn field(&self, name: &str) -> Option<&Field> {
        self.fields.iter().find(|f| f.name == name)
    }

    /// The values of field `name` with `components` per element, emptied for refilling: the
    /// field is created the first time and its buffer reused after, so a frame written into the
    /// same `Frame` allocates nothing once the sizes are reached.
    pub fn field_mut(&mut self, name: &'static str, components: usize) -> &mut Vec<f64> {
        let at = match self.fields.iter().position(|f| f.name == name) {
            Some(at) => at,
            None => {
                self.fields.push(Field { name, components, values: Vec::new() });
                self.fields.len() - 1
            }
        };
        let field = &mut self.fields[at];
        field.components = components;
        field.values.clear();
        &mut field.values
    }
}

/// The region the motion of a scene starting at `points` (flat, 3 per point, `up` the axis that
/// points up in their frame: y for a view's frames) stays in, for [`Context::bounds`]: their
/// bounding box widened sideways (the two other axes) by a third of its size, when `falls`
/// extended down along gravity (`-y`, or `-z` for [`Up::Z`]) to 1.3 times its size below its
/// top, and down to the ground (the height along `up`) when there is one. `([-1; 3], [1; 3])`
/// for no points. A z-up crate frames its own points and turns the box with its context
/// ([`Context::turn_z_up`]).
#[must_use]
pub fn frame_box(points: &[f64], up: Up, ground: Option<f64>, falls: bool) -> ([f64; 3], [f64; 3]) {
    let (mut lo, mut hi) = ([f64::MAX; 3], [f64::MIN; 3]);
    for p in points.chunks_exact(3) {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    if lo[0] > hi[0] {
        return ([-1.0; 3], [1.0; 3]);
    }
    let size = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max).max(1e-3);
    let a = up.axis();
    for k in (0..3).filter(|&k| k != a) {
        lo[k] -= size / 3.0;
        hi[k] += size / 3.0;
    }
    if falls {
        lo[a] = (hi[a] - 1.3 * size).min(lo[a]);
    }
    if let Some(h) = ground {
        lo[a] = h;
    }
    (lo, hi)
}

/// What a scene looks like: a description of its method, the static [`Context`] and a
/// [`Frame`] per output time.
pub trait View: Solver {
    /// The method in a few words, for run summaries: integrator, linear solver, transfer.
    fn method(&self) -> String;

    /// The static context of the run, from the initial state.
    fn context(&self, state: &Self::State) -> Context;

    /// The frame of `state`, written into `out`'s buffers (see [`Frame::field_mut`]).
    fn frame(&self, state: &Self::State, out: &mut Frame);

    /// The run's error so far against the reference the scene carries (an exact solution, a
    /// published table), where it has one.
    fn reference_error(&self, state: &Self::State) -> Option<f64> {
        let _ = state;
        None
    }
}

#[cfg(test)]
mod tests {
    use super::{Prop, Shape, Up, frame_box, ground_height};

    #[test]
    fn shapes_are_drawn_as_props_and_the_first_upward_plane_is_the_ground() {
        let b = Shape::Box { center: [1.0, 2.0, 3.0], half_extents: [0.5, 0.25, 2.0] };
        assert_eq!(Prop::of_shape(&b), Some(Prop::Cuboid { lo: [0.5, 1.75, 1.0], hi: [1.5, 2.25, 5.0] }));
        let s = Shape::Sphere { center: [0.0, 0.0, 1.0], radius: 0.5 };
        assert_eq!(Prop::of_shape(&s), Some(Prop::Sphere { center: [0.0, 0.0, 1.0], radius: 0.5 }));
        let c = Shape::Capsule { a: [0.0; 3], b: [0.0, 1.0, 0.0], radius: 0.1 };
        assert_eq!(Prop::of_shape(&c), Some(Prop::Capsule { a: [0.0; 3], b: [0.0, 1.0, 0.0], radius: 0.1 }));
        let plane = |z: f64, normal: [f64; 3]| Shape::Plane { point: [5.0, 5.0, z], normal };
        assert_eq!(Prop::of_shape(&plane(0.0, [0.0, 0.0, 1.0])), None);
        // A tilted or downward plane is no ground; an upward normal of any length is.
        let shapes = [
            plane(9.0, [0.0, 0.1, 1.0]),
            plane(8.0, [0.0, 0.0, -1.0]),
            s,
            plane(-0.5, [0.0, 0.0, 2.0]),
            plane(3.0, [0.0, 0.0, 1.0]),
        ];
        assert_eq!(ground_height(&shapes, Up::Z), Some(-0.5));
        assert_eq!(ground_height(&shapes[..3], Up::Z), None);
        // Up along y: the first plane of normal +y (any length), its point's y.
        assert_eq!(ground_height(&shapes, Up::Y), None);
        let at = |y: f64, normal: [f64; 3]| Shape::Plane { point: [5.0, y, 7.0], normal };
        let y_up = [
            at(1.0, [0.0, 0.0, 1.0]),
            at(2.0, [0.0, -1.0, 0.0]),
            at(3.0, [0.1, 1.0, 0.0]),
            at(4.0, [0.0, 0.5, 0.0]),
        ];
        assert_eq!(ground_height(&y_up, Up::Y), Some(4.0));
    }

    #[test]
    fn the_frame_box_frames_the_points_and_reaches_the_ground() {
        assert_eq!(frame_box(&[], Up::Y, None, true), ([-1.0; 3], [1.0; 3]));
        // Points from (0, 1, 0) to (3, 1, 0): size 3, widened by 1 on each side in x and z;
        // falling, down along -y to 1.3 sizes below the top, or to the ground.
        let x = [0.0, 1.0, 0.0, 3.0, 1.0, 0.0];
        assert_eq!(frame_box(&x, Up::Y, None, false), ([-1.0, 1.0, -1.0], [4.0, 1.0, 1.0]));
        assert_eq!(frame_box(&x, Up::Y, None, true).0, [-1.0, 1.0 - 1.3 * 3.0, -1.0]);
        assert_eq!(frame_box(&x, Up::Y, Some(0.25), true).0, [-1.0, 0.25, -1.0]);
        // The same points z up: from (0, 0, 1) to (3, 0, 1), widened in x and y, falling along -z.
        let x = [0.0, 0.0, 1.0, 3.0, 0.0, 1.0];
        assert_eq!(frame_box(&x, Up::Z, None, false), ([-1.0, -1.0, 1.0], [4.0, 1.0, 1.0]));
        assert_eq!(frame_box(&x, Up::Z, None, true).0[2], 1.0 - 1.3 * 3.0);
        assert_eq!(frame_box(&x, Up::Z, Some(0.25), true).0[2], 0.25);
    }
}
