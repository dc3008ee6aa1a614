//! Determinism across thread counts: a run on rayon pools of 1, 2 and 4 threads must end in the
//! same state, bit for bit.

use super::{Check, Judge};

const THREADS: [usize; 3] = [1, 2, 4];
const SOURCE: &str = "the same run on 1 thread";

/// Number of positions in `a` and `b` whose bits differ (a length mismatch counts every value).
pub fn differing_bits(a: &[f64], b: &[f64]) -> usize {
    if a.len() != b.len() {
        return a.len().max(b.len());
    }
    a.iter().zip(b).filter(|(x, y)| x.to_bits() != y.to_bits()).count()
}

/// Runs `run` on pools of 1, 2 and 4 threads and turns the flattened final states into checks
/// against the 1-thread run.
pub fn across_threads(
    crate_name: &'static str,
    case: &str,
    run: impl Fn() -> Result<Vec<f64>, String> + Sync,
) -> Vec<Check> {
    let mut finals = Vec::new();
    for threads in THREADS {
        let result = crate::par::with_threads(threads, &run).and_then(|r| r);
        finals.push((threads, result));
    }
    let reference = match &finals[0].1 {
        Ok(v) => v.clone(),
        Err(e) => {
            return vec![Check {
                crate_name,
                case: format!("{case} (1 thread failed: {e})"),
                metric: "values differing".into(),
                measured: f64::NAN,
                reference: 0.0,
                tolerance: 0.0,
                judge: Judge::AtMost,
                source: SOURCE,
            }];
        }
    };
    finals[1..]
        .iter()
        .map(|(threads, result)| {
            let measured = match result {
                Ok(v) => differing_bits(&reference, v) as f64,
                Err(_) => f64::NAN,
            };
            Check {
                crate_name,
                case: format!("{case}: {threads} threads vs 1 ({} values)", reference.len()),
                metric: "values whose bits differ".into(),
                measured,
                reference: 0.0,
                tolerance: 0.0,
                judge: Judge::AtMost,
                source: SOURCE,
            }
        })
        .collect()
}
