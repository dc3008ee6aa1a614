//! How the props around a scene are drawn: colliders solid, tank walls as edges.

use super::io;
use anim_core::scene::Prop;
use anim_io::preview::{Camera, Canvas, Colors, MeshStyle, Shading};

/// The colour of obstacles: a light grey, apart from the bodies' blue and orange.
pub(super) const OBSTACLE: [u8; 3] = [190, 190, 180];

/// How solid obstacles are drawn: the obstacle colour on both sides, flat shaded.
pub(super) const OBSTACLE_STYLE: MeshStyle =
    MeshStyle { color: OBSTACLE, back_color: OBSTACLE, shading: Shading::Flat };

/// Draws an obstacle prop: a sphere as a shaded ball, a box as its six faces, a capsule as its
/// tube and two balls, a tank as its twelve edges.
pub(super) fn draw_obstacle(canvas: &mut Canvas, camera: &Camera, prop: &Prop) -> Result<(), String> {
    let solid = OBSTACLE_STYLE;
    match *prop {
        Prop::Sphere { center, radius } => {
            io(canvas.draw_particles(camera, &[center], radius, Colors::Uniform(OBSTACLE)))
        }
        Prop::Cuboid { lo, hi } => io(canvas.draw_mesh(camera, &box_corners(lo, hi), &BOX_FACES, &solid)),
        Prop::Tank { lo, hi } => io(canvas.draw_lines(
            camera,
            &box_corners(lo, hi),
            &BOX_EDGES,
            1.5,
            Colors::Uniform([120, 120, 130]),
        )),
        Prop::Capsule { a, b, radius } => {
            let (a, b) = (anim_core::glam::DVec3::from_array(a), anim_core::glam::DVec3::from_array(b));
            let axis = b - a;
            if axis.length() > 0.0 {
                let u = axis.normalize().any_orthonormal_vector();
                let v = axis.normalize().cross(u);
                const SIDES: usize = 24;
                let mut ring = Vec::with_capacity(2 * SIDES);
                for end in [a, b] {
                    for k in 0..SIDES {
                        let t = std::f64::consts::TAU * k as f64 / SIDES as f64;
                        ring.push((end + radius * (t.cos() * u + t.sin() * v)).to_array());
                    }
                }
                let tube: Vec<[usize; 3]> = (0..SIDES)
                    .flat_map(|k| {
                        let n = (k + 1) % SIDES;
                        [[k, n, SIDES + k], [n, SIDES + n, SIDES + k]]
                    })
                    .collect();
                io(canvas.draw_mesh(camera, &ring, &tube, &solid))?;
            }
            io(canvas.draw_particles(
                camera,
                &[a.to_array(), b.to_array()],
                radius,
                Colors::Uniform(OBSTACLE),
            ))
        }
        _ => Ok(()),
    }
}

/// The corners of the box a solid prop or a tank takes, `(lo, hi)`; `None` for the ground,
/// an attractor or an anchor.
pub(super) fn extent(prop: &Prop) -> Option<([f64; 3], [f64; 3])> {
    match *prop {
        Prop::Sphere { center, radius } => Some((center.map(|c| c - radius), center.map(|c| c + radius))),
        Prop::Capsule { a, b, radius } => Some((
            std::array::from_fn(|k| a[k].min(b[k]) - radius),
            std::array::from_fn(|k| a[k].max(b[k]) + radius),
        )),
        Prop::Cuboid { lo, hi } | Prop::Tank { lo, hi } => Some((lo, hi)),
        _ => None,
    }
}

/// The corners of the box `[lo, hi]`, corner `i` taking `hi` on the axes of the bits of `i`.
fn box_corners(lo: [f64; 3], hi: [f64; 3]) -> [[f64; 3]; 8] {
    std::array::from_fn(|i| std::array::from_fn(|a| if i >> a & 1 == 1 { hi[a] } else { lo[a] }))
}

/// The twelve triangles of a box's faces over [`box_corners`], counter-clockwise from outside.
const BOX_FACES: [[usize; 3]; 12] = [
    [0, 2, 1],
    [1, 2, 3],
    [4, 5, 6],
    [5, 7, 6],
    [0, 1, 4],
    [1, 5, 4],
    [2, 6, 3],
    [3, 6, 7],
    [0, 4, 2],
    [2, 4, 6],
    [1, 3, 5],
    [3, 7, 5],
];

/// The twelve edges of a box over [`box_corners`].
const BOX_EDGES: [[usize; 2]; 12] =
    [[0, 1], [2, 3], [4, 5], [6, 7], [0, 2], [1, 3], [4, 6], [5, 7], [0, 4], [1, 5], [2, 6], [3, 7]];
