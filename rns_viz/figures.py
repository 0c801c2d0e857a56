"""The paper's figures redrawn from our simulations (matplotlib).

Each ``figN`` writes ``figN.png`` laid out like the paper's figure, axes in SI units;
``gain_map_<model>`` writes the gain map of the model's law in the paper (rns_viz.analysis).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING

import numpy as np

from rns_viz.analysis import EQUATIONS, PAPER_GAINS, gain_map, modes_of
from rns_viz.model import FsmsModel
from rns_viz.paths import path_family
from rns_viz.scenarios import run_scenario
from rns_viz.sim import StepLog

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure


def _pyplot() -> ModuleType:
    """matplotlib.pyplot with the Agg backend, imported on first use (pyplot takes a second to load)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _col(log: StepLog, name: str) -> np.ndarray:
    return log.column(name)


def _deflection(ax: Axes, log: StepLog, label: str | None = None, scale: float = 1e3) -> None:
    ax.plot(_col(log, "t"), scale * _col(log, "xb_1"), lw=1.0, label=label)
    ax.set_ylabel("base deflection x_b [mm]")
    ax.grid(alpha=0.3)


def fig3(out: Path) -> Path:
    log = run_scenario("fig3", 12.0).log
    plt = _pyplot()
    fig, (a, b) = plt.subplots(2, 1, figsize=(6.5, 5.5), sharex=True)
    _deflection(a, log)
    a.axvline(1.0, color="gray", ls=":", lw=1)
    a.axvline(3.0, color="tab:red", ls="--", lw=1)
    a.text(3.05, a.get_ylim()[1] * 0.8, "suppression on", color="tab:red", fontsize=8)
    for i in range(3):
        b.plot(_col(log, "t"), _col(log, f"theta_{i + 1}"), lw=1.0, label=f"θ{i + 1}")
    b.set_ylabel("joint angle [rad]")
    b.set_xlabel("time [s]")
    b.legend(fontsize=8, ncol=3)
    b.grid(alpha=0.3)
    fig.suptitle("Fig. 3  Planar 3R: base vibration control (kick at 1 s, Eq. 15 from 3 s)", fontsize=10)
    return _save(fig, out / "fig3.png")


def fig4(out: Path) -> Path:
    log = run_scenario("fig4").log
    plt = _pyplot()
    fig = plt.figure(figsize=(9, 5))
    grid = fig.add_gridspec(3, 2, width_ratios=[1.1, 1])
    path = fig.add_subplot(grid[:, 0])
    path.plot(_col(log, "ee_ref_x"), _col(log, "ee_ref_y"), "k--", lw=1.5, label="ref")
    path.plot(_col(log, "ee_x"), _col(log, "ee_y"), "tab:blue", lw=1, label="act")
    path.set_aspect("equal")
    path.set_xlabel("x [m]")
    path.set_ylabel("y [m]")
    path.legend(fontsize=8)
    path.grid(alpha=0.3)
    t = _col(log, "t")
    xb = fig.add_subplot(grid[0, 1])
    _deflection(xb, log, scale=1e6)
    xb.set_ylabel("x_b [µm]")
    err = fig.add_subplot(grid[1, 1], sharex=xb)
    err.plot(t, 1e3 * np.hypot(_col(log, "ee_x") - _col(log, "ee_ref_x"), _col(log, "ee_y") - _col(log, "ee_ref_y")))
    err.set_ylabel("|e_e| [mm]")
    err.grid(alpha=0.3)
    th = fig.add_subplot(grid[2, 1], sharex=xb)
    for i in range(3):
        th.plot(t, _col(log, f"theta_{i + 1}"), lw=1, label=f"θ{i + 1}")
    th.set_ylabel("θ [rad]")
    th.set_xlabel("time [s]")
    th.legend(fontsize=7, ncol=3)
    th.grid(alpha=0.3)
    fig.suptitle("Fig. 4  Planar 3R: reactionless end-point path tracking (Eq. 24)", fontsize=10)
    return _save(fig, out / "fig4.png")


