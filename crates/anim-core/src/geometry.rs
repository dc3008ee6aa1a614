//! Collider geometry shared by the particle, position-based, finite-element and MPM solvers:
//! [`Shape`], a plane, sphere, axis-aligned box or capsule, with its signed distance and outward
//! unit normal ([`Shape::signed_distance`]) and the check of its parameters ([`Shape::check`]).
//!
//! Each solver keeps its own contact model (penalty force, positional constraint, penalty
//! energy, grid boundary condition) and its own arithmetic where it differs (the finite-element
//! plane distance `n . x - n . point`, MPM's `f32` kernels); the shape data is this one type, one
//! scene-file spelling everywhere:
//!
//! ```json
//! { "plane": { "point": [0, 0, 0], "normal": [0, 0, 1] } }
//! { "sphere": { "center": [0, 0, 1], "radius": 0.5 } }
//! { "box": { "center": [0, 0, 0], "half_extents": [1, 0.5, 0.25] } }
//! { "capsule": { "a": [0, 0, 0], "b": [0, 0, 2], "radius": 0.5 } }
//! ```
//!
//! A solver that cannot handle a shape refuses it when its model is built, naming the collider
//! and the shape ([`Shape::name`]).
//!
//! [`closest_point_on_triangle`] serves the triangle-mesh queries (contacts between meshed
//! bodies, the closest point of a closed surface).

use glam::DVec3;

/// A solid collider shape. Its signed distance is negative inside, positive outside.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case", deny_unknown_fields))]
pub enum Shape {
    /// The half-space below a plane: solid where `(x - point) . normal < 0`.
    Plane {
        /// A point of the plane.
        point: [f64; 3],
        /// Outward normal (any non-zero length; the solvers normalise it).
        normal: [f64; 3],
    },
    /// A solid ball (a disk in 2-D solvers).
    Sphere {
        /// Centre.
        center: [f64; 3],
        /// Radius (> 0).
        radius: f64,
    },
    /// A solid axis-aligned box.
    Box {
        /// Centre.
        center: [f64; 3],
        /// Half the edge lengths (each > 0).
        half_extents: [f64; 3],
    },
    /// A solid capsule: the points within `radius` of the segment `a b`.
    Capsule {
        /// First end of the axis.
        a: [f64; 3],
        /// Second end of the axis.
        b: [f64; 3],
        /// Radius (> 0).
        radius: f64,
    },
}

impl Shape {
    /// The ground plane `z = height` with outward normal `+z`.
    #[must_use]
    pub fn ground(height: f64) -> Self {
        Shape::Plane { point: [0.0, 0.0, height], normal: [0.0, 0.0, 1.0] }
    }

