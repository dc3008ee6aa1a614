//! The box and capsule penalty contact against finite differences and closed forms.

use super::*;
use crate::{EARTH_GRAVITY, NetworkBuilder, SpringNetwork};
use anim_core::integrate::{IntegratorKind, MechanicalSystem, NewtonParams, study::advance};
use anim_core::linalg::LinearSolverKind;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const BOX: Shape = Shape::Box { center: [0.1, -0.2, 0.3], half_extents: [0.5, 0.3, 0.4] };
const CAPSULE: Shape = Shape::Capsule { a: [-0.3, 0.1, 0.0], b: [0.4, -0.2, 0.5], radius: 0.35 };

fn collider(shape: Shape) -> Collider {
    Collider { shape, stiffness: 40.0, damping: 0.3, friction: 0.7, smoothing: 0.05, thickness: 0.0 }
}

/// Where a sample sits: inside the grown shape and away from the places where the force or its
/// derivative has a kink (the grown surface, the end of the smoothing zone, a box's inner ridges
/// and the planes between its face, edge and corner zones, a capsule's cap boundaries and axis),
/// with its region's label.
fn region(c: &Collider, x: DVec3) -> Option<&'static str> {
    let (phi, _) = c.shape.signed_distance(x);
    let p = c.thickness - phi;
    let margin = 1e-4;
    if !(p > margin) || (p - c.smoothing).abs() < margin {
        return None;
    }
    match c.shape {
        Shape::Box { center, half_extents } => {
            let q = (x - DVec3::from_array(center)).abs() - DVec3::from_array(half_extents);
            if q.to_array().iter().any(|q| q.abs() < margin) {
                return None;
            }
            let mut sorted = q.to_array();
            sorted.sort_by(f64::total_cmp);
            match q.cmpgt(DVec3::ZERO).bitmask().count_ones() {
                0 => (sorted[2] - sorted[1] > margin).then_some("inside"),
                1 => Some("beside a face"),
                2 => Some("beside an edge"),
                _ => Some("beside a corner"),
            }
        }
        Shape::Capsule { a, b, .. } => {
            let (a, b) = (DVec3::from_array(a), DVec3::from_array(b));
            let t = (x - a).dot(b - a) / (b - a).length_squared();
            let r = (x - (a + t.clamp(0.0, 1.0) * (b - a))).length();
            if t.abs() < margin || (t - 1.0).abs() < margin || r < 1e-2 {
                None
            } else if t > 0.0 && t < 1.0 {
                Some(if p < c.smoothing { "side, smoothing" } else { "side, linear" })
            } else {
                Some(if p < c.smoothing { "cap, smoothing" } else { "cap, linear" })
            }
        }
        _ => Some("any"),
    }
}

/// The Jacobians at `(x, v)`: `(K, D)`.
pub(super) fn jacobians<G: Geometry>(c: &Collider<G>, x: DVec3, v: DVec3, exact: bool) -> (DMat3, DMat3) {
    let (mut k, mut d) = (DMat3::ZERO, DMat3::ZERO);
    c.jacobians(x, v, exact, &mut k, &mut d);
    (k, d)
}

/// Central differences of the force in `x` (`wrt_x`) or in `v`, column by column.
pub(super) fn finite_differences<G: Geometry>(c: &Collider<G>, x: DVec3, v: DVec3, wrt_x: bool) -> DMat3 {
    let h = 1e-7;
    let cols = DVec3::AXES.map(|e| {
        let (plus, minus) = if wrt_x {
            (c.force(x + h * e, v), c.force(x - h * e, v))
        } else {
            (c.force(x, v + h * e), c.force(x, v - h * e))
        };
        (plus - minus) / (2.0 * h)
    });
    DMat3::from_cols(cols[0], cols[1], cols[2])
}

pub(super) fn max_abs(m: DMat3) -> f64 {
    m.to_cols_array().iter().fold(0.0f64, |a, v| a.max(v.abs()))
}

