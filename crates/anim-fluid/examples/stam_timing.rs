//! Per-step time of Stam's solver (and of the copy its failure guard makes each step): `cargo run --release -p anim-fluid --example stam_timing -- N STEPS`.

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).map_or(Ok(128), |s| s.parse())?;
    let steps: usize = args.get(2).map_or(Ok(50), |s| s.parse())?;
    let mut f = anim_fluid::stam::StamFluid::new(n, anim_fluid::stam::StamParams::default())?;
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
    // What the step's failure guard adds: copying the six (N+2)^2 arrays aside.
    let size = (n + 2) * (n + 2);
    let from: Vec<Vec<f32>> = (0..6).map(|k| vec![k as f32; size]).collect();
    let mut to: Vec<Vec<f32>> = (0..6).map(|_| vec![0.0; size]).collect();
    let t = std::time::Instant::now();
    for _ in 0..steps {
        for (a, b) in to.iter_mut().zip(&from) {
            a.copy_from_slice(std::hint::black_box(b));
        }
        std::hint::black_box(&to);
    }
    let guard = t.elapsed().as_secs_f64() / steps as f64;
    println!("{{\"n\":{n},\"steps\":{steps},\"per_step_s\":{per:.6},\"guard_copy_s\":{guard:.7}}}");
    Ok(())
}
