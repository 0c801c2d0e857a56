"""Reactionless paths of TREP (the paper's Fig. 8).

TREP's two joints and one elastic base coordinate leave a one-dimensional reaction null space: at
every configuration one direction of joint motion, n(theta), pushes the base not at all. Its integral
curves are the reactionless paths; an arm moved along one leaves the flexible beam at rest. This script
traces a family of them and draws them in joint space and as end-effector paths.

    python examples/01_reactionless_paths.py [--out DIR]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from rns_viz.model import FsmsModel
from rns_viz.paths import path_family


def main(out: Path) -> Path:
    model = FsmsModel.from_name("trep")
    paths = path_family(model, count=16)
    fig, (joints, hand) = plt.subplots(1, 2, figsize=(9, 4.2))
    for path in paths:
        joints.plot(np.rad2deg(path.theta[:, 0]), np.rad2deg(path.theta[:, 1]), lw=1)
        hand.plot(path.ee[:, 0], path.ee[:, 1], lw=1)
    joints.set(xlabel="θ1 (deg)", ylabel="θ2 (deg)", title="reactionless paths in joint space")
    hand.set(xlabel="x (m)", ylabel="y (m)", title="the hand along them (base frame)", aspect="equal")
    fig.tight_layout()
    out.mkdir(parents=True, exist_ok=True)
    fig.savefig(out / "01_reactionless_paths.png", dpi=100)
    print(f"{len(paths)} paths, {sum(len(p.theta) for p in paths)} points")
    return out / "01_reactionless_paths.png"


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("."), help="folder for the picture")
    main(parser.parse_args().out)
