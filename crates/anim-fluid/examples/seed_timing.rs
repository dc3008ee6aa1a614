//! Per-step time of the seed mode: `cargo run --release -p anim-fluid --example seed_timing -- N STEPS`.

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).map_or(Ok(128), |s| s.parse())?;
    let steps: usize = args.get(2).map_or(Ok(50), |s| s.parse())?;
    let mut f = anim_fluid::seed::SeedFluid::new(n, anim_fluid::seed::SeedParams::default())?;
    for _ in 0..5 {
        f.apply_source_pattern();
        f.step()?;
    }
    let t = std::time::Instant::now();
    for _ in 0..steps {
        f.apply_source_pattern();
        f.step()?;
    }
    let per = t.elapsed().as_secs_f64() / steps as f64;
    println!("{{\"n\":{n},\"steps\":{steps},\"per_step_s\":{per:.6}}}");
    Ok(())
}
