"""A 2D dam break with anim.mpm: a block of weakly compressible fluid collapses in a box. Prints
the surge front over time and, when matplotlib is installed, plots the particles at four times
into mpm_dam_break.png.

    python crates/anim-py/examples/mpm_dam_break.py
"""

import numpy as np

import anim


def main():
    sim = anim.mpm.Simulation(2, [{"fluid": {"bulk": 2e5}}], params={"resolution": 64})
    h = 1.0 / 64
    # Two particles per cell along each axis in a 0.3 x 0.5 m column at the left wall.
    xs = np.arange(0.05 + h / 4, 0.35, h / 2)
    ys = np.arange(0.05 + h / 4, 0.55, h / 2)
    block = np.stack(np.meshgrid(xs, ys), axis=-1).reshape(-1, 2)
    volume = (h / 2) ** 2
    sim.add_particles(block, mass=1000.0 * volume, volume=volume)
    print(f"{sim.num_particles} particles")
    dt = 2e-4
    shots = []
    for frame in range(4):
        if frame:
            sim.step(500, dt=dt)
        x = sim.positions
        shots.append((sim.time, x))
        print(f"t = {sim.time:.2f} s: front at x = {x[:, 0].max():.3f} m, top at y = {x[:, 1].max():.3f} m")
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed: no plot")
        return
    fig, axes = plt.subplots(1, 4, figsize=(12, 3.2))
    for ax, (t, x) in zip(axes, shots):
        ax.scatter(x[:, 0], x[:, 1], s=0.5)
        ax.set(xlim=(0, 1), ylim=(0, 1), aspect="equal", title=f"t = {t:.2f} s")
    fig.tight_layout()
    fig.savefig("mpm_dam_break.png", dpi=100)
    print("wrote mpm_dam_break.png")


if __name__ == "__main__":
    main()
