"""Two checkouts of rns_viz compared, for bench_jobs and bench_ring: a benchmark's ``--measure`` mode runs
in a fresh Python per tree and round (that tree first on its path), the rounds alternating which tree goes
first so both see the same machine load, and the medians are printed side by side with their ratio."""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

Found = dict[str, dict[str, list[float]]]  # tree -> figure -> one value per round


def measure_in(script: Path, tree: Path, *args: str) -> dict[str, float]:
    """The figures ``script --measure args`` prints as its last line (JSON), run with ``tree`` on the path."""
    env = {**os.environ, "PYTHONPATH": str(tree), "PYTHONDONTWRITEBYTECODE": "1"}  # leave the tree as it is
    out = subprocess.run(
        [sys.executable, str(script), "--measure", *args],
        cwd=tree,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
        check=True,
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def compare(script: Path, other: Path | None, rounds: int, *args: str) -> tuple[dict[str, Path], Found]:
    """Each tree's figures over ``rounds`` rounds: this checkout (the script's) and ``other``, if given."""
    trees = {"this": script.resolve().parent.parent}
    if other is not None:
        trees["other"] = other.resolve()
    found: Found = {tree: {} for tree in trees}
    for r in range(rounds):
        for tree in list(trees) if r % 2 == 0 else list(reversed(trees)):
            for figure, value in measure_in(script, trees[tree], *args).items():
                found[tree].setdefault(figure, []).append(value)
    return trees, found


def print_medians(trees: dict[str, Path], found: Found, unit: str, scale: float = 1.0) -> None:
    """The trees, then one line per figure: its median over the rounds (times ``scale``) per tree, and
    the ratio this / other (below 1: this tree is faster)."""
    for tree, path in trees.items():
        print(f"{tree}: {path}")
    ratio = "     ratio" if len(trees) == 2 else ""
    print(f"{unit + ' (median)':<24}" + "".join(f"{t:>10}" for t in trees) + ratio)
    for figure in found["this"]:
        values = [statistics.median(found[t][figure]) * scale for t in trees]
        ratio = f"{values[0] / values[1]:>10.3f}" if len(values) == 2 else ""
        print(f"{figure:<24}" + "".join(f"{v:>10.3f}" for v in values) + ratio)


def main(
    script: str, doc: str, measure: Callable[[int], None], rounds: int, calls: int, unit: str, scale: float
) -> None:
    """A benchmark's command line: ``[OTHER_TREE] [--rounds R] [--calls N]``; ``--measure`` (internal) runs
    ``measure(calls)``, which prints its figures as one JSON line; else the comparison is printed."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument("other", type=Path, nargs="?", help="root of another checkout of rns_viz")
    parser.add_argument("--rounds", type=int, default=rounds)
    parser.add_argument("--calls", type=int, default=calls)
    parser.add_argument("--measure", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.measure:
        measure(args.calls)
        return
    load = os.getloadavg()[0]
    trees, found = compare(Path(script), args.other, args.rounds, "--calls", str(args.calls))
    after = os.getloadavg()[0]
    print(f"{doc.splitlines()[0]}\n{args.rounds} rounds, {args.calls} calls; load before {load:.2f}, after {after:.2f}")
    print_medians(trees, found, unit, scale)
