"""Time per step of anim-mpm's 3D peer-benchmark scene (`benchmark-3d`, Taichi's `mpm3d` fluid:
65,536 particles at 64^3) driven from Python, measured as the crate's Rust example measures it:

    python crates/anim-py/bench/mpm_step.py [cells] [steps]
    cargo run --release -p anim-mpm --example throughput -- 3 64 100 2

50 warm-up steps, then 5 repeats of `steps` steps; the median time per step. Python calls
`sim.step(steps)` once per repeat (the GIL is released inside), so the figure shows what the
bindings add to the Rust loop. rayon uses every core, as the example's last argument `2` does
on a 2-core machine.
"""

import statistics
import sys
import time

import anim


def main():
    cells = int(sys.argv[1]) if len(sys.argv) > 1 else 64
    steps = int(sys.argv[2]) if len(sys.argv) > 2 else 100
    sim = anim.mpm.Simulation.scene("benchmark-3d", cells)
    sim.step(50)
    times = []
    for _ in range(5):
        start = time.perf_counter()
        sim.step(steps)
        times.append((time.perf_counter() - start) / steps)
    t = statistics.median(times)
    print(
        f"3D n={cells} particles={sim.num_particles} from Python: {t * 1e3:.3f} ms/step "
        f"(range {min(times) * 1e3:.3f} .. {max(times) * 1e3:.3f}), {sim.num_particles / t / 1e6:.2f} M particle-steps/s"
    )


if __name__ == "__main__":
    main()
