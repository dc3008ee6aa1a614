//! Coulomb friction at obstacle contacts, one coefficient `mu >= 0` per obstacle (0, the default,
//! is frictionless).
//!
//! **Explicit step** (velocity level). When the contact projection removes an approaching normal
//! velocity `dv_n = -v . n > 0` from a vertex, the tangential velocity `v_t = v - (v . n) n` may
//! change by at most `mu dv_n`: a vertex whose tangential speed is below that sticks (`v_t` set
//! to zero), a faster one slides with its tangential speed reduced by `mu dv_n`
//! ([`coulomb_velocity`]). The position gets the same change times `dt`, as if the impulse had
//! been part of the velocity update.
//!
//! **Backward Euler** (a lagged, smoothed friction potential; Li et al. 2020, "Incremental
//! Potential Contact", section 5). At the start of a step, every vertex `i` penetrating an
//! obstacle with `mu > 0` at `x_n` becomes a [`FrictionContact`]: its normal force magnitude
//! `lambda = kappa max(-phi(x_n), 0)` (the penalty force of the step start), a tangent basis `T`
//! (3 x 2) of the obstacle at that point, and the threshold `eps_v dt`. Both stay fixed over the
//! step (lagged), so the friction force is the gradient of
//!
//! ```text
//! D(x_i) = mu lambda f0(|u|),   u = T^T (x_i - x_n,i),
//! f1(y) = -y^2 / (eps_v dt)^2 + 2 y / (eps_v dt)   for y < eps_v dt,   1 otherwise,
//! f0(y) = -y^3 / (3 (eps_v dt)^2) + y^2 / (eps_v dt) + eps_v dt / 3   for y < eps_v dt,   y otherwise,
//! ```
//!
//! (`f0' = f1`; `f1` is C1, `f0` C2), which Newton's line search sees like any other term of the incremental
//! potential. Its gradient is `mu lambda f1(|u|) T u / |u|`; the Hessian is
//! `mu lambda T [f1'(y) u u^T / y^2 + f1(y) / y (I - u u^T / y^2)] T^T` (`y = |u|`) whose two
//! eigenvalues in the tangent plane, `f1'(y)` and `f1(y) / y` (times `mu lambda`), are clamped at
//! zero: IPC's closed-form projection to positive semi-definite (both are already `>= 0` for a
//! point against a fixed obstacle, and at `u = 0` the Hessian is `2 mu lambda / (eps_v dt) T T^T`).
//! A vertex held by static friction creeps at most at speed `eps_v`: under a tangential load
//! `F < mu lambda` its step displacement solves `mu lambda f1(y) = F`, so
//! `y / dt = eps_v (1 - sqrt(1 - F / (mu lambda))) < eps_v`.
//!
//! The normal force is the penalty force at `x_n`, so friction acts from the step after a vertex
//! first penetrates. In the sliding regime the Hessian has no curvature along the motion: Newton
//! started from the inertial predictor, which puts a contact vertex deep in that regime, overshoots
//! at impacts and the line search shortens every step. With friction contacts Newton therefore
//! starts from `x_n` (as IPC does), inside the smoothed static zone (`docs/guides/anim-fem.md`
//! has the iteration counts).
//!
//! Quasi-static solves ([`FemSimulation::solve_static`](crate::sim::FemSimulation::solve_static))
//! have no time step and no friction. The contacts are a list with room for every vertex and
//! frictional obstacle, made when the simulation is built, so a step does not allocate; they are
//! summed in vertex order, so results do not depend on the thread count.

use crate::boundary::Colliders;

/// Default smoothing velocity `eps_v` of the implicit friction (m/s): tangential speeds below it
/// count as sticking.
pub const DEFAULT_EPS_V: f64 = 1e-3;

/// A lagged friction contact of one vertex with one obstacle, fixed over a backward Euler step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrictionContact {
    /// The vertex.
    pub vertex: usize,
    /// Its position `x_n` at the start of the step.
    pub start: [f64; 3],
    /// Two orthonormal tangent vectors of the obstacle at `start` (the columns of `T`).
    pub basis: [[f64; 3]; 2],
    /// `mu lambda`: the friction coefficient times the normal force at the step start (N).
    pub weight: f64,
    /// `eps_v dt` (m): tangential step displacements below it are smoothed static friction.
    pub threshold: f64,
}

