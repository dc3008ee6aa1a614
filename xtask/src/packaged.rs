//! `cargo xtask packaged`: the library crates as the registry would serve them, built from
//! their packaged sources against the lowest versions their dependency ranges allow.
//!
//! 1. `cargo package --workspace --no-verify` writes each crate's `.crate` archive, exactly the
//!    files a user downloads, under the target directory's `package/`.
//! 2. Every publishable archive (its manifest does not say `publish = false`) is unpacked into
//!    `target/xtask/packaged/`, which becomes a workspace of its own; its `[patch.crates-io]`
//!    points each anim crate at its unpacked copy, since they are not on the registry.
//! 3. Its lockfile is resolved by `cargo update -Z direct-minimal-versions`: the lowest version
//!    each of our direct requirements allows (their own dependencies at the newest). The flag is
//!    cargo's, unstable; `RUSTC_BOOTSTRAP=1` allows it on a stable toolchain for that one command.
//! 4. `cargo check --workspace --lib --bins --all-features` there: every library and program of
//!    every packaged crate, with every feature, compiles from its packaged files against those
//!    versions (what `cargo package` verifies, without its code generation). A file a crate
//!    needs but does not package, or a lower bound below the API the code uses, fails here.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// Runs `cargo` with `args` in `dir`; `Err` carries its output when it fails.
fn cargo(dir: &Path, args: &[&str], env: &[(&str, &str)]) -> Result<(), String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let start = Instant::now();
    let mut cmd = Command::new(cargo);
    cmd.current_dir(dir).args(args).env_remove("RUSTFLAGS");
    for (k, v) in env {
        cmd.env(k, v);
    }
    let out = cmd.output().map_err(|e| format!("could not run cargo: {e}"))?;
    if !out.status.success() {
        return Err(format!(
            "`cargo {}` in {} failed:\n{}{}",
            args.join(" "),
            dir.display(),
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    eprintln!("  cargo {} ({:.0} s)", args.join(" "), start.elapsed().as_secs_f64());
    Ok(())
}

/// The directory name (`anim-core-0.1.0`) and package name of each `.crate` archive in `dir`.
fn archives(dir: &Path) -> Result<Vec<(PathBuf, String)>, String> {
    let mut found = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(|e| format!("{}: {e}", dir.display()))? {
        let path = entry.map_err(|e| e.to_string())?.path();
        if path.extension().is_some_and(|e| e == "crate") {
            let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or_default().to_string();
            // `name-version`: the version is what follows the last '-'.
            if let Some((name, _)) = stem.rsplit_once('-') {
                found.push((path.clone(), name.to_string()));
            }
        }
    }
    found.sort();
    Ok(found)
}

/// Whether an unpacked manifest keeps its crate off the registry.
fn unpublished(manifest: &str) -> bool {
    manifest.lines().any(|l| l.replace(' ', "") == "publish=false")
}

fn check(root: &Path, target: &Path) -> Result<(), String> {
    let package_dir = target.join("package");
    let _ = std::fs::remove_dir_all(&package_dir);
    cargo(root, &["package", "--workspace", "--no-verify", "--allow-dirty", "--quiet"], &[])?;
    let dir = root.join("target/xtask/packaged");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let mut members = Vec::new();
    for (archive, name) in archives(&package_dir)? {
        let status = Command::new("tar")
            .arg("-xzf")
            .arg(&archive)
            .arg("-C")
            .arg(&dir)
            .status()
            .map_err(|e| format!("could not run tar: {e}"))?;
        if !status.success() {
            return Err(format!("tar could not unpack {}", archive.display()));
        }
        let unpacked = archive.file_stem().and_then(|s| s.to_str()).unwrap_or_default().to_string();
        let manifest = std::fs::read_to_string(dir.join(&unpacked).join("Cargo.toml"))
            .map_err(|e| format!("{unpacked}/Cargo.toml: {e}"))?;
        if unpublished(&manifest) {
            let _ = std::fs::remove_dir_all(dir.join(&unpacked));
        } else {
            members.push((name, unpacked));
        }
    }
    if members.is_empty() {
        return Err(format!("no publishable crate archive in {}", package_dir.display()));
    }
    let list = members.iter().map(|(_, d)| format!("\"{d}\"")).collect::<Vec<_>>().join(", ");
    let patch = members.iter().map(|(n, d)| format!("{n} = {{ path = \"{d}\" }}\n")).collect::<String>();
    let workspace = format!(
        "# The packaged crates as a workspace of their own (`cargo xtask packaged`).\n\
         [workspace]\nresolver = \"3\"\nmembers = [{list}]\n\n[patch.crates-io]\n{patch}"
    );
    std::fs::write(dir.join("Cargo.toml"), workspace).map_err(|e| e.to_string())?;
    eprintln!("  unpacked: {}", members.iter().map(|(_, d)| d.as_str()).collect::<Vec<_>>().join(", "));
    cargo(&dir, &["update", "--quiet", "-Z", "direct-minimal-versions"], &[("RUSTC_BOOTSTRAP", "1")])?;
    let check_target = root.join("target/xtask/packaged-target");
    let check_target = check_target.to_string_lossy().into_owned();
    cargo(
        &dir,
        &["check", "--quiet", "--workspace", "--lib", "--bins", "--all-features"],
        &[("CARGO_TARGET_DIR", check_target.as_str())],
    )
}

/// Runs the packaged-crates check; `true` when it passed.
pub fn run_check() -> bool {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap_or(Path::new(".")).to_path_buf();
    let target = std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| root.join("target"), PathBuf::from);
    eprintln!("== packaged: every publishable crate from its .crate archive, lowest direct versions");
    match check(&root, &target) {
        Ok(()) => {
            eprintln!("== packaged: passed");
            true
        }
        Err(e) => {
            eprintln!("== packaged: FAILED: {e}");
            false
        }
    }
}

#[cfg(test)]
mod tests {
    use super::unpublished;

    #[test]
    fn publish_false_is_read_with_or_without_spaces() {
        assert!(unpublished("[package]\nname = \"ci\"\npublish = false\n"));
        assert!(unpublished("[package]\npublish=false\n"));
        assert!(!unpublished("[package]\nname = \"anim-core\"\n"));
        assert!(!unpublished("[package]\npublish = [\"crates-io\"]\n"));
    }
}
