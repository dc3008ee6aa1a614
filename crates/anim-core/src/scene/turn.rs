//! The one conversion from a z-up solver's frame to the y-up frame of every [`Frame`] and
//! [`Context`] ([`super::view`]): the rotation by a quarter turn about x,
//! `(x, y, z) -> (x, z, -y)`. It takes `+z` (up) to `+y`, keeps `x`, and sends `+y` to `-z`; a
//! proper rotation (determinant 1), so lengths, angles, handedness and the orientation of
//! triangles are kept. A z-up crate builds its context and frames in its own frame and turns
//! them last, in [`View::context`](super::View::context) and
//! [`View::frame`](super::View::frame).
//!
//! ```
//! use anim_core::scene::{Context, Frame, Prop, turn_z_up};
//!
//! // A point 1 m above the origin of a z-up solver is 1 m above it y up.
//! assert_eq!(turn_z_up([0.0, 0.0, 1.0]), [0.0, 1.0, 0.0]);
//!
//! let mut frame = Frame { points: vec![1.0, 2.0, 3.0], ..Frame::default() };
//! frame.field_mut("velocity", 3).extend([0.0, 0.0, -9.81]);
//! frame.turn_z_up(3, &["velocity"]);
//! assert_eq!(frame.points, [1.0, 3.0, -2.0]);
//! assert_eq!(frame.field("velocity").map(|f| f.values.clone()), Some(vec![0.0, -9.81, -0.0]));
//!
//! // A pole moving with the scene, 2 m tall z up, stands 2 m tall y up.
//! let mut frame = Frame::default();
//! frame.props.push(Prop::Capsule { a: [0.0; 3], b: [0.0, 0.0, 2.0], radius: 0.02 });
//! frame.turn_z_up(3, &[]);
//! assert_eq!(frame.props, [Prop::Capsule { a: [0.0, 0.0, -0.0], b: [0.0, 2.0, -0.0], radius: 0.02 }]);
//!
//! let mut context = Context::default();
//! context.props.push(Prop::Ground { height: 0.5 }); // the plane z = 0.5, then y = 0.5
//! context.turn_z_up();
//! assert_eq!(context.props, [Prop::Ground { height: 0.5 }]);
//! ```

use super::view::{Context, Frame, Prop};

/// A point or vector of a z-up frame in the y-up frame: `(x, y, z) -> (x, z, -y)`.
#[must_use]
pub fn turn_z_up([x, y, z]: [f64; 3]) -> [f64; 3] {
    [x, z, -y]
}

/// The axis-aligned box with corners `lo` and `hi`, turned: the corners turned and sorted again
/// (the turn sends `+y` to `-z`, so the lower corner's y becomes the upper corner's z).
fn turned_box(lo: [f64; 3], hi: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let (a, b) = (turn_z_up(lo), turn_z_up(hi));
    (std::array::from_fn(|k| a[k].min(b[k])), std::array::from_fn(|k| a[k].max(b[k])))
}

impl Prop {
    /// The prop of a z-up frame in the y-up frame ([`turn_z_up`]): points turned, a box's
    /// corners turned and sorted again; the ground `z = h` becomes the ground `y = h`.
    #[must_use]
    pub fn turned_z_up(self) -> Self {
        match self {
            Prop::Ground { height } => Prop::Ground { height },
            Prop::Sphere { center, radius } => Prop::Sphere { center: turn_z_up(center), radius },
            Prop::Capsule { a, b, radius } => Prop::Capsule { a: turn_z_up(a), b: turn_z_up(b), radius },
            Prop::Cuboid { lo, hi } => {
                let (lo, hi) = turned_box(lo, hi);
                Prop::Cuboid { lo, hi }
            }
            Prop::Tank { lo, hi } => {
                let (lo, hi) = turned_box(lo, hi);
                Prop::Tank { lo, hi }
            }
            Prop::Attractor { at } => Prop::Attractor { at: turn_z_up(at) },
            Prop::Anchor { at, point } => Prop::Anchor { at: turn_z_up(at), point },
        }
    }
}

