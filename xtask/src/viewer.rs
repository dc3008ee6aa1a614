//! `cargo xtask viewer`: opens the browser viewer of three runs in headless Chromium and checks
//! what it draws.
//!
//! For a cloth (`cloth`), a 3D MPM scene (`dam-break`) and a 2D grid fluid (`smoke-box-2d`),
//! it runs the scene through the `anim` command's library, screenshots `viewer.html` at frame 0
//! and at the last frame (the page without its controls, `#frame=N&bare`), and asserts that
//! each screenshot is not blank (at least 1% of its pixels differ from the background) and that
//! the object moved (at least 0.5% of the pixels differ between the two). The screenshots stay
//! in the output folder (`target/xtask/viewer/` by default).
//!
//! Chromium is Debian's `chromium` (or `chromium-headless-shell`, or `$ANIM_CHROMIUM`). Where
//! none is installed the check is skipped with a note, unless `ANIM_REQUIRE_CHROMIUM` is set
//! (CI sets it once it has installed Chromium): then a missing browser is a failure.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The page's background (`#f4f4f6`).
const BACKGROUND: [u8; 3] = [0xf4, 0xf4, 0xf6];
/// A pixel differs when a channel differs by more than this.
const DIFFERS: u8 = 12;
/// Screenshot size.
const SIZE: (u32, u32) = (640, 480);

/// A scene the check runs: name and the run's extra arguments.
const SCENES: [(&str, &str, &[&str]); 3] = [
    ("cloth", "a cloth", &["--frames", "30"]),
    ("dam-break", "a 3D MPM scene", &["--frames", "24", "--resolution", "24"]),
    ("smoke-box-2d", "a 2D grid fluid", &["--frames", "30", "--resolution", "64"]),
];

/// What one scene's screenshots showed.
struct Outcome {
    scene: &'static str,
    what: &'static str,
    /// Fraction of pixels off the background at frame 0 and at the last frame.
    drawn: (f64, f64),
    /// Fraction of pixels that differ between the two.
    moved: f64,
    shots: (PathBuf, PathBuf),
}

impl Outcome {
    fn passed(&self) -> bool {
        self.drawn.0 >= 0.01 && self.drawn.1 >= 0.01 && self.moved >= 0.005
    }
}

/// The Chromium to use, if one is installed.
fn chromium() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("ANIM_CHROMIUM") {
        return Some(PathBuf::from(p));
    }
    let path = std::env::var_os("PATH")?;
    ["chromium", "chromium-headless-shell", "chromium-browser", "google-chrome"]
        .iter()
        .flat_map(|name| std::env::split_paths(&path).map(move |dir| dir.join(name)))
        .find(|p| p.is_file())
}

/// Runs the check; `out` receives the runs and screenshots. Returns whether it passed (or was
/// skipped where allowed).
pub fn run(out: &Path) -> bool {
    let Some(browser) = chromium() else {
        let required = std::env::var_os("ANIM_REQUIRE_CHROMIUM").is_some();
        println!(
            "viewer check: SKIPPED: no Chromium found (Debian: apt-get install chromium; or set ANIM_CHROMIUM){}",
            if required { "; ANIM_REQUIRE_CHROMIUM is set, so this is a failure" } else { "" }
        );
        return !required;
    };
    let mut ok = true;
    println!("viewer check with {}", browser.display());
    println!("| scene | what | drawn at frame 0 | drawn at the last frame | pixels changed | verdict |");
    println!("| --- | --- | --- | --- | --- | --- |");
    for (scene, what, extra) in SCENES {
        match check(&browser, out, scene, what, extra) {
            Ok(o) => {
                let verdict = if o.passed() { "pass" } else { "FAIL" };
                ok &= o.passed();
                println!(
                    "| {} | {} | {:.1}% | {:.1}% | {:.1}% | {verdict} |",
                    o.scene,
                    o.what,
                    100.0 * o.drawn.0,
                    100.0 * o.drawn.1,
                    100.0 * o.moved
                );
                println!(
                    "|  | screenshots: {} and {} |  |  |  |  |",
                    o.shots.0.display(),
                    o.shots.1.display()
                );
            }
            Err(e) => {
                ok = false;
                println!("| {scene} | {what} | | | | FAIL: {e} |");
            }
        }
    }
    ok
}

