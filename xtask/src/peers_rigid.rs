//! `cargo xtask bench --peers`, anim-rigid part: forward kinematics and joint Jacobians on the
//! Franka Panda (fingers locked, 7 DoF) and the UR5, ns per call, against Pinocchio's C++
//! library from the `pin` wheel (header-only, `g++ -O3 -march=native`), measured side by side.
//!
//! The C++ program (`xtask/peers/pinocchio/kinematics_bench.cpp`) builds its Pinocchio model from
//! a text file written here from anim-rigid's model of the same URDF, with the joint types
//! Pinocchio's URDF parser chooses (the two models agree to 1e-16: `tests/pinocchio.rs`); the
//! wheel ships no urdfdom headers, so its URDF parser cannot be compiled against. Needs Python
//! with `pin==4.1.0` and `cmeel-eigen` (installed with pip when missing) and g++.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use anim_rigid::{
    Axis, Data, JointType, Model, UrdfOptions, compute_joint_jacobians, forward_kinematics, load_urdf,
};

/// The timing program, relative to the xtask crate.
const SOURCE: &str = "peers/pinocchio/kinematics_bench.cpp";
const CALLS_PER_BATCH: usize = 20_000;
const BATCHES: usize = 15;
const CONFIGS: usize = 1024;
const ROUNDS: usize = 3;

fn python() -> String {
    std::env::var("PYTHON").unwrap_or_else(|_| "python3".into())
}

/// The `cmeel.prefix` holding Pinocchio's and Eigen's headers, if present.
fn find_prefix() -> Option<PathBuf> {
    let out = Command::new(python())
        .args(["-c", "import site; print('\\n'.join(site.getsitepackages() + [site.getusersitepackages()]))"])
        .output()
        .ok()?;
    String::from_utf8_lossy(&out.stdout).lines().map(|l| Path::new(l.trim()).join("cmeel.prefix")).find(|p| {
        p.join("include/pinocchio/algorithm/kinematics.hpp").exists()
            && p.join("include/eigen3/Eigen/Core").exists()
    })
}

fn ensure_prefix() -> Result<PathBuf, String> {
    if let Some(p) = find_prefix() {
        return Ok(p);
    }
    eprintln!("== Pinocchio headers not found: {} -m pip install pin==4.1.0 cmeel-eigen==3.4.1", python());
    let out = Command::new(python())
        .args(["-m", "pip", "install", "--quiet", "pin==4.1.0", "cmeel-eigen==3.4.1"])
        .output()
        .map_err(|e| format!("could not run pip: {e}"))?;
    if !out.status.success() {
        return Err(format!(
            "pip install failed: {}",
            String::from_utf8_lossy(&out.stderr).lines().last().unwrap_or("")
        ));
    }
    find_prefix().ok_or_else(|| {
        "pin installed, but cmeel.prefix/include/pinocchio or include/eigen3 is missing".into()
    })
}

/// Compiles the timing program (cached while the binary is newer than the source).
fn build(prefix: &Path) -> Result<PathBuf, String> {
    let source = Path::new(env!("CARGO_MANIFEST_DIR")).join(SOURCE);
    let dir = Path::new("target/xtask");
    std::fs::create_dir_all(dir).map_err(|e| e.to_string())?;
    let bin = dir.join("pinocchio_kinematics_bench");
    let fresh = match (
        std::fs::metadata(&bin).and_then(|m| m.modified()),
        std::fs::metadata(&source).and_then(|m| m.modified()),
    ) {
        (Ok(b), Ok(s)) => b > s,
        _ => false,
    };
    if fresh {
        return Ok(bin);
    }
    let include = prefix.join("include");
    let eigen = include.join("eigen3");
    let args: Vec<String> = vec![
        "-O3".into(),
        "-march=native".into(),
        "-DNDEBUG".into(),
        "-std=c++17".into(),
        // Pinocchio's own interface definitions (lib/cmake/pinocchio: pinocchio_headers).
        "-DBOOST_MPL_LIMIT_LIST_SIZE=30".into(),
        "-DBOOST_MPL_LIMIT_VECTOR_SIZE=30".into(),
        "-DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS".into(),
        "-DBOOST_FUSION_INVOKE_MAX_ARITY=12".into(),
        format!("-I{}", include.display()),
        format!("-I{}", eigen.display()),
        source.display().to_string(),
        "-o".into(),
        bin.display().to_string(),
    ];
    eprintln!("== g++ {}", args.join(" "));
    let out = Command::new("g++").args(&args).output().map_err(|e| format!("could not run g++: {e}"))?;
    if !out.status.success() {
        let err = String::from_utf8_lossy(&out.stderr);
        let first: Vec<&str> = err.lines().filter(|l| l.contains("error")).take(5).collect();
        return Err(format!("g++ failed:\n{}", first.join("\n")));
    }
    Ok(bin)
}

