//! Where and when a measurement was taken: the UTC date and the machine (CPU model, cores), for
//! the report and the committed peer ratios.

use std::time::{SystemTime, UNIX_EPOCH};

/// The machine a run measured on.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Machine {
    /// CPU model name (`/proc/cpuinfo`), or `unknown cpu`.
    pub cpu: String,
    /// Logical cores available to the process.
    pub cores: usize,
}

impl Machine {
    /// This machine.
    pub fn this() -> Self {
        let cpu = std::fs::read_to_string("/proc/cpuinfo")
            .ok()
            .and_then(|s| {
                s.lines()
                    .find(|l| l.starts_with("model name"))
                    .and_then(|l| l.split_once(':'))
                    .map(|(_, v)| v.split_whitespace().collect::<Vec<_>>().join(" "))
            })
            .filter(|s| !s.is_empty())
            .unwrap_or_else(|| "unknown cpu".into());
        Machine { cpu, cores: cores() }
    }

    /// `"<cpu>, <cores> cores"`.
    pub fn describe(&self) -> String {
        format!("{}, {} cores", self.cpu, self.cores)
    }
}

/// Logical cores available to the process (at least 1).
pub fn cores() -> usize {
    std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1)
}

/// Today's UTC date as `YYYY-MM-DD`.
pub fn today() -> String {
    let secs = SystemTime::now().duration_since(UNIX_EPOCH).map_or(0, |d| d.as_secs());
    date_of(secs)
}

/// The UTC date of a Unix time, `YYYY-MM-DD` (proleptic Gregorian calendar; the civil-from-days
/// algorithm of Howard Hinnant, "chrono-Compatible Low-Level Date Algorithms").
pub fn date_of(unix_seconds: u64) -> String {
    let z = (unix_seconds / 86_400) as i64 + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!("{year:04}-{month:02}-{day:02}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dates_match_the_calendar() {
        // Reference dates: `date -u -d @SECONDS +%F`.
        assert_eq!(date_of(0), "1970-01-01");
        assert_eq!(date_of(951_782_400), "2000-02-29");
        assert_eq!(date_of(951_868_799), "2000-02-29");
        assert_eq!(date_of(951_868_800), "2000-03-01");
        assert_eq!(date_of(1_709_251_199), "2024-02-29");
        assert_eq!(date_of(4_107_542_400), "2100-03-01");
    }

    #[test]
    fn this_machine_has_cores() {
        let m = Machine::this();
        assert!(m.cores >= 1 && !m.cpu.is_empty());
        assert!(m.describe().ends_with(&format!("{} cores", m.cores)));
    }
}