#[test]
fn box_and_capsule_jacobians_match_central_finite_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(0x626f78);
    // Without a thickness a box has only its inside; with one, the zones beside its faces, edges
    // and corners where the grown box is rounded.
    let cases = [(BOX, 0.0, 1), (BOX, 0.1, 4), (CAPSULE, 0.0, 4), (CAPSULE, 0.1, 4)];
    for (shape, thickness, regions) in cases {
        let c = Collider { thickness, ..collider(shape) };
        let mut seen = std::collections::BTreeMap::new();
        while seen.values().sum::<usize>() < 400 {
            // Half the samples anywhere, half near a box's corners or a capsule's ends.
            let x = if rng.random_bool(0.5) {
                DVec3::from_array(std::array::from_fn(|_| rng.random_range(-0.8..0.9)))
            } else {
                let signs =
                    DVec3::from_array(std::array::from_fn(|_| if rng.random_bool(0.5) { 1.0 } else { -1.0 }));
                match shape {
                    // Mostly in the octant beyond the corner.
                    Shape::Box { center, half_extents } => {
                        let out = DVec3::from_array(std::array::from_fn(|_| rng.random_range(-0.02..0.1)));
                        DVec3::from_array(center) + signs * (DVec3::from_array(half_extents) + out)
                    }
                    Shape::Capsule { a, b, .. } => {
                        let end = DVec3::from_array(if rng.random_bool(0.5) { a } else { b });
                        end + signs * DVec3::from_array(std::array::from_fn(|_| rng.random_range(0.0..0.4)))
                    }
                    _ => DVec3::ZERO,
                }
            };
            let Some(label) = region(&c, x) else { continue };
            *seen.entry(label).or_insert(0) += 1;
            let v = DVec3::from_array(std::array::from_fn(|_| rng.random_range(-1.0..1.0)));
            let (p, n, _) = c.probe(x).expect("inside");
            let what = format!("{} (thickness {thickness}) {label} at {x}", shape.name());
            // Exact: every term of df/dx and df/dv.
            let (k, d) = jacobians(&c, x, v, true);
            let (k_fd, d_fd) = (finite_differences(&c, x, v, true), finite_differences(&c, x, v, false));
            let scale = max_abs(k_fd).max(max_abs(d_fd)).max(1e-3);
            let (ek, ed) = (max_abs(k - k_fd) / scale, max_abs(d - d_fd) / scale);
            assert!(ek < 1e-6, "{what}: K off by {ek:e}\n{k}\n{k_fd}");
            assert!(ed < 1e-6, "{what}: D off by {ed:e}");
            // Definite: -e'(p) max(1 - tau_n v_n, 0) n n^T, the same D.
            let slope = if p < c.smoothing { c.stiffness * p / c.smoothing } else { c.stiffness };
            let expected = -(slope * (1.0 - c.damping * n.dot(v)).max(0.0)) * crate::geom::outer(n, n);
            let (k_def, d_def) = jacobians(&c, x, v, false);
            assert!(max_abs(k_def - expected) <= 1e-12 * scale, "{what}: definite K");
            assert_eq!(d_def, d, "{what}: definite D");
        }
        // Every region of the shape was sampled, not only the easy one.
        assert_eq!(seen.len(), regions, "{} (thickness {thickness}): {seen:?}", shape.name());
        assert!(
            seen.values().all(|&count| count >= 10),
            "{} (thickness {thickness}): {seen:?}",
            shape.name()
        );
    }
}