/// The model as the timing program reads it: one line per joint.
fn model_file(model: &Model, path: &Path) -> Result<(), String> {
    let mut s = String::new();
    for j in &model.joints()[1..] {
        let (code, axis) = match j.kind {
            JointType::Revolute(Axis::X) => ("RX", Axis::X.vector()),
            JointType::Revolute(Axis::Y) => ("RY", Axis::Y.vector()),
            JointType::Revolute(Axis::Z) => ("RZ", Axis::Z.vector()),
            JointType::Revolute(a) => ("RU", a.vector()),
            JointType::Prismatic(Axis::X) => ("PX", Axis::X.vector()),
            JointType::Prismatic(Axis::Y) => ("PY", Axis::Y.vector()),
            JointType::Prismatic(Axis::Z) => ("PZ", Axis::Z.vector()),
            JointType::Prismatic(a) => ("PU", a.vector()),
            other => return Err(format!("the peer benchmark has no {} joints", other.name())),
        };
        let r = j.placement.rotation.transpose().to_cols_array(); // row-major
        let t = j.placement.translation;
        s.push_str(&format!("joint {} {code} {:e} {:e} {:e}", j.parent, axis.x, axis.y, axis.z));
        for x in r {
            s.push_str(&format!(" {x:e}"));
        }
        s.push_str(&format!(" {:e} {:e} {:e} {:e} {:e}\n", t.x, t.y, t.z, j.limits.lower, j.limits.upper));
    }
    std::fs::write(path, s).map_err(|e| e.to_string())
}

