//! A hard case's sweep of a speed (or any parameter) upwards: how many of its bodies fail at each
//! value, the largest value before the first failure, and that first failure, in words.

use super::fmt_num;

/// The failures counted at each value of a sweep, in the sweep's order.
///
/// ```
/// use anim_core::cases::Sweep;
///
/// // Bodies go through a plate from 2 m/s on.
/// let s = Sweep::run(&[0.5, 1.0, 2.0, 20.0], |v| Ok::<_, String>(if v < 2.0 { 0 } else { 3 }))?;
/// assert_eq!((s.held(), s.first_failure()), (1.0, Some(2.0)));
/// assert_eq!(s.describe("cube", 8, 20.0), "every cube caught up to 1 m/s, some through from 2 m/s (of 8: 3 at 20 m/s)");
/// let none = Sweep::run(&[1.0, 5.0], |_| Ok::<_, String>(0))?;
/// assert_eq!(none.describe("cube", 8, 5.0), "every cube caught at every speed tried, up to 5 m/s (of 8: 0 at 5 m/s)");
/// # Ok::<(), String>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Sweep {
    /// Each value with the failures counted there.
    pub counts: Vec<(f64, usize)>,
}

impl Sweep {
    /// Counts the failures `count(value)` at each of `values` (ascending).
    ///
    /// # Errors
    /// The first error of `count`, with the value it was run at.
    pub fn run<E: std::fmt::Display>(
        values: &[f64],
        mut count: impl FnMut(f64) -> Result<usize, E>,
    ) -> Result<Self, String> {
        let counts = values
            .iter()
            .map(|&v| count(v).map(|n| (v, n)).map_err(|e| format!("at {}: {e}", fmt_num(v))))
            .collect::<Result<_, _>>()?;
        Ok(Self { counts })
    }

    /// The largest value before the first with a failure (0 when the first value fails).
    #[must_use]
    pub fn held(&self) -> f64 {
        self.counts.iter().take_while(|c| c.1 == 0).last().map_or(0.0, |c| c.0)
    }

    /// The first value with a failure.
    #[must_use]
    pub fn first_failure(&self) -> Option<f64> {
        self.counts.iter().find(|c| c.1 > 0).map(|c| c.0)
    }

    /// The sweep of speeds (m/s) in words, for `of` bodies named `body`: the speed up to which
    /// every one was caught, the first at which some went through, and the counts from `from` on.
    #[must_use]
    pub fn describe(&self, body: &str, of: usize, from: f64) -> String {
        let fast: Vec<String> = self
            .counts
            .iter()
            .filter(|c| c.0 >= from)
            .map(|&(v, n)| format!("{n} at {} m/s", fmt_num(v)))
            .collect();
        match self.first_failure() {
            Some(v) => format!(
                "every {body} caught up to {} m/s, some through from {} m/s (of {of}: {})",
                fmt_num(self.held()),
                fmt_num(v),
                fast.join(", ")
            ),
            None => format!(
                "every {body} caught at every speed tried, up to {} m/s (of {of}: {})",
                fmt_num(self.held()),
                fast.join(", ")
            ),
        }
    }
}