/// Runs `scene`, screenshots its viewer at the first and last frame and measures the pictures.
fn check(
    browser: &Path,
    out: &Path,
    scene: &'static str,
    what: &'static str,
    extra: &[&str],
) -> Result<Outcome, String> {
    let dir = out.join(scene);
    let _ = std::fs::remove_dir_all(&dir);
    let dir_arg = dir.display().to_string();
    let mut argv =
        vec!["anim", scene, "--out", dir_arg.as_str(), "--quiet", "--no-preview", "--format", "none"];
    argv.extend_from_slice(extra);
    let args = <Runner as clap::Parser>::try_parse_from(&argv).map_err(|e| e.to_string())?;
    anim_cli::run::run(&args.run)?;
    let page = dir.join("viewer.html");
    let page = std::fs::canonicalize(&page).map_err(|e| format!("{}: {e}", page.display()))?;
    let first = dir.join("frame-first.png");
    let last = dir.join("frame-last.png");
    screenshot(browser, &dir, &page, "frame=0&bare", &first)?;
    screenshot(browser, &dir, &page, "frame=last&bare", &last)?;
    let (a, b) = (read_rgb(&first)?, read_rgb(&last)?);
    let moved = a.chunks_exact(3).zip(b.chunks_exact(3)).filter(|(p, q)| differs(p, q)).count() as f64
        / (a.len() / 3).max(1) as f64;
    Ok(Outcome { scene, what, drawn: (drawn(&a), drawn(&b)), moved, shots: (first, last) })
}

/// The `anim run` arguments, parsed as the command line parses them.
#[derive(clap::Parser)]
struct Runner {
    #[command(flatten)]
    run: anim_cli::run::RunArgs,
}

/// Chromium's screenshot of `page#fragment`, `SIZE` pixels, into `png`.
fn screenshot(browser: &Path, dir: &Path, page: &Path, fragment: &str, png: &Path) -> Result<(), String> {
    let _ = std::fs::remove_file(png);
    let profile = dir.join("chromium-profile");
    let output = Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--use-angle=swiftshader",
            "--enable-unsafe-swiftshader",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--no-first-run",
            "--hide-scrollbars",
            "--virtual-time-budget=20000",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg(format!("--window-size={},{}", SIZE.0, SIZE.1))
        .arg(format!("--screenshot={}", png.display()))
        .arg(format!("file://{}#{fragment}", page.display()))
        .output()
        .map_err(|e| format!("cannot start {}: {e}", browser.display()))?;
    let _ = std::fs::remove_dir_all(&profile);
    if !png.is_file() {
        let err = String::from_utf8_lossy(&output.stderr);
        let tail: Vec<&str> = err.lines().rev().take(5).collect();
        return Err(format!("no screenshot of {}#{fragment}: {}", page.display(), tail.join(" / ")));
    }
    Ok(())
}

/// The RGB pixels of a PNG.
fn read_rgb(path: &Path) -> Result<Vec<u8>, String> {
    let file = std::fs::File::open(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut decoder = png::Decoder::new(std::io::BufReader::new(file));
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = decoder.read_info().map_err(|e| format!("{}: {e}", path.display()))?;
    let mut buf = vec![0; reader.output_buffer_size().unwrap_or(0)];
    let info = reader.next_frame(&mut buf).map_err(|e| format!("{}: {e}", path.display()))?;
    let bytes = &buf[..info.buffer_size()];
    let channels = info.color_type.samples();
    if channels < 3 {
        return Err(format!("{}: not an RGB picture", path.display()));
    }
    Ok(bytes.chunks_exact(channels).flat_map(|p| [p[0], p[1], p[2]]).collect())
}

fn differs(p: &[u8], q: &[u8]) -> bool {
    p.iter().zip(q).any(|(a, b)| a.abs_diff(*b) > DIFFERS)
}

/// Fraction of pixels off the background.
fn drawn(rgb: &[u8]) -> f64 {
    rgb.chunks_exact(3).filter(|p| differs(p, &BACKGROUND)).count() as f64 / (rgb.len() / 3).max(1) as f64
}

#[cfg(test)]
mod tests {
    use super::{differs, drawn};

    #[test]
    fn a_picture_of_background_is_blank_and_a_drawn_one_is_not() {
        let blank = [0xf4u8, 0xf4, 0xf6].repeat(100);
        assert_eq!(drawn(&blank), 0.0);
        let mut one = blank.clone();
        one[30..33].copy_from_slice(&[0, 0, 0]);
        assert!((drawn(&one) - 0.01).abs() < 1e-12);
        // Anti-aliasing noise within the threshold is no difference.
        assert!(!differs(&[10, 10, 10], &[22, 0, 10]));
        assert!(differs(&[10, 10, 10], &[23, 10, 10]));
    }
}
