//! The points of a work-precision study measured so far, so that a point another method already
//! beats in both time and error need not be run: what keeps a study's sweep from spending
//! minutes on a slow method at a tolerance a fast one reached in a fraction of a second.

/// Measured `(seconds, error)` points of one problem (one resolution of a study, say).
///
/// A point yet to be run is *beaten* when some measured point took no longer than the point's
/// lower bound on time and reached an error no larger than the error it aims at. A sweep that
/// tightens a tolerance has such a bound: the time of its own previous, looser point.
///
/// ```
/// use anim_core::cases::Frontier;
///
/// let mut f = Frontier::default();
/// f.add(0.4, 2e-9); // a multigrid solve to 1e-8 in 0.4 s
/// // Jacobi took 15 s for 1e-2; 1e-3 takes at least as long and is beaten:
/// assert_eq!(f.beaten(15.0, 1e-3), Some((0.4, 2e-9)));
/// // a point that may take less than 0.4 s is not:
/// assert_eq!(f.beaten(0.1, 1e-3), None);
/// // nor one aiming below every error measured:
/// assert_eq!(f.beaten(15.0, 1e-10), None);
/// ```
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Frontier {
    points: Vec<(f64, f64)>,
}

impl Frontier {
    /// Records a measured point (non-finite values are ignored: a failed measurement beats
    /// nothing).
    pub fn add(&mut self, seconds: f64, error: f64) {
        if seconds.is_finite() && error.is_finite() {
            self.points.push((seconds, error));
        }
    }

    /// The fastest measured point that beats a point taking at least `at_least` seconds and
    /// aiming at `error`: one no slower and no less accurate. `None` when none does.
    #[must_use]
    pub fn beaten(&self, at_least: f64, error: f64) -> Option<(f64, f64)> {
        self.points
            .iter()
            .copied()
            .filter(|&(s, e)| s <= at_least && e <= error)
            .min_by(|a, b| a.0.total_cmp(&b.0))
    }
}
