//! Twists the built-in cylinder and prints its volume under LBS and DQS over time; with a path
//! argument, loads that skinned glTF instead and prints its bounding box over its first clip.
//!
//! `cargo run --release -p anim-skin --example candy_wrapper [FILE.gltf|FILE.glb]`

use anim_skin::{SkinningMethod, scenes};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    if let Some(path) = std::env::args().nth(1) {
        let scene = scenes::from_gltf(&path)?;
        for w in &scene.warnings {
            eprintln!("warning: {w}");
        }
        let mut data = scene.data();
        let mut p = Vec::new();
        for f in 0..=10 {
            let t = scene.duration * f as f64 / 10.0;
            scene.pose(&mut data, t, SkinningMethod::Lbs)?;
            data.positions(&mut p);
            let (lo, hi) = p.iter().fold(([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]), |(lo, hi), q| {
                (std::array::from_fn(|d| lo[d].min(q[d])), std::array::from_fn(|d| hi[d].max(q[d])))
            });
            println!("t = {t:.2}: {} vertices in {lo:.3?} .. {hi:.3?}", p.len());
        }
        return Ok(());
    }
    let scene = scenes::twisted_cylinder(None)?;
    let rest = scene.rest_volume();
    let mut data = scene.data();
    println!("twist (deg)  LBS volume  DQS volume  (rest {rest:.5})");
    for f in 0..=8 {
        let t = scene.duration * f as f64 / 8.0;
        scene.pose(&mut data, t, SkinningMethod::Lbs)?;
        let lbs = scenes::volume(&scene.character, &data);
        scene.pose(&mut data, t, SkinningMethod::Dqs)?;
        let dqs = scenes::volume(&scene.character, &data);
        println!("{:>11.1}  {:>9.1} %  {:>9.1} %", 90.0 * t, 100.0 * lbs / rest, 100.0 * dqs / rest);
    }
    Ok(())
}
