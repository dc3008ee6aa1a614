//! Thread scaling of each parallel solver family: a fixed scene of each crate (through its
//! public scene presets) stepped on rayon pools of 1, 2, ... threads; time per step, speed-up
//! over one thread, and whether the state after the first steps is bit for bit the one-thread
//! state (it must be: results do not depend on the thread count).

use std::fmt::Write as _;
use std::time::Instant;

/// A scene being stepped.
trait Stepper {
    fn step(&mut self) -> Result<(), String>;
    /// A hash of the state's bits.
    fn fingerprint(&self) -> u64;
}

fn hash_f64(values: impl IntoIterator<Item = f64>) -> u64 {
    // FNV-1a over the bit patterns.
    values.into_iter().fold(0xcbf2_9ce4_8422_2325, |h, v| (h ^ v.to_bits()).wrapping_mul(0x100_0000_01b3))
}

struct Springs(anim_springs::SpringSimulation, anim_core::integrate::State, f64);
impl Stepper for Springs {
    fn step(&mut self) -> Result<(), String> {
        use anim_core::solver::Solver;
        self.0.step(&mut self.1, self.2).map(drop).map_err(|e| e.to_string())
    }
    fn fingerprint(&self) -> u64 {
        hash_f64(self.1.x.iter().chain(&self.1.v).copied())
    }
}

/// A PBD scene stepped within its duration: the benchmark cloth's few Gauss-Seidel iterations
/// do not carry the pins' support across 100^2 particles, so the cloth falls nearly freely and
/// the constraints at the pins pass the divergence guard's 100x stretch after about 62 steps
/// (1 s), before the preset's nominal 100-step duration. The timing loop (2 s per thread count
/// in full mode, about 180 steps) therefore restarts the scene from its initial state every
/// `max_steps` steps: 30 (0.5 s) for the benchmark cloth, whose peer bench runs 15 at 100^2.
struct Pbd {
    sim: anim_pbd::PbdSimulation,
    state: anim_core::integrate::State,
    dt: f64,
    start: anim_core::integrate::State,
    steps: usize,
    max_steps: usize,
}
impl Stepper for Pbd {
    fn step(&mut self) -> Result<(), String> {
        use anim_core::solver::Solver;
        if self.steps == self.max_steps {
            self.state.clone_from(&self.start);
            self.steps = 0;
        }
        self.steps += 1;
        self.sim.step(&mut self.state, self.dt).map(drop).map_err(|e| e.to_string())
    }
    fn fingerprint(&self) -> u64 {
        hash_f64(self.state.x.iter().chain(&self.state.v).copied())
    }
}

struct Fem(anim_fem::sim::FemSimulation, anim_core::integrate::State, f64);
impl Stepper for Fem {
    fn step(&mut self) -> Result<(), String> {
        use anim_core::solver::Solver;
        self.0.step(&mut self.1, self.2).map(drop).map_err(|e| e.to_string())
    }
    fn fingerprint(&self) -> u64 {
        hash_f64(self.1.x.iter().chain(&self.1.v).copied())
    }
}

struct Mpm(anim_mpm::scenes::Scene<2>);
impl Stepper for Mpm {
    fn step(&mut self) -> Result<(), String> {
        use anim_core::solver::Solver;
        let s = &mut self.0;
        s.sim.step(&mut s.state, s.dt).map(drop).map_err(|e| e.to_string())
    }
    fn fingerprint(&self) -> u64 {
        hash_f64(self.0.state.x.iter().chain(&self.0.state.v).map(|&v| f64::from(v)))
    }
}

struct Fluid(anim_fluid::scenes::FluidScene, Vec<f64>);
impl Stepper for Fluid {
    fn step(&mut self) -> Result<(), String> {
        let dt = self.0.dt;
        self.0.step_by(dt).map(drop).map_err(|e| e.to_string())
    }
    fn fingerprint(&self) -> u64 {
        let mut d = self.1.clone();
        self.0.density_into(&mut d);
        let mut v = Vec::new();
        self.0.velocity_into(&mut v);
        hash_f64(d.into_iter().chain(v))
    }
}

struct Flip(anim_flip::FlipSimulation<2>, anim_flip::Particles<2>);
impl Stepper for Flip {
    fn step(&mut self) -> Result<(), String> {
        self.0.advance(&mut self.1, 2e-3).map(drop).map_err(|e| e.to_string())
    }
    fn fingerprint(&self) -> u64 {
        hash_f64(self.1.x.iter().chain(&self.1.v).flatten().copied())
    }
}

struct Skin(anim_skin::scenes::SkinScene, anim_skin::CharacterData, f64, Vec<[f64; 3]>);
impl Stepper for Skin {
    fn step(&mut self) -> Result<(), String> {
        self.2 += 0.02;
        self.0.pose(&mut self.1, self.2, anim_skin::SkinningMethod::Dqs).map_err(|e| e.to_string())
    }
    fn fingerprint(&self) -> u64 {
        let mut p = self.3.clone();
        self.1.positions(&mut p);
        hash_f64(p.into_iter().flatten())
    }
}