    /// The shape's scene-file name: "plane", "sphere", "box" or "capsule".
    #[must_use]
    pub fn name(&self) -> &'static str {
        match self {
            Shape::Plane { .. } => "plane",
            Shape::Sphere { .. } => "sphere",
            Shape::Box { .. } => "box",
            Shape::Capsule { .. } => "capsule",
        }
    }

    /// Checks the parameters: finite coordinates, a non-zero plane normal that normalises to a
    /// finite unit vector, positive radii and half extents, distinct capsule ends whose squared
    /// distance is positive and finite.
    ///
    /// # Errors
    /// A description of the first problem, naming the shape.
    pub fn check(&self) -> Result<(), String> {
        self.check_in(3)
    }

    /// [`check`](Self::check) for a solver in `dim` (1 to 3) dimensions, which reads only the
    /// first `dim` components of each vector (a 2-D box needs no third half extent).
    ///
    /// # Errors
    /// A description of the first problem, naming the shape.
    pub fn check_in(&self, dim: usize) -> Result<(), String> {
        let dim = dim.clamp(1, 3);
        let finite = |v: &[f64; 3]| v[..dim].iter().all(|c| c.is_finite());
        let positive = |v: f64| v > 0.0 && v.is_finite();
        // The first `dim` components, the others zero.
        let vector =
            |v: &[f64; 3]| DVec3::from_array(std::array::from_fn(|i| if i < dim { v[i] } else { 0.0 }));
        match self {
            Shape::Plane { point, normal } => {
                if !finite(point) || !finite(normal) {
                    return Err(format!("plane point {point:?} and normal {normal:?} must be finite"));
                }
                if !(normal[..dim].iter().map(|c| c * c).sum::<f64>().sqrt() > 1e-12) {
                    return Err(format!("plane normal must be non-zero, got {normal:?}"));
                }
                // A normal whose squared length overflows would normalise to zero.
                if vector(normal).try_normalize().is_none() {
                    return Err(format!(
                        "plane normal {normal:?} is too long to normalise to a finite unit vector"
                    ));
                }
            }
            Shape::Sphere { center, radius } => {
                if !finite(center) {
                    return Err(format!("sphere centre {center:?} must be finite"));
                }
                if !positive(*radius) {
                    return Err(format!("sphere radius must be positive and finite, got {radius}"));
                }
            }
            Shape::Box { center, half_extents } => {
                if !finite(center) {
                    return Err(format!("box centre {center:?} must be finite"));
                }
                if !half_extents[..dim].iter().all(|h| positive(*h)) {
                    return Err(format!(
                        "box half extents must be positive and finite, got {half_extents:?}"
                    ));
                }
            }
            Shape::Capsule { a, b, radius } => {
                if !finite(a) || !finite(b) {
                    return Err(format!("capsule ends {a:?} and {b:?} must be finite"));
                }
                if !positive(*radius) {
                    return Err(format!("capsule radius must be positive and finite, got {radius}"));
                }
                if a[..dim] == b[..dim] {
                    return Err(format!("capsule ends coincide at {a:?} (use a sphere)"));
                }
                // The distance divides by the squared axis length: it must neither underflow to
                // zero (ends distinct but too close) nor overflow (ends too far apart).
                let axis_squared = (vector(b) - vector(a)).length_squared();
                if !positive(axis_squared) {
                    return Err(format!(
                        "capsule axis from {a:?} to {b:?} has squared length {axis_squared}: it must be \
                         positive and finite (ends too close together or too far apart)"
                    ));
                }
            }
        }
        Ok(())
    }

    /// A copy with a unit plane normal (other shapes unchanged); call it on a checked shape.
    #[must_use]
    pub fn normalized(self) -> Self {
        match self {
            Shape::Plane { point, normal } => {
                Shape::Plane { point, normal: DVec3::from_array(normal).normalize().to_array() }
            }
            other => other,
        }
    }

    /// The shape of a 2-D scene, in the plane `z = 0`: the third components dropped (a box's
    /// depth made 1 m, so that any z lies well inside it) and a plane's normal of unit length.
    /// Call it on a shape checked in 2-D ([`Shape::check_in`] with `dim = 2`): the components
    /// it drops are never read again, whatever they held (even NaN).
    #[must_use]
    pub fn in_plane(self) -> Self {
        let flat = |v: [f64; 3]| [v[0], v[1], 0.0];
        match self {
            Shape::Plane { point, normal } => {
                Shape::Plane { point: flat(point), normal: flat(normal) }.normalized()
            }
            Shape::Sphere { center, radius } => Shape::Sphere { center: flat(center), radius },
            Shape::Box { center, half_extents } => {
                Shape::Box { center: flat(center), half_extents: [half_extents[0], half_extents[1], 1.0] }
            }
            Shape::Capsule { a, b, radius } => Shape::Capsule { a: flat(a), b: flat(b), radius },
        }
    }

    /// Signed distance of point `p` and the outward unit normal of the closest surface point
    /// (`phi < 0` inside; the gradient of `phi` wherever it is differentiable). The plane normal
    /// is used as stored: normalise it first ([`Shape::normalized`]). At a sphere's centre the
    /// normal is `+z`, on a capsule's axis any unit vector perpendicular to it.
    #[must_use]
    pub fn signed_distance(&self, p: DVec3) -> (f64, DVec3) {
        match *self {
            Shape::Plane { point, normal } => {
                let n = DVec3::from_array(normal);
                ((p - DVec3::from_array(point)).dot(n), n)
            }
            Shape::Sphere { center, radius } => {
                let d = p - DVec3::from_array(center);
                let len = d.length();
                let n = if len > 0.0 { d / len } else { DVec3::Z };
                (len - radius, n)
            }
            Shape::Capsule { a, b, radius } => {
                let (a, b) = (DVec3::from_array(a), DVec3::from_array(b));
                let ab = b - a;
                let t = ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0);
                let d = p - (a + t * ab);
                let len = d.length();
                let n = if len > 0.0 {
                    d / len
                } else {
                    // On the axis: any direction perpendicular to it (glam's construction needs
                    // the unit axis).
                    ab.normalize().any_orthonormal_vector()
                };
                (len - radius, n)
            }
            Shape::Box { center, half_extents } => {
                let h = DVec3::from_array(half_extents);
                let d = p - DVec3::from_array(center);
                let q = d.abs() - h;
                if q.max_element() > 0.0 {
                    let outside = q.max(DVec3::ZERO);
                    let len = outside.length();
                    let n = (outside * d.signum()) / len;
                    (len, n)
                } else {
                    // Inside: the nearest face.
                    let (axis, depth) = if q.x >= q.y && q.x >= q.z {
                        (DVec3::X, q.x)
                    } else if q.y >= q.z {
                        (DVec3::Y, q.y)
                    } else {
                        (DVec3::Z, q.z)
                    };
                    let sign = if d.dot(axis) >= 0.0 { 1.0 } else { -1.0 };
                    (depth, axis * sign)
                }
            }
        }
    }
}

