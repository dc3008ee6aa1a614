//! Reference second-order systems with known solutions, used by the conformance suite, the
//! work-precision studies and the tests of every integrator.
//!
//! - [`HarmonicOscillator`]: `m x'' = -k x - c x'`, exact solution in closed form (undamped,
//!   under-, critically and over-damped).
//! - [`KeplerOrbit`]: a planet around a fixed sun, `x'' = -mu x / |x|^3` in the plane, exact
//!   solution through Kepler's equation; nonlinear, with an indefinite force Jacobian.

use super::{MechanicalSystem, SecondOrderSystem};
use crate::linalg::CsrMatrix;
use crate::solver::EnergyParts;

/// A 1-D damped harmonic oscillator `m x'' = -k x - c x'`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HarmonicOscillator {
    /// Mass.
    pub mass: f64,
    /// Spring stiffness.
    pub stiffness: f64,
    /// Linear damping coefficient.
    pub damping: f64,
}

impl HarmonicOscillator {
    /// An undamped oscillator with angular frequency `sqrt(k / m)`.
    #[must_use]
    pub fn new(mass: f64, stiffness: f64) -> Self {
        Self { mass, stiffness, damping: 0.0 }
    }

    /// A damped oscillator.
    #[must_use]
    pub fn damped(mass: f64, stiffness: f64, damping: f64) -> Self {
        Self { mass, stiffness, damping }
    }

    /// Undamped angular frequency `sqrt(k / m)`.
    #[must_use]
    pub fn omega(&self) -> f64 {
        (self.stiffness / self.mass).sqrt()
    }

    /// Exact `(x(t), v(t))` from `(x0, v0)` at time 0.
    #[must_use]
    pub fn exact(&self, x0: f64, v0: f64, t: f64) -> (f64, f64) {
        let w0 = self.omega();
        let zeta = self.damping / (2.0 * (self.stiffness * self.mass).sqrt());
        let s = -zeta * w0; // real part of the roots
        if zeta < 1.0 - 1e-12 {
            let wd = w0 * (1.0 - zeta * zeta).sqrt();
            let (sin, cos) = (wd * t).sin_cos();
            let e = (s * t).exp();
            let b = (v0 - s * x0) / wd;
            let x = e * (x0 * cos + b * sin);
            let v = e * (s * (x0 * cos + b * sin) + (-x0 * wd * sin + b * wd * cos));
            (x, v)
        } else if zeta > 1.0 + 1e-12 {
            let d = w0 * (zeta * zeta - 1.0).sqrt();
            let (r1, r2) = (s + d, s - d);
            // x = A e^{r1 t} + B e^{r2 t}, A + B = x0, r1 A + r2 B = v0.
            let a = (v0 - r2 * x0) / (r1 - r2);
            let b = x0 - a;
            let (e1, e2) = ((r1 * t).exp(), (r2 * t).exp());
            (a * e1 + b * e2, a * r1 * e1 + b * r2 * e2)
        } else {
            // Critical: x = (A + B t) e^{s t}.
            let a = x0;
            let b = v0 - s * x0;
            let e = (s * t).exp();
            ((a + b * t) * e, (b + s * (a + b * t)) * e)
        }
    }
}

impl SecondOrderSystem for HarmonicOscillator {
    fn dof(&self) -> usize {
        1
    }

    fn acceleration(&mut self, _t: f64, x: &[f64], v: &[f64], a: &mut [f64]) {
        a[0] = (-self.stiffness * x[0] - self.damping * v[0]) / self.mass;
    }

    fn energy(&mut self, _t: f64, x: &[f64], v: &[f64]) -> Option<f64> {
        Some(0.5 * self.mass * v[0] * v[0] + 0.5 * self.stiffness * x[0] * x[0])
    }

    fn energy_parts(&mut self, _t: f64, x: &[f64], v: &[f64]) -> Option<EnergyParts> {
        let kinetic = 0.5 * self.mass * v[0] * v[0];
        Some(EnergyParts { kinetic, gravity: 0.0, elastic: 0.5 * self.stiffness * x[0] * x[0] })
    }
}

impl MechanicalSystem for HarmonicOscillator {
    fn inverse_mass(&self, w: &mut [f64]) {
        w[0] = 1.0 / self.mass;
    }

    fn force(&mut self, _t: f64, x: &[f64], v: &[f64], f: &mut [f64]) {
        f[0] = -self.stiffness * x[0] - self.damping * v[0];
    }

    fn linearize(&mut self, _t: f64, _x: &[f64], _v: &[f64]) {}

