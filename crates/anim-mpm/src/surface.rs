//! A closed, consistently oriented triangle surface and the lattice points inside it: the
//! subset of `anim_core::surface::ClosedSurface` the bodies of a scene file use, kept here until
//! anim-core provides it (same names, same behaviour).

use std::collections::HashMap;
use std::fmt;

/// Why a triangle list is not a closed surface: the triangle, edge or vertex at fault.
#[derive(Debug, Clone, PartialEq)]
pub enum SurfaceError {
    /// No triangles.
    Empty,
    /// A vertex with a non-finite coordinate.
    NonFinite {
        /// The vertex (0-based).
        vertex: usize,
        /// Its position.
        position: [f64; 3],
    },
    /// A triangle naming a vertex that does not exist.
    Index {
        /// The triangle (0-based).
        triangle: usize,
        /// Its vertices.
        vertices: [usize; 3],
        /// The vertex count.
        count: usize,
    },
    /// A triangle of zero area.
    ZeroArea {
        /// The triangle (0-based).
        triangle: usize,
        /// Its vertices.
        vertices: [usize; 3],
    },
    /// An edge not shared by exactly two triangles of opposite orientation.
    Edge {
        /// The edge's vertices.
        edge: [usize; 2],
        /// The triangles having it.
        triangles: Vec<usize>,
        /// What is wrong.
        reason: &'static str,
    },
    /// The enclosed volume is not positive (the triangles face inwards).
    Inverted {
        /// The signed volume.
        volume: f64,
    },
}

impl fmt::Display for SurfaceError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SurfaceError::Empty => write!(f, "no triangles"),
            SurfaceError::NonFinite { vertex, position } => {
                write!(f, "vertex {vertex} has the non-finite position {position:?}")
            }
            SurfaceError::Index { triangle, vertices: [a, b, c], count } => {
                write!(
                    f,
                    "triangle {triangle} (vertices {a}, {b}, {c}) names a vertex beyond the {count} vertices"
                )
            }
            SurfaceError::ZeroArea { triangle, vertices: [a, b, c] } => {
                write!(f, "triangle {triangle} (vertices {a}, {b}, {c}) has zero area")
            }
            SurfaceError::Edge { edge: [a, b], triangles, reason } => {
                write!(f, "edge ({a}, {b}) of triangles {triangles:?}: {reason}; the surface is not closed")
            }
            SurfaceError::Inverted { volume } => {
                write!(f, "the triangles face inwards (enclosed volume {volume:e})")
            }
        }
    }
}

impl std::error::Error for SurfaceError {}

/// A closed, manifold, consistently and outward oriented triangle surface.
#[derive(Debug, Clone, PartialEq)]
pub struct ClosedSurface {
    positions: Vec<[f64; 3]>,
    triangles: Vec<[usize; 3]>,
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

impl ClosedSurface {
    /// Checks and keeps the surface: finite positions, indices in range, no zero-area triangle,
    /// every edge shared by exactly two triangles that run along it in opposite directions, a
    /// positive enclosed volume.
    ///
    /// # Errors
    /// [`SurfaceError`] naming the first vertex, triangle or edge at fault.
    pub fn new(positions: Vec<[f64; 3]>, triangles: Vec<[usize; 3]>) -> Result<Self, SurfaceError> {
        if triangles.is_empty() {
            return Err(SurfaceError::Empty);
        }
        if let Some((vertex, p)) =
            positions.iter().enumerate().find(|(_, p)| !p.iter().all(|c| c.is_finite()))
        {
            return Err(SurfaceError::NonFinite { vertex, position: *p });
        }
        let count = positions.len();
        let mut edges: HashMap<[usize; 2], Vec<(usize, bool)>> = HashMap::new();
        for (t, &tri) in triangles.iter().enumerate() {
            if tri.iter().any(|&v| v >= count) {
                return Err(SurfaceError::Index { triangle: t, vertices: tri, count });
            }
            let [a, b, c] = tri.map(|v| positions[v]);
            let n = cross(sub(b, a), sub(c, a));
            if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] || !(norm(n) > 0.0) {
                return Err(SurfaceError::ZeroArea { triangle: t, vertices: tri });
            }
            for k in 0..3 {
                let (u, v) = (tri[k], tri[(k + 1) % 3]);
                edges.entry([u.min(v), u.max(v)]).or_default().push((t, u < v));
            }
        }
        let mut keys: Vec<_> = edges.keys().copied().collect();
        keys.sort_unstable();
        for key in keys {
            let uses = &edges[&key];
            let triangles: Vec<usize> = uses.iter().map(|u| u.0).collect();
            let reason = match uses.as_slice() {
                [_] => "an open boundary edge (one triangle)",
                [(_, d0), (_, d1)] if d0 == d1 => {
                    "both triangles run along it the same way (inconsistent orientation)"
                }
                [_, _] => continue,
                _ => "more than two triangles (not manifold)",
            };
            return Err(SurfaceError::Edge { edge: key, triangles, reason });
        }
        let surface = ClosedSurface { positions, triangles };
        let volume = surface.volume();
        if !(volume > 0.0) {
            return Err(SurfaceError::Inverted { volume });
        }
        Ok(surface)
    }