impl Context {
    /// Turns a context built in a z-up frame into the y-up frame ([`turn_z_up`]): its props,
    /// the vertices of its mesh props (the triangles keep their orientation: a rotation) and its
    /// bounds (corners sorted again). Cells, pins and notes name points and need no turn. An
    /// image grid is left as it is: its cells would be reordered with its frames' fields, and
    /// the grid solvers work y up already.
    pub fn turn_z_up(&mut self) {
        for prop in &mut self.props {
            *prop = prop.turned_z_up();
        }
        for mesh in &mut self.mesh_props {
            for p in &mut mesh.positions {
                *p = turn_z_up(*p);
            }
        }
        if let Some((lo, hi)) = self.bounds {
            self.bounds = Some(turned_box(lo, hi));
        }
    }
}

impl Frame {
    /// Turns a frame written in a z-up frame into the y-up frame ([`turn_z_up`]), in place
    /// (nothing is allocated): the points when there are 3 coordinates per point
    /// (`point_dim`, [`Context::point_dim`]), and the per-point or per-cell vector fields
    /// named in `vectors` (`"velocity"`) that the frame has, and the moving props
    /// ([`Prop::turned_z_up`]). Scalar fields need no turn.
    ///
    /// # Panics
    /// A field named in `vectors` that does not have 3 components (a caller's mistake).
    pub fn turn_z_up(&mut self, point_dim: usize, vectors: &[&str]) {
        if point_dim == 3 {
            turn_all(&mut self.points);
        }
        for field in self.fields.iter_mut().filter(|f| vectors.contains(&f.name)) {
            assert_eq!(
                field.components, 3,
                "field `{}` turned as a vector has {} components",
                field.name, field.components
            );
            turn_all(&mut field.values);
        }
        for prop in &mut self.props {
            *prop = prop.turned_z_up();
        }
    }
}