    fn jacobian_apply(&self, c_x: f64, c_v: f64, dx: &[f64], out: &mut [f64]) {
        out[0] = -(c_x * self.stiffness + c_v * self.damping) * dx[0];
    }

    fn jacobian_diagonal(&self, c_x: f64, c_v: f64, out: &mut [f64]) -> bool {
        out[0] = -(c_x * self.stiffness + c_v * self.damping);
        true
    }

    fn jacobian_assemble(&self, c_x: f64, c_v: f64, out: &mut CsrMatrix) -> bool {
        let value = -(c_x * self.stiffness + c_v * self.damping);
        if out.nrows() != 1 || out.nnz() != 1 {
            *out = CsrMatrix::from_triplets(1, 1, &[(0, 0, value)]);
        } else {
            out.values_mut()[0] = value;
        }
        true
    }
}

/// A body of unit mass orbiting a fixed centre: `x'' = -mu x / |x|^3`, `x` in the plane.
///
/// [`KeplerOrbit::ellipse`] starts at periapsis of an ellipse of semi-major axis 1 and the given
/// eccentricity, with `mu = 1`, so the period is `2 pi` and the exact solution follows from
/// Kepler's equation `E - e sin E = t`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KeplerOrbit {
    /// Gravitational parameter `G M`.
    pub mu: f64,
    /// Eccentricity of the reference ellipse (for [`exact`](Self::exact)).
    pub eccentricity: f64,
    jac: [[f64; 2]; 2],
}

impl KeplerOrbit {
    /// The orbit of semi-major axis 1, `mu = 1`, eccentricity `e` in `[0, 1)`.
    ///
    /// # Panics
    /// If `e` is outside `[0, 1)`.
    #[must_use]
    #[track_caller]
    pub fn ellipse(e: f64) -> Self {
        assert!((0.0..1.0).contains(&e), "KeplerOrbit: eccentricity must lie in [0, 1), got {e}");
        Self { mu: 1.0, eccentricity: e, jac: [[0.0; 2]; 2] }
    }

    /// Initial state at periapsis: `x = (1 - e, 0)`, `v = (0, sqrt((1 + e) / (1 - e)))`.
    #[must_use]
    pub fn initial(&self) -> ([f64; 2], [f64; 2]) {
        let e = self.eccentricity;
        ([1.0 - e, 0.0], [0.0, ((1.0 + e) / (1.0 - e)).sqrt()])
    }

    /// Orbital period (`2 pi` for `mu = 1`).
    #[must_use]
    pub fn period(&self) -> f64 {
        2.0 * std::f64::consts::PI / self.mu.sqrt()
    }

    /// Exact position and velocity at time `t` from [`initial`](Self::initial).
    #[must_use]
    pub fn exact(&self, t: f64) -> ([f64; 2], [f64; 2]) {
        let e = self.eccentricity;
        let n = self.mu.sqrt(); // mean motion for a = 1
        let m = n * t;
        // Newton on E - e sin E = M for the mean anomaly reduced to [0, 2 pi); sin and cos of E
        // are periodic, so the reduction loses nothing.
        let two_pi = 2.0 * std::f64::consts::PI;
        let m = m.rem_euclid(two_pi);
        let mut big_e = if e > 0.8 { std::f64::consts::PI } else { m + e * m.sin() };
        for _ in 0..100 {
            let (s, c) = big_e.sin_cos();
            let step = (big_e - e * s - m) / (1.0 - e * c);
            big_e -= step;
            if step.abs() <= 4.0 * f64::EPSILON * (1.0 + big_e.abs()) {
                break;
            }
        }
        let (s, c) = big_e.sin_cos();
        let b = (1.0 - e * e).sqrt();
        let e_dot = n / (1.0 - e * c);
        ([c - e, b * s], [-s * e_dot, b * c * e_dot])
    }

    /// Total energy `|v|^2 / 2 - mu / |x|` (`-1/2` on the reference ellipse).
    #[must_use]
    pub fn energy_of(&self, x: &[f64], v: &[f64]) -> f64 {
        0.5 * (v[0] * v[0] + v[1] * v[1]) - self.mu / (x[0] * x[0] + x[1] * x[1]).sqrt()
    }

    /// Angular momentum `x × v` (conserved).
    #[must_use]
    pub fn angular_momentum(x: &[f64], v: &[f64]) -> f64 {
        x[0] * v[1] - x[1] * v[0]
    }
}

impl SecondOrderSystem for KeplerOrbit {
    fn dof(&self) -> usize {
        2
    }

    fn acceleration(&mut self, t: f64, x: &[f64], v: &[f64], a: &mut [f64]) {
        self.force(t, x, v, a);
    }