type Make = fn(bool) -> Result<Box<dyn Stepper>, String>;

/// `(crate, scene described, builder)`; the builder takes `quick`.
fn families() -> Vec<(&'static str, &'static str, Make)> {
    vec![
        ("anim-springs", "benchmark cloth 96^2 (quick) / 128^2, symplectic Euler", |quick| {
            let s = anim_springs::scenes::benchmark_cloth(if quick { 96 } else { 128 })
                .map_err(|e| e.to_string())?;
            let dt = s.dt;
            let (sim, state) = s.into_simulation().map_err(|e| e.to_string())?;
            Ok(Box::new(Springs(sim, state, dt)))
        }),
        ("anim-springs", "hanging cloth 32^2 (quick) / 48^2, backward Euler + Cholesky", |quick| {
            let s = anim_springs::scenes::hanging_cloth(Some(if quick { 32 } else { 48 }))
                .map_err(|e| e.to_string())?;
            let dt = s.dt;
            let (sim, state) = s.into_simulation().map_err(|e| e.to_string())?;
            Ok(Box::new(Springs(sim, state, dt)))
        }),
        ("anim-pbd", "benchmark cloth 100^2, XPBD, the preset's solver", |_quick| {
            let s = match anim_pbd::scenes::by_name("benchmark-cloth", Some(100)) {
                Some(r) => r.map_err(|e| e.to_string())?,
                None => return Err("no benchmark-cloth preset".into()),
            };
            let dt = s.dt;
            let (sim, state) = s.into_simulation().map_err(|e| e.to_string())?;
            Ok(Box::new(Pbd { sim, start: state.clone(), state, dt, steps: 0, max_steps: 30 }))
        }),
        ("anim-fem", "cantilever beam, resolution 6 (quick) / 8, backward Euler", |quick| {
            let s = match anim_fem::scenes::by_name("cantilever-beam", Some(if quick { 6 } else { 8 })) {
                Some(r) => r.map_err(|e| e.to_string())?,
                None => return Err("no cantilever-beam preset".into()),
            };
            let dt = s.dt;
            let (sim, state) = s.into_simulation().map_err(|e| e.to_string())?;
            Ok(Box::new(Fem(sim, state, dt)))
        }),
        ("anim-mpm", "2D MLS-MPM benchmark, 128^2 (quick) / 256^2 grid", |quick| {
            match anim_mpm::scenes::by_name("benchmark-2d", Some(if quick { 128 } else { 256 })) {
                Some(Ok(anim_mpm::scenes::MpmScene::Two(s))) => Ok(Box::new(Mpm(s))),
                Some(Ok(_)) => Err("benchmark-2d is not 2D".into()),
                Some(Err(e)) => Err(e.to_string()),
                None => Err("no benchmark-2d preset".into()),
            }
        }),
        ("anim-fluid", "3D smoke plume 32^3 (quick) / 48^3, MacCormack + MGPCG", |quick| {
            match anim_fluid::scenes::by_name("smoke-plume-3d", Some(if quick { 32 } else { 48 })) {
                Some(Ok(s)) => Ok(Box::new(Fluid(s, Vec::new()))),
                Some(Err(e)) => Err(e.to_string()),
                None => Err("no smoke-plume-3d preset".into()),
            }
        }),
        ("anim-flip", "2D dam break 64 (quick) / 128 cells across, APIC, dt = 2 ms", |quick| {
            let (sim, p, _) = anim_flip::scenes::dam_break(
                if quick { 64 } else { 128 },
                0.2,
                anim_flip::FlipParams::default(),
            )
            .map_err(|e| e.to_string())?;
            Ok(Box::new(Flip(sim, p)))
        }),
        ("anim-skin", "twisted cylinder, 2048 (quick) / 4096 segments, DQS", |quick| {
            let s = anim_skin::scenes::twisted_cylinder(Some(if quick { 2048 } else { 4096 }))
                .map_err(|e| e.to_string())?;
            let data = s.data();
            Ok(Box::new(Skin(s, data, 0.0, Vec::new())))
        }),
    ]
}

/// One measured row.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Row {
    pub krate: String,
    pub scene: String,
    pub threads: usize,
    /// Seconds per step (NaN when the run failed).
    #[serde(with = "anim_core::cases::float")]
    pub seconds: f64,
    /// Speed-up over the one-thread run of the same scene.
    #[serde(with = "anim_core::cases::float")]
    pub speedup: f64,
    /// Whether the state after the first steps equals the one-thread state bit for bit.
    pub identical: Option<bool>,
    /// An error, if the scene failed.
    pub note: String,
}

/// The 1-minute load average (`/proc/loadavg`), if known: other processes on the same cores
/// take time from the threads being measured.
pub fn load_average() -> Option<f64> {
    std::fs::read_to_string("/proc/loadavg").ok()?.split_whitespace().next()?.parse().ok()
}

