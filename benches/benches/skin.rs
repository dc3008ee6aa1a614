//! Criterion benches of anim-skin: LBS and DQS on a 100,000-vertex mesh with 4 influences per
//! vertex, on 1 thread and on all threads, with throughput in vertex-influences, next to a
//! memory-bandwidth bound over the same bytes.
//!
//! The bound ("stream bound" rows, throughput in bytes/s): one pass that reads exactly the arrays
//! skinning reads (rest positions and normals, 6 x f64; joints 4 x u16; weights 4 x f64: 88
//! bytes per vertex) and writes the arrays it writes (6 x f64: 48 bytes), 136 bytes per vertex
//! or 13.6 MB per pass, doing one add per input value, with the same chunked rayon loop on the
//! same pool. Skinning time divided by the stream time is how far a kernel is from being memory
//! bound. (The whole working set fits in this machine's last-level cache, so the bound measured
//! here is cache bandwidth, higher than DRAM bandwidth: a conservative bound.)
//! The per-joint data (64 joints) is a few kilobytes and is not counted; neither is the one byte
//! per vertex DQS reads besides (the dominant slot), 0.7% of the bytes.
//!
//! After criterion's rows, `cargo bench` prints the ratios measured interleaved (each round times
//! the stream pass, then each kernel, back to back: a load change on a shared machine hits all
//! alike), for the dispatched kernels (AVX2 where the CPU has it) and the portable ones.

use anim_core::glam::{DMat4, DQuat, DVec3};
use anim_skin::skinning::skin_portable;
use anim_skin::{Skinned, SkinnedMesh, SkinningMethod, skin};
use criterion::{Criterion, Throughput, criterion_group};
use rayon::prelude::*;
use std::hint::black_box;

const N: usize = 100_000;
const K: usize = 4;
const JOINTS: usize = 64;
/// Bytes read and written per vertex by skinning and by the stream bound.
const STREAM_BYTES_PER_VERTEX: usize = 6 * 8 + K * 2 + K * 8 + 6 * 8;

fn mesh() -> (SkinnedMesh, Vec<DMat4>) {
    let mut s = 99u64;
    let mut rnd = move || {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let pos: Vec<[f64; 3]> = (0..N).map(|_| [rnd(), rnd(), rnd()]).collect();
    let nrm: Vec<[f64; 3]> = (0..N).map(|_| [0.0, 0.0, 1.0]).collect();
    let js: Vec<u16> = (0..N * K).map(|_| (rnd() * JOINTS as f64) as u16).collect();
    let ws: Vec<f64> = (0..N * K).map(|_| rnd() + 0.1).collect();
    let mesh = SkinnedMesh::new(&pos, Some(&nrm), K, &js, &ws, vec![], JOINTS)
        .unwrap_or_else(|e| panic!("bench mesh: {e}"));
    let m = (0..JOINTS)
        .map(|j| {
            DMat4::from_rotation_translation(DQuat::from_rotation_y(0.1 * j as f64), DVec3::splat(j as f64))
        })
        .collect();
    (mesh, m)
}

fn stream(mesh: &SkinnedMesh, out: &mut Skinned) {
    const C: usize = anim_skin::skinning::CHUNK;
    let (js, ws) = (mesh.joints(), mesh.weights());
    out.x
        .par_chunks_mut(C)
        .zip(out.y.par_chunks_mut(C))
        .zip(out.z.par_chunks_mut(C))
        .zip(out.nx.par_chunks_mut(C))
        .zip(out.ny.par_chunks_mut(C))
        .zip(out.nz.par_chunks_mut(C))
        .enumerate()
        .for_each(|(c, (((((ox, oy), oz), onx), ony), onz))| {
            for i in 0..ox.len() {
                let v = c * C + i;
                let w: f64 = ws[v * K..v * K + K].iter().sum::<f64>()
                    + js[v * K..v * K + K].iter().map(|&j| f64::from(j)).sum::<f64>();
                ox[i] = mesh.x[v] + w;
                oy[i] = mesh.y[v] + w;
                oz[i] = mesh.z[v] + w;
                onx[i] = mesh.nx[v] + w;
                ony[i] = mesh.ny[v] + w;
                onz[i] = mesh.nz[v] + w;
            }
        });
}

fn skinning(c: &mut Criterion) {
    let (mesh, m) = mesh();
    let mut out = Skinned::new(&mesh);
    let all = rayon::current_num_threads();
    let mut g = c.benchmark_group("skin 100k vertices x 4 influences");
    for threads in [1, all] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap_or_else(|e| panic!("pool: {e}"));
        g.throughput(Throughput::Elements((N * K) as u64));
        for (label, method) in [("lbs", SkinningMethod::Lbs), ("dqs", SkinningMethod::Dqs)] {
            g.bench_function(format!("{label} {threads} thread(s)"), |b| {
                b.iter(|| pool.install(|| skin(&mesh, black_box(&m), method, &mut out)))
            });
        }
        g.throughput(Throughput::Bytes((N * STREAM_BYTES_PER_VERTEX) as u64));
        g.bench_function(format!("stream bound {threads} thread(s)"), |b| {
            b.iter(|| pool.install(|| stream(black_box(&mesh), &mut out)))
        });
    }
    g.finish();
}