/// Our median ns per call of `f` over pre-generated configurations, the same protocol as the
/// C++ program (batches of calls cycling through 1024 configurations, median of 15 batches).
fn time_ours(model: &Model, mut f: impl FnMut(&Model, &mut Data, &[f64]) -> f64) -> f64 {
    let mut state = 42u64;
    let mut uniform = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let qs: Vec<Vec<f64>> =
        (0..CONFIGS).map(|_| anim_rigid::config::random_configuration(model, &mut uniform)).collect();
    let mut data = Data::new(model);
    let mut sink = 0.0;
    let mut times: Vec<f64> = (0..BATCHES)
        .map(|_| {
            let start = Instant::now();
            for i in 0..CALLS_PER_BATCH {
                sink += f(model, &mut data, std::hint::black_box(&qs[i % CONFIGS]));
            }
            start.elapsed().as_secs_f64() * 1e9 / CALLS_PER_BATCH as f64
        })
        .collect();
    std::hint::black_box(sink);
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

fn field(line: &str, key: &str) -> Option<String> {
    let rest = &line[line.find(&format!("\"{key}\":"))? + key.len() + 3..];
    let rest = rest.trim_start();
    let end = rest.find([',', '}']).unwrap_or(rest.len());
    Some(rest[..end].trim().trim_matches('"').to_string())
}

/// Runs the comparison and prints the table; false if our side could not run.
pub fn run() -> bool {
    let testdata = Path::new(env!("CARGO_MANIFEST_DIR")).join("../crates/anim-rigid/testdata");
    let robots: [(&str, &str, &[&str]); 2] = [
        ("panda", "panda.urdf", &["panda_finger_joint1", "panda_finger_joint2"]),
        ("ur5", "ur5_robot.urdf", &[]),
    ];
    println!(
        "\npeer benchmark: anim-rigid vs Pinocchio (C++, header-only, g++ -O3 -march=native), ns per call: median of {BATCHES} batches of {CALLS_PER_BATCH} calls over {CONFIGS} random configurations, best of {ROUNDS} alternating rounds"
    );
    let peer = ensure_prefix().and_then(|p| build(&p));
    if let Err(e) = &peer {
        println!("\nNOTE: Pinocchio peer SKIPPED: {e}\n");
    }
    let mut rows: Vec<(String, &str, f64, f64)> = Vec::new();
    for (name, urdf, locked) in robots {
        let mut options = UrdfOptions::default();
        for j in locked {
            options = options.lock_joint(j, 0.0);
        }
        let model = match load_urdf(testdata.join(urdf), &options) {
            Ok(m) => m,
            Err(e) => {
                eprintln!("{e}");
                return false;
            }
        };
        // Three alternating rounds, the fastest of each side: the machine is shared, and the
        // minimum over rounds is the least disturbed measurement.
        let (mut fk, mut jac) = (f64::INFINITY, f64::INFINITY);
        let mut theirs = (f64::INFINITY, f64::INFINITY);
        let file = Path::new("target/xtask").join(format!("pinocchio_model_{name}.txt"));
        let peer_model = match &peer {
            Ok(_) => model_file(&model, &file),
            Err(e) => Err(e.clone()),
        };
        if let (Ok(_), Err(e)) = (&peer, &peer_model) {
            println!("NOTE: {name}: {e}");
        }
        for _ in 0..ROUNDS {
            fk = fk.min(time_ours(&model, |m, d, q| {
                forward_kinematics(m, d, q);
                d.world_placements[m.njoints() - 1].translation.x
            }));
            jac = jac.min(time_ours(&model, |m, d, q| {
                compute_joint_jacobians(m, d, q);
                d.jacobian.column(m.nv() - 1).v.x
            }));
            let (Ok(bin), Ok(())) = (&peer, &peer_model) else { continue };
            match Command::new(bin).arg(&file).arg(CALLS_PER_BATCH.to_string()).output() {
                Ok(o) if o.status.success() => {
                    for line in String::from_utf8_lossy(&o.stdout).lines() {
                        let ns = field(line, "ns_per_call")
                            .and_then(|v| v.parse::<f64>().ok())
                            .unwrap_or(f64::NAN);
                        match field(line, "kernel").as_deref() {
                            Some("forward_kinematics") => theirs.0 = theirs.0.min(ns),
                            Some("compute_joint_jacobians") => theirs.1 = theirs.1.min(ns),
                            _ => {}
                        }
                    }
                }
                Ok(o) => println!("NOTE: Pinocchio program failed: {}", String::from_utf8_lossy(&o.stderr)),
                Err(e) => println!("NOTE: could not run {}: {e}", bin.display()),
            }
        }
        if !theirs.0.is_finite() {
            theirs = (f64::NAN, f64::NAN);
        }
        rows.push((name.to_string(), "forward_kinematics", fk, theirs.0));
        rows.push((name.to_string(), "compute_joint_jacobians", jac, theirs.1));
    }
    println!(
        "\n| robot | kernel | anim-rigid | Pinocchio | ours / theirs |\n| --- | --- | --- | --- | --- |"
    );
    for (robot, kernel, ours, theirs) in &rows {
        println!("| {robot} | {kernel} | {ours:.1} ns | {theirs:.1} ns | {:.3} |", ours / theirs);
    }
    let dir = Path::new("target/xtask");
    let written = std::fs::create_dir_all(dir).and_then(|_| {
        let mut f = std::fs::File::create(dir.join("peers_rigid.csv"))?;
        writeln!(f, "robot,kernel,ours_ns,pinocchio_ns,ours_over_theirs")?;
        for (robot, kernel, ours, theirs) in &rows {
            writeln!(f, "{robot},{kernel},{ours},{theirs},{}", ours / theirs)?;
        }
        Ok(())
    });
    if let Err(e) = written {
        eprintln!("could not write target/xtask/peers_rigid.csv: {e}");
    }
    true
}
