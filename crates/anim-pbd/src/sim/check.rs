//! The guard and the commit. A step is computed in the solver's own buffers and copied into the
//! caller's state only when it succeeded: on error the state is unchanged, and so is the
//! simulation's memory (step count, external forces, pending body targets:
//! [`PbdSimulation::memory`](crate::PbdSimulation::memory)).
//!
//! After each step every position and velocity is checked ([`PbdError::NonFinite`], whose
//! message begins with `anim-pbd: step N:` and names the particle, the component `x`/`y`/`z`, the
//! value, the particle's last finite position or velocity, and the first constraint whose update
//! was not finite, or else the first constraint at that particle), and the largest stretch
//! `|x_i - x_j| / l` over the distance constraints is compared with
//! [`PbdParams::max_stretch`] ([`PbdError::Diverged`]).

use super::error::PbdError;
use super::params::PbdParams;
use super::scratch::Data;
use crate::constraint::{ConstraintFunction, load};
use crate::model::PbdModel;
use crate::project::CONTACT_ID;
use anim_core::glam::DVec3;
use anim_core::integrate::State;
use std::sync::atomic::Ordering;

/// Loads the caller's state into the step's buffers `d.x`, `d.v`.
pub(super) fn load_state(d: &mut Data, state: &State) {
    copy_vec3(&mut d.x, &state.x);
    copy_vec3(&mut d.v, &state.v);
}

/// The post-step checks of the step computed in `d`, the run's step number `step`, from `state`
/// (the state before the step, for the last finite values): see the module docs.
pub(super) fn check(
    model: &PbdModel,
    params: &PbdParams,
    d: &Data,
    step: u64,
    state: &State,
) -> Result<(), PbdError> {
    let bad_x = d.x.iter().position(|p| !p.is_finite());
    let bad_v = d.v.iter().position(|p| !p.is_finite());
    let flagged = d.bad.load(Ordering::Relaxed);
    if bad_x.is_some() || bad_v.is_some() || flagged != usize::MAX {
        let (field, particle, after, old) = match (bad_x, bad_v) {
            (Some(p), _) => ("position", p, Some(d.x[p]), &state.x),
            (None, Some(p)) => ("velocity", p, Some(d.v[p]), &state.v),
            // A skipped non-finite update left the state finite: name the constraint's first particle.
            (None, None) => ("position", first_particle(model, flagged), None, &state.x),
        };
        let component = after.and_then(|a| a.to_array().iter().position(|c| !c.is_finite()));
        let value = match (after, component) {
            (Some(a), Some(c)) => a[c],
            _ => f64::NAN,
        };
        let constraint = if flagged < model.constraints.len() && flagged != CONTACT_ID as usize {
            Some(flagged)
        } else {
            model.incident(particle).next()
        };
        return Err(PbdError::NonFinite {
            step,
            field,
            particle,
            component,
            value,
            last_finite: load(old, particle).to_array(),
            constraint: constraint.map(|c| (c, model.constraints[c].function.name())),
        });
    }
    if params.max_stretch.is_finite() {
        let mut worst: Option<(f64, usize, usize, usize)> = None;
        for (j, c) in model.constraints.iter().enumerate() {
            if let ConstraintFunction::Distance { particles: [a, b], rest_length } = c.function
                && rest_length > 0.0
            {
                let r = (d.x[a] - d.x[b]).length() / rest_length;
                if r > params.max_stretch && worst.is_none_or(|w| r > w.0) {
                    worst = Some((r, j, a, b));
                }
            }
        }
        if let Some((ratio, constraint, i, j)) = worst {
            return Err(PbdError::Diverged { step, constraint, i, j, ratio, bound: params.max_stretch });
        }
    }
    Ok(())
}

/// The first particle of constraint `flagged` (0 for a contact or none).
fn first_particle(model: &PbdModel, flagged: usize) -> usize {
    if flagged < model.constraints.len() {
        model.constraint_particles(flagged).first().copied().unwrap_or(0)
    } else {
        0
    }
}

/// Commits a checked step: copies the step's positions and velocities into `state`, at time `t`.
pub(super) fn commit(d: &Data, state: &mut State, t: f64) {
    for (i, (x, v)) in d.x.iter().zip(&d.v).enumerate() {
        state.x[3 * i..3 * i + 3].copy_from_slice(&x.to_array());
        state.v[3 * i..3 * i + 3].copy_from_slice(&v.to_array());
    }
    state.t = t;
}

/// Copies `from` into `to` reusing `to`'s buffers.
fn copy_vec3(to: &mut [DVec3], from: &[f64]) {
    for (i, t) in to.iter_mut().enumerate() {
        *t = load(from, i);
    }
}
