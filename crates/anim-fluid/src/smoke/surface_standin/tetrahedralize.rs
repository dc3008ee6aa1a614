//! The tetrahedral mesh of a closed surface's inside: Kuhn's six tetrahedra per lattice cube,
//! kept by their centroid, with the boundary vertices moved onto the surface where that keeps
//! every tetrahedron well shaped (see the [module](super)).

use std::collections::HashMap;

use anim_core::glam::DVec3;

use super::{ClosedSurface, SurfaceError, Tetrahedra};

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
    let [a, b, c, d] = t.map(|i| p[i]);
    (b - a).dot((c - a).cross(d - a))
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
    for _ in 0..2 {
        pending.retain(|&v| {
            let from = positions[v];
            let target = s.closest_point(from);
            if (target - from).length() > 2.0 * cell {
                return false;
            }
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
