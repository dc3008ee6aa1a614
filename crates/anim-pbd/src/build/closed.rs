//! Closed surfaces oriented outward: the one check behind a closed contact body
//! ([`PbdBuilder::contact_body`](crate::PbdBuilder::contact_body)), a global volume's mesh
//! ([`PbdBuilder::global_volume`](crate::PbdBuilder::global_volume)) and a scene file's closed
//! cloth or soft body surface. Every directed edge must appear once, with its opposite, and the
//! enclosed volume must be positive; the first bad edge in triangle order is named, so the
//! message is the same from run to run.

use anim_core::glam::DVec3;
use std::collections::HashMap;
use std::fmt;

/// Why triangles are not a closed surface oriented outward.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum NotClosed {
    /// Not closed, not manifold or not consistently oriented: the reason, naming the edge.
    Open(String),
    /// Closed and consistently oriented, but enclosing this volume, which is not positive.
    Inward(f64),
}

impl fmt::Display for NotClosed {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Open(reason) => f.write_str(reason),
            Self::Inward(v) => {
                write!(f, "the enclosed volume {v:e} is not positive: the triangles face inward")
            }
        }
    }
}

/// Whether `triangles` are closed and consistently oriented: every directed edge once, with its
/// opposite; the reason, naming the first bad edge in triangle order, if not.
fn closed_surface(triangles: &[[usize; 3]]) -> Result<(), String> {
    let mut directed: HashMap<(usize, usize), usize> = HashMap::new();
    for (t, tri) in triangles.iter().enumerate() {
        for k in 0..3 {
            let e = (tri[k], tri[(k + 1) % 3]);
            if directed.insert(e, t).is_some() {
                return Err(format!(
                    "edge {e:?} runs the same way in two triangles (the second is triangle {t}): \
                     the surface is not consistently oriented or not manifold"
                ));
            }
        }
    }
    for (t, tri) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            if !directed.contains_key(&(b, a)) {
                return Err(format!(
                    "edge ({a}, {b}) of triangle {t} has no opposite: the surface is not closed"
                ));
            }
        }
    }
    Ok(())
}

/// The volume enclosed by the closed `triangles` at positions `pos`: the sum of the signed
/// volumes of the tetrahedra from the first corner to each triangle (the same as from the
/// origin for a closed surface, without the rounding of coordinates far from it).
fn enclosed_volume(triangles: &[[usize; 3]], pos: impl Fn(usize) -> DVec3) -> f64 {
    let Some(first) = triangles.first() else { return 0.0 };
    let o = pos(first[0]);
    triangles.iter().map(|t| (pos(t[0]) - o).dot((pos(t[1]) - o).cross(pos(t[2]) - o))).sum::<f64>() / 6.0
}

/// Whether `triangles` (indices into positions `pos`) are a closed surface oriented outward:
/// closed and consistently oriented, enclosing a positive volume.
pub(crate) fn closed_outward(
    triangles: &[[usize; 3]],
    pos: impl Fn(usize) -> DVec3,
) -> Result<(), NotClosed> {
    closed_surface(triangles).map_err(NotClosed::Open)?;
    let v = enclosed_volume(triangles, pos);
    if v > 0.0 { Ok(()) } else { Err(NotClosed::Inward(v)) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{BuildError, ConstraintParams, PbdBuilder, shapes};

    /// An icosphere with one triangle left out names, every time, the first edge in triangle
    /// order without an opposite, whichever check runs it (a contact body or a global volume).
    #[test]
    fn an_open_surface_names_the_first_edge_without_an_opposite_in_triangle_order() {
        let (pos, mut tris) = shapes::icosphere(1);
        tris.remove(37);
        // The first edge, in triangle order, that no triangle runs the other way.
        let first = tris
            .iter()
            .enumerate()
            .flat_map(|(t, tri)| (0..3).map(move |k| (t, tri[k], tri[(k + 1) % 3])))
            .find(|&(_, a, b)| !tris.iter().any(|u| (0..3).any(|k| (u[k], u[(k + 1) % 3]) == (b, a))))
            .expect("open");
        let expected = format!(
            "edge ({}, {}) of triangle {} has no opposite: the surface is not closed",
            first.1, first.2, first.0
        );
        let p = |i: usize| DVec3::from_array(pos[i]);
        for _ in 0..8 {
            assert_eq!(closed_outward(&tris, p), Err(NotClosed::Open(expected.clone())));
            let mut b = PbdBuilder::new();
            for &x in &pos {
                b.particle(x, 1.0);
            }
            b.global_volume(&tris, 1.0, ConstraintParams::rigid());
            match b.build() {
                Err(BuildError::BadVolumeMesh { reason }) => {
                    assert_eq!(reason, format!("constraint 0: {expected}"))
                }
                other => panic!("{other:?}"),
            }
        }
    }

    /// The enclosed volume does not depend on the distance from the origin: a unit cube's
    /// surface 1e9 m away encloses exactly 1 m^3 (from the origin, the terms would be some
    /// 1e27 m^3 and their sum's rounding some 1e11 m^3); reversed it faces inward.
    #[test]
    fn the_enclosed_volume_is_measured_from_the_surface_not_the_origin() {
        let (pos, tets) = shapes::tet_box([1; 3], [1e9; 3], 1.0);
        let tris = shapes::tet_surface(&pos, &tets);
        let v = enclosed_volume(&tris, |i| DVec3::from_array(pos[i]));
        assert_eq!(v, 1.0);
        assert_eq!(closed_outward(&tris, |i| DVec3::from_array(pos[i])), Ok(()));
        let reversed: Vec<[usize; 3]> = tris.iter().map(|&[a, b, c]| [a, c, b]).collect();
        assert_eq!(closed_outward(&reversed, |i| DVec3::from_array(pos[i])), Err(NotClosed::Inward(-1.0)));
    }
}
