//! `cargo xtask bench`: runs the criterion benches and prints a table of medians; with `--peers`,
//! runs the peer comparisons of [`crate::peers`] and merges their ratios into `docs/report/peers.csv`.

use crate::peers::{self, human, ratios};
use std::io::Write;
use std::process::Command;

/// One benchmark's result as reported in criterion's `bencher` output format.
struct Row {
    name: String,
    ns: f64,
    spread: f64,
}

fn parse_bencher(out: &str) -> Vec<Row> {
    // Lines look like: "test core/svd3/f64 ... bench:         123 ns/iter (+/- 4)"
    out.lines()
        .filter_map(|line| {
            let rest = line.strip_prefix("test ")?;
            let (name, rest) = rest.split_once(" ... bench:")?;
            let (ns, rest) = rest.trim().split_once(" ns/iter")?;
            let spread = rest.trim().trim_start_matches("(+/-").trim_end_matches(')').trim().replace(',', "");
            Some(Row {
                name: name.trim().to_string(),
                ns: ns.replace(',', "").trim().parse().ok()?,
                spread: spread.parse().unwrap_or(f64::NAN),
            })
        })
        .collect()
}

pub fn run(filter: Option<&str>) -> bool {
    if std::env::args().skip(2).any(|a| a == "--peers") {
        // `--filter` picks peers by name (springs, rigid, pbd, fem, mpm, fluid, flip).
        type Peer = (&'static str, fn() -> bool);
        let peers: [Peer; 7] = [
            ("springs", peers::springs::run),
            ("rigid", peers::rigid::run),
            ("pbd", peers::pbd::run),
            ("fem", peers::fem::run),
            ("mpm", peers::mpm::run),
            ("fluid", peers::fluid::run),
            ("flip", peers::flip::run),
        ];
        let mut ok = true;
        for (name, run) in peers {
            if filter.is_none_or(|f| name.contains(f) || f.contains(name)) {
                ok &= run();
            }
        }
        // Rows of the crates measured now replace theirs in the committed file; others stay.
        let measured = ratios::take();
        let crates: std::collections::BTreeSet<String> = measured.iter().map(|r| r.krate.clone()).collect();
        let path = std::path::Path::new(ratios::PATH);
        match ratios::update(path, measured) {
            Ok(n) => eprintln!(
                "updated {} ({n} rows; measured now: {})",
                path.display(),
                if crates.is_empty() {
                    "none".to_string()
                } else {
                    crates.into_iter().collect::<Vec<_>>().join(", ")
                }
            ),
            Err(e) => {
                eprintln!("could not update {}: {e}", path.display());
                ok = false;
            }
        }
        return ok;
    }
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let mut args = vec!["bench", "-p", "anim-benches", "--benches", "--", "--output-format", "bencher"];
    if let Some(f) = filter {
        args.push(f);
    }
    eprintln!("== cargo {}", args.join(" "));
    let output = match Command::new(cargo).args(&args).output() {
        Ok(o) => o,
        Err(e) => {
            eprintln!("could not run cargo bench: {e}");
            return false;
        }
    };
    let stdout = String::from_utf8_lossy(&output.stdout);
    if !output.status.success() {
        eprintln!("{}", String::from_utf8_lossy(&output.stderr));
        eprintln!("cargo bench failed");
        return false;
    }
    let rows = parse_bencher(&stdout);
    println!("| benchmark | median | spread |\n| --- | --- | --- |");
    for r in &rows {
        println!("| {} | {} | +/- {} |", r.name, human(r.ns), human(r.spread));
    }
    let dir = std::path::Path::new("target/xtask");
    let written = std::fs::create_dir_all(dir).and_then(|_| {
        let mut f = std::fs::File::create(dir.join("bench.csv"))?;
        writeln!(f, "benchmark,median_ns,spread_ns")?;
        for r in &rows {
            writeln!(f, "{},{},{}", r.name, r.ns, r.spread)?;
        }
        Ok(())
    });
    match written {
        Ok(()) => eprintln!("wrote target/xtask/bench.csv ({} benchmarks)", rows.len()),
        Err(e) => eprintln!("could not write target/xtask/bench.csv: {e}"),
    }
    !rows.is_empty()
}

#[cfg(test)]
mod tests {
    #[test]
    fn parses_bencher_lines() {
        let rows = super::parse_bencher(
            "noise\ntest svd3/f64 ... bench:       1,234 ns/iter (+/- 56)\ntest cg/poisson-64 ... bench: 9 ns/iter (+/- 0)\n",
        );
        assert_eq!(rows.len(), 2);
        assert_eq!(rows[0].name, "svd3/f64");
        assert_eq!(rows[0].ns, 1234.0);
        assert_eq!(rows[0].spread, 56.0);
        assert_eq!(rows[1].ns, 9.0);
    }
}
