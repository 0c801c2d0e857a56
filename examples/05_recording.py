"""A recording: two of the paper's experiments run headless, written as CSV, read back and compared.

Fig. 11: TREP's arm goes from (90°, 0) to (90°, 180°) in 2.5 s, once along the reactionless path and
once by a joint-space quintic that turns link 2 alone. The logs are written in rns_viz's one CSV format
(units in the header, 17 significant digits), so what is read back is exactly what was simulated.

    python examples/05_recording.py [--out DIR]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from rns_viz.csvio import read_csv
from rns_viz.scenarios import run_scenario

RUNS = {"fig11-fast": "along the reactionless path", "fig11-joint2": "link 2 alone (joint-space quintic)"}


def main(out: Path) -> Path:
    out.mkdir(parents=True, exist_ok=True)
    fig, ax = plt.subplots(figsize=(8, 3.5))
    for name, label in RUNS.items():
        log = run_scenario(name, duration=4.0).log
        log.write_csv(out / f"{name}.csv")
        table = read_csv(out / f"{name}.csv")
        assert np.array_equal(table.column("xb_1"), log.column("xb_1"))  # the very floats simulated
        xb = table.column("xb_1")
        ax.plot(table.column("t"), xb * 1e3, label=label, lw=1)
        columns = ", ".join(table.columns[:4])
        print(f"{name}: {len(xb)} rows, columns {columns}, ...; peak |x_b| {np.abs(xb).max():.1e} m")
    ax.set(xlabel="t (s)", ylabel="x_b (mm)", title="Fig. 11: the same end points, two motions")
    ax.legend()
    fig.tight_layout()
    fig.savefig(out / "05_recording.png", dpi=100)
    return out / "05_recording.png"


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("."), help="folder for the CSV files and the picture")
    main(parser.parse_args().out)