/// Turns every triple of `flat` in place.
fn turn_all(flat: &mut [f64]) {
    for p in flat.chunks_exact_mut(3) {
        let y = p[1];
        p[1] = p[2];
        p[2] = -y;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Field, MeshProp};

    fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
        [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
    }

    /// The turn is a proper rotation: up (+z) goes to up (+y), the axes stay orthonormal and a
    /// right-handed triple stays right-handed (the turn of a cross product is the cross product
    /// of the turns), on the axes and on an arbitrary pair.
    #[test]
    fn the_turn_takes_z_up_to_y_up_and_keeps_handedness() {
        let (x, y, z) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
        assert_eq!(turn_z_up(z), [0.0, 1.0, 0.0], "up stays up");
        assert_eq!(turn_z_up(x), x);
        assert_eq!(turn_z_up(y), [0.0, 0.0, -1.0]);
        assert_eq!(cross(turn_z_up(x), turn_z_up(y)), turn_z_up(z), "x' x y' = z'");
        let (a, b) = ([0.3, -1.2, 2.5], [-0.7, 0.4, 1.1]);
        assert_eq!(cross(turn_z_up(a), turn_z_up(b)), turn_z_up(cross(a, b)));
        // Gravity along -z falls along -y.
        assert_eq!(turn_z_up([0.0, 0.0, -9.81]), [0.0, -9.81, -0.0]);
    }

    /// A cuboid's and a tank's corners are turned and sorted again: the box from (0, 1, 2) to
    /// (3, 5, 7) z up spans y in [2, 7] and z in [-5, -1] y up; points and bounds turn alike.
    #[test]
    fn a_context_turns_its_props_meshes_and_bounds() {
        let tetrahedron = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let triangles = vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
        let mut context = Context {
            props: vec![
                Prop::Ground { height: 0.25 },
                Prop::Cuboid { lo: [0.0, 1.0, 2.0], hi: [3.0, 5.0, 7.0] },
                Prop::Tank { lo: [-1.0, -2.0, 0.0], hi: [1.0, 2.0, 3.0] },
                Prop::Sphere { center: [1.0, 2.0, 3.0], radius: 0.5 },
                Prop::Capsule { a: [0.0, -1.0, 0.5], b: [0.0, 1.0, 0.5], radius: 0.1 },
                Prop::Attractor { at: [0.0, 4.0, 0.0] },
                Prop::Anchor { at: [0.0, 0.0, -1.0], point: 3 },
            ],
            mesh_props: vec![MeshProp { positions: tetrahedron, triangles: triangles.clone() }],
            bounds: Some(([0.0, 1.0, 2.0], [3.0, 5.0, 7.0])),
            ..Context::default()
        };
        context.turn_z_up();
        assert_eq!(
            context.props,
            [
                Prop::Ground { height: 0.25 },
                Prop::Cuboid { lo: [0.0, 2.0, -5.0], hi: [3.0, 7.0, -1.0] },
                Prop::Tank { lo: [-1.0, 0.0, -2.0], hi: [1.0, 3.0, 2.0] },
                Prop::Sphere { center: [1.0, 3.0, -2.0], radius: 0.5 },
                Prop::Capsule { a: [0.0, 0.5, 1.0], b: [0.0, 0.5, -1.0], radius: 0.1 },
                Prop::Attractor { at: [0.0, 0.0, -4.0] },
                Prop::Anchor { at: [0.0, -1.0, 0.0], point: 3 },
            ]
        );
        assert_eq!(context.bounds, Some(([0.0, 2.0, -5.0], [3.0, 7.0, -1.0])));
        let mesh = &context.mesh_props[0];
        assert_eq!(mesh.positions, [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]]);
        assert_eq!(mesh.triangles, triangles);
        // The faces still face outward: the normal of face [1, 2, 3] points away from vertex 0.
        let p = &mesh.positions;
        let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
        let n = cross(sub(p[2], p[1]), sub(p[3], p[1]));
        let out = sub(p[1], p[0]);
        assert!(n[0] * out[0] + n[1] * out[1] + n[2] * out[2] > 0.0, "{n:?}");
    }

    /// A frame's points and named vector fields turn in place, other fields and 2D points not;
    /// the buffers are the same allocations after the turn.
    #[test]
    fn a_frame_turns_its_points_and_vector_fields_in_place() {
        let mut frame = Frame {
            time: 0.5,
            points: vec![1.0, 2.0, 3.0, -4.0, 5.0, -6.0],
            fields: vec![
                Field { name: "velocity", components: 3, values: vec![0.0, 0.0, -1.0, 1.0, 1.0, 0.0] },
                Field { name: "normal", components: 3, values: vec![0.0, 1.0, 0.0, 0.0, 0.0, 1.0] },
                Field { name: "mass", components: 1, values: vec![2.0, 3.0] },
            ],
            props: vec![Prop::Sphere { center: [0.0, 1.0, 2.0], radius: 0.5 }],
        };
        let buffers = (frame.points.as_ptr(), frame.fields[0].values.as_ptr());
        frame.turn_z_up(3, &["velocity", "normal", "absent"]);
        assert_eq!(frame.points, [1.0, 3.0, -2.0, -4.0, -6.0, -5.0]);
        assert_eq!(frame.fields[0].values, [0.0, -1.0, -0.0, 1.0, 0.0, -1.0]);
        assert_eq!(frame.fields[1].values, [0.0, 0.0, -1.0, 0.0, 1.0, -0.0]);
        assert_eq!(frame.props, [Prop::Sphere { center: [0.0, 2.0, -1.0], radius: 0.5 }]);
        assert_eq!(frame.fields[2].values, [2.0, 3.0]);
        assert_eq!((frame.points.as_ptr(), frame.fields[0].values.as_ptr()), buffers);
        // Two coordinates per point (a system drawn in the plane): the points are not triples.
        let mut planar = Frame { points: vec![1.0, 2.0, 3.0], ..Frame::default() };
        planar.turn_z_up(1, &[]);
        assert_eq!(planar.points, [1.0, 2.0, 3.0]);
    }

    #[test]
    #[should_panic(expected = "field `mass` turned as a vector has 1 components")]
    fn turning_a_scalar_field_as_a_vector_is_a_mistake() {
        let mut frame = Frame::default();
        frame.field_mut("mass", 1).push(1.0);
        frame.turn_z_up(3, &["mass"]);
    }
}