    fn energy(&mut self, _t: f64, x: &[f64], v: &[f64]) -> Option<f64> {
        Some(self.energy_of(x, v))
    }

    fn energy_parts(&mut self, _t: f64, x: &[f64], v: &[f64]) -> Option<EnergyParts> {
        let kinetic = 0.5 * (v[0] * v[0] + v[1] * v[1]);
        Some(EnergyParts { kinetic, gravity: 0.0, elastic: -self.mu / (x[0] * x[0] + x[1] * x[1]).sqrt() })
    }
}

impl MechanicalSystem for KeplerOrbit {
    fn inverse_mass(&self, w: &mut [f64]) {
        w[0] = 1.0;
        w[1] = 1.0;
    }

    fn force(&mut self, _t: f64, x: &[f64], _v: &[f64], f: &mut [f64]) {
        let r2 = x[0] * x[0] + x[1] * x[1];
        let r3 = r2 * r2.sqrt();
        f[0] = -self.mu * x[0] / r3;
        f[1] = -self.mu * x[1] / r3;
    }

    fn linearize(&mut self, _t: f64, x: &[f64], _v: &[f64]) {
        // K = mu (3 x x^T / r^5 - I / r^3): symmetric, indefinite.
        let r2 = x[0] * x[0] + x[1] * x[1];
        let r = r2.sqrt();
        let r3 = r2 * r;
        let r5 = r3 * r2;
        for i in 0..2 {
            for j in 0..2 {
                let delta = if i == j { 1.0 } else { 0.0 };
                self.jac[i][j] = self.mu * (3.0 * x[i] * x[j] / r5 - delta / r3);
            }
        }
    }

    fn jacobian_apply(&self, c_x: f64, _c_v: f64, dx: &[f64], out: &mut [f64]) {
        for i in 0..2 {
            out[i] = c_x * (self.jac[i][0] * dx[0] + self.jac[i][1] * dx[1]);
        }
    }

    fn jacobian_diagonal(&self, c_x: f64, _c_v: f64, out: &mut [f64]) -> bool {
        out[0] = c_x * self.jac[0][0];
        out[1] = c_x * self.jac[1][1];
        true
    }

    fn jacobian_assemble(&self, c_x: f64, _c_v: f64, out: &mut CsrMatrix) -> bool {
        if out.nrows() != 2 || out.nnz() != 4 {
            *out = CsrMatrix::from_triplets(2, 2, &[(0, 0, 0.0), (0, 1, 0.0), (1, 0, 0.0), (1, 1, 0.0)]);
        }
        let values = out.values_mut();
        values[0] = c_x * self.jac[0][0];
        values[1] = c_x * self.jac[0][1];
        values[2] = c_x * self.jac[1][0];
        values[3] = c_x * self.jac[1][1];
        true
    }
}

/// A vertical chain of `n` point masses joined by linear springs under gravity, the top mass
/// fixed: `m x_i'' = k (x_{i-1} - x_i - l) - k (x_i - x_{i+1} - l) - m g` (1-D, `x` up).
///
/// The static equilibrium is known in closed form: spring `i` (between masses `i` and `i+1`)
/// carries the weight of the `n - 1 - i` masses below it, so its stretch is
/// `(n - 1 - i) m g / k`. The force Jacobian is the constant tridiagonal matrix of a discrete
/// Laplacian, assembled once and reused (its pattern never changes).
#[derive(Debug, Clone)]
pub struct LinearChain {
    n: usize,
    mass: f64,
    stiffness: f64,
    rest_length: f64,
    gravity: f64,
    damping: f64,
}

impl LinearChain {
    /// A chain of `n >= 2` masses `mass`, springs of stiffness `stiffness` and rest length
    /// `rest_length`, under gravity `gravity` (positive, pointing down).
    ///
    /// # Panics
    /// If `n < 2` or a parameter is not positive (gravity may be zero).
    #[must_use]
    #[track_caller]
    pub fn new(n: usize, mass: f64, stiffness: f64, rest_length: f64, gravity: f64) -> Self {
        assert!(n >= 2, "LinearChain needs at least 2 masses, got {n}");
        assert!(
            mass > 0.0 && stiffness > 0.0 && rest_length > 0.0 && gravity >= 0.0,
            "LinearChain: bad parameters"
        );
        Self { n, mass, stiffness, rest_length, gravity, damping: 0.0 }
    }

    /// Adds damping along the springs (coefficient per spring, on relative velocity).
    #[must_use]
    pub fn with_damping(mut self, damping: f64) -> Self {
        self.damping = damping;
        self
    }

