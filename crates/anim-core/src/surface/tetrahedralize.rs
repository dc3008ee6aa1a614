//! The tetrahedral mesh of a closed surface's inside: Kuhn's six tetrahedra per lattice cube,
//! kept by their centroid, with the boundary vertices moved onto the surface where that keeps
//! every tetrahedron well shaped (see the [module](super)).

use std::collections::HashMap;

use glam::DVec3;

use super::{ClosedSurface, SurfaceError, Tetrahedra};
use crate::geometry::{closest_point_on_triangle, tet_signed_volume6};

/// The most lattice cubes a mesh may span.
pub(super) const MAX_CUBES: usize = 1 << 21;

/// A moved vertex may shrink a tetrahedron to this fraction of its lattice volume, no further.
const MIN_VOLUME_FRACTION: f64 = 0.1;

/// The six orderings of the axes; each walks from a cube's corner to the opposite one.
const PATHS: [[usize; 3]; 6] = [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]];

pub(super) fn mesh(s: &ClosedSurface, cell: f64) -> Result<Tetrahedra, SurfaceError> {
    if !(cell > 0.0 && cell.is_finite()) {
        return Err(SurfaceError::Resolution(format!(
            "the cell size must be positive and finite, got {cell}"
        )));
    }
    let extent = s.hi - s.lo;
    let n = [0, 1, 2].map(|a| ((extent[a] / cell).ceil()).max(1.0));
    if n.iter().product::<f64>() > MAX_CUBES as f64 {
        return Err(SurfaceError::Resolution(format!(
            "a cell of {cell} makes {}x{}x{} lattice cubes over the surface's bounds (at most {MAX_CUBES}): take a larger cell",
            n[0], n[1], n[2]
        )));
    }
    let n = n.map(|x| x as usize);
    let node = |c: [usize; 3]| c[0] + (n[0] + 1) * (c[1] + (n[1] + 1) * c[2]);
    let mut tets = Vec::new();
    for path in PATHS {
        // The centroid of this path's tetrahedron sits at (3 e_a + 2 e_b + e_c) / 4 in its cube.
        let mut offset = [0.0; 3];
        for (w, &axis) in [0.75, 0.5, 0.25].iter().zip(&path) {
            offset[axis] = *w;
        }
        let origin = [0, 1, 2].map(|a| s.lo[a] + offset[a] * cell);
        let inside = s.inside_lattice(origin, cell, n)?;
        let odd = matches!(path, [0, 2, 1] | [1, 0, 2] | [2, 1, 0]);
        for (c, _) in inside.iter().enumerate().filter(|(_, i)| **i) {
            let corner = [c % n[0], (c / n[0]) % n[1], c / (n[0] * n[1])];
            let mut walk = [corner; 4];
            for step in 0..3 {
                walk[step + 1] = walk[step];
                walk[step + 1][path[step]] += 1;
            }
            let t = walk.map(node);
            tets.push(if odd { [t[0], t[1], t[3], t[2]] } else { t });
        }
    }
    if tets.is_empty() {
        return Err(SurfaceError::Resolution(format!(
            "a cell of {cell} is too coarse for the surface: no tetrahedron's centroid is inside"
        )));
    }
    tets.sort_unstable();
    // Keep the used lattice nodes, in lattice order.
    let mut index = vec![usize::MAX; (n[0] + 1) * (n[1] + 1) * (n[2] + 1)];
    for t in &tets {
        for &v in t {
            index[v] = 0;
        }
    }
    let mut positions = Vec::new();
    for (v, slot) in index.iter_mut().enumerate().filter(|(_, s)| **s == 0) {
        *slot = positions.len();
        let c = [v % (n[0] + 1), (v / (n[0] + 1)) % (n[1] + 1), v / ((n[0] + 1) * (n[1] + 1))];
        positions.push(DVec3::from_array([0, 1, 2].map(|a| s.lo[a] + c[a] as f64 * cell)));
    }
    for t in &mut tets {
        *t = t.map(|v| index[v]);
    }
    snap_boundary(s, cell, &mut positions, &tets);
    Ok((positions.iter().map(|p| p.to_array()).collect(), tets))
}

/// Six times the signed volume of a tetrahedron.
fn volume6(p: &[DVec3], t: [usize; 4]) -> f64 {
    let [a, b, c, d] = t.map(|i| p[i].to_array());
    tet_signed_volume6(a, b, c, d)
}

/// Moves each boundary vertex onto the surface, or 3/4, 1/2 or 1/4 of the way, or leaves it,
/// whichever first keeps every tetrahedron around it above [`MIN_VOLUME_FRACTION`] of its
/// lattice volume; twice over, so that a vertex held back by its neighbours may follow them.
fn snap_boundary(s: &ClosedSurface, cell: f64, positions: &mut [DVec3], tets: &[[usize; 4]]) {
    let mut faces: HashMap<[usize; 3], u32> = HashMap::with_capacity(tets.len() * 2);
    let mut around: Vec<Vec<u32>> = vec![Vec::new(); positions.len()];
    for (e, t) in tets.iter().enumerate() {
        for skip in 0..4 {
            let mut f = [0; 3];
            let mut m = 0;
            for (k, &v) in t.iter().enumerate() {
                if k != skip {
                    f[m] = v;
                    m += 1;
                }
            }
            f.sort_unstable();
            *faces.entry(f).or_insert(0) += 1;
        }
        for &v in t {
            around[v].push(e as u32);
        }
    }
    let mut boundary: Vec<usize> = faces.iter().filter(|(_, c)| **c == 1).flat_map(|(f, _)| *f).collect();
    boundary.sort_unstable();
    boundary.dedup();
    let floor = MIN_VOLUME_FRACTION * cell.powi(3);
    // Two passes: a vertex held back by a neighbour's move may go once the neighbour has moved.
    let mut pending = boundary;
    let near = Near::new(s, cell);
    let mut candidates = Vec::new();
    for _ in 0..2 {
        pending.retain(|&v| {
            let from = positions[v];
            let Some(target) = near.closest_within(s, from, 2.0 * cell, &mut candidates) else {
                return false;
            };
            for fraction in [1.0, 0.75, 0.5, 0.25] {
                positions[v] = from.lerp(target, fraction);
                if around[v].iter().all(|&e| volume6(positions, tets[e as usize]) >= floor) {
                    return fraction < 1.0;
                }
            }
            positions[v] = from;
            true
        });
    }
}