/// Steps compared for determinism before the timing starts.
const CHECK_STEPS: usize = 3;

/// (seconds per step, fingerprint after `CHECK_STEPS` steps) on a pool of `threads` threads.
fn measure(make: Make, quick: bool, threads: usize) -> Result<(f64, u64), String> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().map_err(|e| e.to_string())?;
    pool.install(|| {
        let mut s = make(quick)?;
        for _ in 0..CHECK_STEPS {
            s.step()?;
        }
        let fingerprint = s.fingerprint();
        let budget = if quick { 0.25 } else { 2.0 };
        let mut batches = Vec::new();
        for _ in 0..3 {
            let start = Instant::now();
            let mut n = 0usize;
            while n < 2 || start.elapsed().as_secs_f64() < budget / 3.0 {
                s.step()?;
                n += 1;
            }
            batches.push(start.elapsed().as_secs_f64() / n as f64);
        }
        batches.sort_by(f64::total_cmp);
        Ok((batches[1], fingerprint))
    })
}

/// `(crate, scene)` of every family, in report order.
pub fn family_names() -> Vec<(&'static str, &'static str)> {
    families().into_iter().map(|(k, s, _)| (k, s)).collect()
}

/// Times family `index` (of [`family_names`]) at each of `threads`.
pub fn run_family(index: usize, quick: bool, threads: &[usize]) -> Vec<Row> {
    let Some(&(krate, scene, make)) = families().get(index) else { return Vec::new() };
    let mut rows = Vec::new();
    let t0 = Instant::now();
    let mut base: Option<(f64, u64)> = None;
    for &t in threads {
        let row = match measure(make, quick, t) {
            Ok((seconds, fp)) => {
                let b = *base.get_or_insert((seconds, fp));
                Row {
                    krate: krate.into(),
                    scene: scene.into(),
                    threads: t,
                    seconds,
                    speedup: b.0 / seconds,
                    identical: Some(b.1 == fp),
                    note: String::new(),
                }
            }
            Err(e) => Row {
                krate: krate.into(),
                scene: scene.into(),
                threads: t,
                seconds: f64::NAN,
                speedup: f64::NAN,
                identical: None,
                note: e,
            },
        };
        rows.push(row);
    }
    eprintln!("  scaling {krate:<13} {:>6.1} s", t0.elapsed().as_secs_f64());
    rows
}

/// The rows as a Markdown table.
pub fn markdown(rows: &[Row]) -> String {
    let mut s = String::from(
        "| crate | scene | threads | time / step | speed-up over 1 thread | same bits as 1 thread |\n\
         | --- | --- | --- | --- | --- | --- |\n",
    );
    for r in rows {
        let same = match r.identical {
            Some(true) => "yes".to_string(),
            Some(false) => "**no**".to_string(),
            None => format!("failed: {}", r.note.replace('|', "/")),
        };
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {:.2} | {same} |",
            r.krate,
            r.scene,
            r.threads,
            crate::registry::seconds(r.seconds),
            r.speedup
        );
    }
    s
}

/// Parses `--threads 1,2,4`: at least one count, each at least 1; 1 is put first if missing.
pub fn parse_threads(s: &str) -> Result<Vec<usize>, String> {
    let mut v = Vec::new();
    for part in s.split(',') {
        let n: usize =
            part.trim().parse().map_err(|_| format!("--threads: `{part}` is not a thread count"))?;
        if n == 0 {
            return Err("--threads: counts start at 1".into());
        }
        if !v.contains(&n) {
            v.push(n);
        }
    }
    if !v.contains(&1) {
        v.insert(0, 1);
    }
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thread_lists_parse() {
        assert_eq!(parse_threads("1,2"), Ok(vec![1, 2]));
        assert_eq!(parse_threads("4, 8"), Ok(vec![1, 4, 8]));
        assert!(parse_threads("0").is_err());
        assert!(parse_threads("two").unwrap_err().contains("`two`"));
    }

    #[test]
    fn every_family_builds_and_steps_in_quick_mode() {
        for (krate, scene, make) in families() {
            let mut s = make(true).unwrap_or_else(|e| panic!("{krate} {scene}: {e}"));
            let before = s.fingerprint();
            s.step().unwrap_or_else(|e| panic!("{krate} {scene}: {e}"));
            assert_ne!(before, s.fingerprint(), "{krate} {scene}: a step changed nothing");
        }
    }

    #[test]
    fn the_table_flags_a_thread_count_dependence() {
        let row = |threads, identical| Row {
            krate: "anim-x".into(),
            scene: "s".into(),
            threads,
            seconds: 1e-3 / threads as f64,
            speedup: threads as f64,
            identical,
            note: String::new(),
        };
        let md = markdown(&[row(1, Some(true)), row(2, Some(false))]);
        assert!(md.contains("| anim-x | s | 1 | 1.00 ms | 1.00 | yes |"), "{md}");
        assert!(md.contains("| anim-x | s | 2 | 500.00 us | 2.00 | **no** |"), "{md}");
    }
}