criterion_group!(benches, skinning);

/// Runs of each kernel in the interleaved comparison.
const ROUNDS: usize = 200;

/// The ratio of each kernel's time to the stream bound's, measured interleaved: every round
/// times one stream pass, one LBS pass and one DQS pass back to back, so that a load change on
/// a shared machine hits all three alike. Prints the ratio of the fastest runs (each kernel's
/// intrinsic cost) and the median of the per-round ratios.
fn interleaved_ratios() {
    let (mesh, m) = mesh();
    let mut out = Skinned::new(&mesh);
    let all = rayon::current_num_threads();
    println!(
        "\nskinning time / stream-bound time, {ROUNDS} interleaved rounds (100k vertices x 4 influences):"
    );
    for threads in [1, all] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap_or_else(|e| panic!("pool: {e}"));
        let mut t = [[0.0f64; ROUNDS]; 5];
        for r in 0..ROUNDS {
            let time = |f: &mut dyn FnMut()| {
                let s = std::time::Instant::now();
                f();
                s.elapsed().as_secs_f64()
            };
            t[0][r] = time(&mut || pool.install(|| stream(black_box(&mesh), &mut out)));
            for (i, method) in [(1, SkinningMethod::Lbs), (2, SkinningMethod::Dqs)] {
                t[i][r] = time(&mut || {
                    pool.install(|| skin(&mesh, black_box(&m), method, &mut out))
                        .unwrap_or_else(|e| panic!("skin: {e}"))
                });
                t[i + 2][r] = time(&mut || {
                    pool.install(|| skin_portable(&mesh, black_box(&m), method, &mut out))
                        .unwrap_or_else(|e| panic!("skin: {e}"))
                });
            }
        }
        let fastest = t.map(|s| s.iter().copied().fold(f64::INFINITY, f64::min));
        let median = |i: usize| {
            let mut r: Vec<f64> = (0..ROUNDS).map(|k| t[i][k] / t[0][k]).collect();
            r.sort_by(f64::total_cmp);
            r[ROUNDS / 2]
        };
        println!(
            "  {threads} thread(s): stream {:.3} ms ({:.1} GB/s); LBS {:.3} ms = {:.2}x (median ratio {:.2}x); \
             DQS {:.3} ms = {:.2}x (median ratio {:.2}x)",
            fastest[0] * 1e3,
            (N * STREAM_BYTES_PER_VERTEX) as f64 / fastest[0] * 1e-9,
            fastest[1] * 1e3,
            fastest[1] / fastest[0],
            median(1),
            fastest[2] * 1e3,
            fastest[2] / fastest[0],
            median(2)
        );
        println!(
            "  {threads} thread(s), portable kernels: LBS {:.2}x (median {:.2}x), DQS {:.2}x (median {:.2}x)",
            fastest[3] / fastest[0],
            median(3),
            fastest[4] / fastest[0],
            median(4)
        );
    }
}

fn main() {
    benches();
    Criterion::default().configure_from_args().final_summary();
    // `cargo bench` passes `--bench`; `cargo test --benches` does not (one quick pass only).
    if std::env::args().any(|a| a == "--bench") {
        interleaved_ratios();
    }
}
