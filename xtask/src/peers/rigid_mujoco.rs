//! `cargo xtask bench --peers`, anim-rigid against MuJoCo: inverse dynamics, the mass matrix and
//! forward dynamics on the same URDFs and the same samples of `(q, v, a, τ)` as anim-rigid, by
//! MuJoCo's C API from the `mujoco` wheel (its headers and `libmujoco.so` ship inside the
//! package; `xtask/peers/mujoco/dynamics_bench.c`, compiled with `gcc -O3 -march=native`).
//!
//! MuJoCo compiles the URDF itself. The file it is given is the robot's URDF without visual and
//! collision elements (their meshes are not shipped, and no contact is computed) and with the
//! joints anim-rigid locks made fixed; the program sets the same gravity, removes armature,
//! damping and friction loss, and checks its inverse dynamics, mass matrix and forward dynamics
//! against anim-rigid's on every sample before it times anything (it refuses to time on a
//! difference above [`TOLERANCE`] relative to the largest entry). The pipelines are MuJoCo's
//! smallest that compute each quantity from `q` (see the program's header).
//!
//! The wheel is found through the Python of [`crate::python::python`] (`PYTHON` picks a
//! virtual environment); without it the MuJoCo columns are skipped with a note.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

use anim_core::lie::Se3;
use anim_rigid::{Data, FrameKind, Model, crba, forward_dynamics, rnea};

use super::rigid::Sample;
use crate::python::json_field as field;

/// The timing program, relative to the xtask crate, and its binary under `target/xtask`.
const PROGRAM: (&str, &str) = ("peers/mujoco/dynamics_bench.c", "mujoco_dynamics_bench");

/// Largest difference from anim-rigid's results, relative to the largest entry of the result,
/// that MuJoCo may have for the timings to count.
pub const TOLERANCE: f64 = 1e-9;

/// The `mujoco` package folder and its version, if the wheel is installed.
fn find_wheel() -> Option<(PathBuf, String)> {
    let out = Command::new(crate::python::python())
        .args(["-c", "import mujoco, os; print(os.path.dirname(mujoco.__file__)); print(mujoco.__version__)"])
        .output()
        .ok()?;
    if !out.status.success() {
        return None;
    }
    let text = String::from_utf8_lossy(&out.stdout);
    let mut lines = text.lines();
    let dir = PathBuf::from(lines.next()?.trim());
    let version = lines.next()?.trim().to_string();
    dir.join("include/mujoco/mujoco.h").exists().then_some((dir, version))
}

/// The shared library inside the package folder (`libmujoco.so.X.Y.Z`).
fn find_library(dir: &Path) -> Option<PathBuf> {
    std::fs::read_dir(dir)
        .ok()?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .find(|p| p.file_name().and_then(|n| n.to_str()).is_some_and(|n| n.starts_with("libmujoco.so")))
}

/// The MuJoCo peer, ready to run: its binary and the wheel's version.
pub struct Peer {
    bin: PathBuf,
    /// The version of the `mujoco` wheel (`4.0.0`).
    pub version: String,
}

/// Finds the wheel and compiles the program (cached while the binary is newer than the source).
pub fn prepare() -> Result<Peer, String> {
    let (dir, version) = find_wheel().ok_or_else(|| {
        format!("the `mujoco` wheel is not installed for {} (pip install mujoco)", crate::python::python())
    })?;
    let lib = find_library(&dir).ok_or_else(|| format!("no libmujoco.so in {}", dir.display()))?;
    let source = Path::new(env!("CARGO_MANIFEST_DIR")).join(PROGRAM.0);
    let out_dir = Path::new("target/xtask");
    std::fs::create_dir_all(out_dir).map_err(|e| e.to_string())?;
    let bin = out_dir.join(PROGRAM.1);
    let modified = |p: &Path| std::fs::metadata(p).and_then(|m| m.modified()).ok();
    let fresh = matches!((modified(&bin), modified(&source), modified(&lib)), (Some(b), Some(s), Some(l)) if b > s && b > l);
    if !fresh {
        let args: Vec<String> = vec![
            "-O3".into(),
            "-march=native".into(),
            format!("-I{}", dir.join("include").display()),
            source.display().to_string(),
            lib.display().to_string(),
            format!("-Wl,-rpath,{}", dir.display()),
            "-lm".into(),
            "-o".into(),
            bin.display().to_string(),
        ];
        eprintln!("== gcc {}", args.join(" "));
        let out = Command::new("gcc").args(&args).output().map_err(|e| format!("could not run gcc: {e}"))?;
        if !out.status.success() {
            let err = String::from_utf8_lossy(&out.stderr);
            let first: Vec<&str> = err.lines().filter(|l| l.contains("error")).take(5).collect();
            return Err(format!("gcc failed:\n{}", first.join("\n")));
        }
    }
    Ok(Peer { bin, version })
}

