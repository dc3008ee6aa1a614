//! `cargo xtask bench --peers`, anim-rigid part: forward kinematics and joint Jacobians on the
//! Franka Panda (fingers locked, 7 DoF) and the UR5, and RNEA, CRBA and ABA on the Panda, the UR5,
//! the 32-joint chain of `crates/anim-rigid/testdata/chain32.urdf` and, from the gzip'd
//! example-robot-data URDFs under `testdata/robots`, iCub (32 DoF), TIAGo without hand (12 DoF)
//! and the human model (36 DoF) on fixed bases, ns per call, against Pinocchio's C++ library from
//! the `pin` wheel (header-only, `g++ -O3 -march=native`), measured side by side. ABA is timed in
//! both of our forms too (`aba_local`, `aba_world`, each against Pinocchio's same convention),
//! with the per-round ratio of our two forms.
//!
//! The C++ programs (`xtask/peers/pinocchio/kinematics_bench.cpp`, `dynamics_bench.cpp`) build
//! their Pinocchio model from a text file written here from anim-rigid's model of the same URDF,
//! with the joint types Pinocchio's URDF parser chooses and each body's inertia (the two models
//! agree to 1e-15: `tests/pinocchio.rs`, `tests/pinocchio_dynamics.rs`); the wheel ships no
//! urdfdom headers, so its URDF parser cannot be compiled against. Pinocchio's CRBA and ABA are
//! timed in both of its conventions (LOCAL, its default, and WORLD) and compared with the faster
//! one. Needs Python with `pin==4.1.0` and `cmeel-eigen` (installed with pip when missing) and g++.
//!
//! MuJoCo (its C API from the `mujoco` wheel, [`super::rigid_mujoco`]) is timed in the same
//! rounds on the Panda, the UR5 and the chain, on the same samples: inverse dynamics, the mass
//! matrix, and forward dynamics against our [`forward_dynamics`] (Pinocchio's row for that is its
//! ABA); the closing table gives each against the faster of the two peers.

use crate::python::json_field as field;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use anim_rigid::{
    Axis, Data, JointType, Model, UrdfOptions, aba, aba_local, aba_world, compute_joint_jacobians, crba,
    forward_dynamics, forward_dynamics_cholesky, forward_kinematics, load_urdf, parse_urdf, rnea,
};

/// The timing programs, relative to the xtask crate, and their binaries under `target/xtask`.
const KINEMATICS: (&str, &str) = ("peers/pinocchio/kinematics_bench.cpp", "pinocchio_kinematics_bench");
const DYNAMICS: (&str, &str) = ("peers/pinocchio/dynamics_bench.cpp", "pinocchio_dynamics_bench");
const CALLS_PER_BATCH: usize = 20_000;
const BATCHES: usize = 15;
const CONFIGS: usize = 1024;
const ROUNDS: usize = 5;

