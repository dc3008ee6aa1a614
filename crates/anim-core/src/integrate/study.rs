//! Helpers for convergence and work-precision studies of integrators.

use super::{IntegrateError, Integrator, State};

/// Advances `state` by `steps` steps of `dt`.
///
/// # Errors
/// The first step error, with the state as it was before that step.
pub fn advance<S: ?Sized>(
    integrator: &mut dyn Integrator<S>,
    system: &mut S,
    state: &mut State,
    dt: f64,
    steps: usize,
) -> Result<(), IntegrateError> {
    for _ in 0..steps {
        integrator.step(system, state, dt)?;
    }
    Ok(())
}

/// Least-squares slope of `log(error)` against `log(dt)`: the measured order of convergence.
///
/// Returns `NaN` when fewer than two points have a positive, finite error.
#[must_use]
pub fn fit_order(dts: &[f64], errors: &[f64]) -> f64 {
    let pts: Vec<(f64, f64)> = dts
        .iter()
        .zip(errors)
        .filter(|(h, e)| **h > 0.0 && **e > 0.0 && e.is_finite())
        .map(|(h, e)| (h.ln(), e.ln()))
        .collect();
    if pts.len() < 2 {
        return f64::NAN;
    }
    let n = pts.len() as f64;
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / n;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / n;
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx) * (p.0 - mx)).sum();
    sxy / sxx
}

#[cfg(test)]
mod tests {
    use super::fit_order;

    #[test]
    fn slope_of_exact_power_laws() {
        let dts = [0.1, 0.05, 0.025, 0.0125];
        for p in [1.0, 2.0, 4.0] {
            let errs: Vec<f64> = dts.iter().map(|h: &f64| 3.0 * h.powf(p)).collect();
            assert!((fit_order(&dts, &errs) - p).abs() < 1e-12);
        }
        assert!(fit_order(&[0.1], &[1.0]).is_nan());
    }
}
