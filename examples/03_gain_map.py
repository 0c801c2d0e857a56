"""A gain map: how fast the base settles under law (30) for every pair of gains (g_b, g_m).

The closed loop the simulator runs (plant, law, damped inverse, velocity servo, 1 ms step) is
linearised about TREP at rest; it is affine in the gains, so three linearisations give it at every
gain. The map colours each pair by how fast the base settles after TREP's default kick (sigma_b =
ln 10 / the time to 10 % of the peak deflection) and marks the paper's gains.

    python examples/03_gain_map.py [--out DIR]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from rns_viz.analysis import linearise, map_of, modes_of
from rns_viz.model import FsmsModel


def main(out: Path) -> Path:
    model = FsmsModel.from_name("trep")
    loop = linearise(model, "velocity", np.deg2rad([90.0, 0.0]))
    grid = map_of(loop, np.logspace(-1, 3.5, 40), np.logspace(-1, 3.5, 40))  # g_b, g_m in 1/s
    rate = np.where(grid.stable, grid.base_decay_rate, np.nan)
    paper = modes_of(loop, 24.0, 20.0)  # Fig. 10's gains
    print(
        f"after TREP's kick at the paper's gains (24, 20): 10 % in {float(paper.base_time_to_10pct):.1f} s, "
        f"sigma_b {float(paper.base_decay_rate):.3f} 1/s"
    )
    g_b, g_m, fastest = grid.best()  # among the cells the linear loop can predict
    print(f"fastest predictable on this grid: {fastest:.2f} 1/s at g_b = {g_b:.3g}, g_m = {g_m:.3g}")
    fig, ax = plt.subplots(figsize=(5.5, 4.5))
    image = ax.pcolormesh(grid.g_b, grid.g_m, rate.T, shading="nearest", cmap="viridis")
    ax.plot(24.0, 20.0, "w*", ms=12, label="Fig. 10 (24, 20)")
    ax.set(xscale="log", yscale="log", xlabel="g_b (1/s)", ylabel="g_m (1/s)", title="TREP, law (30): σ_b")
    fig.colorbar(image, label="base decay rate σ_b (1/s); blank: unstable")
    ax.legend(loc="lower left")
    fig.tight_layout()
    out.mkdir(parents=True, exist_ok=True)
    fig.savefig(out / "03_gain_map.png", dpi=100)
    return out / "03_gain_map.png"


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("."), help="folder for the picture")
    main(parser.parse_args().out)