#[test]
fn the_force_pushes_out_along_the_nearest_surface_and_vanishes_outside() {
    let c = Collider { smoothing: 0.0, ..collider(BOX) };
    // 0.05 below the top face (z = 0.7) and far from the others: pushed up by k p.
    let f = c.force(DVec3::new(0.1, -0.2, 0.65), DVec3::ZERO);
    assert!((f - DVec3::new(0.0, 0.0, 40.0 * 0.05)).length() < 1e-12, "{f}");
    // 0.02 inside the face x = 0.6: pushed along +x.
    let f = c.force(DVec3::new(0.58, -0.2, 0.3), DVec3::ZERO);
    assert!((f - DVec3::new(40.0 * 0.02, 0.0, 0.0)).length() < 1e-12, "{f}");
    // Outside, beside an edge: nothing.
    assert_eq!(c.force(DVec3::new(0.61, 0.11, 0.3), DVec3::ONE), DVec3::ZERO);
    assert_eq!(c.energy(DVec3::new(0.61, 0.11, 0.3)), 0.0);
    let c = Collider { smoothing: 0.0, ..collider(CAPSULE) };
    // Beside the middle of the axis, 0.1 from it: pushed away from the axis by k (r - 0.1).
    let (a, b) = (DVec3::new(-0.3, 0.1, 0.0), DVec3::new(0.4, -0.2, 0.5));
    let side = (b - a).normalize().any_orthonormal_vector();
    let x = 0.5 * (a + b) + 0.1 * side;
    let f = c.force(x, DVec3::ZERO);
    assert!((f - 40.0 * 0.25 * side).length() < 1e-12, "{f}");
    assert!((c.energy(x) - 0.5 * 40.0 * 0.25 * 0.25).abs() < 1e-12);
    // Beyond an end, along the axis: pushed out along the axis.
    let out = (b - a).normalize();
    let f = c.force(b + 0.3 * out, DVec3::ZERO);
    assert!((f - 40.0 * 0.05 * out).length() < 1e-12, "{f}");
    // On the axis itself: a finite push and no curvature term.
    let f = c.force(0.5 * (a + b), DVec3::ONE);
    assert!(f.is_finite() && (f.length() > 0.0), "{f}");
    let (k, d) = jacobians(&c, 0.5 * (a + b), DVec3::ONE, true);
    assert!(k.is_finite() && d.is_finite());
}

/// A particle on a box's top face settles at the penalty depth, and one dropped onto a capsule's
/// side comes to rest on top of it, with the definite Jacobian and sparse Cholesky.
#[cfg_attr(not(feature = "faer"), ignore = "sparse Cholesky needs the `faer` feature")]
#[test]
fn particles_rest_on_a_box_and_a_capsule_at_the_penalty_depth() {
    let settle = |shape: Shape, thickness: f64, start: [f64; 3]| {
        let mut b = NetworkBuilder::new();
        b.gravity(EARTH_GRAVITY);
        b.particle(start, 0.2);
        b.collider(Collider {
            shape,
            stiffness: 1000.0,
            damping: 0.5,
            friction: 1.0,
            smoothing: 1e-3,
            thickness,
        });
        let mut net = b.build().expect("builds");
        let mut state = net.rest_state();
        let mut integ = IntegratorKind::BackwardEuler.build_with::<SpringNetwork>(
            3,
            NewtonParams::with_tolerance(1e-12),
            LinearSolverKind::Cholesky,
        );
        advance(integ.as_mut(), &mut net, &mut state, 0.005, 2000).expect("steps");
        let mut f = vec![0.0; 3];
        net.force(0.0, &state.x, &state.v, &mut f);
        (state, f)
    };
    // phi(p) = k_c (p - delta/2) = m g.
    let depth = 0.2 * 9.81 / 1000.0 + 0.5e-3;
    let table = Shape::Box { center: [0.0, 0.0, 0.25], half_extents: [0.5, 0.5, 0.25] };
    for thickness in [0.0, 0.01] {
        let (state, _) = settle(table, thickness, [0.1, 0.2, 0.55]);
        let z = 0.5 + thickness - depth;
        assert!((state.x[2] - z).abs() < 1e-9, "z = {}, expected {z}", state.x[2]);
        assert!((state.x[0] - 0.1).abs() < 1e-12 && (state.x[1] - 0.2).abs() < 1e-12);
    }
    // A horizontal capsule along x: the particle rests on its top line.
    let bar = Shape::Capsule { a: [-0.5, 0.0, 0.2], b: [0.5, 0.0, 0.2], radius: 0.2 };
    for thickness in [0.0, 0.01] {
        let (state, f) = settle(bar, thickness, [0.1, 0.0, 0.6]);
        let z = 0.4 + thickness - depth;
        assert!((state.x[2] - z).abs() < 1e-9, "z = {}, expected {z}", state.x[2]);
        assert!(f.iter().all(|c| c.abs() < 1e-9), "net force {f:?}");
    }
}
