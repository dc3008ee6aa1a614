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
pub(crate) fn closed_surface(triangles: &[[usize; 3]]) -> Result<(), String> {
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