/// Removes every `<tag ...>...</tag>` (and `<tag .../>`) element from URDF text.
fn strip_elements(xml: &str, tag: &str) -> String {
    let (open, close) = (format!("<{tag}"), format!("</{tag}>"));
    let mut out = String::with_capacity(xml.len());
    let mut rest = xml;
    while let Some(start) = rest.find(&open) {
        // `<visual` must not match `<visualization`.
        let after = rest[start + open.len()..].chars().next();
        if !after.is_some_and(|c| c.is_whitespace() || c == '>' || c == '/') {
            out.push_str(&rest[..start + open.len()]);
            rest = &rest[start + open.len()..];
            continue;
        }
        out.push_str(&rest[..start]);
        let tail = &rest[start..];
        let head_end = tail.find('>').map_or(tail.len(), |i| i + 1);
        rest = if tail[..head_end].ends_with("/>") {
            &tail[head_end..]
        } else {
            tail.find(&close).map_or("", |i| &tail[i + close.len()..])
        };
    }
    out.push_str(rest);
    out
}

/// The URDF as MuJoCo is given it: no visual or collision geometry, `locked` joints fixed, and
/// `balanceinertia` on, so that MuJoCo compiles bodies whose principal moments miss the triangle
/// inequality (the 32-joint chain's first link, `0.004 + 0.003 = 0.007` before its products of
/// inertia); [`inertia_file`] then gives every body its exact inertia back.
pub fn urdf_for_mujoco(urdf: &Path, locked: &[&str]) -> Result<String, String> {
    let xml = std::fs::read_to_string(urdf).map_err(|e| format!("{}: {e}", urdf.display()))?;
    let mut xml = strip_elements(&strip_elements(&xml, "visual"), "collision");
    let robot = xml.find("<robot").ok_or_else(|| format!("{}: no <robot> element", urdf.display()))?;
    let after = robot + xml[robot..].find('>').map_or(0, |i| i + 1);
    xml.insert_str(after, "\n  <mujoco><compiler balanceinertia=\"true\"/></mujoco>");
    for name in locked {
        let key = format!("name=\"{name}\"");
        let Some(at) = xml.find(&key) else {
            return Err(format!("{}: no joint {name} to lock", urdf.display()));
        };
        let head_end = at + xml[at..].find('>').unwrap_or(0);
        let head = xml[at..head_end]
            .replace("type=\"prismatic\"", "type=\"fixed\"")
            .replace("type=\"revolute\"", "type=\"fixed\"");
        xml.replace_range(at..head_end, &head);
    }
    Ok(xml)
}

/// Writes each moving body's inertia as anim-rigid has it (one line per body: the URDF link at
/// the joint, mass, centre of mass and rotational inertia about it in the joint frame,
/// row-major); the program sets MuJoCo's principal inertia and its orientation from it (with
/// `mju_eig3`) after checking that mass and centre of mass are the same.
pub fn inertia_file(model: &Model, path: &Path) -> Result<(), String> {
    let mut s = String::new();
    for (i, inertia) in model.inertias().iter().enumerate().skip(1) {
        let link = model
            .frames()
            .iter()
            .find(|f| f.kind == FrameKind::Body && f.parent_joint == i && f.placement == Se3::IDENTITY)
            .ok_or_else(|| format!("joint {i} has no link at its frame"))?;
        let _ = write!(
            s,
            "{} {:e} {:e} {:e} {:e}",
            link.name, inertia.mass, inertia.com.x, inertia.com.y, inertia.com.z
        );
        for x in inertia.rotational.transpose().to_cols_array() {
            let _ = write!(s, " {x:e}");
        }
        s.push('\n');
    }
    std::fs::write(path, s).map_err(|e| format!("{}: {e}", path.display()))
}