/// IPC's mollifier `f1(y)` (the friction force magnitude per `mu lambda`) for threshold `eps`.
#[inline]
#[must_use]
pub fn f1(y: f64, eps: f64) -> f64 {
    if y < eps { y * (2.0 * eps - y) / (eps * eps) } else { 1.0 }
}

/// `f0(y)`, the antiderivative of [`f1`] with `f0(eps) = eps`.
#[inline]
#[must_use]
pub fn f0(y: f64, eps: f64) -> f64 {
    if y < eps { -y * y * y / (3.0 * eps * eps) + y * y / eps + eps / 3.0 } else { y }
}

/// Two orthonormal vectors perpendicular to the unit vector `n` (a fixed choice for each `n`).
#[must_use]
pub fn tangent_basis(n: [f64; 3]) -> [[f64; 3]; 2] {
    let a = if n[0].abs() < 0.9 { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] };
    let an = a[0] * n[0] + a[1] * n[1] + a[2] * n[2];
    let t = [a[0] - an * n[0], a[1] - an * n[1], a[2] - an * n[2]];
    let l = (t[0] * t[0] + t[1] * t[1] + t[2] * t[2]).sqrt();
    let t1 = [t[0] / l, t[1] / l, t[2] / l];
    let t2 = [n[1] * t1[2] - n[2] * t1[1], n[2] * t1[0] - n[0] * t1[2], n[0] * t1[1] - n[1] * t1[0]];
    [t1, t2]
}

/// Appends to `out` the friction contacts of a backward Euler step starting at positions `xn`:
/// one per vertex (not fully fixed) and obstacle (shape or mesh) with `mu > 0` that the vertex
/// penetrates, with `lambda = kappa (-phi)`. `out` is cleared first; it never grows past
/// `vertices x frictional obstacles` entries.
pub fn lagged_contacts(
    obstacles: Colliders<'_>,
    kappa: f64,
    threshold: f64,
    xn: &[f64],
    fixed: &[bool],
    out: &mut Vec<FrictionContact>,
) {
    out.clear();
    if obstacles.frictional() == 0 {
        return;
    }
    for (i, p) in xn.chunks_exact(3).enumerate() {
        if fixed[3 * i] && fixed[3 * i + 1] && fixed[3 * i + 2] {
            continue;
        }
        let start = [p[0], p[1], p[2]];
        for (o, mu) in obstacles.iter() {
            if mu == 0.0 {
                continue;
            }
            let Some((phi, n)) = o.distance(start) else { continue };
            if phi < 0.0 {
                out.push(FrictionContact {
                    vertex: i,
                    start,
                    basis: tangent_basis(n),
                    weight: mu * kappa * -phi,
                    threshold,
                });
            }
        }
    }
}

impl FrictionContact {
    /// The friction potential `mu lambda f0(|u|)` at the vertex position `x`; adds its gradient
    /// to `grad` and its positive semi-definite Hessian (row-major 3 x 3) to `hess` when given.
    #[must_use]
    pub fn potential(&self, x: [f64; 3], grad: Option<&mut [f64; 3]>, hess: Option<&mut [f64; 9]>) -> f64 {
        let d = [x[0] - self.start[0], x[1] - self.start[1], x[2] - self.start[2]];
        let [t1, t2] = self.basis;
        let u = [t1[0] * d[0] + t1[1] * d[1] + t1[2] * d[2], t2[0] * d[0] + t2[1] * d[1] + t2[2] * d[2]];
        let y = (u[0] * u[0] + u[1] * u[1]).sqrt();
        let eps = self.threshold;
        let w = self.weight;
        // f1(y) / y, finite at y = 0.
        let f1_over_y = if y < eps { (2.0 * eps - y) / (eps * eps) } else { 1.0 / y };
        if let Some(g) = grad {
            for c in 0..3 {
                g[c] += w * f1_over_y * (u[0] * t1[c] + u[1] * t2[c]);
            }
        }
        if let Some(h) = hess {
            // The 2 x 2 Hessian in the tangent plane: eigenvalue f1'(y) along u/|u|, f1(y)/y
            // across, both clamped at zero.
            let across = w * f1_over_y.max(0.0);
            let along = if y < eps { w * (2.0 * (eps - y) / (eps * eps)).max(0.0) } else { 0.0 };
            let mut hu = [[across, 0.0], [0.0, across]];
            if y > 0.0 {
                let e = [u[0] / y, u[1] / y];
                for (a, row) in hu.iter_mut().enumerate() {
                    for (b, v) in row.iter_mut().enumerate() {
                        *v += (along - across) * e[a] * e[b];
                    }
                }
            }
            for r in 0..3 {
                let tr = [t1[r], t2[r]];
                for c in 0..3 {
                    let tc = [t1[c], t2[c]];
                    let mut v = 0.0;
                    for a in 0..2 {
                        for b in 0..2 {
                            v += tr[a] * hu[a][b] * tc[b];
                        }
                    }
                    h[3 * r + c] += v;
                }
            }
        }
        w * f0(y, eps)
    }
}