def fig8(out: Path) -> Path:
    model = FsmsModel.from_name("trep")
    paths = path_family(model, 40, ds=0.05)
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6, 6))
    for p in paths:
        ax.plot(p.ee[:, 0], p.ee[:, 1], lw=0.8, color="tab:blue")
    arm = model.arm_points(model.spec.default_configuration)
    ax.plot(arm[:, 0], arm[:, 1], "o-", color="tab:orange", lw=3, label="arm at θ = (90°, 0)")
    ax.set_aspect("equal")
    ax.set_xlabel("x [m] (low-stiffness axis)")
    ax.set_ylabel("y [m]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
    ax.set_title(
        "Fig. 8  Reactionless paths in the workspace of TREP\n"
        "(40 level sets of w·x_cm, end-effector in the base frame)",
        fontsize=10,
    )
    return _save(fig, out / "fig8.png")


def _on_off(out: Path, names: tuple[str, str], title: str, filename: str, joints: bool) -> Path:
    plt = _pyplot()
    rows = 2 if joints else 1
    fig, axes = plt.subplots(rows, 2, figsize=(10, 3.2 * rows), sharex=True, squeeze=False)
    logs = [run_scenario(n).log for n in names]
    limit = max(np.abs(_col(log, "xb_1")).max() for log in logs) * 1e3 * 1.1
    for k, (name, log) in enumerate(zip(names, logs, strict=True)):
        _deflection(axes[0, k], log)
        axes[0, k].set_ylim(-limit, limit)
        axes[0, k].set_title(f"({'ab'[k]}) {name}", fontsize=9)
        if joints:
            for i in range(2):
                axes[1, k].plot(_col(log, "t"), _col(log, f"theta_{i + 1}"), lw=1, label=f"θ{i + 1}")
            axes[1, k].set_ylabel("θ [rad]")
            axes[1, k].legend(fontsize=7)
            axes[1, k].grid(alpha=0.3)
        axes[-1, k].set_xlabel("time [s]")
    fig.suptitle(title, fontsize=10)
    return _save(fig, out / filename)


def fig10(out: Path) -> Path:
    return _on_off(
        out,
        ("fig10-on", "fig10-off"),
        "Fig. 10  TREP base vibration: (a) with, (b) without suppression (Eq. 30, g_m = 20, g_b = 24 1/s)",
        "fig10.png",
        joints=False,
    )


def fig11(out: Path) -> Path:
    plt = _pyplot()
    fig, axes = plt.subplots(4, 2, figsize=(10, 10), gridspec_kw={"height_ratios": [1.6, 1, 1, 1]})
    runs = {name: run_scenario(name).log for name in ("fig11-slow", "fig11-fast", "fig11-joint2")}
    panels = ((0, ("fig11-slow", "fig11-fast"), "(a) reactionless"), (1, ("fig11-joint2",), "(b) link 2 only"))
    limit = 1.1e3 * max(np.abs(_col(log, "xb_1")).max() for log in runs.values())
    for col, names, title in panels:
        axes[0, col].set_title(title, fontsize=9)
        for name in names:
            log = runs[name]
            label = name.removeprefix("fig11-")
            axes[0, col].plot(_col(log, "ee_x"), _col(log, "ee_y"), lw=1.2, label=label)
            axes[1, col].plot(_col(log, "t"), 1e3 * _col(log, "xb_1"), lw=1, label=label)
            axes[2, col].plot(_col(log, "t"), _col(log, "theta_2"), lw=1, label=label)
            axes[3, col].plot(_col(log, "t"), _col(log, "thetadot_2"), lw=1, label=label)
        axes[0, col].set_aspect("equal")
        axes[0, col].set_xlabel("x [m]")
        axes[0, col].set_ylabel("y [m]")
        axes[1, col].set_ylim(-limit, limit)
        for row, label in ((1, "x_b [mm]"), (2, "θ2 [rad]"), (3, "θ2' [rad/s]")):
            axes[row, col].set_ylabel(label)
            axes[row, col].grid(alpha=0.3)
            axes[row, col].legend(fontsize=7)
        axes[0, col].grid(alpha=0.3)
        axes[0, col].legend(fontsize=7)
        axes[3, col].set_xlabel("time [s]")
    title = "Fig. 11  TREP path motion: (a) reactionless at two speeds, (b) link 2 only (same end points)"
    fig.suptitle(title, fontsize=10)
    return _save(fig, out / "fig11.png")


def fig12(out: Path) -> Path:
    return _on_off(
        out,
        ("fig12-on", "fig12-off"),
        "Fig. 12  TREP cyclic reactionless motion (ū = 30) with a kick at 4 s: (a) with, (b) without suppression",
        "fig12.png",
        joints=True,
    )


def _gain_map(out: Path, name: str, law: str) -> Path:
    """Base and arm decay rates over g_b x g_m (1/s, log colour), unstable region grey, cells the linear loop
    cannot predict for the model's kick hatched, paper's gains marked."""
    from matplotlib.colors import ListedColormap, LogNorm

    model = FsmsModel.from_name(name)
    result = gain_map(model, law)
    loop = result.loop
    plt = _pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.6), sharey=True)
    rates = (result.base_decay_rate, result.arm_decay_rate)
    positive = np.concatenate([r[result.stable & (r > 0)] for r in rates])
    norm = LogNorm(vmin=max(positive.min(), 1e-3), vmax=positive.max())
    grey = ListedColormap(["0.6"])
    for ax, rate, title in zip(axes, rates, ("base", "arm modes"), strict=True):
        ax.pcolormesh(result.g_m, result.g_b, np.ma.masked_where(result.stable, rate), cmap=grey, shading="nearest")
        shown = np.ma.masked_where(~result.stable | ~(rate > 0), rate)
        image = ax.pcolormesh(result.g_m, result.g_b, shown, cmap="viridis", norm=norm, shading="nearest")
        odd = (result.stable & ~result.predictable).astype(float)
        if odd.any():
            ax.contourf(result.g_m, result.g_b, odd, levels=[0.5, 1.5], colors="none", hatches=["////"])
        for k, mark in enumerate(PAPER_GAINS.get((name, loop.law), ())):
            sigma = float(modes_of(loop, mark.g_b, mark.g_m).base_decay_rate)
            ax.plot(mark.g_m, mark.g_b, "o", mfc="none", mec="tab:red", ms=9, mew=2)
            text = f"{mark.label}: σ_b = {sigma:.2f}/s"
            ax.annotate(text, (mark.g_m, mark.g_b), (8, 8 - 14 * k), textcoords="offset points", color="w", fontsize=8)
        ax.set_xscale("log")
        ax.set_yscale("log")
        what = "σ_b = ln 10 / time to 10 %" if title == "base" else "slowest decay rate σ_a"
        ax.set_title(f"{title}: {what} [1/s]", fontsize=9)
        ax.set_xlabel("g_m [1/s]")
        fig.colorbar(image, ax=ax)
    axes[0].set_ylabel("g_b [1/s]")
    fig.suptitle(
        f"Gain map: {model.name}, law {EQUATIONS[loop.law]}, {loop.regime} (1 ms step map; "
        f"{result.stable.mean():.0%} of the grid stable, {result.predictable.mean():.0%} predictable)\n"
        "grey: unstable; hatched: the linear loop cannot predict this kick "
        "(arm swing > 0.5 rad, a joint limit, no decay after it)",
        fontsize=10,
    )
    return _save(fig, out / f"gain_map_{name}.png")


def gain_map_trep(out: Path) -> Path:
    return _gain_map(out, "trep", "velocity")


def gain_map_planar3r(out: Path) -> Path:
    return _gain_map(out, "planar3r", "acceleration")


FIGURES: dict[str, Callable[[Path], Path]] = {
    "fig3": fig3,
    "fig4": fig4,
    "fig8": fig8,
    "fig10": fig10,
    "fig11": fig11,
    "fig12": fig12,
    "gain_map_trep": gain_map_trep,
    "gain_map_planar3r": gain_map_planar3r,
}


def _save(fig: Figure, path: Path) -> Path:
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    import matplotlib.pyplot as plt

    plt.close(fig)
    return path


def draw_all(out: str | Path, names: list[str] | None = None) -> list[Path]:
    """Draw the chosen (default: all) figures into ``out``; returns the files written."""
    directory = Path(out)
    directory.mkdir(parents=True, exist_ok=True)
    return [FIGURES[name](directory) for name in (names or list(FIGURES))]