    /// The chain at rest length, at rest: `x_i = -i l`.
    #[must_use]
    pub fn rest_state(&self) -> super::State {
        super::State::new((0..self.n).map(|i| -(i as f64) * self.rest_length).collect(), vec![0.0; self.n])
    }

    /// Exact static equilibrium positions.
    #[must_use]
    pub fn equilibrium(&self) -> Vec<f64> {
        let mut x = vec![0.0; self.n];
        for i in 0..self.n - 1 {
            let stretch = (self.n - 1 - i) as f64 * self.mass * self.gravity / self.stiffness;
            x[i + 1] = x[i] - self.rest_length - stretch;
        }
        x
    }

    fn spring_apply(&self, coeff: f64, dx: &[f64], out: &mut [f64]) {
        out.iter_mut().for_each(|o| *o = 0.0);
        for i in 0..self.n - 1 {
            let d = coeff * (dx[i + 1] - dx[i]);
            out[i] += d;
            out[i + 1] -= d;
        }
    }
}

impl SecondOrderSystem for LinearChain {
    fn dof(&self) -> usize {
        self.n
    }

    fn acceleration(&mut self, t: f64, x: &[f64], v: &[f64], a: &mut [f64]) {
        self.force(t, x, v, a);
        a[0] = 0.0;
        for ai in &mut a[1..] {
            *ai /= self.mass;
        }
    }

    fn energy(&mut self, t: f64, x: &[f64], v: &[f64]) -> Option<f64> {
        self.energy_parts(t, x, v).map(|e| e.total())
    }

    fn energy_parts(&mut self, _t: f64, x: &[f64], v: &[f64]) -> Option<EnergyParts> {
        let mut parts = EnergyParts::default();
        for i in 0..self.n {
            parts.kinetic += 0.5 * self.mass * v[i] * v[i];
            parts.gravity += self.mass * self.gravity * x[i];
        }
        for i in 0..self.n - 1 {
            let s = x[i] - x[i + 1] - self.rest_length;
            parts.elastic += 0.5 * self.stiffness * s * s;
        }
        Some(parts)
    }
}

impl MechanicalSystem for LinearChain {
    fn inverse_mass(&self, w: &mut [f64]) {
        w.iter_mut().for_each(|w| *w = 1.0 / self.mass);
        w[0] = 0.0;
    }

    fn force(&mut self, _t: f64, x: &[f64], v: &[f64], f: &mut [f64]) {
        f.iter_mut().for_each(|f| *f = -self.mass * self.gravity);
        for i in 0..self.n - 1 {
            // Tension (positive when stretched) pulls mass i down and mass i+1 up.
            let s = self.stiffness * (x[i] - x[i + 1] - self.rest_length) + self.damping * (v[i] - v[i + 1]);
            f[i] -= s;
            f[i + 1] += s;
        }
    }

    fn linearize(&mut self, _t: f64, _x: &[f64], _v: &[f64]) {}

    fn jacobian_apply(&self, c_x: f64, c_v: f64, dx: &[f64], out: &mut [f64]) {
        self.spring_apply(c_x * self.stiffness + c_v * self.damping, dx, out);
    }

    fn jacobian_diagonal(&self, c_x: f64, c_v: f64, out: &mut [f64]) -> bool {
        let c = c_x * self.stiffness + c_v * self.damping;
        out.iter_mut().for_each(|o| *o = -2.0 * c);
        out[0] = -c;
        out[self.n - 1] = -c;
        true
    }

    fn jacobian_assemble(&self, c_x: f64, c_v: f64, out: &mut CsrMatrix) -> bool {
        let c = c_x * self.stiffness + c_v * self.damping;
        if out.nrows() != self.n || out.nnz() != 3 * self.n - 2 {
            let mut t = Vec::with_capacity(3 * self.n);
            for i in 0..self.n {
                if i > 0 {
                    t.push((i, i - 1, 0.0));
                }
                t.push((i, i, 0.0));
                if i + 1 < self.n {
                    t.push((i, i + 1, 0.0));
                }
            }
            *out = CsrMatrix::from_triplets(self.n, self.n, &t);
        }
        let last = self.n - 1;
        let values = out.values_mut();
        for i in 0..self.n {
            // Row i holds (i-1, i, i+1) in column order and starts at 3 i - 1 (row 0 at 0).
            let mut k = if i == 0 { 0 } else { 3 * i - 1 };
            if i > 0 {
                values[k] = c;
                k += 1;
            }
            values[k] = if i == 0 || i == last { -c } else { -2.0 * c };
            if i < last {
                values[k + 1] = c;
            }
        }
        true
    }
}