/// Velocity-level Coulomb friction of the explicit step on one vertex's velocity `v` after the
/// removal of an approaching normal velocity `dvn > 0` along the unit normal `n`: the tangential
/// velocity changes by at most `mu dvn` (to zero when smaller: sticking). Only the components
/// not marked `fixed` change. Returns the velocity change, which the step also applies to the
/// position times `dt` (so that `x_{n+1} = x_n + dt v_{n+1}` holds with the friction impulse,
/// and a sticking vertex does not creep).
pub fn coulomb_velocity(v: &mut [f64], n: [f64; 3], dvn: f64, mu: f64, fixed: &[bool]) -> [f64; 3] {
    let vn = v[0] * n[0] + v[1] * n[1] + v[2] * n[2];
    let vt = [v[0] - vn * n[0], v[1] - vn * n[1], v[2] - vn * n[2]];
    let speed = (vt[0] * vt[0] + vt[1] * vt[1] + vt[2] * vt[2]).sqrt();
    let bound = mu * dvn;
    // Fraction of v_t removed: all of it when sticking.
    let scale = if speed <= bound { 1.0 } else { bound / speed };
    let mut dv = [0.0; 3];
    for c in 0..3 {
        if !fixed[c] {
            dv[c] = -scale * vt[c];
            v[c] += dv[c];
        }
    }
    dv
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn mollifier_is_c1_and_f0_integrates_f1() {
        let eps = 0.3;
        assert_eq!(f1(0.0, eps), 0.0);
        assert!((f1(eps * (1.0 - 1e-12), eps) - 1.0).abs() < 1e-11);
        assert!((f0(eps * (1.0 - 1e-12), eps) - eps).abs() < 1e-11);
        // f0' = f1 by central differences on both sides of the threshold; f1' -> 0 at eps.
        for y in [0.05, 0.17, 0.29, 0.31, 0.8] {
            let h = 1e-6;
            let d = (f0(y + h, eps) - f0(y - h, eps)) / (2.0 * h);
            assert!((d - f1(y, eps)).abs() < 1e-8, "y {y}: {d} vs {}", f1(y, eps));
        }
        let h = 1e-7;
        // The slope 2 (eps - y) / eps^2 vanishes at eps (it is 2 / eps = 6.7 at 0).
        assert!((f1(eps - h, eps) - f1(eps - 2.0 * h, eps)) / h < 1e-5);
    }

    #[test]
    fn tangent_basis_is_orthonormal() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        for _ in 0..50 {
            let a: [f64; 3] = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
            let l = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
            let n = a.map(|c| c / l);
            let [t1, t2] = tangent_basis(n);
            let dot = |p: [f64; 3], q: [f64; 3]| p[0] * q[0] + p[1] * q[1] + p[2] * q[2];
            for (p, q, want) in [(t1, t1, 1.0), (t2, t2, 1.0), (t1, t2, 0.0), (t1, n, 0.0), (t2, n, 0.0)] {
                assert!((dot(p, q) - want).abs() < 1e-14);
            }
        }
    }

    /// Gradient against central differences of the energy, Hessian against central
    /// differences of the gradient, for displacements inside the smoothed (static) zone and
    /// beyond it (sliding), with a tilted normal.
    #[test]
    fn friction_gradient_and_hessian_match_finite_differences() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let theta = 0.4_f64;
        let n = [theta.sin() * 0.6, theta.sin() * 0.8, theta.cos()];
        let contact = FrictionContact {
            vertex: 0,
            start: [0.3, -0.2, 0.1],
            basis: tangent_basis(n),
            weight: 0.4 * 25.0,
            threshold: 1e-3 * 0.01,
        };
        let eps = contact.threshold;
        for (trial, scale) in [0.2, 0.5, 0.9, 1.5, 4.0, 30.0].into_iter().cycle().take(24).enumerate() {
            // A tangential displacement of length `scale * eps` plus an arbitrary normal part.
            let angle: f64 = rng.random_range(0.0..std::f64::consts::TAU);
            let [t1, t2] = contact.basis;
            let normal: f64 = rng.random_range(-1.0..1.0) * eps;
            let x: [f64; 3] = std::array::from_fn(|c| {
                contact.start[c] + scale * eps * (angle.cos() * t1[c] + angle.sin() * t2[c]) + normal * n[c]
            });
            let mut g = [0.0; 3];
            let mut h = [0.0; 9];
            let _ = contact.potential(x, Some(&mut g), Some(&mut h));
            let step = 1e-4 * eps;
            let g_scale = contact.weight;
            let h_scale = contact.weight * 2.0 / eps;
            for c in 0..3 {
                let mut xp = x;
                let mut xm = x;
                xp[c] += step;
                xm[c] -= step;
                let fd =
                    (contact.potential(xp, None, None) - contact.potential(xm, None, None)) / (2.0 * step);
                assert!((fd - g[c]).abs() <= 1e-6 * g_scale, "trial {trial} gradient {c}: {fd} vs {}", g[c]);
                let mut gp = [0.0; 3];
                let mut gm = [0.0; 3];
                let _ = contact.potential(xp, Some(&mut gp), None);
                let _ = contact.potential(xm, Some(&mut gm), None);
                for r in 0..3 {
                    let fdh = (gp[r] - gm[r]) / (2.0 * step);
                    let an = h[3 * r + c];
                    assert!(
                        (fdh - an).abs() <= 1e-5 * h_scale,
                        "trial {trial} hessian ({r},{c}): {fdh} vs {an}"
                    );
                }
            }
            // Sliding: the force has magnitude mu lambda, opposite to the tangential displacement.
            if scale > 1.0 {
                let norm = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
                assert!((norm - contact.weight).abs() < 1e-12 * contact.weight);
            }
            // Positive semi-definite: v^T H v >= 0 for random v; n is in the null space.
            for _ in 0..5 {
                let v: [f64; 3] = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
                let q: f64 = (0..3).map(|r| (0..3).map(|c| v[r] * h[3 * r + c] * v[c]).sum::<f64>()).sum();
                assert!(q >= -1e-12 * h_scale, "v^T H v = {q}");
            }
            let hn: f64 = (0..3).map(|r| (0..3).map(|c| h[3 * r + c] * n[c]).sum::<f64>().abs()).sum();
            assert!(hn < 1e-9 * h_scale);
        }
    }

    #[test]
    fn explicit_coulomb_sticks_or_slides_by_the_normal_impulse() {
        let n = [0.0, 0.0, 1.0];
        let free = [false; 3];
        // Tangential speed 0.3 below mu dvn = 0.5 * 1.0: sticks.
        let mut v = [0.3, 0.0, 0.0];
        let dv = coulomb_velocity(&mut v, n, 1.0, 0.5, &free);
        assert_eq!((v, dv), ([0.0, 0.0, 0.0], [-0.3, 0.0, 0.0]));
        // Tangential speed 5 along (3, 4)/5: reduced by 0.5 to 4.5, direction kept.
        let mut v = [3.0, 4.0, 0.0];
        let _ = coulomb_velocity(&mut v, n, 1.0, 0.5, &free);
        assert!((v[0] - 2.7).abs() < 1e-15 && (v[1] - 3.6).abs() < 1e-15 && v[2] == 0.0, "{v:?}");
        // A fixed component keeps its value.
        let mut v = [0.3, 0.2, 0.0];
        let _ = coulomb_velocity(&mut v, n, 1.0, 0.5, &[true, false, false]);
        assert_eq!(v, [0.3, 0.0, 0.0]);
    }
}
