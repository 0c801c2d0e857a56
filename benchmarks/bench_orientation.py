"""Benchmark: the cost of the reactionless resolved-rate reference's step (run every 1 ms) on boom7 with
the orientation target tracked (secondary task) against position only, in the same run.

    python benchmarks/bench_orientation.py              # r = 1 and r = 3, 2000 steps per round
    python benchmarks/bench_orientation.py --rounds 9

Each round steps a fresh reference toward the same reachable pose for ``--steps`` steps, orientation
off then on (interleaved A/B rounds); CPU time (time.process_time) per step, medians over rounds and
the ratio on/off, with the machine's load average.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

import numpy as np

from rns_viz.live.operator.moving_references import ResolvedRate
from rns_viz.model import FsmsModel
from rns_viz.rns import rns_projector


def reachable_pose(model: FsmsModel, theta: np.ndarray, steps: int = 300) -> np.ndarray:
    """A configuration reached by a random reactionless motion (seeded)."""
    z = np.random.default_rng(4).normal(size=model.n)
    for _ in range(steps):
        theta = theta + 1e-3 * rns_projector(model.mass_matrix(model.q(theta))[model.selected, model.m :]) @ z
    return theta


def per_step_us(model: FsmsModel, goal: np.ndarray, orient: bool, steps: int) -> float:
    rr = ResolvedRate(model, model.spec.default_configuration, v_max=0.1)
    rr.set_orientation(orient)
    rr.set_goal(rr.ee(goal))
    rr.set_goal_rotation(rr.ee_rotation(goal))
    t0 = time.process_time()
    for _ in range(steps):
        rr.step(1e-3)
    return 1e6 * (time.process_time() - t0) / steps


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--steps", type=int, default=2000)
    args = parser.parse_args()
    for r in (1, 3):
        model = FsmsModel.from_name("boom7").with_selection([int(i < r) for i in range(6)])
        goal = reachable_pose(model, model.spec.default_configuration.copy())
        off, on = [], []
        for _ in range(args.rounds):
            off.append(per_step_us(model, goal, False, args.steps))
            on.append(per_step_us(model, goal, True, args.steps))
        m_off, m_on = statistics.median(off), statistics.median(on)
        print(
            f"boom7 r = {r}: step {m_off:.1f} us (position only), {m_on:.1f} us (with orientation), "
            f"ratio {m_on / m_off:.2f}; load average {os.getloadavg()}"
        )


if __name__ == "__main__":
    main()
