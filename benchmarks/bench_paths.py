"""Benchmark: the TREP reactionless path family (Fig. 8), rns_viz versus a solve_ivp baseline.

Run on demand:  python benchmarks/bench_paths.py [--count 40] [--repeats 15]
Prints medians (ms) of both in the same run, their ratio, and the drift of w x_cm along the
paths as a fraction of its range over the workspace.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np
import pinocchio as pin
from scipy.integrate import solve_ivp

from rns_viz import _native as rns_native
from rns_viz.model import FsmsModel
from rns_viz.paths import default_seeds, path_family, potential


def solve_ivp_family(
    model: FsmsModel, seeds: np.ndarray, max_length: float = 60.0, method: str = "DOP853", rtol: float = 1e-9
) -> list[np.ndarray]:
    """The straightforward version: one solve_ivp per seed, crba for H_bm, closure by event."""
    q = np.zeros(model.nv)
    m = model.m

    def field(_s: float, theta: np.ndarray) -> np.ndarray:
        q[m:] = theta
        h = pin.crba(model.pin_model, model.data, q)[0, m:]
        n = np.array([h[1], -h[0]])
        return n / np.linalg.norm(n)

    curves = []
    for seed in seeds:
        tangent = field(0.0, seed)

        def back_home(s: float, theta: np.ndarray, seed: np.ndarray = seed, tangent: np.ndarray = tangent) -> float:
            """Signed distance to the seed's section; crosses upward when the path returns."""
            return float(((theta - seed + np.pi) % (2 * np.pi) - np.pi) @ tangent) if s > 0.5 else -1.0

        back_home.terminal = True  # type: ignore[attr-defined]
        back_home.direction = 1.0  # type: ignore[attr-defined]
        sol = solve_ivp(field, (0.0, max_length), seed, method=method, rtol=rtol, atol=rtol * 1e-3, events=back_home)
        curves.append(sol.y.T)
    return curves


def median_ms(fn, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return 1e3 * statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=40)
    parser.add_argument("--repeats", type=int, default=15)
    args = parser.parse_args()
    model = FsmsModel.from_name("trep")
    seeds = default_seeds(model, args.count)
    ours = median_ms(lambda: path_family(model, args.count), args.repeats)
    kernels = "native" if rns_native.core is not None else f"Python ({rns_native.why})"
    saved, rns_native.core = rns_native.core, None  # the same tracer with pinocchio called from Python
    python_kernels = median_ms(lambda: path_family(model, args.count), max(3, args.repeats // 3))
    rns_native.core = saved
    base = median_ms(lambda: solve_ivp_family(model, seeds), max(3, args.repeats // 5))
    loose = median_ms(lambda: solve_ivp_family(model, seeds, method="RK45", rtol=1e-6), max(3, args.repeats // 3))
    paths = path_family(model, args.count)
    corners = np.array([[0.0, 0.0], [np.pi, 0.0]])
    span = np.ptp([potential(model, th) for th in corners])
    drift = max(np.ptp([potential(model, th) for th in p.theta]) for p in paths) / span
    base_drift = max(np.ptp([potential(model, th) for th in c]) for c in solve_ivp_family(model, seeds)) / span
    loose_curves = solve_ivp_family(model, seeds, method="RK45", rtol=1e-6)
    loose_drift = max(np.ptp([potential(model, th) for th in c]) for c in loose_curves) / span
    points = sum(len(p.s) for p in paths)
    print(f"TREP path family, {args.count} curves, {points} points, ends: {sorted({p.end for p in paths})}")
    print(f"{'method':<28}{'median ms':>10}{'w x_cm drift / range':>24}")
    print(f"{'rns_viz path_family':<28}{ours:>10.1f}{drift:>24.1e}   (centre-of-mass kernels: {kernels})")
    print(f"{'  same, Python kernels':<28}{python_kernels:>10.1f}")
    print(f"{'solve_ivp RK45 rtol 1e-6':<28}{loose:>10.1f}{loose_drift:>24.1e}")
    print(f"{'solve_ivp DOP853 rtol 1e-9':<28}{base:>10.1f}{base_drift:>24.1e}")
    print(f"speed-up: {loose / ours:.1f}x over RK45 1e-6, {base / ours:.1f}x over DOP853 1e-9")


if __name__ == "__main__":
    main()
