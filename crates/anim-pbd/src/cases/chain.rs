//! The hanging chain: `n` particles of mass `m` below a pin, joined by links of rest length `l`
//! under gravity `g`. At rest link `j` (1 = top) carries the weight below it,
//! `T_j = (n - j + 1) m g`. XPBD with compliance `alpha` (the inverse stiffness: the link's
//! energy is `C^2 / (2 alpha)`, Macklin et al. 2016) converges at rest to the force balance
//! `C_j / alpha = T_j`: link `j` stretches by `alpha T_j` whatever the iteration count or time
//! step, which the conformance checks measure; the hard cases start lighter chains far from rest.

use crate::{BuildError, Chain, ConstraintParams, PbdBuilder, PbdModel, PbdParams, PbdSimulation};
use anim_core::integrate::State;

/// A vertical chain of `n` free particles of mass `m` below a pin, links of rest length `l`.
pub(super) struct HangingChain {
    /// Free particles.
    pub(super) n: usize,
    /// Mass of each particle (kg).
    pub(super) m: f64,
    /// Rest length of each link (m).
    pub(super) l: f64,
    /// Gravity (m/s^2).
    pub(super) g: f64,
}

/// The chain of the conformance checks: ten 1 kg particles, 1 m links.
pub(super) const CHAIN: HangingChain = HangingChain { n: 10, m: 1.0, l: 1.0, g: 9.81 };

impl HangingChain {
    /// The chain pinned at its top particle, links with the given stretch parameters.
    pub(super) fn model(&self, stretch: ConstraintParams) -> Result<PbdModel, BuildError> {
        let mut b = PbdBuilder::new();
        b.gravity([0.0, 0.0, -self.g]);
        let r = b.chain(&Chain {
            count: self.n + 1,
            start: [0.0; 3],
            end: [0.0, 0.0, -(self.n as f64) * self.l],
            mass: self.m,
            stretch,
        })?;
        b.pin(r.start);
        b.build()
    }

    /// Tension of link `j` (1 = top): the weight of the particles below it.
    pub(super) fn tension(&self, j: usize) -> f64 {
        (self.n - j + 1) as f64 * self.m * self.g
    }

    /// Exact heights of particles 1..=n for compliance `alpha`: link j stretches by `alpha T_j`.
    pub(super) fn exact(&self, alpha: f64) -> Vec<f64> {
        let mut z = 0.0;
        (1..=self.n)
            .map(|j| {
                z -= self.l + alpha * self.tension(j);
                z
            })
            .collect()
    }

    /// Runs to rest (max |v| below `tol` m/s, at most `max_t` s); returns the state and steps.
    pub(super) fn settle(
        &self,
        model: PbdModel,
        params: PbdParams,
        dt: f64,
        tol: f64,
        max_t: f64,
    ) -> Option<(State, usize)> {
        let mut state = model.rest_state();
        let mut sim = PbdSimulation::new(model, params).ok()?;
        let max_steps = (max_t / dt) as usize;
        for k in 1..=max_steps {
            sim.advance(&mut state, dt).ok()?;
            if k > 10 && state.v.iter().fold(0.0f64, |a, v| a.max(v.abs())) < tol {
                return Some((state, k));
            }
        }
        Some((state, max_steps))
    }
}
