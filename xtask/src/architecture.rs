//! Keeps `docs/ARCHITECTURE.md` honest: every path it names in backticks must exist.

#[cfg(test)]
mod tests {
    use std::path::Path;

    /// Backticked tokens that look like repository paths (contain a `/` and no spaces).
    fn named_paths(doc: &str) -> Vec<String> {
        doc.split('`')
            .skip(1)
            .step_by(2)
            .filter(|t| {
                t.contains('/') && !t.contains(' ') && !t.contains("shared/") && !t.starts_with("target/")
            })
            .map(str::to_string)
            .collect()
    }

    #[test]
    fn every_path_in_the_architecture_doc_exists() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let doc = std::fs::read_to_string(root.join("docs/ARCHITECTURE.md")).unwrap();
        let paths = named_paths(&doc);
        assert!(paths.len() >= 10, "expected the doc to name its paths, found {paths:?}");
        let missing: Vec<&String> =
            paths.iter().filter(|p| !root.join(p.trim_end_matches('/')).exists()).collect();
        assert!(missing.is_empty(), "docs/ARCHITECTURE.md names paths that do not exist: {missing:?}");
    }

    #[test]
    fn path_extraction_skips_prose_and_finds_paths() {
        let doc =
            "see `crates/a/src/lib.rs` and `Solver::step(&mut self, state)` and `cargo xtask` or `x/y/`";
        assert_eq!(named_paths(doc), vec!["crates/a/src/lib.rs".to_string(), "x/y/".to_string()]);
    }
}