/// The `cmeel.prefix` holding Pinocchio's and Eigen's headers, if present.
fn find_prefix() -> Option<PathBuf> {
    let out = Command::new(crate::python::python())
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
    eprintln!(
        "== Pinocchio headers not found: {} -m pip install pin==4.1.0 cmeel-eigen==3.4.1",
        crate::python::python()
    );
    let out = Command::new(crate::python::python())
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

/// Compiles a timing program (cached while the binary is newer than the source).
fn build(prefix: &Path, (source, name): (&str, &str)) -> Result<PathBuf, String> {
    let source = Path::new(env!("CARGO_MANIFEST_DIR")).join(source);
    let dir = Path::new("target/xtask");
    std::fs::create_dir_all(dir).map_err(|e| e.to_string())?;
    let bin = dir.join(name);
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

/// Loads a URDF, gzip'd when its name ends in `.gz`.
fn load(path: &Path, options: &UrdfOptions) -> Result<Model, String> {
    if path.extension().is_some_and(|e| e == "gz") {
        use std::io::Read;
        let mut xml = String::new();
        std::fs::File::open(path)
            .and_then(|f| flate2::read::GzDecoder::new(f).read_to_string(&mut xml))
            .map_err(|e| format!("{}: {e}", path.display()))?;
        parse_urdf(&xml, options).map_err(|e| format!("{}: {e}", path.display()))
    } else {
        load_urdf(path, options).map_err(|e| e.to_string())
    }
}

/// The model as the timing programs read it: one line per joint, with the body's inertia
/// (mass, centre of mass, rotational inertia about it, row-major) after the limits.
fn model_file(model: &Model, path: &Path) -> Result<(), String> {
    let mut s = String::new();
    for (i, j) in model.joints().iter().enumerate().skip(1) {
        let unbounded = anim_rigid::pinocchio::is_unbounded_revolute(j);
        let (code, axis) = match j.kind {
            JointType::Revolute(Axis::X) if unbounded => ("RUBX", Axis::X.vector()),
            JointType::Revolute(Axis::Y) if unbounded => ("RUBY", Axis::Y.vector()),
            JointType::Revolute(Axis::Z) if unbounded => ("RUBZ", Axis::Z.vector()),
            JointType::Revolute(a) if unbounded => ("RUBU", a.vector()),
            JointType::Free => ("FF", Axis::X.vector()),
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
        // The C++ reader takes no `inf`: no limit is written as ±1e300.
        let (lower, upper) = (j.limits.lower.max(-1e300), j.limits.upper.min(1e300));
        s.push_str(&format!(" {:e} {:e} {:e} {lower:e} {upper:e}", t.x, t.y, t.z));
        let inertia = &model.inertias()[i];
        s.push_str(&format!(
            " {:e} {:e} {:e} {:e}",
            inertia.mass, inertia.com.x, inertia.com.y, inertia.com.z
        ));
        for x in inertia.rotational.transpose().to_cols_array() {
            s.push_str(&format!(" {x:e}"));
        }
        s.push('\n');
    }
    std::fs::write(path, s).map_err(|e| e.to_string())
}

/// One pre-generated input of the timed kernels.
pub struct Sample {
    /// Configuration.
    pub q: Vec<f64>,
    /// Velocity.
    pub v: Vec<f64>,
    /// Acceleration (inverse dynamics).
    pub a: Vec<f64>,
    /// Joint forces (forward dynamics).
    pub tau: Vec<f64>,
}

/// The 1024 inputs our kernels (and MuJoCo's) are timed on, the same for every call.
pub fn samples(model: &Model) -> Vec<Sample> {
    let mut state = 42u64;
    let mut uniform = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let nv = model.nv();
    (0..CONFIGS)
        .map(|_| Sample {
            q: anim_rigid::config::random_configuration(model, &mut uniform),
            v: (0..nv).map(|_| 4.0 * uniform() - 2.0).collect(),
            a: (0..nv).map(|_| 6.0 * uniform() - 3.0).collect(),
            tau: (0..nv).map(|_| 20.0 * uniform() - 10.0).collect(),
        })
        .collect()
}

/// Our median ns per call of `f` over pre-generated inputs, the same protocol as the C++
/// programs (batches of calls cycling through 1024 inputs, median of 15 batches).
fn time_ours(model: &Model, samples: &[Sample], mut f: impl FnMut(&Model, &mut Data, &Sample) -> f64) -> f64 {
    let mut data = Data::new(model);
    let mut sink = 0.0;
    let mut times: Vec<f64> = (0..BATCHES)
        .map(|_| {
            let start = Instant::now();
            for i in 0..CALLS_PER_BATCH {
                sink += f(model, &mut data, std::hint::black_box(&samples[i % CONFIGS]));
            }
            start.elapsed().as_secs_f64() * 1e9 / CALLS_PER_BATCH as f64
        })
        .collect();
    std::hint::black_box(sink);
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

/// Runs a peer program on a model file; `(kernel, ns)` pairs, or a note why not.
fn run_peer(bin: &Path, file: &Path) -> Result<Vec<(String, f64)>, String> {
    let o = Command::new(bin)
        .arg(file)
        .arg(CALLS_PER_BATCH.to_string())
        .output()
        .map_err(|e| format!("could not run {}: {e}", bin.display()))?;
    if !o.status.success() {
        return Err(format!("Pinocchio program failed: {}", String::from_utf8_lossy(&o.stderr)));
    }
    Ok(String::from_utf8_lossy(&o.stdout)
        .lines()
        .filter_map(|line| {
            let ns = field(line, "ns_per_call")?.parse::<f64>().ok()?;
            Some((field(line, "kernel")?, ns))
        })
        .collect())
}

/// One row of the table: robot, kernel, ours, Pinocchio (best convention), Pinocchio detail.
type Row = (String, &'static str, f64, f64, String);

/// One row of the MuJoCo table: robot, kernel, ours, MuJoCo, Pinocchio (best convention).
type MujocoRow = (String, &'static str, f64, f64, f64);

/// The robots MuJoCo is compared on.
const MUJOCO_ROBOTS: [&str; 3] = ["panda", "ur5", "chain32"];

/// Writes the URDF MuJoCo loads and the samples file for one robot; their paths.
fn mujoco_inputs(
    name: &str,
    urdf: &Path,
    locked: &[&str],
    model: &Model,
    samples: &[Sample],
) -> Result<(PathBuf, PathBuf, PathBuf), String> {
    let dir = Path::new("target/xtask");
    let xml = super::rigid_mujoco::urdf_for_mujoco(urdf, locked)?;
    let urdf_out = dir.join(format!("mujoco_{name}.urdf"));
    std::fs::write(&urdf_out, xml).map_err(|e| format!("{}: {e}", urdf_out.display()))?;
    let file = dir.join(format!("mujoco_samples_{name}.txt"));
    super::rigid_mujoco::samples_file(model, samples, &file)?;
    let inertias = dir.join(format!("mujoco_inertias_{name}.txt"));
    super::rigid_mujoco::inertia_file(model, &inertias)?;
    Ok((urdf_out, file, inertias))
}

/// Runs the comparison and prints the table; false if our side could not run.
pub fn run() -> bool {
    let testdata = Path::new(env!("CARGO_MANIFEST_DIR")).join("../crates/anim-rigid/testdata");
    // (name, URDF, locked joints, time kinematics, time dynamics)
    let robots: [(&str, &str, &[&str], bool, bool); 6] = [
        ("panda", "panda.urdf", &["panda_finger_joint1", "panda_finger_joint2"], true, true),
        ("ur5", "ur5_robot.urdf", &[], true, true),
        ("chain32", "chain32.urdf", &[], false, true),
        ("icub", "robots/icub_description/robots/icub.urdf.gz", &[], false, true),
        ("tiago_no_hand", "robots/tiago_description/robots/tiago_no_hand.urdf.gz", &[], false, true),
        ("human", "robots/human_description/robots/human.urdf.gz", &[], false, true),
    ];
    println!(
        "\npeer benchmark: anim-rigid vs Pinocchio (C++, header-only, g++ -O3 -march=native), ns per call: median of {BATCHES} batches of {CALLS_PER_BATCH} calls over {CONFIGS} random inputs, best of {ROUNDS} alternating rounds"
    );
    let prefix = ensure_prefix();
    let kin_peer = prefix.clone().and_then(|p| build(&p, KINEMATICS));
    let dyn_peer = prefix.and_then(|p| build(&p, DYNAMICS));
    for peer in [&kin_peer, &dyn_peer] {
        if let Err(e) = peer {
            println!("\nNOTE: Pinocchio peer SKIPPED: {e}\n");
        }
    }
    let mujoco = super::rigid_mujoco::prepare();
    match &mujoco {
        Ok(peer) => println!("MuJoCo {} (C API of the `mujoco` wheel) on panda, ur5, chain32", peer.version),
        Err(e) => println!("\nNOTE: MuJoCo peer SKIPPED: {e}\n"),
    }
    let mut rows: Vec<Row> = Vec::new();
    let mut mujoco_rows: Vec<MujocoRow> = Vec::new();
    // `ANIM_RIGID_ROBOTS=panda,ur5,chain32` measures only those; this run's rows replace all of
    // anim-rigid's in peers.csv, so the other robots' rows are dropped.
    let only = std::env::var("ANIM_RIGID_ROBOTS").ok();
    let wanted = |name: &str| only.as_deref().is_none_or(|list| list.split(',').any(|r| r.trim() == name));
    for (name, urdf, locked, kinematics, dynamics) in robots.into_iter().filter(|r| wanted(r.0)) {
        let mut options = UrdfOptions::default();
        for j in locked {
            options = options.lock_joint(j, 0.0);
        }
        let model = match load(&testdata.join(urdf), &options) {
            Ok(m) => m,
            Err(e) => {
                eprintln!("{e}");
                return false;
            }
        };
        let file = Path::new("target/xtask").join(format!("pinocchio_model_{name}.txt"));
        let peer_model = model_file(&model, &file);
        if let Err(e) = &peer_model {
            println!("NOTE: {name}: {e}");
        }
        let samples = samples(&model);
        // MuJoCo compiles the URDF itself: the arms and the chain, not the collection's robots.
        let mujoco_inputs = match (&mujoco, MUJOCO_ROBOTS.contains(&name)) {
            (Ok(_), true) => mujoco_inputs(name, &testdata.join(urdf), locked, &model, &samples)
                .map_err(|e| println!("NOTE: MuJoCo on {name}: {e}"))
                .ok(),
            _ => None,
        };
        let mut mujoco_best: std::collections::BTreeMap<String, f64> = std::collections::BTreeMap::new();
        let mut agreement = [0.0f64; 3];
        let mut ours_fd_cholesky = f64::INFINITY;
        let mut ours_fd = f64::INFINITY;
        // Three alternating rounds, the fastest of each side: the machine is shared, and the
        // minimum over rounds is the least disturbed measurement.
        let mut ours = [f64::INFINITY; 7];
        // Per round: our aba_local / aba_world, measured back to back.
        let mut local_over_world = Vec::new();
        let mut theirs: std::collections::BTreeMap<String, f64> = std::collections::BTreeMap::new();
        for _ in 0..ROUNDS {
            if kinematics {
                ours[0] = ours[0].min(time_ours(&model, &samples, |m, d, s| {
                    forward_kinematics(m, d, &s.q);
                    d.world_placements[m.njoints() - 1].translation.x
                }));
                ours[1] = ours[1].min(time_ours(&model, &samples, |m, d, s| {
                    compute_joint_jacobians(m, d, &s.q);
                    d.jacobian.column(m.nv() - 1).v.x
                }));
            }
            if dynamics {
                ours[2] = ours[2]
                    .min(time_ours(&model, &samples, |m, d, s| rnea(m, d, &s.q, &s.v, &s.a)[m.nv() - 1]));
                ours[3] =
                    ours[3].min(time_ours(&model, &samples, |m, d, s| crba(m, d, &s.q)[(0, m.nv() - 1)]));
                ours[4] = ours[4]
                    .min(time_ours(&model, &samples, |m, d, s| aba(m, d, &s.q, &s.v, &s.tau)[m.nv() - 1]));
                let local =
                    time_ours(&model, &samples, |m, d, s| aba_local(m, d, &s.q, &s.v, &s.tau)[m.nv() - 1]);
                let world =
                    time_ours(&model, &samples, |m, d, s| aba_world(m, d, &s.q, &s.v, &s.tau)[m.nv() - 1]);
                ours[5] = ours[5].min(local);
                ours[6] = ours[6].min(world);
                local_over_world.push(local / world);
                ours_fd_cholesky = ours_fd_cholesky.min(time_ours(&model, &samples, |m, d, s| {
                    forward_dynamics_cholesky(m, d, &s.q, &s.v, &s.tau).map_or(f64::NAN, |x| x[m.nv() - 1])
                }));
                ours_fd = ours_fd.min(time_ours(&model, &samples, |m, d, s| {
                    forward_dynamics(m, d, &s.q, &s.v, &s.tau)[m.nv() - 1]
                }));
            }
            if let (Ok(peer), Some((urdf, file, inertias))) = (&mujoco, &mujoco_inputs) {
                match super::rigid_mujoco::run(peer, urdf, file, inertias, CALLS_PER_BATCH) {
                    Ok(run) => {
                        for (a, b) in agreement.iter_mut().zip(run.agreement) {
                            *a = a.max(b);
                        }
                        for (kernel, ns) in run.times {
                            let e = mujoco_best.entry(kernel).or_insert(f64::INFINITY);
                            *e = e.min(ns);
                        }
                    }
                    Err(e) => println!("NOTE: MuJoCo on {name}: {e}"),
                }
            }
            if peer_model.is_err() {
                continue;
            }
            let peers = [(kinematics, &kin_peer), (dynamics, &dyn_peer)];
            for (wanted, peer) in peers {
                let (true, Ok(bin)) = (wanted, peer) else { continue };
                match run_peer(bin, &file) {
                    Ok(pairs) => {
                        for (kernel, ns) in pairs {
                            let e = theirs.entry(kernel).or_insert(f64::INFINITY);
                            *e = e.min(ns);
                        }
                    }
                    Err(e) => println!("NOTE: {e}"),
                }
            }
        }
        let get = |k: &str| theirs.get(k).copied().unwrap_or(f64::NAN);
        if kinematics {
            rows.push((
                name.to_string(),
                "forward_kinematics",
                ours[0],
                get("forward_kinematics"),
                String::new(),
            ));
            rows.push((
                name.to_string(),
                "compute_joint_jacobians",
                ours[1],
                get("compute_joint_jacobians"),
                String::new(),
            ));
        }
        if dynamics {
            rows.push((name.to_string(), "rnea", ours[2], get("rnea"), String::new()));
            for (k, kernel) in [(3, "crba"), (4, "aba")] {
                let (local, world) = (get(&format!("{kernel}_local")), get(&format!("{kernel}_world")));
                let detail = format!("LOCAL {local:.1} ns, WORLD {world:.1} ns");
                rows.push((name.to_string(), kernel, ours[k], local.min(world), detail));
            }
            for (k, kernel, convention) in [(5, "aba_local", "aba_local"), (6, "aba_world", "aba_world")] {
                rows.push((name.to_string(), kernel, ours[k], get(convention), "same convention".into()));
            }
            if !mujoco_best.is_empty() {
                let m = |k: &str| mujoco_best.get(k).copied().unwrap_or(f64::NAN);
                println!(
                    "{name}: MuJoCo against anim-rigid on {CONFIGS} samples, largest difference relative to the largest entry: inverse dynamics {:.1e}, mass matrix {:.1e}, forward dynamics {:.1e}",
                    agreement[0], agreement[1], agreement[2]
                );
                // Pinocchio's faster convention where it has two.
                let best = |k: &str| get(&format!("{k}_local")).min(get(&format!("{k}_world")));
                mujoco_rows.push((name.to_string(), "rnea", ours[2], m("rnea"), get("rnea")));
                mujoco_rows.push((name.to_string(), "crba", ours[3], m("crba"), best("crba")));
                // Our forward dynamics as a user calls it, against MuJoCo's pipeline and
                // Pinocchio's ABA (its faster convention).
                mujoco_rows.push((
                    name.to_string(),
                    "forward_dynamics",
                    ours_fd,
                    m("forward_dynamics"),
                    best("aba"),
                ));
                println!(
                    "{name}: ours forward dynamics: forward_dynamics {ours_fd:.1} ns, CRBA + LDLT {ours_fd_cholesky:.1} ns, ABA {:.1} ns",
                    ours[4]
                );
            }
            local_over_world.sort_by(f64::total_cmp);
            if let (Some(lo), Some(hi)) = (local_over_world.first(), local_over_world.last()) {
                println!(
                    "{name}: ours aba_local / aba_world per round: median {:.3}, range {lo:.3}-{hi:.3} ({} rounds)",
                    local_over_world[local_over_world.len() / 2],
                    local_over_world.len()
                );
            }
        }
    }
    println!(
        "\n| robot | kernel | anim-rigid | Pinocchio | ours / theirs | Pinocchio by convention |\n| --- | --- | --- | --- | --- | --- |"
    );
    for (robot, kernel, ours, theirs, detail) in &rows {
        println!("| {robot} | {kernel} | {ours:.1} ns | {theirs:.1} ns | {:.3} | {detail} |", ours / theirs);
        super::ratios::record(
            "anim-rigid",
            &format!("{robot} {kernel}"),
            "Pinocchio",
            1,
            ours * 1e-9,
            theirs * 1e-9,
        );
    }
    if let (Ok(peer), false) = (&mujoco, mujoco_rows.is_empty()) {
        let label = format!("MuJoCo {}", peer.version);
        println!(
            "\n| robot | kernel | anim-rigid | {label} | ours / MuJoCo | ours / best of MuJoCo and Pinocchio |\n| --- | --- | --- | --- | --- | --- |"
        );
        for (robot, kernel, ours, theirs, pinocchio) in &mujoco_rows {
            println!(
                "| {robot} | {kernel} | {ours:.1} ns | {theirs:.1} ns | {:.3} | {:.3} |",
                ours / theirs,
                ours / theirs.min(*pinocchio)
            );
            super::ratios::record(
                "anim-rigid",
                &format!("{robot} {kernel}"),
                &label,
                1,
                ours * 1e-9,
                theirs * 1e-9,
            );
        }
    }
    let dir = Path::new("target/xtask");
    let written = std::fs::create_dir_all(dir).and_then(|_| {
        let mut f = std::fs::File::create(dir.join("peers_rigid.csv"))?;
        writeln!(f, "robot,kernel,ours_ns,pinocchio_ns,ours_over_theirs")?;
        for (robot, kernel, ours, theirs, _) in &rows {
            writeln!(f, "{robot},{kernel},{ours},{theirs},{}", ours / theirs)?;
        }
        Ok(())
    });
    if let Err(e) = written {
        eprintln!("could not write target/xtask/peers_rigid.csv: {e}");
    }
    true
}
