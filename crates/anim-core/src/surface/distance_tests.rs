//! The distance field against brute force (every triangle's closest point and the winding
//! number at every node), the unit cube's exact distance, and finite differences.

use super::tests::cube;
use super::*;

/// The exact signed distance to the unit cube `[0, 1]^3`.
fn cube_distance(p: DVec3) -> f64 {
    let q = (p - DVec3::splat(0.5)).abs() - DVec3::splat(0.5);
    q.max(DVec3::ZERO).length() + q.max_element().min(0.0)
}

/// The cube's field on the lattice of spacing 0.1 from -0.35 (nodes off the faces).
fn cube_lattice() -> ([f64; 3], f64, [usize; 3]) {
    ([-0.35; 3], 0.1, [18; 3])
}

/// Within the band every node holds the exact signed distance (the closest of all triangles by
/// brute force, the sign of the winding number), rounded to `f32`; beyond it the narrow band
/// is clamped at the band's width with the right sign.
#[test]
fn the_narrow_band_is_exact_near_the_surface_and_clamped_beyond() {
    let (p, t) = cube();
    let s = ClosedSurface::new(p, t).unwrap();
    let (origin, h, counts) = cube_lattice();
    let field = DistanceField::narrow_band(&s, origin, h, counts, 2).unwrap();
    let mut clamped = 0;
    for k in 0..counts[2] {
        for j in 0..counts[1] {
            for i in 0..counts[0] {
                let x = DVec3::from_array(origin) + DVec3::new(i as f64, j as f64, k as f64) * h;
                let exact =
                    (s.closest_point(x) - x).length() * if s.contains(x.to_array()) { -1.0 } else { 1.0 };
                assert!((exact - cube_distance(x)).abs() < 1e-12);
                let v = f64::from(field.node([i, j, k]));
                if exact.abs() < 2.0 * h {
                    assert_eq!(v, f64::from(exact as f32), "node {i} {j} {k}");
                } else {
                    assert_eq!(v, f64::from((2.0 * h * exact.signum()) as f32), "node {i} {j} {k}");
                    clamped += 1;
                }
            }
        }
    }
    assert!(clamped > 1000, "{clamped}");
}

/// The full field: exact in its band, and beyond it the first-order fast-sweeping solution
/// within half a spacing plus 6% of the true distance, with the sign of the inside test: deep
/// in the cube and far outside it.
#[test]
fn fast_sweeping_fills_the_lattice_to_first_order() {
    let (p, t) = cube();
    let s = ClosedSurface::new(p, t).unwrap();
    let (origin, h, counts) = ([-1.05; 3], 0.1, [32; 3]);
    let field = DistanceField::new(&s, origin, h, counts).unwrap();
    let mut worst: f64 = 0.0;
    for k in 0..counts[2] {
        for j in 0..counts[1] {
            for i in 0..counts[0] {
                let x = DVec3::from_array(origin) + DVec3::new(i as f64, j as f64, k as f64) * h;
                let exact = cube_distance(x);
                let v = f64::from(field.node([i, j, k]));
                assert_eq!(v < 0.0, exact < 0.0, "node {i} {j} {k}: {v} against {exact}");
                if exact.abs() < 3.0 * h {
                    assert!((v - exact).abs() < 1e-6, "node {i} {j} {k}: {v} against {exact}");
                }
                // First order: half a spacing low on the cube's medial axis, a few percent
                // high far from its corners.
                let bound = 0.5 * h + 0.06 * exact.abs();
                assert!((v - exact).abs() < bound, "node {i} {j} {k}: {v} against {exact}");
                worst = worst.max((v - exact).abs() / bound);
            }
        }
    }
    // The bound is met, not slack by an order of magnitude.
    assert!(worst > 0.5, "{worst}");
}

/// Near a sphere's surface the interpolated distance converges to the polyhedron's exact one
/// (brute force), and the normal points away from the centre.
#[test]
fn the_interpolated_distance_of_a_sphere_converges() {
    let (p, t) = icosphere(5);
    let s = ClosedSurface::new(p, t).unwrap();
    let probes: Vec<DVec3> = (0..200)
        .map(|n| {
            let (a, b) = (n as f64 * 2.399_963, (n as f64 * 0.618_034).fract() * 2.0 - 1.0);
            let r = 0.96 + 0.08 * ((n * 7 % 11) as f64 / 10.0);
            DVec3::new(a.cos() * (1.0 - b * b).sqrt(), a.sin() * (1.0 - b * b).sqrt(), b) * r
        })
        .collect();
    let error = |h: f64| {
        let field = DistanceField::around(&s, h, 4.0 * h).unwrap();
        probes
            .iter()
            .map(|&x| {
                let sample = field.sample(x).unwrap();
                assert!(sample.normal().dot(x.normalize()) > 0.99, "{x}");
                // The exact distance to the polyhedron (its faces lie inside the unit sphere by
                // up to 2e-4 at 5 subdivisions).
                let exact = (s.closest_point(x) - x).length() * if x.length() < 1.0 { -1.0 } else { 1.0 };
                (sample.distance - exact).abs()
            })
            .fold(0.0, f64::max)
    };
    let (coarse, fine) = (error(0.08), error(0.04));
    // About h^2 / 4 at the coarse spacing; at the fine one the polyhedron's edges (3 cm apart)
    // start to show, where its distance has creases inside.
    assert!(coarse < 0.0025 && fine < 0.5 * coarse, "{coarse} {fine}");
}