/// The closest point of triangle `[a, b, c]` to `p` and its barycentric coordinates `[wa, wb, wc]`
/// (`q = wa a + wb b + wc c`), by the Voronoi regions of the vertices, edges and face (Ericson,
/// *Real-Time Collision Detection*, 2005, section 5.1.5). The triangle must have non-zero area.
///
/// ```
/// use anim_core::geometry::closest_point_on_triangle;
/// use anim_core::glam::DVec3;
///
/// let t = [DVec3::ZERO, DVec3::X, DVec3::Y];
/// let (q, w) = closest_point_on_triangle(DVec3::new(0.25, 0.25, 1.0), t);
/// assert_eq!((q, w), (DVec3::new(0.25, 0.25, 0.0), [0.5, 0.25, 0.25]));
/// ```
#[must_use]
pub fn closest_point_on_triangle(p: DVec3, [a, b, c]: [DVec3; 3]) -> (DVec3, [f64; 3]) {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, [1.0, 0.0, 0.0]);
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return (b, [0.0, 1.0, 0.0]);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (a + v * ab, [1.0 - v, v, 0.0]);
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return (c, [0.0, 0.0, 1.0]);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let v = d2 / (d2 - d6);
        return (a + v * ac, [1.0 - v, 0.0, v]);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let v = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + v * (c - b), [0.0, 1.0 - v, v]);
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, u) = (vb * denom, vc * denom);
    (a + ab * v + ac * u, [1.0 - v - u, v, u])
}

