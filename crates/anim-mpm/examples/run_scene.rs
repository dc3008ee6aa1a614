//! Runs a built-in scene: `cargo run --release -p anim-mpm --example run_scene -- NAME [STEPS]
//! [RESOLUTION]`, printing time, substeps, energy and the particle bounding box every tenth of the
//! run.

use anim_mpm::scenes;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let name = args.first().map_or("three-materials", String::as_str);
    let mut scene =
        scenes::by_name(name, args.get(2).and_then(|r| r.parse().ok())).ok_or("unknown scene")??;
    let steps = args.get(1).and_then(|s| s.parse().ok()).unwrap_or_else(|| scene.steps());
    println!("{}: {} particles, {steps} steps of {} s", scene.description(), scene.len(), scene.dt());
    let start = std::time::Instant::now();
    for s in 1..=steps {
        let r = scene.step()?;
        if s % (steps / 10).max(1) == 0 {
            let pos = scene.positions();
            let lo = pos.iter().fold([f32::MAX; 3], |a, p| [a[0].min(p[0]), a[1].min(p[1]), a[2].min(p[2])]);
            let hi = pos.iter().fold([f32::MIN; 3], |a, p| [a[0].max(p[0]), a[1].max(p[1]), a[2].max(p[2])]);
            println!(
                "t = {:.3} s, substeps {}, energy {:.4e}, box {lo:.3?} .. {hi:.3?}",
                r.time,
                r.iterations,
                r.energy.unwrap_or(f64::NAN)
            );
        }
    }
    println!("wall time {:.2} s", start.elapsed().as_secs_f64());
    Ok(())
}
