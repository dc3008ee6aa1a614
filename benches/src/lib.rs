//! Criterion benchmarks of the anim kernels live under `benches/`.
