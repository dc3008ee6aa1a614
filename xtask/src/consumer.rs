//! `cargo xtask consumer`: the workspace's crates as a Rust developer outside it picks them.
//!
//! Writes a fresh Cargo project under `target/xtask/consumer/` (its own `[workspace]`, so none
//! of this workspace's settings or lockfile apply) that depends on anim-pbd and anim-rigid by
//! path, **default features off**, and on glam by its own `glam = "0.34"` requirement. Its
//! lockfile is resolved from scratch, so the newest versions the crates' ranges allow are the
//! ones built. The program drops a cloth on a sphere and loads a two-link robot from URDF text,
//! passing the consumer's own `glam::DVec3` values in (gravity, a target) and reading
//! anim-rigid's out into the consumer's `glam::DVec3` (which compiles only if the two glam
//! versions unify), and checks both against closed forms. It is built and run twice: with the
//! crates' default features off, then with anim-pbd's `parallel` on; the two runs must print the
//! same cloth, bit for bit. With the crates' default features off the consumer's dependency
//! tree (`cargo tree`) must hold no serde crate at all: scene files and checkpoints are the
//! crates' `serde` feature, and a user who steps a cloth or a robot does not build them.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

const MAIN: &str = r##"//! A consumer of anim-pbd and anim-rigid, outside their workspace.
use glam::DVec3;

const URDF: &str = r#"<robot name="two-link">
  <link name="base"/>
  <link name="upper"><inertial><mass value="1"/><origin xyz="0.5 0 0"/>
    <inertia ixx="0.01" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="lower"><inertial><mass value="1"/><origin xyz="0.4 0 0"/>
    <inertia ixx="0.01" iyy="0.08" izz="0.08" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="10" velocity="5"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="lower"/>
    <origin xyz="1 0 0"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="10" velocity="5"/></joint>
</robot>"#;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // The cloth: 20 x 20, inextensible, dropped on a sphere; gravity is the consumer's DVec3.
    use anim_pbd::{Bending, Cloth, Solver, Collider, ConstraintParams, Method, PbdBuilder, PbdParams, PbdSimulation, SolverKind};
    let gravity = DVec3::new(0.0, 0.0, -9.81);
    let mut b = PbdBuilder::new();
    b.gravity(gravity.to_array());
    b.cloth(&Cloth {
        nx: 20,
        ny: 20,
        origin: [-0.5, -0.5, 1.0],
        u: [1.0, 0.0, 0.0],
        v: [0.0, 1.0, 0.0],
        particle_mass: 1e-3,
        stretch: ConstraintParams::rigid(),
        bending: Bending::Isometric(ConstraintParams::with_compliance(10.0)),
    })?;
    b.collider(Collider::sphere([0.0, 0.0, 0.5], 0.3).with_thickness(0.01).with_friction(0.5, 0.3));
    let model = b.build()?;
    let mut state = model.rest_state();
    let mut sim = PbdSimulation::new(model, PbdParams::new(Method::Xpbd, SolverKind::ColoredGaussSeidel, 5, 2))?;
    for _ in 0..60 {
        sim.step(&mut state, 1.0 / 60.0)?;
    }
    let c = 3 * (10 * 20 + 10);
    let centre = DVec3::from_slice(&state.x[c..c + 3]);
    // At rest on the sphere: its top (0.8) plus the contact thickness.
    if (centre.z - 0.81).abs() > 0.02 {
        return Err(format!("cloth centre at z = {}, expected 0.81 +- 0.02", centre.z).into());
    }
    let bits: u64 = state.x.iter().fold(0u64, |h, v| h.rotate_left(5) ^ v.to_bits());
    println!("cloth: centre {centre:.4}, state hash {bits:016x}");

    // The robot: forward kinematics read into the consumer's DVec3.
    let robot = anim_rigid::parse_urdf(URDF, &anim_rigid::UrdfOptions::default())?;
    let mut data = anim_rigid::Data::new(&robot);
    let q = [0.5, -0.3];
    anim_rigid::forward_kinematics(&robot, &mut data, &q);
    let elbow: DVec3 = data.world_placements[2].translation;
    // Both joints turn about +y: the arm moves in the vertical x-z plane.
    let expected = DVec3::new(q[0].cos(), 0.0, -q[0].sin());
    if (elbow - expected).length() > 1e-14 {
        return Err(format!("elbow at {elbow}, expected {expected}").into());
    }
    let mut robot = robot;
    robot.set_gravity(gravity);
    let tau = anim_rigid::gravity_torques(&robot, &mut data, &q).to_vec();
    // g(q) = dV/dq with V = 9.81 (z_upper + z_lower), z_upper = -0.5 sin q0,
    // z_lower = -(sin q0 + 0.4 sin(q0 + q1)) (unit masses).
    let g = 9.81;
    let closed = [
        -g * (1.5 * q[0].cos() + 0.4 * (q[0] + q[1]).cos()),
        -g * 0.4 * (q[0] + q[1]).cos(),
    ];
    if tau.iter().zip(&closed).any(|(a, b)| (a - b).abs() > 1e-12) {
        return Err(format!("gravity torques {tau:?}, closed form {closed:?}").into());
    }
    println!("robot: elbow at {elbow:.6}, gravity torques {tau:?}");
    Ok(())
}
"##;

