//! Reference problems with closed-form answers: the two-particle spring and the static hanging
//! chain. The tests, the conformance suite and the examples share them.

use crate::build::{Chain, NetworkBuilder, SpringParams};
use crate::error::BuildError;
use crate::network::SpringNetwork;
use anim_core::glam::DVec3;
use anim_core::integrate::State;
use anim_core::integrate::systems::HarmonicOscillator;

/// Two free particles joined by one spring, moving along the spring's axis, without gravity.
///
/// With `r = x_1 - x_2` and the reduced mass `mu = m_1 m_2 / (m_1 + m_2)`, the relative motion is
/// `mu r'' = -k (|r| - l) r/|r| - c (r' . r/|r|) r/|r|`. If the initial relative velocity is along
/// `r`, the direction never changes and the stretch `s = |r| - l` is a damped harmonic oscillator
/// `mu s'' = -k s - c s'` (exact solution in [`HarmonicOscillator::exact`]), while the centre of
/// mass moves uniformly. So `x_1 = x_cm + (m_2 / M) r`, `x_2 = x_cm - (m_1 / M) r`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TwoParticleSpring {
    /// Mass of particle 1.
    pub m1: f64,
    /// Mass of particle 2.
    pub m2: f64,
    /// Stiffness `k`.
    pub stiffness: f64,
    /// Damping along the spring `c`.
    pub damping: f64,
    /// Rest length `l`.
    pub rest_length: f64,
    /// Unit direction of `x_1 - x_2`.
    pub axis: [f64; 3],
    /// Initial stretch `s(0)` (|s| < l keeps the particles apart).
    pub stretch: f64,
    /// Initial stretch rate `s'(0)`.
    pub stretch_rate: f64,
    /// Initial centre of mass.
    pub center: [f64; 3],
    /// Velocity of the centre of mass.
    pub center_velocity: [f64; 3],
}

impl TwoParticleSpring {
    /// A representative case: unequal masses, an oblique axis, a moving centre of mass.
    #[must_use]
    pub fn example() -> Self {
        let axis = DVec3::new(1.0, 2.0, 2.0) / 3.0;
        Self {
            m1: 1.0,
            m2: 3.0,
            stiffness: 12.0,
            damping: 0.0,
            rest_length: 1.0,
            axis: axis.to_array(),
            stretch: 0.3,
            stretch_rate: 0.4,
            center: [0.1, -0.2, 0.3],
            center_velocity: [0.05, 0.0, -0.1],
        }
    }

    /// Reduced mass `m1 m2 / (m1 + m2)`.
    #[must_use]
    pub fn reduced_mass(&self) -> f64 {
        self.m1 * self.m2 / (self.m1 + self.m2)
    }

    /// Period of the undamped relative oscillation `2 pi sqrt(mu / k)`.
    #[must_use]
    pub fn period(&self) -> f64 {
        2.0 * std::f64::consts::PI * (self.reduced_mass() / self.stiffness).sqrt()
    }

    /// The network (no gravity, no pins): particle 0 is `x_1`, particle 1 is `x_2`.
    ///
    /// # Errors
    /// A [`BuildError`] for non-positive masses or stiffness.
    pub fn network(&self) -> Result<SpringNetwork, BuildError> {
        let mut b = NetworkBuilder::new();
        let (x, _) = self.exact(0.0);
        let a = b.particle([x[0], x[1], x[2]], self.m1);
        let c = b.particle([x[3], x[4], x[5]], self.m2);
        b.spring_with_rest_length(a, c, self.rest_length, SpringParams::new(self.stiffness, self.damping));
        b.build()
    }

    /// The initial state.
    #[must_use]
    pub fn initial_state(&self) -> State {
        let (x, v) = self.exact(0.0);
        State::new(x.to_vec(), v.to_vec())
    }

    /// Exact positions and velocities `([x1, x2], [v1, v2])` at time `t`.
    #[must_use]
    pub fn exact(&self, t: f64) -> ([f64; 6], [f64; 6]) {
        let mu = self.reduced_mass();
        let total = self.m1 + self.m2;
        let osc = HarmonicOscillator::damped(mu, self.stiffness, self.damping);
        let (s, sd) = osc.exact(self.stretch, self.stretch_rate, t);
        let n = DVec3::from_array(self.axis);
        let vc = DVec3::from_array(self.center_velocity);
        let xc = DVec3::from_array(self.center) + t * vc;
        let r = (self.rest_length + s) * n;
        let rd = sd * n;
        let (x1, x2) = (xc + (self.m2 / total) * r, xc - (self.m1 / total) * r);
        let (v1, v2) = (vc + (self.m2 / total) * rd, vc - (self.m1 / total) * rd);
        ([x1.x, x1.y, x1.z, x2.x, x2.y, x2.z], [v1.x, v1.y, v1.z, v2.x, v2.y, v2.z])
    }
}

/// A vertical chain hanging from a pinned top particle under gravity `-g z`.
///
/// At static equilibrium spring `i` (between particles `i` and `i + 1`) carries the weight of the
/// `count - 1 - i` particles below it, so it is stretched by `(count - 1 - i) m g / k`; the
/// particles stay on the vertical line through the pin.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HangingChain {
    /// Number of particles (>= 2), the first pinned at the origin.
    pub count: usize,
    /// Mass of each particle.
    pub mass: f64,
    /// Spring stiffness.
    pub stiffness: f64,
    /// Spring damping.
    pub damping: f64,
    /// Spring rest length.
    pub rest_length: f64,
    /// Gravity magnitude (pointing down z).
    pub gravity: f64,
}

impl HangingChain {
    /// The network, built at rest length (unstretched) along `-z` from the origin.
    ///
    /// # Errors
    /// A [`BuildError`] for invalid parameters.
    pub fn network(&self) -> Result<SpringNetwork, BuildError> {
        let mut b = NetworkBuilder::new();
        b.gravity([0.0, 0.0, -self.gravity]);
        let length = self.rest_length * self.count.saturating_sub(1) as f64;
        let r = b.chain(&Chain {
            count: self.count,
            start: [0.0, 0.0, 0.0],
            end: [0.0, 0.0, -length],
            mass: self.mass,
            spring: SpringParams::new(self.stiffness, self.damping),
        })?;
        b.pin(r.start);
        b.build()
    }

    /// Exact equilibrium positions as a flat `3 count` vector.
    #[must_use]
    pub fn equilibrium(&self) -> Vec<f64> {
        let mut x = vec![0.0; 3 * self.count];
        let mut z = 0.0;
        for i in 0..self.count.saturating_sub(1) {
            let stretch = (self.count - 1 - i) as f64 * self.mass * self.gravity / self.stiffness;
            z -= self.rest_length + stretch;
            x[3 * (i + 1) + 2] = z;
        }
        x
    }

    /// Total static stretch `sum_i (count - 1 - i) m g / k`.
    #[must_use]
    pub fn total_stretch(&self) -> f64 {
        let n = self.count as f64;
        n * (n - 1.0) / 2.0 * self.mass * self.gravity / self.stiffness
    }
}