/// Six times the signed volume of the tetrahedron `(a, b, c, d)`: the triple product
/// `(b - a) . ((c - a) x (d - a))`, positive when `d` is on the side of the triangle `(a, b, c)`
/// its counter-clockwise normal points to, zero for a flat one.
///
/// ```
/// use anim_core::geometry::tet_signed_volume6;
/// use anim_core::glam::DVec3;
///
/// let [o, x, y, z] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
/// assert_eq!(tet_signed_volume6(o, x, y, z), 1.0);
/// assert_eq!(tet_signed_volume6(o, y, x, z), -1.0);
/// assert_eq!(tet_signed_volume6(o, x, y, [0.3, 0.7, 0.0]), 0.0);
/// // The same bits as glam's dot and cross products, term for term.
/// let p = [[0.1, -0.7, 0.3], [1.3, 0.2, -0.4], [-0.6, 0.9, 0.8], [0.4, 0.3, 1.7]];
/// let [a, b, c, d] = p.map(DVec3::from_array);
/// assert_eq!(tet_signed_volume6(p[0], p[1], p[2], p[3]).to_bits(), (b - a).dot((c - a).cross(d - a)).to_bits());
/// ```
#[inline]
#[must_use]
pub fn tet_signed_volume6(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]) -> f64 {
    let sub = |p: [f64; 3]| [p[0] - a[0], p[1] - a[1], p[2] - a[2]];
    let (u, v, w) = (sub(b), sub(c), sub(d));
    u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
        + u[2] * (v[0] * w[1] - v[1] * w[0])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12
    }

    #[test]
    fn distances_match_the_analytic_ones() {
        let plane = Shape::Plane { point: [0.0, 0.0, 1.0], normal: [0.0, 3.0, 4.0] }.normalized();
        let (phi, n) = plane.signed_distance(DVec3::new(7.0, 3.0, 5.0));
        assert!(close(phi, (3.0 * 3.0 + 4.0 * 4.0) / 5.0) && n.abs_diff_eq(DVec3::new(0.0, 0.6, 0.8), 1e-15));
        let sphere = Shape::Sphere { center: [1.0, 0.0, 0.0], radius: 0.5 };
        assert!(close(sphere.signed_distance(DVec3::new(1.0, 2.0, 0.0)).0, 1.5));
        assert!(close(sphere.signed_distance(DVec3::new(1.2, 0.0, 0.0)).0, -0.3));
        let unit = Shape::Sphere { center: [0.0; 3], radius: 1.0 };
        assert!((unit.signed_distance(DVec3::new(0.0, 0.3, 0.0)).0 + 0.7).abs() < 1e-15);
        assert_eq!(sphere.signed_distance(DVec3::new(1.0, 0.0, 0.0)), (-0.5, DVec3::Z));
        let b = Shape::Box { center: [1.0, 0.0, 0.0], half_extents: [1.0, 0.5, 0.25] };
        // Outside a face, outside an edge, outside a corner, inside.
        assert!(close(b.signed_distance(DVec3::new(3.0, 0.0, 0.0)).0, 1.0));
        assert!(close(b.signed_distance(DVec3::new(3.0, 1.5, 0.0)).0, 2f64.sqrt()));
        assert!(close(b.signed_distance(DVec3::new(-1.0, -1.5, 1.25)).0, 3f64.sqrt()));
        let (phi, n) = b.signed_distance(DVec3::new(1.1, 0.0, -0.2));
        assert!(close(phi, -0.05) && n == -DVec3::Z);
        // The normals: outside a face, inside near a face, outside an edge.
        let (d, n) = b.signed_distance(DVec3::new(1.0, 0.0, 0.5));
        assert!((d - 0.25).abs() < 1e-15 && n == DVec3::Z);
        let (d, n) = b.signed_distance(DVec3::new(1.9, 0.0, 0.0));
        assert!((d + 0.1).abs() < 1e-15 && n == DVec3::X, "{d} {n}");
        let (d, n) = b.signed_distance(DVec3::new(3.0, 1.5, 0.0));
        assert!(
            (d - 2f64.sqrt()).abs() < 1e-15 && (n - DVec3::new(1.0, 1.0, 0.0).normalize()).length() < 1e-15
        );
        let c = Shape::Capsule { a: [0.0; 3], b: [0.0, 0.0, 2.0], radius: 0.5 };
        assert!(close(c.signed_distance(DVec3::new(2.0, 0.0, 1.0)).0, 1.5));
        assert!(close(c.signed_distance(DVec3::new(0.0, 0.0, 3.0)).0, 0.5));
        assert!(close(c.signed_distance(DVec3::new(0.0, -0.3, -0.4)).0, 0.0));
        // The normals beside the axis and beyond an end.
        let (d, n) = c.signed_distance(DVec3::new(1.0, 0.0, 1.0));
        assert!((d - 0.5).abs() < 1e-15 && n == DVec3::X);
        let (d, n) = c.signed_distance(DVec3::new(0.0, 0.0, 3.0));
        assert!((d - 0.5).abs() < 1e-15 && n == DVec3::Z);
        let (phi, n) = c.signed_distance(DVec3::new(0.0, 0.0, 1.0));
        assert!(close(phi, -0.5) && close(n.length(), 1.0) && close(n.z, 0.0));
    }

    #[test]
    fn capsule_normal_on_the_axis_is_unit_and_perpendicular() {
        // Axis ends and points exactly on the axis (dyadic coordinates, so the closest axis point
        // is computed without rounding): y-axis capsules both ways, a z-axis one, diagonal ones.
        type Case = ([f64; 3], [f64; 3], &'static [[f64; 3]]);
        let cases: [Case; 6] = [
            (
                [0.0, -1.0, 0.5],
                [0.0, 2.0, 0.5],
                &[[0.0, -1.0, 0.5], [0.0, 0.5, 0.5], [0.0, 1.25, 0.5], [0.0, 2.0, 0.5]],
            ),
            ([0.0, 3.0, 0.0], [0.0, 1.0, 0.0], &[[0.0, 3.0, 0.0], [0.0, 2.0, 0.0], [0.0, 1.0, 0.0]]),
            ([0.0; 3], [0.0, 0.0, 2.0], &[[0.0, 0.0, 1.0]]),
            ([0.0; 3], [1.0, 2.0, 2.0], &[[0.0; 3], [0.25, 0.5, 0.5], [0.5, 1.0, 1.0], [1.0, 2.0, 2.0]]),
            ([1.0; 3], [-2.0; 3], &[[1.0; 3], [-0.5; 3], [-2.0; 3]]),
            ([0.0; 3], [2.0, -1.0, -2.0], &[[1.0, -0.5, -1.0]]),
        ];
        for (a, b, points) in cases {
            let c = Shape::Capsule { a, b, radius: 0.25 };
            let axis = (DVec3::from_array(b) - DVec3::from_array(a)).normalize();
            for &p in points {
                let (phi, n) = c.signed_distance(DVec3::from_array(p));
                assert_eq!(phi, -0.25, "{c:?} at {p:?} is not on the axis");
                assert!(close(n.length(), 1.0) && close(n.dot(axis), 0.0), "{c:?} at {p:?}: normal {n}");
            }
        }
    }

    #[test]
    fn normals_are_finite_difference_gradients() {
        use rand::{Rng, SeedableRng};
        use rand_chacha::ChaCha8Rng;

        let (capsule_a, capsule_b) = (DVec3::new(-0.3, 0.1, 0.0), DVec3::new(0.4, -0.2, 0.5));
        let (box_center, box_half) = (DVec3::new(0.1, 0.0, 0.2), DVec3::new(0.6, 0.4, 0.3));
        let shapes = [
            Shape::Plane { point: [0.1, -0.2, 0.3], normal: [1.0, -2.0, 0.5] }.normalized(),
            Shape::Sphere { center: [0.2, 0.1, -0.1], radius: 0.7 },
            Shape::Box { center: box_center.to_array(), half_extents: box_half.to_array() },
            Shape::Capsule { a: capsule_a.to_array(), b: capsule_b.to_array(), radius: 0.35 },
        ];
        // A seeded sample of [-1.5, 1.5]^3, then the places where the distance has a kink: points
        // on the capsule's axis (its ends included), the sphere's centre, and the box's ridges
        // (edges and corners of its surface, and the inner ridges where two or three faces are
        // equally near).
        let mut rng = ChaCha8Rng::seed_from_u64(0x6e6f726d);
        let mut points: Vec<DVec3> = (0..200)
            .map(|_| DVec3::from_array(std::array::from_fn(|_| rng.random_range(-1.5..1.5))))
            .collect();
        points.extend([0.0, 0.25, 0.5, 0.75, 1.0].map(|t| capsule_a.lerp(capsule_b, t)));
        points.push(DVec3::new(0.2, 0.1, -0.1));
        for signs in [DVec3::ONE, DVec3::new(-1.0, 1.0, -1.0), DVec3::new(1.0, -1.0, 1.0)] {
            for ridge in [
                box_half,
                DVec3::new(box_half.x, box_half.y, 0.0),
                DVec3::new(box_half.x, 0.1, box_half.z),
                DVec3::new(0.0, box_half.y, box_half.z),
                DVec3::new(0.5, 0.3, 0.0),
                DVec3::new(0.5, 0.3, 0.2),
                DVec3::new(0.4, 0.2, 0.1),
            ] {
                points.push(box_center + signs * ridge);
            }
        }
        let eps = 1e-6;
        let mut checked = 0;
        for shape in shapes {
            for &p in &points {
                let (phi, n) = shape.signed_distance(p);
                assert!(phi.is_finite() && close(n.length(), 1.0), "{shape:?} at {p}");
                let fd = DVec3::from_array(std::array::from_fn(|a| {
                    let e = DVec3::AXES[a] * eps;
                    (shape.signed_distance(p + e).0 - shape.signed_distance(p - e).0) / (2.0 * eps)
                }));
                // Skip the ridges where the distance is not differentiable (box edges seen from
                // inside): there the one-sided differences disagree.
                let kink = (0..3).any(|a| {
                    let e = DVec3::AXES[a] * eps;
                    let fwd = (shape.signed_distance(p + e).0 - phi) / eps;
                    let bwd = (phi - shape.signed_distance(p - e).0) / eps;
                    (fwd - bwd).abs() > 1e-3
                });
                if kink {
                    continue;
                }
                assert!((fd - n).length() < 1e-5, "{shape:?} at {p}: normal {n}, finite differences {fd}");
                checked += 1;
            }
        }
        assert!(checked > 700, "{checked}");
    }

    #[test]
    fn checks_name_the_shape_and_value() {
        assert_eq!(Shape::ground(0.5).check(), Ok(()));
        assert!(
            Shape::Plane { point: [0.0; 3], normal: [0.0; 3] }.check().unwrap_err().contains("plane normal")
        );
        let e = Shape::Sphere { center: [0.0; 3], radius: -1.0 }.check().unwrap_err();
        assert!(e.contains("sphere radius") && e.contains("-1"), "{e}");
        let e = Shape::Box { center: [0.0; 3], half_extents: [1.0, 0.0, 1.0] }.check().unwrap_err();
        assert!(e.contains("box half extents"), "{e}");
        let e = Shape::Capsule { a: [1.0; 3], b: [1.0; 3], radius: 1.0 }.check().unwrap_err();
        assert!(e.contains("capsule ends coincide"), "{e}");
        assert!(Shape::Sphere { center: [f64::NAN; 3], radius: 1.0 }.check().is_err());
        // In 2-D only the first two components count.
        let flat = Shape::Box { center: [0.5, 0.5, f64::NAN], half_extents: [0.4, 0.05, 0.0] };
        assert!(flat.check().is_err() && flat.check_in(2).is_ok());
        let up = Shape::Plane { point: [0.0; 3], normal: [0.0, 0.0, 1.0] };
        assert!(up.check().is_ok() && up.check_in(2).is_err());
    }

    #[test]
    fn checks_refuse_what_overflows_or_underflows() {
        // The squared length of this normal overflows: it would normalise to zero.
        let huge = Shape::Plane { point: [0.0; 3], normal: [1e200, 0.0, 0.0] };
        let e = huge.check().unwrap_err();
        assert!(e.contains("plane normal") && e.contains("unit"), "{e}");
        assert!(huge.check_in(2).is_err());
        // Only the first `dim` components count: a huge third one is fine in 2-D.
        assert!(Shape::Plane { point: [0.0; 3], normal: [0.0, 1.0, 1e200] }.check_in(2).is_ok());
        assert!(Shape::Plane { point: [0.0; 3], normal: [1e150, 0.0, 0.0] }.check().is_ok());
        // Capsule ends distinct but so close, or so far apart, that the squared axis length
        // underflows to zero or overflows: the distance would be NaN.
        for (a, b) in [
            ([0.0; 3], [1e-170, 0.0, 0.0]),
            ([1e-300, -1e-300, 0.0], [0.0; 3]),
            ([1e200, 0.0, 0.0], [-1e200, 0.0, 0.0]),
            ([f64::MAX, 0.0, 0.0], [-f64::MAX, 0.0, 0.0]),
        ] {
            let capsule = Shape::Capsule { a, b, radius: 0.5 };
            let e = capsule.check().expect_err(&format!("{capsule:?}"));
            assert!(e.contains("capsule axis"), "{e}");
            // Unchecked, its distance would not be a number.
            let nan = [DVec3::from_array(a), DVec3::new(0.1, 0.2, 0.3)]
                .into_iter()
                .any(|p| capsule.signed_distance(p).0.is_nan());
            assert!(nan, "{capsule:?}");
        }
        let e = Shape::Capsule { a: [0.0; 3], b: [0.0, 0.0, 1e-170], radius: 0.5 }.check_in(3).unwrap_err();
        assert!(e.contains("capsule axis"), "{e}");
        // In 2-D the ends differ only in the ignored third component: they coincide.
        let e = Shape::Capsule { a: [0.0; 3], b: [0.0, 0.0, 1.0], radius: 0.5 }.check_in(2).unwrap_err();
        assert!(e.contains("capsule ends coincide"), "{e}");
        assert!(Shape::Capsule { a: [0.0; 3], b: [1e-150, 0.0, 0.0], radius: 0.5 }.check().is_ok());
    }

    #[cfg(feature = "serde")]
    #[test]
    fn scene_file_spelling() {
        let s: Shape =
            serde_json::from_str(r#"{ "box": { "center": [0, 0, 0], "half_extents": [1, 2, 3] } }"#).unwrap();
        assert_eq!(s, Shape::Box { center: [0.0; 3], half_extents: [1.0, 2.0, 3.0] });
        assert_eq!(s.name(), "box");
        assert!(
            serde_json::from_str::<Shape>(r#"{ "Box": { "center": [0, 0, 0], "half": [1, 2, 3] } }"#)
                .is_err()
        );
        assert!(
            serde_json::from_str::<Shape>(r#"{ "sphere": { "center": [0, 0, 0], "radius": 1, "r": 2 } }"#)
                .is_err()
        );
        let json = serde_json::to_string(&Shape::ground(1.0)).unwrap();
        assert_eq!(json, r#"{"plane":{"point":[0.0,0.0,1.0],"normal":[0.0,0.0,1.0]}}"#);
    }

    #[test]
    fn the_closest_point_of_a_triangle_is_found_in_every_region() {
        let t = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let case = |p: DVec3, q: DVec3, b: [f64; 3]| {
            let (got, bary) = closest_point_on_triangle(p, t);
            assert!((got - q).length() < 1e-15, "{p}: {got}");
            assert!(bary.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-15), "{p}: {bary:?}");
            let back = bary[0] * t[0] + bary[1] * t[1] + bary[2] * t[2];
            assert!((back - q).length() < 1e-15);
        };
        case(DVec3::new(0.25, 0.25, 1.0), DVec3::new(0.25, 0.25, 0.0), [0.5, 0.25, 0.25]);
        case(DVec3::new(-1.0, -1.0, 0.5), DVec3::ZERO, [1.0, 0.0, 0.0]);
        case(DVec3::new(2.0, -0.5, 0.0), DVec3::X, [0.0, 1.0, 0.0]);
        case(DVec3::new(-0.5, 3.0, 0.0), DVec3::Y, [0.0, 0.0, 1.0]);
        case(DVec3::new(0.5, -1.0, 0.0), DVec3::new(0.5, 0.0, 0.0), [0.5, 0.5, 0.0]);
        case(DVec3::new(-1.0, 0.5, 0.0), DVec3::new(0.0, 0.5, 0.0), [0.5, 0.0, 0.5]);
        case(DVec3::new(1.0, 1.0, 0.0), DVec3::new(0.5, 0.5, 0.0), [0.0, 0.5, 0.5]);
    }
}