fn manifest(root: &Path) -> String {
    let path = |c: &str| root.join("crates").join(c).display().to_string().replace('\\', "/");
    format!(
        r#"[package]
name = "anim-consumer-check"
version = "0.0.0"
edition = "2024"
publish = false

# A project of its own: none of the anim workspace's settings apply.
[workspace]

[dependencies]
anim-pbd = {{ path = "{}", default-features = false }}
anim-rigid = {{ path = "{}", default-features = false }}
glam = "0.34"

[features]
parallel = ["anim-pbd/parallel"]
"#,
        path("anim-pbd"),
        path("anim-rigid")
    )
}

/// Builds and runs the consumer with `args` added to `cargo run`; returns its standard output.
fn run(dir: &Path, target: &Path, extra: &[&str]) -> Result<String, String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let start = Instant::now();
    let out = Command::new(cargo)
        .args(["run", "--quiet", "--manifest-path"])
        .arg(dir.join("Cargo.toml"))
        .args(extra)
        .env("CARGO_TARGET_DIR", target)
        .env_remove("RUSTFLAGS")
        .output()
        .map_err(|e| format!("could not run cargo: {e}"))?;
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    if !out.status.success() {
        return Err(format!(
            "`cargo run {}` failed:\n{}{}",
            extra.join(" "),
            stdout,
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    eprintln!(
        "  cargo run {} ({:.0} s):\n{}",
        extra.join(" "),
        start.elapsed().as_secs_f64(),
        stdout.trim_end()
    );
    Ok(stdout)
}

/// The serde crates that must stay out of a consumer with the crates' default features off.
const SERDE_CRATES: [&str; 5] = ["serde", "serde_core", "serde_derive", "serde_json", "serde_path_to_error"];

/// Checks with `cargo tree` that the consumer, with the features `extra` asks for, builds no
/// serde crate.
fn serde_free(dir: &Path, target: &Path, extra: &[&str]) -> Result<(), String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = Command::new(cargo)
        .args(["tree", "--quiet", "-e", "normal", "--prefix", "none", "--manifest-path"])
        .arg(dir.join("Cargo.toml"))
        .args(extra)
        .env("CARGO_TARGET_DIR", target)
        .output()
        .map_err(|e| format!("could not run cargo tree: {e}"))?;
    let tree = String::from_utf8_lossy(&out.stdout);
    if !out.status.success() || tree.trim().is_empty() {
        return Err(format!(
            "`cargo tree {}` failed:\n{}",
            extra.join(" "),
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    let mut serde: Vec<&str> = tree
        .lines()
        .filter(|l| l.split_whitespace().next().is_some_and(|name| SERDE_CRATES.contains(&name)))
        .collect();
    serde.sort_unstable();
    serde.dedup();
    if serde.is_empty() {
        eprintln!(
            "  {}: no serde crate",
            ["cargo tree"].iter().chain(extra).copied().collect::<Vec<_>>().join(" ")
        );
        Ok(())
    } else {
        Err(format!(
            "with the crates' default features off the consumer builds serde crates ({}): a dependency \
             asks for serde outside a `serde` feature",
            serde.join(", ")
        ))
    }
}

/// The versions the consumer's fresh lockfile chose for a few of the crates' dependencies.
fn resolved(dir: &Path) -> String {
    let lock = std::fs::read_to_string(dir.join("Cargo.lock")).unwrap_or_default();
    let mut found = Vec::new();
    let mut name = None;
    for line in lock.lines() {
        if let Some(n) = line.strip_prefix("name = ") {
            name = Some(n.trim_matches('"').to_string());
        } else if let (Some(v), Some(n)) = (line.strip_prefix("version = "), name.take())
            && ["glam", "thiserror", "roxmltree", "rayon"].contains(&n.as_str())
        {
            found.push(format!("{n} {}", v.trim_matches('"')));
        }
    }
    found.join(", ")
}

fn check(root: &Path) -> Result<(), String> {
    let dir: PathBuf = root.join("target/xtask/consumer");
    let src = dir.join("src");
    std::fs::create_dir_all(&src).map_err(|e| format!("{}: {e}", src.display()))?;
    std::fs::write(dir.join("Cargo.toml"), manifest(root)).map_err(|e| e.to_string())?;
    std::fs::write(src.join("main.rs"), MAIN).map_err(|e| e.to_string())?;
    // Resolved afresh every time: the newest versions the ranges allow.
    let _ = std::fs::remove_file(dir.join("Cargo.lock"));
    let target = root.join("target/xtask/consumer-target");
    let sequential = run(&dir, &target, &[])?;
    eprintln!("  resolved: {}", resolved(&dir));
    serde_free(&dir, &target, &[])?;
    let parallel = run(&dir, &target, &["--features", "parallel"])?;
    serde_free(&dir, &target, &["--features", "parallel"])?;
    let cloth = |s: &str| s.lines().find(|l| l.starts_with("cloth:")).unwrap_or("").to_string();
    if cloth(&sequential) != cloth(&parallel) {
        return Err(format!(
            "the cloth differs with anim-pbd's `parallel` feature:\n  {}\n  {}",
            cloth(&sequential),
            cloth(&parallel)
        ));
    }
    Ok(())
}

/// Runs the consumer check; `true` when it passed.
pub fn run_check() -> bool {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap_or(Path::new(".")).to_path_buf();
    eprintln!("== consumer: anim-pbd and anim-rigid by path, default features off (no serde), own glam 0.34");
    match check(&root) {
        Ok(()) => {
            eprintln!("== consumer: passed");
            true
        }
        Err(e) => {
            eprintln!("== consumer: FAILED: {e}");
            false
        }
    }
}