/// Writes the samples and anim-rigid's results for them (the program's input format).
pub fn samples_file(model: &Model, samples: &[Sample], path: &Path) -> Result<(), String> {
    if model.nq() != model.nv() {
        return Err("the MuJoCo comparison takes one angle or offset per joint only".into());
    }
    let nv = model.nv();
    let g = model.gravity();
    let mut data = Data::new(model);
    let mut s = format!("{nv} {} {:e} {:e} {:e}\n", samples.len(), g.x, g.y, g.z);
    for sample in samples {
        let h = crba(model, &mut data, &sample.q).clone();
        let tau = rnea(model, &mut data, &sample.q, &sample.v, &sample.a).to_vec();
        let ddq = forward_dynamics(model, &mut data, &sample.q, &sample.v, &sample.tau).to_vec();
        let rows = [&sample.q, &sample.v, &sample.a, &sample.tau, &tau];
        for x in rows.into_iter().flatten() {
            let _ = write!(s, "{x:e} ");
        }
        for i in 0..nv {
            for j in 0..nv {
                let _ = write!(s, "{:e} ", h[(i, j)]);
            }
        }
        for x in &ddq {
            let _ = write!(s, "{x:e} ");
        }
        s.push('\n');
    }
    std::fs::write(path, s).map_err(|e| format!("{}: {e}", path.display()))
}

/// What one run of the program printed: the agreement line and `(kernel, ns)` pairs.
pub struct Run {
    /// Largest relative differences from anim-rigid: inverse dynamics, mass matrix, forward
    /// dynamics.
    pub agreement: [f64; 3],
    /// Median ns per call per kernel (`rnea`, `crba`, `forward_dynamics`).
    pub times: Vec<(String, f64)>,
}

/// Runs the program on a URDF and a samples file.
pub fn run(peer: &Peer, urdf: &Path, samples: &Path, inertias: &Path, calls: usize) -> Result<Run, String> {
    let o = Command::new(&peer.bin)
        .arg(urdf)
        .arg(samples)
        .arg(calls.to_string())
        .arg(format!("{TOLERANCE:e}"))
        .arg(inertias)
        .output()
        .map_err(|e| format!("could not run {}: {e}", peer.bin.display()))?;
    let stdout = String::from_utf8_lossy(&o.stdout);
    let number =
        |line: &str, key: &str| field(line, key).and_then(|x| x.parse::<f64>().ok()).unwrap_or(f64::NAN);
    let agreement = stdout
        .lines()
        .find(|l| field(l, "kernel").as_deref() == Some("check"))
        .map(|l| [number(l, "rnea"), number(l, "crba"), number(l, "forward_dynamics")]);
    if !o.status.success() {
        return Err(format!(
            "MuJoCo program failed ({}), agreement {agreement:?}: {}",
            o.status,
            String::from_utf8_lossy(&o.stderr).trim()
        ));
    }
    let times = stdout
        .lines()
        .filter_map(|line| Some((field(line, "kernel")?, field(line, "ns_per_call")?.parse::<f64>().ok()?)))
        .collect();
    Ok(Run { agreement: agreement.unwrap_or([f64::NAN; 3]), times })
}

#[cfg(test)]
mod tests {
    use super::strip_elements;

    #[test]
    fn strips_elements_and_keeps_the_rest() {
        let xml = "<link name=\"a\"><visual><geometry/></visual><visualization/><collision x=\"1\"/><inertial/></link>";
        let out = strip_elements(&strip_elements(xml, "visual"), "collision");
        assert_eq!(out, "<link name=\"a\"><visualization/><inertial/></link>");
    }
}