/// The gradient and Hessian are the interpolant's: central differences of the sampled distance
/// agree inside a cell.
#[test]
fn the_gradient_and_hessian_match_finite_differences() {
    let (p, t) = icosphere(3);
    let s = ClosedSurface::new(p, t).unwrap();
    let field = DistanceField::around(&s, 0.1, 0.3).unwrap();
    let eps = 1e-6;
    for x in [DVec3::new(0.33, -0.41, 0.72), DVec3::new(-0.02, 0.07, 0.13), DVec3::new(1.07, 0.21, -0.18)] {
        let f = |y: DVec3| field.sample(y).unwrap();
        let s0 = f(x);
        for a in 0..3 {
            let e = DVec3::AXES[a] * eps;
            let (up, down) = (f(x + e), f(x - e));
            let g = (up.distance - down.distance) / (2.0 * eps);
            assert!((g - s0.gradient[a]).abs() < 1e-6, "gradient {a} at {x}: {g} {}", s0.gradient[a]);
            let hcol = (up.gradient - down.gradient) / (2.0 * eps);
            assert!((hcol - s0.hessian.col(a)).abs().max_element() < 1e-5, "hessian {a} at {x}");
        }
        assert_eq!(s0.hessian, s0.hessian.transpose());
        assert_eq!([s0.hessian.x_axis.x, s0.hessian.y_axis.y, s0.hessian.z_axis.z], [0.0; 3]);
    }
}

/// Outside the lattice and at non-finite points there is no sample; the lattice's corners are.
#[test]
fn samples_exist_on_the_lattice_only() {
    let (p, t) = cube();
    let s = ClosedSurface::new(p, t).unwrap();
    let (origin, h, counts) = cube_lattice();
    let field = DistanceField::new(&s, origin, h, counts).unwrap();
    assert_eq!(field.far_corner(), DVec3::splat(-0.35 + 1.7));
    assert!(field.sample(field.origin()).is_some() && field.sample(field.far_corner()).is_some());
    assert!(field.sample(field.origin() - DVec3::X * 1e-9).is_none());
    assert!(field.sample(field.far_corner() + DVec3::Z * 1e-9).is_none());
    assert!(field.sample(DVec3::new(f64::NAN, 0.5, 0.5)).is_none());
}

/// The table does not depend on the thread count.
#[test]
fn the_field_is_the_same_on_one_and_two_threads() {
    let (p, t) = icosphere(3);
    let s = ClosedSurface::new(p, t).unwrap();
    let build = |threads| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| DistanceField::around(&s, 0.07, 0.2).unwrap())
    };
    let (one, two) = (build(1), build(2));
    let nodes = one.counts();
    for k in 0..nodes[2] {
        for j in 0..nodes[1] {
            for i in 0..nodes[0] {
                assert_eq!(one.node([i, j, k]).to_bits(), two.node([i, j, k]).to_bits());
            }
        }
    }
}

/// Bad lattices are refused with the reason.
#[test]
fn bad_lattices_are_refused() {
    let (p, t) = cube();
    let s = ClosedSurface::new(p, t).unwrap();
    let message = |r: Result<DistanceField, SurfaceError>| r.unwrap_err().to_string();
    assert!(message(DistanceField::around(&s, 0.0, 0.1)).contains("cell must be positive"));
    assert!(message(DistanceField::around(&s, 0.1, -1.0)).contains("margin"));
    assert!(message(DistanceField::around(&s, 1e-4, 0.1)).contains("make the cell larger"));
    assert!(message(DistanceField::new(&s, [0.0; 3], 0.1, [1, 5, 5])).contains("at least two nodes"));
    assert!(message(DistanceField::new(&s, [0.0; 3], 0.1, [300, 300, 300])).contains("2^24"));
    assert!(message(DistanceField::narrow_band(&s, [0.0; 3], 0.1, [5; 3], 0)).contains("band"));
    assert!(message(DistanceField::new(&s, [f64::NAN, 0.0, 0.0], 0.1, [5; 3])).contains("origin"));
}