    /// The generalized winding number of the surface about `p` (1 inside, 0 outside).
    #[must_use]
    pub fn winding_number(&self, p: [f64; 3]) -> f64 {
        let mut total = 0.0;
        for tri in &self.triangles {
            let [a, b, c] = tri.map(|v| sub(self.positions[v], p));
            let (la, lb, lc) = (norm(a), norm(b), norm(c));
            let det = dot(a, cross(b, c));
            let den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
            total += 2.0 * det.atan2(den);
        }
        total / (4.0 * std::f64::consts::PI)
    }

    /// Whether `p` is inside: winding number above one half.
    #[must_use]
    pub fn contains(&self, p: [f64; 3]) -> bool {
        self.winding_number(p) > 0.5
    }

    /// The axis-aligned bounding box `(min, max)`.
    #[must_use]
    pub fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for tri in &self.triangles {
            for &v in tri {
                for k in 0..3 {
                    lo[k] = lo[k].min(self.positions[v][k]);
                    hi[k] = hi[k].max(self.positions[v][k]);
                }
            }
        }
        (lo, hi)
    }

    /// The enclosed volume.
    #[must_use]
    pub fn volume(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| self.positions[v]);
                dot(a, cross(b, c)) / 6.0
            })
            .sum()
    }

    /// The centres of the cells of a grid of cells `spacing` wide laid over the bounds from
    /// their lower corner, that lie inside the surface; x fastest, then y, then z.
    #[must_use]
    pub fn sample_inside(&self, spacing: f64) -> Vec<[f64; 3]> {
        let (lo, hi) = self.bounds();
        let counts: [usize; 3] =
            std::array::from_fn(|k| ((hi[k] - lo[k]) / spacing).ceil().max(0.0) as usize);
        let at = |k: usize, i: usize| lo[k] + (i as f64 + 0.5) * spacing;
        let mut out = Vec::new();
        let mut crossings: Vec<(f64, i32)> = Vec::new();
        for iz in 0..counts[2] {
            for iy in 0..counts[1] {
                let (y, z) = (at(1, iy), at(2, iz));
                // Signed crossings of the line along +x through (y, z); a line through an edge
                // or a vertex falls back to the winding number of each point.
                crossings.clear();
                let mut degenerate = false;
                for tri in &self.triangles {
                    let [a, b, c] = tri.map(|v| self.positions[v]);
                    let d = (b[1] - a[1]) * (c[2] - a[2]) - (b[2] - a[2]) * (c[1] - a[1]);
                    if d == 0.0 {
                        continue;
                    }
                    let u = ((y - a[1]) * (c[2] - a[2]) - (z - a[2]) * (c[1] - a[1])) / d;
                    let v = ((b[1] - a[1]) * (z - a[2]) - (b[2] - a[2]) * (y - a[1])) / d;
                    let w = 1.0 - u - v;
                    if u < 0.0 || v < 0.0 || w < 0.0 {
                        continue;
                    }
                    if u == 0.0 || v == 0.0 || w == 0.0 {
                        degenerate = true;
                        break;
                    }
                    let x = w * a[0] + u * b[0] + v * c[0];
                    crossings.push((x, if d > 0.0 { 1 } else { -1 }));
                }
                for ix in 0..counts[0] {
                    let p = [at(0, ix), y, z];
                    let inside = if degenerate {
                        self.contains(p)
                    } else {
                        // Winding number: the signed crossings ahead of p along +x, outward
                        // normals with +x component counting +1.
                        crossings.iter().filter(|c| c.0 > p[0]).map(|c| c.1).sum::<i32>() > 0
                    };
                    if inside {
                        out.push(p);
                    }
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit cube `[0, 1]^3`, outward.
    fn cube() -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
        let p = (0..8).map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64]).collect();
        let t = vec![
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
        (p, t)
    }

    #[test]
    fn a_cube_is_closed_and_its_lattice_points_are_inside() {
        let (p, t) = cube();
        let s = ClosedSurface::new(p, t).expect("closed");
        assert!((s.volume() - 1.0).abs() < 1e-12);
        assert!(s.contains([0.5, 0.5, 0.5]) && !s.contains([1.5, 0.5, 0.5]));
        assert!((s.winding_number([0.3, 0.6, 0.2]) - 1.0).abs() < 1e-9);
        assert_eq!(s.sample_inside(0.25).len(), 64);
        assert_eq!(s.sample_inside(0.5).len(), 8);
    }

    #[test]
    fn an_open_or_flipped_surface_is_refused_by_edge() {
        let (p, mut t) = cube();
        t.pop();
        let e = ClosedSurface::new(p.clone(), t).unwrap_err().to_string();
        assert!(e.contains("edge (") && e.contains("not closed"), "{e}");
        let (_, mut t) = cube();
        t[0] = [0, 1, 2];
        let e = ClosedSurface::new(p.clone(), t).unwrap_err().to_string();
        assert!(e.contains("edge (") && e.contains("orientation"), "{e}");
        let (_, t) = cube();
        let inward: Vec<_> = t.iter().map(|&[a, b, c]| [a, c, b]).collect();
        assert!(matches!(ClosedSurface::new(p, inward), Err(SurfaceError::Inverted { .. })));
    }
}
