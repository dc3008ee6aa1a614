//! Procedural meshes for scenes and tests: an icosphere (a closed triangle mesh for balloons), a
//! tetrahedralised box, a tetrahedral "bunny-like" blob, and the boundary of any tet mesh.
//!
//! Tetrahedral meshes are plain arrays (`positions`, `tets`), so a mesh read from a file by any
//! reader (anim-io's Gmsh and TetGen readers, say) goes to
//! [`PbdBuilder::tet_mesh`](crate::PbdBuilder::tet_mesh) the same way.

use crate::constraint::tet_volume;
use anim_core::glam::DVec3;
use std::collections::HashMap;

/// A unit-radius icosphere around the origin (anim-core's, re-exported here).
pub use anim_core::surface::icosphere;

/// A box of `n[0] x n[1] x n[2]` cubic cells of edge `h` from `origin`, each cell split into 6
/// tetrahedra around its main diagonal (Kuhn's subdivision: conforming across cells). All
/// tetrahedra are positively oriented.
#[must_use]
pub fn tet_box(n: [usize; 3], origin: [f64; 3], h: f64) -> (Vec<[f64; 3]>, Vec<[usize; 4]>) {
    tet_cells(n, origin, h, |_| true)
}

/// A "bunny-like" soft blob of radius about `radius` centred at `center`: the cells of a cubic
/// grid (`cells` across the body) whose centres lie inside a union of spheres (body, head, two
/// ears, tail), each split into 6 tetrahedra, unused vertices removed.
#[must_use]
pub fn tet_blob(center: [f64; 3], radius: f64, cells: usize) -> (Vec<[f64; 3]>, Vec<[usize; 4]>) {
    let c = DVec3::from_array(center);
    let r = radius;
    // (centre offset, radius) in units of r; x forward, z up.
    let parts = [
        (DVec3::new(0.0, 0.0, 0.0), 1.0),
        (DVec3::new(0.75, 0.0, 0.55), 0.55),
        (DVec3::new(0.8, 0.18, 1.1), 0.2),
        (DVec3::new(0.8, -0.18, 1.1), 0.2),
        (DVec3::new(-0.95, 0.0, 0.15), 0.25),
    ];
    let lo = c + DVec3::new(-1.25, -1.05, -1.05) * r;
    let hi = c + DVec3::new(1.4, 1.05, 1.35) * r;
    let h = 2.0 * r / cells.max(2) as f64;
    let dims = ((hi - lo) / h).ceil();
    let n = [dims.x as usize, dims.y as usize, dims.z as usize];
    let inside = |p: DVec3| parts.iter().any(|&(o, s)| (p - (c + o * r)).length() < s * r);
    tet_cells(n, lo.to_array(), h, inside)
}

fn tet_cells(
    n: [usize; 3],
    origin: [f64; 3],
    h: f64,
    keep: impl Fn(DVec3) -> bool,
) -> (Vec<[f64; 3]>, Vec<[usize; 4]>) {
    let o = DVec3::from_array(origin);
    let (nx, ny) = (n[0] + 1, n[1] + 1);
    let vid = |a: usize, b: usize, c: usize| (c * ny + b) * nx + a;
    let mut tets = Vec::new();
    // The 6 monotone paths from corner 000 to 111.
    let perms = [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]];
    for k in 0..n[2] {
        for j in 0..n[1] {
            for i in 0..n[0] {
                let centre = o + h * DVec3::new(i as f64 + 0.5, j as f64 + 0.5, k as f64 + 0.5);
                if !keep(centre) {
                    continue;
                }
                for perm in perms {
                    let mut corner = [i, j, k];
                    let mut tet = [vid(i, j, k), 0, 0, 0];
                    for (s, &axis) in perm.iter().enumerate() {
                        corner[axis] += 1;
                        tet[s + 1] = vid(corner[0], corner[1], corner[2]);
                    }
                    tets.push(tet);
                }
            }
        }
    }
    // Keep only used vertices, renumbered in grid order.
    let total = nx * ny * (n[2] + 1);
    let mut map = vec![usize::MAX; total];
    for t in &tets {
        for &v in t {
            map[v] = 0;
        }
    }
    let mut positions = Vec::new();
    for (v, m) in map.iter_mut().enumerate() {
        if *m == 0 {
            *m = positions.len();
            let (a, b, c) = (v % nx, (v / nx) % ny, v / (nx * ny));
            positions.push((o + h * DVec3::new(a as f64, b as f64, c as f64)).to_array());
        }
    }
    for t in &mut tets {
        *t = t.map(|v| map[v]);
        let p = t.map(|v| DVec3::from_array(positions[v]));
        if tet_volume(p).0 < 0.0 {
            t.swap(2, 3);
        }
    }
    (positions, tets)
}

/// The boundary faces of a tet mesh (faces that belong to one tetrahedron), oriented with
/// outward normals, in the order the tetrahedra list them.
#[must_use]
pub fn tet_surface(positions: &[[f64; 3]], tets: &[[usize; 4]]) -> Vec<[usize; 3]> {
    let mut count: HashMap<[usize; 3], usize> = HashMap::new();
    let faces =
        |t: &[usize; 4]| [[t[1], t[2], t[3]], [t[0], t[3], t[2]], [t[0], t[1], t[3]], [t[0], t[2], t[1]]];
    let sorted = |mut f: [usize; 3]| {
        f.sort_unstable();
        f
    };
    for t in tets {
        for f in faces(t) {
            *count.entry(sorted(f)).or_default() += 1;
        }
    }
    let mut out = Vec::new();
    for t in tets {
        let p = t.map(|v| DVec3::from_array(positions[v]));
        let positive = tet_volume(p).0 > 0.0;
        for f in faces(t) {
            if count[&sorted(f)] == 1 {
                // For a positive tet these faces point outward; flip them for a negative one.
                out.push(if positive { f } else { [f[0], f[2], f[1]] });
            }
        }
    }
    out
}
