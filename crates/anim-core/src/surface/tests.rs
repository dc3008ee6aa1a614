use super::*;

/// The unit cube, 12 outward triangles.
pub(super) fn cube() -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
    let p = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
        [1.0, 1.0, 1.0],
        [0.0, 1.0, 1.0],
    ];
    let t = vec![
        [0, 2, 1],
        [0, 3, 2],
        [4, 5, 6],
        [4, 6, 7],
        [0, 1, 5],
        [0, 5, 4],
        [1, 2, 6],
        [1, 6, 5],
        [2, 3, 7],
        [2, 7, 6],
        [3, 0, 4],
        [3, 4, 7],
    ];
    (p, t)
}

/// A sphere of radius `r`: the icosahedron subdivided `levels` times, vertices on the sphere.
fn sphere(r: f64, levels: usize) -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
    let (p, t) = icosphere(levels);
    (p.iter().map(|v| v.map(|x| x * r)).collect(), t)
}

/// A torus about z, major radius `big`, minor `small`, `n` by `m` quads split in two.
fn torus(big: f64, small: f64, n: usize, m: usize) -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
    let mut p = Vec::new();
    for i in 0..n {
        let u = 2.0 * PI * i as f64 / n as f64;
        for j in 0..m {
            let v = 2.0 * PI * j as f64 / m as f64;
            let r = big + small * v.cos();
            p.push([r * u.cos(), r * u.sin(), small * v.sin()]);
        }
    }
    let at = |i: usize, j: usize| (i % n) * m + (j % m);
    let mut t = Vec::new();
    for i in 0..n {
        for j in 0..m {
            t.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            t.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    (p, t)
}

fn polytope(s: &ClosedSurface, tets: &[[usize; 4]], p: &[[f64; 3]]) -> (f64, f64) {
    let p: Vec<DVec3> = p.iter().map(|x| DVec3::from_array(*x)).collect();
    let v: Vec<f64> = tets.iter().map(|t| tetrahedralize_volume6(&p, *t) / 6.0).collect();
    let _ = s;
    (v.iter().sum(), v.iter().copied().fold(f64::INFINITY, f64::min))
}

fn tetrahedralize_volume6(p: &[DVec3], t: [usize; 4]) -> f64 {
    let [a, b, c, d] = t.map(|i| p[i]);
    (b - a).dot((c - a).cross(d - a))
}

#[test]
fn the_cube_encloses_its_volume_and_its_inside() {
    let (p, t) = cube();
    let s = ClosedSurface::new(p.clone(), t.clone()).unwrap();
    assert!((s.volume() - 1.0).abs() < 1e-14);
    assert!((s.winding_number([0.3, 0.6, 0.2]) - 1.0).abs() < 1e-12);
    assert!(s.winding_number([1.3, 0.6, 0.2]).abs() < 1e-12);
    // Every triangle turned inward: still closed and consistent, same volume and inside.
    let inward = ClosedSurface::new(p, t.iter().map(|&[a, b, c]| [a, c, b]).collect()).unwrap();
    assert!((inward.volume() - 1.0).abs() < 1e-14);
    assert!(inward.contains([0.3, 0.6, 0.2]) && !inward.contains([-0.1, 0.6, 0.2]));
}

#[test]
fn a_surface_that_is_not_closed_is_refused_naming_the_edge_or_triangle() {
    let (p, t) = cube();
    let mut open = t.clone();
    open.remove(3); // [4, 6, 7]
    let e = ClosedSurface::new(p.clone(), open).unwrap_err();
    assert!(matches!(e, SurfaceError::Open { .. }), "{e}");
    assert!(e.to_string().contains("not closed"), "{e}");
    let mut flipped = t.clone();
    flipped[5] = [0, 4, 5];
    let e = ClosedSurface::new(p.clone(), flipped).unwrap_err();
    assert!(matches!(e, SurfaceError::Inconsistent { triangles: [_, 5], .. }), "{e}");
    let mut extra = t.clone();
    extra.push([0, 2, 1]);
    extra.push([0, 1, 2]);
    let e = ClosedSurface::new(p.clone(), extra).unwrap_err();
    assert!(matches!(e, SurfaceError::Inconsistent { .. } | SurfaceError::NonManifold { .. }), "{e}");
    let mut degenerate = t.clone();
    degenerate[0] = [0, 0, 1];
    let e = ClosedSurface::new(p.clone(), degenerate).unwrap_err();
    assert_eq!(e, SurfaceError::Degenerate { triangle: 0, vertices: [0, 0, 1] });
    let mut index = t.clone();
    index[2] = [4, 5, 8];
    assert_eq!(
        ClosedSurface::new(p.clone(), index).unwrap_err().to_string(),
        "triangle 2 names vertex 8, but there are 8 vertices"
    );
    let mut nan = p.clone();
    nan[6][1] = f64::NAN;
    assert!(matches!(
        ClosedSurface::new(nan, t.clone()).unwrap_err(),
        SurfaceError::NonFinite { vertex: 6, .. }
    ));
    assert_eq!(ClosedSurface::new(p, vec![]).unwrap_err(), SurfaceError::Empty);
    // A closed surface folded flat: two copies of one square, back to back (edge (0, 2) is
    // shared by all four triangles) ...
    let flat = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
    let sheet = vec![[0, 1, 2], [0, 2, 3], [0, 2, 1], [0, 3, 2]];
    let e = ClosedSurface::new(flat.clone(), sheet).unwrap_err();
    assert_eq!(e, SurfaceError::NonManifold { edge: [2, 0], count: 4 });
    // ... and one triangle back to back with itself: closed, manifold, consistent, no volume.
    let e = ClosedSurface::new(flat, vec![[0, 1, 2], [0, 2, 1]]).unwrap_err();
    assert_eq!(e, SurfaceError::ZeroVolume);
}

/// A surface whose extents multiply past `f64` is refused as too large, not misread as
/// degenerate or as holding nothing; one just inside the range is measured.
#[test]
fn a_surface_too_large_to_measure_is_refused() {
    let (p, t) = cube();
    let scaled = |s: f64| p.iter().map(|v| v.map(|x| x * s)).collect::<Vec<_>>();
    let e = ClosedSurface::new(scaled(1e110), t.clone()).unwrap_err();
    assert_eq!(e, SurfaceError::TooLarge { extent: [1e110; 3] });
    assert!(e.to_string().contains("too large"), "{e}");
    let s = ClosedSurface::new(scaled(1e100), t.clone()).expect("measurable");
    assert!((s.volume() / 1e300 - 1.0).abs() < 1e-12, "{}", s.volume());
    let e = ClosedSurface::new(scaled(1e160), t).unwrap_err();
    assert!(matches!(e, SurfaceError::TooLarge { .. }), "{e}");
}

#[test]
fn the_sphere_winding_number_is_one_inside_and_zero_outside() {
    let (p, t) = sphere(1.0, 3);
    let s = ClosedSurface::new(p.clone(), t.clone()).unwrap();
    // The inscribed polytope's volume: below the ball's, by O(h^2).
    let ball = 4.0 / 3.0 * PI;
    assert!(s.volume() < ball && s.volume() > 0.98 * ball, "{}", s.volume());
    assert!((s.winding_number([0.1, -0.2, 0.3]) - 1.0).abs() < 1e-12);
    assert!(s.winding_number([1.5, 0.0, 0.0]).abs() < 1e-12);
    let centroid = [0, 1, 2].map(|a| (p[t[40][0]][a] + p[t[40][1]][a] + p[t[40][2]][a]) / 3.0);
    let (inner, outer) = (centroid.map(|x| 0.999 * x), centroid.map(|x| 1.001 * x));
    assert!((s.winding_number(inner) - 1.0).abs() < 1e-6 && s.winding_number(outer).abs() < 1e-6);
}

/// The row-by-row classification agrees with the solid-angle sum at every lattice point off
/// the surface, including lattices whose rows run exactly along edges and through vertices.
#[test]
fn the_lattice_classification_agrees_with_the_winding_number() {
    let shapes = [cube(), sphere(0.7, 2), torus(0.6, 0.25, 24, 12)];
    let lattices = [
        ([0.0, 0.0, 0.0], 0.125, [9, 9, 9]),
        ([-0.8, -0.8, -0.8], 0.1, [17, 17, 17]),
        ([-0.93, -0.91, -0.3], 0.07, [28, 27, 9]),
    ];
    for (shape, (p, t)) in shapes.into_iter().enumerate() {
        let s = ClosedSurface::new(p, t).unwrap();
        for &(origin, h, counts) in &lattices {
            let fast = s.inside_lattice(origin, h, counts).unwrap();
            let mut compared = 0;
            for (c, &inside) in fast.iter().enumerate() {
                let ijk = [c % counts[0], (c / counts[0]) % counts[1], c / (counts[0] * counts[1])];
                let x = [0, 1, 2].map(|a| origin[a] + ijk[a] as f64 * h);
                let w = s.winding_number(x);
                if (w - 0.5).abs() > 0.25 {
                    assert_eq!(inside, w > 0.5, "shape {shape}, point {x:?}, winding number {w}");
                    compared += 1;
                }
            }
            assert!(compared > fast.len() / 2, "shape {shape}: only {compared} points off the surface");
        }
    }
}

#[test]
fn the_torus_hole_is_empty_and_lattice_samples_fill_the_volume() {
    let (p, t) = torus(0.6, 0.25, 48, 24);
    let s = ClosedSurface::new(p, t).unwrap();
    assert!(!s.contains([0.0, 0.0, 0.0]) && s.contains([0.6, 0.0, 0.0]) && s.contains([0.0, -0.6, 0.1]));
    let h = 0.02;
    let points = s.sample_inside(h).unwrap();
    let sampled = points.len() as f64 * h.powi(3);
    assert!((sampled - s.volume()).abs() < 0.02 * s.volume(), "{sampled} vs {}", s.volume());
    assert!(points.iter().step_by(97).all(|&x| s.winding_number(x) > 0.5));
    let (unit, _) = cube();
    let c = ClosedSurface::new(unit, cube().1).unwrap();
    assert_eq!(c.sample_inside(0.25).unwrap().len(), 64);
}

#[test]
fn the_cube_is_meshed_exactly_by_its_lattice() {
    let (p, t) = cube();
    let s = ClosedSurface::new(p, t).unwrap();
    let (nodes, tets) = s.tetrahedralize(0.25).unwrap();
    assert_eq!(nodes.len(), 125);
    assert_eq!(tets.len(), 384);
    let (volume, smallest) = polytope(&s, &tets, &nodes);
    assert!((volume - 1.0).abs() < 1e-12);
    assert!((smallest - 0.25f64.powi(3) / 6.0).abs() < 1e-15, "every tetrahedron is a Kuhn tetrahedron");
}

/// The mesh of a sphere: positive, well-shaped tetrahedra whose volume converges to the
/// surface's as the cell shrinks, with the boundary on the surface.
#[test]
fn the_sphere_mesh_converges_to_its_volume() {
    let (p, t) = sphere(1.0, 4);
    let s = ClosedSurface::new(p, t).unwrap();
    let mut errors = Vec::new();
    for cell in [0.4, 0.2, 0.1] {
        let (nodes, tets) = s.tetrahedralize(cell).unwrap();
        let (volume, smallest) = polytope(&s, &tets, &nodes);
        assert!(
            smallest >= 0.1 * cell.powi(3) / 6.0 * (1.0 - 1e-9),
            "cell {cell}: a tetrahedron of {smallest}"
        );
        let outside = nodes.iter().map(|&x| DVec3::from_array(x).length()).fold(0.0, f64::max);
        assert!(outside < 1.0 + 0.5 * cell, "cell {cell}: a node at radius {outside}");
        errors.push((volume - s.volume()).abs() / s.volume());
    }
    assert!(errors[2] < 0.03 && errors[2] < errors[1] && errors[1] < errors[0], "{errors:?}");
}

#[test]
fn the_torus_mesh_keeps_the_hole() {
    let (p, t) = torus(0.6, 0.25, 48, 24);
    let s = ClosedSurface::new(p, t).unwrap();
    let (nodes, tets) = s.tetrahedralize(0.05).unwrap();
    let (volume, smallest) = polytope(&s, &tets, &nodes);
    assert!(smallest > 0.0);
    assert!((volume - s.volume()).abs() < 0.05 * s.volume(), "{volume} vs {}", s.volume());
    let nearest = nodes.iter().map(|x| (x[0] * x[0] + x[1] * x[1]).sqrt()).fold(f64::INFINITY, f64::min);
    assert!(nearest > 0.3, "a node {nearest} from the axis, inside the hole");
}

#[test]
fn a_bad_cell_is_refused() {
    let (p, t) = sphere(1.0, 1);
    let s = ClosedSurface::new(p, t).unwrap();
    for cell in [0.0, -1.0, f64::NAN, 1e-4] {
        assert!(matches!(s.tetrahedralize(cell), Err(SurfaceError::Resolution(_))), "cell {cell}");
    }
    assert!(matches!(s.tetrahedralize(10.0), Err(SurfaceError::Resolution(m)) if m.contains("too coarse")));
    assert!(s.inside_lattice([0.0; 3], 0.0, [2, 2, 2]).is_err());
    // One point past 2^27 is refused before anything is allocated; so is a sampling spacing
    // whose lattice count overflows.
    let e = s.inside_lattice([0.0; 3], 1e-3, [513, 512, 512]).unwrap_err();
    assert!(e.to_string().contains("at most 134217728 points"), "{e}");
    assert!(matches!(s.sample_inside(1e-300), Err(SurfaceError::Resolution(_))));
}
