"""Command line: ``rns-viz`` starts the app; ``rns-viz info|paths|run|gains|figures`` work headless.

Bad arguments give one clear line on stderr and exit status 2, never a traceback.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from rns_viz.params import MODEL_NAMES, ModelFileError, model_key, param_file_for

if TYPE_CHECKING:
    from rns_viz.model import FsmsModel

MODEL_HELP = f"{', '.join(MODEL_NAMES)} (bundled; a packaged arm needs its extra), or a model's parameter file (.toml)"


class CliError(Exception):
    """A problem with what the user asked for; printed as one line."""


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if value <= 0:
        raise argparse.ArgumentTypeError(f"must be at least 1, got {value}")
    return value


def _positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not (np.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"must be a positive finite number, got {text}")
    return value


def _law_arg(text: str) -> str:
    from rns_viz.analysis.linear import law_kind

    try:
        return law_kind(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _port(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a port number, got {text!r}") from None
    if not 0 <= value <= 65535:
        raise argparse.ArgumentTypeError(f"port must be 0..65535, got {value}")
    return value


def _model_arg(text: str) -> str:
    if text in MODEL_NAMES or text.endswith(".toml"):
        return text
    choices = ", ".join(MODEL_NAMES)
    raise argparse.ArgumentTypeError(f"invalid choice: {text!r} (choose from {choices} or a .toml file)")


def _load_model(name: str) -> FsmsModel:
    """A bundled model by name, or any model from its parameter file (``*.toml``)."""
    from rns_viz.model import FsmsModel

    return FsmsModel.from_file(name) if name.endswith(".toml") else FsmsModel.from_name(name)


def _models_in(folder: Path) -> list[str]:
    """The model keys of the parameter files (``*.toml``) in ``folder`` that read as models; each one that
    does not is named on stderr and left out (a folder of a student's files must not stop the app)."""
    if not folder.is_dir():
        if folder.exists():
            raise CliError(f"--model-dir {folder}: not a folder")
        return []
    keys = []
    for path in sorted(folder.glob("*.toml")):
        try:
            _load_model(str(path))
        except (ModelFileError, OSError) as exc:
            print(f"rns-viz: skipping {path}: {exc}", file=sys.stderr)
            continue
        keys.append(model_key(str(path)))
    return keys


def _open_for_writing(path: Path):
    try:
        return path.open("w", newline="")
    except OSError as exc:
        raise CliError(f"cannot write {path}: {exc.strerror}") from None


def cmd_info(args: argparse.Namespace) -> None:
    from rns_viz.sim import native as native_step

    model = _load_model(args.model)
    q0 = model.q(model.spec.default_configuration)
    terms = model.terms(q0, np.zeros(model.nv))
    info = {
        "model": model.name,
        "urdf": str(model.spec.urdf_path),
        "parameters": str(model.spec.param_path),
        "base_dof": model.m,
        "arm_dof": model.n,
        "base_joints": list(model.spec.base.joints),
        "arm_joints": list(model.arm_joint_names),
        "selection": model.spec.base.selection.astype(int).tolist(),
        "rns_dim": model.n - len(model.selected),
        "default_configuration_rad": model.spec.default_configuration.tolist(),
        "default_configuration_deg": np.rad2deg(model.spec.default_configuration).tolist(),
        "H_b_kg": terms.H_b.tolist(),
        "K_b_N_per_m": model.K_b.tolist(),
        "D_b_N_s_per_m": model.D_b.tolist(),
        "D_m_N_m_s_per_rad": np.diag(model.D_m).tolist(),
        "arm_mass_kg": model.arm_mass,
        "H_bm_at_default": terms.H_bm.tolist(),
        "ee_at_default_m": terms.ee.tolist(),
        # laws (15)/(30) + RK4 in C++: the optional rns-viz-native (pip install ./native)
        "native_step": native_step.available(),
    }
    if not native_step.available():
        info["native_step_unavailable"] = native_step.unavailable_reason()  # why the Python step runs
    print(json.dumps(info, indent=2))


def cmd_paths(args: argparse.Namespace) -> None:
    from rns_viz.csvio import write_csv
    from rns_viz.paths import path_family
    from rns_viz.sim.log import arm_units

    model = _load_model(args.model)
    out = Path(args.csv)
    handle = _open_for_writing(out)
    try:
        paths = path_family(model, args.count, ds=args.ds)
    except ValueError as exc:
        handle.close()
        raise CliError(str(exc)) from None
    units = ["index", "rad", *[u.position for u in arm_units(model)], "m", "m", "m"]
    columns = ["path", "s", *[f"theta_{i + 1}" for i in range(model.n)], "ee_x", "ee_y", "ee_z"]
    rows = [np.column_stack((np.full(len(p.s), i), p.s, p.theta, p.ee)) for i, p in enumerate(paths)]
    with handle:
        write_csv(handle, columns, units, np.concatenate(rows))
    ends = sorted({p.end for p in paths})
    print(f"wrote {len(paths)} paths ({sum(len(p.s) for p in paths)} points; ends: {', '.join(ends)}) to {out}")


def cmd_run(args: argparse.Namespace) -> None:
    from rns_viz.scenarios import ALL_SCENARIOS, run_scenario
    from rns_viz.sim import SimulationDiverged

    if args.scenario not in ALL_SCENARIOS:
        raise CliError(f"unknown scenario {args.scenario!r}; choose one of: {', '.join(ALL_SCENARIOS)}")
    out = Path(args.csv)
    handle = _open_for_writing(out)
    try:
        sim = run_scenario(args.scenario, args.duration)
    except SimulationDiverged as exc:
        handle.close()
        raise CliError(f"{args.scenario}: {exc}") from None
    with handle:
        sim.log.write_csv(handle)
    peaks = [float(np.abs(sim.log.column(f"xb_{i + 1}")).max()) for i in range(sim.model.m)]
    unit = "m" if len(peaks) == 1 else "m or rad, per base coordinate"
    shown = ", ".join(f"{p:.3e}" for p in peaks)
    print(f"{args.scenario}: {len(sim.log)} steps of {sim.dt * 1e3:g} ms, peak |x_b| = {shown} {unit}; wrote {out}")


def cmd_gains(args: argparse.Namespace) -> None:
    from rns_viz.analysis import EQUATIONS, default_axes, gain_map

    model = _load_model(args.model)
    theta = None
    if args.theta_deg is not None:
        if len(args.theta_deg) != model.n:
            raise CliError(f"--theta-deg needs {model.n} joint angles for {model.name}, got {len(args.theta_deg)}")
        theta = np.deg2rad(args.theta_deg)
    g_b, g_m = default_axes(args.law, args.size)
    try:
        result = gain_map(model, args.law, theta, g_b=g_b, g_m=g_m, view=args.view)
    except ValueError as exc:
        raise CliError(str(exc)) from None
    out = Path(args.csv)
    with _open_for_writing(out) as handle:
        rows = result.write_csv(handle)
    best_b, best_m, best_rate = result.best()
    fastest = (
        f"fastest predictable base decay {best_rate:.3g} /s (10 % in {math.log(10.0) / best_rate:.3g} s) "
        f"at g_b = {best_b:.3g}, g_m = {best_m:.3g} /s"
        if result.predictable.any()
        else "no cell the linear loop can predict"
    )
    print(
        f"{model.name}, law {EQUATIONS[result.loop.law]}: {rows} points, {result.stable.mean():.0%} stable, "
        f"{result.predictable.mean():.0%} predictable {result.loop.regime}; {fastest}; wrote {out}"
    )


def cmd_figures(args: argparse.Namespace) -> None:
    from rns_viz.figures import FIGURES, draw_all

    names = args.only or None
    unknown = sorted(set(names or []) - set(FIGURES))
    if unknown:
        raise CliError(f"unknown figure {', '.join(unknown)}; choose from: {', '.join(FIGURES)}")
    try:
        written = draw_all(args.out, names)
    except ModuleNotFoundError as exc:
        raise CliError(str(exc)) from None
    except OSError as exc:
        raise CliError(f"cannot write to {args.out}: {exc.strerror}") from None
    for path in written:
        print(path)


LOOPBACK = ("127.0.0.1", "localhost", "::1")


def cmd_serve(args: argparse.Namespace) -> None:
    from rns_viz.viz.server.app import serve

    if args.host not in LOOPBACK and not args.host.startswith("127."):
        gated = args.password or os.environ.get("RNS_VIZ_PASSWORD")
        who = "" if gated else " and anyone may take control (no --password)"
        print(f"rns-viz: warning: binding {args.host}: other machines can reach this app{who}", file=sys.stderr)
    password = args.password or os.environ.get("RNS_VIZ_PASSWORD") or None
    models = [model_key(name) for name in args.model or ["trep"]]  # files by absolute path: one key each
    for name in models:  # every file is read and checked now: a bad one is refused before serving
        _load_model(name)
    if args.model_dir is not None:
        models += [name for name in _models_in(Path(args.model_dir)) if name not in models]
    model = models[0]
    if args.lesson is not None:
        from rns_viz.live.teaching.lessons import lessons_for, models_with_lessons

        count = len(lessons_for(model))
        if count == 0:
            raise CliError(f"{model} has no lessons; there are some for {', '.join(models_with_lessons())}")
        if args.lesson > count:
            raise CliError(f"{model} has lessons 1 to {count}, not {args.lesson}")
    extra = [name for name in models if name.endswith(".toml")]
    if args.each_visitor:
        from rns_viz.viz.server.classroom import serve_classroom

        if args.lesson is not None:
            raise CliError("--lesson and --each-visitor do not go together: each visitor starts their own lessons")
        if password is not None:
            raise CliError(
                "--password has no use with --each-visitor: every visitor operates their own simulation, and the "
                "presenter is the page opened on this machine"
            )
        serve_classroom(model, args.host, args.port, extra, args.max_visitors, args.idle_minutes)
        return
    serve(
        model=model,
        host=args.host,
        port=args.port,
        password=password,
        lesson=args.lesson,
        models=extra,
        present=args.present,
        pause_unwatched=args.pause_unwatched,
    )


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="rns-viz",
        description="Reaction null-space control of a flexible-structure-mounted manipulator "
        "(Nenchev et al. 1999). Without a command, starts the browser app.",
    )
    offered = ((name, len(param_file_for(name).app.lessons)) for name in MODEL_NAMES)
    counts = ", ".join(f"{name}: 1-{count}" for name, count in offered if count)
    lesson_help = f"start the app at lesson N of the model ({counts})"
    parser.add_argument("--lesson", dest="top_lesson", metavar="N", type=_positive_int, default=None, help=lesson_help)
    sub = parser.add_subparsers(dest="command")
    info = sub.add_parser("info", help="print a model's dimensions and base parameters as JSON")
    info.add_argument("--model", type=_model_arg, default="trep", help=MODEL_HELP)
    info.set_defaults(func=cmd_info)
    paths = sub.add_parser("paths", help="write the reactionless path family (Fig. 8) as CSV")
    paths.add_argument("--model", type=_model_arg, default="trep", help=MODEL_HELP)
    paths.add_argument("--count", type=_positive_int, default=40, help="number of paths (default 40)")
    paths.add_argument("--ds", type=_positive_float, default=0.2, help="largest step in joint space, rad")
    paths.add_argument("--csv", required=True, help="output file")
    paths.set_defaults(func=cmd_paths)
    run = sub.add_parser("run", help="run one of the paper's experiments headless and write its log as CSV")
    run.add_argument(
        "scenario",
        help="a preset: fig3, fig4, fig10-on/off, fig11-slow/fast/joint2, fig12-on/off, "
        "boom7-kick-on/off, boom7-path, boom7-track, boom7-p2p, trep2-circle-on/off, trep2-kick-on/off",
    )
    run.add_argument("--csv", required=True, help="output file")
    run.add_argument("--duration", type=_positive_float, default=None, help="seconds (default: the preset's)")
    run.set_defaults(func=cmd_run)
    gains = sub.add_parser("gains", help="map the closed loop's base and arm decay rates over g_b x g_m as CSV")
    gains.add_argument("--model", type=_model_arg, default="trep", help=MODEL_HELP)
    gains.add_argument("--law", type=_law_arg, default="velocity", help="15, 16, 30 or acceleration, torque, velocity")
    gains.add_argument("--csv", required=True, help="output file (gains and rates in 1/s; see the CSV formats docs)")
    gains.add_argument("--size", type=_positive_int, default=60, help="grid points per axis (default 60)")
    gains.add_argument(
        "--theta-deg", type=float, nargs="+", default=None, help="the rest configuration, deg (default: the model's)"
    )
    gains.add_argument(
        "--view", choices=("discrete", "continuous"), default="discrete", help="the 1 ms step map or continuous time"
    )
    gains.set_defaults(func=cmd_gains)
    figures = sub.add_parser("figures", help="draw the paper's figures (fig3, fig4, fig8, fig10, fig11, fig12) as PNG")
    figures.add_argument("--out", required=True, help="output directory")
    figures.add_argument("--only", nargs="*", help="a subset of the figures")
    figures.set_defaults(func=cmd_figures)
    serve = sub.add_parser("serve", help="start the browser app (the default command)")
    serve.add_argument(
        "--model",
        type=_model_arg,
        action="append",
        help=MODEL_HELP + "; the first is served, every file joins the model dropdown (repeat to add more)",
    )
    serve.add_argument(
        "--model-dir",
        metavar="DIR",
        default=None,
        help="every model parameter file (*.toml) in DIR joins the model dropdown (files that do not read are skipped)",
    )
    serve.add_argument("--host", default="127.0.0.1", help="address to bind (default 127.0.0.1, this machine only)")
    serve.add_argument("--port", type=_port, default=8080)
    serve.add_argument("--password", default=None, help="operator password (or RNS_VIZ_PASSWORD)")
    serve.add_argument("--lesson", metavar="N", type=_positive_int, default=None, help=lesson_help)
    serve.add_argument(
        "--pause-unwatched",
        action="store_true",
        help="pause the simulation while no page is open (one student's app on JupyterHub: little CPU when idle)",
    )
    serve.add_argument(
        "--each-visitor",
        action="store_true",
        help="give every browser page its own simulation (a lab room on one machine; see docs/deploy/classroom.md)",
    )
    serve.add_argument(
        "--max-visitors",
        metavar="N",
        type=_positive_int,
        default=None,
        help="with --each-visitor: simulations at once (default 1 per CPU core, at most 3); later pages wait",
    )
    serve.add_argument(
        "--idle-minutes",
        metavar="M",
        type=_positive_float,
        default=20.0,
        help="with --each-visitor: close a simulation after M minutes without input (paused after M/4, at most 5)",
    )
    serve.add_argument(
        "--present",
        action="store_true",
        help="for a projector: larger text, wider plots, fewer folders (no gain explorer, replay, gains, log)",
    )
    serve.set_defaults(func=cmd_serve)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    top_lesson = args.top_lesson
    if args.command is None:
        args = parser.parse_args(["serve"])
    if top_lesson is not None and getattr(args, "lesson", 0) is None:
        args.lesson = top_lesson  # rns-viz --lesson N [serve ...]
    try:
        args.func(args)
    except (CliError, ModelFileError) as exc:
        print(f"rns-viz: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return 130
    return 0


if __name__ == "__main__":
    sys.exit(main())