/// The surface's triangles binned by the lattice cubes their bounding boxes overlap (a
/// compressed table: `entries[start[c]..start[c + 1]]` for cube `c`), so that the closest point
/// within a few cells of a vertex is searched among the triangles near it, not among all.
struct Near {
    lo: DVec3,
    cell: f64,
    n: [usize; 3],
    start: Vec<usize>,
    entries: Vec<u32>,
}

impl Near {
    fn new(s: &ClosedSurface, cell: f64) -> Self {
        let extent = s.hi - s.lo;
        let n = [0, 1, 2].map(|a| ((extent[a] / cell).ceil() as usize).max(1));
        let mut near = Near { lo: s.lo, cell, n, start: Vec::new(), entries: Vec::new() };
        let spans: Vec<([usize; 3], [usize; 3])> = s
            .triangles
            .iter()
            .map(|t| {
                let p = t.map(|i| s.positions[i]);
                near.span(p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]))
            })
            .collect();
        let mut start = vec![0usize; n[0] * n[1] * n[2] + 1];
        for &(a, b) in &spans {
            near.cubes(a, b, |c| start[c + 1] += 1);
        }
        for c in 0..start.len() - 1 {
            start[c + 1] += start[c];
        }
        let mut entries = vec![0u32; start[start.len() - 1]];
        let mut fill = start.clone();
        for (t, &(a, b)) in spans.iter().enumerate() {
            near.cubes(a, b, |c| {
                entries[fill[c]] = t as u32;
                fill[c] += 1;
            });
        }
        near.start = start;
        near.entries = entries;
        near
    }

    /// The cubes overlapping the box `[lo, hi]` widened by a millionth of a cube on each side
    /// (so that rounding cannot drop a cube the box touches), clamped to the table.
    fn span(&self, lo: DVec3, hi: DVec3) -> ([usize; 3], [usize; 3]) {
        let index = |x: f64, a: usize, margin: f64| {
            let i = ((x - self.lo[a]) / self.cell + margin).floor();
            i.clamp(0.0, (self.n[a] - 1) as f64) as usize
        };
        ([0, 1, 2].map(|a| index(lo[a], a, -1e-6)), [0, 1, 2].map(|a| index(hi[a], a, 1e-6)))
    }

    /// Calls `f` with the index of every cube from `a` to `b` (inclusive).
    fn cubes(&self, a: [usize; 3], b: [usize; 3], mut f: impl FnMut(usize)) {
        for k in a[2]..=b[2] {
            for j in a[1]..=b[1] {
                for i in a[0]..=b[0] {
                    f(i + self.n[0] * (j + self.n[1] * k));
                }
            }
        }
    }

    /// The closest point of the surface to `p` if it lies within `reach` of `p`: the search of
    /// [`ClosedSurface::closest_point`] over the triangles whose boxes come within `reach`, in
    /// the triangles' order (the same point, bit for bit). `candidates` is scratch space.
    fn closest_within(
        &self,
        s: &ClosedSurface,
        p: DVec3,
        reach: f64,
        candidates: &mut Vec<u32>,
    ) -> Option<DVec3> {
        let (a, b) = self.span(p - DVec3::splat(reach), p + DVec3::splat(reach));
        candidates.clear();
        self.cubes(a, b, |c| candidates.extend_from_slice(&self.entries[self.start[c]..self.start[c + 1]]));
        candidates.sort_unstable();
        candidates.dedup();
        let mut best = (f64::INFINITY, p);
        for &t in candidates.iter() {
            let (q, _) = closest_point_on_triangle(p, s.triangles[t as usize].map(|i| s.positions[i]));
            let d = (q - p).length_squared();
            if d < best.0 {
                best = (d, q);
            }
        }
        (best.0.sqrt() <= reach).then_some(best.1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The binned search gives `closest_point`'s answer bit for bit whenever that answer is
    /// within reach, and nothing otherwise, at points in and around a cube of 12 triangles
    /// binned finely (each face spans many cubes).
    #[test]
    fn the_binned_search_equals_the_full_search_within_reach() {
        let (p, t) = crate::surface::tests::cube();
        let s = ClosedSurface::new(p, t).unwrap();
        let cell = 0.07;
        let near = Near::new(&s, cell);
        let mut scratch = Vec::new();
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut uniform = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut found, mut missed) = (0, 0);
        for _ in 0..4000 {
            let q = DVec3::new(uniform(), uniform(), uniform()) * 1.6 - DVec3::splat(0.3);
            let full = s.closest_point(q);
            let got = near.closest_within(&s, q, 2.0 * cell, &mut scratch);
            if (full - q).length() <= 2.0 * cell {
                assert_eq!(got, Some(full), "{q}");
                found += 1;
            } else {
                assert_eq!(got, None, "{q}");
                missed += 1;
            }
        }
        assert!(found > 500 && missed > 500, "{found} within reach, {missed} beyond");
    }
}
