"""Command line: ``rns-viz`` starts the app; ``rns-viz info|paths|run|figures`` work headless.

Bad arguments give one clear line on stderr and exit status 2, never a traceback.
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from rns_viz.params import MODEL_NAMES, ModelFileError


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


def _load_model(name: str):
    from rns_viz.model import FsmsModel

    return FsmsModel.from_name(name)


def _open_for_writing(path: Path):
    try:
        return path.open("w", newline="")
    except OSError as exc:
        raise CliError(f"cannot write {path}: {exc.strerror}") from None


def cmd_info(args: argparse.Namespace) -> None:
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
    }
    print(json.dumps(info, indent=2))


def cmd_paths(args: argparse.Namespace) -> None:
    from rns_viz.paths import path_family

    model = _load_model(args.model)
    out = Path(args.csv)
    handle = _open_for_writing(out)
    try:
        paths = path_family(model, args.count, ds=args.ds)
    except ValueError as exc:
        handle.close()
        raise CliError(str(exc)) from None
    with handle:
        writer = csv.writer(handle)
        writer.writerow(["path", "s", *[f"theta_{i + 1}" for i in range(model.n)], "ee_x", "ee_y", "ee_z"])
        for index, path in enumerate(paths):
            for s, theta, ee in zip(path.s, path.theta, path.ee, strict=True):
                writer.writerow(
                    [index, repr(float(s)), *(repr(float(t)) for t in theta), *(repr(float(e)) for e in ee)]
                )
    ends = sorted({p.end for p in paths})
    print(f"wrote {len(paths)} paths ({sum(len(p.s) for p in paths)} points; ends: {', '.join(ends)}) to {out}")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="rns-viz",
        description="Reaction null-space control of a flexible-structure-mounted manipulator "
        "(Nenchev et al. 1999). Without a command, starts the browser app.",
    )
    sub = parser.add_subparsers(dest="command")
    info = sub.add_parser("info", help="print a model's dimensions and base parameters as JSON")
    info.add_argument("--model", choices=MODEL_NAMES, default="trep")
    info.set_defaults(func=cmd_info)
    paths = sub.add_parser("paths", help="write the reactionless path family (Fig. 8) as CSV")
    paths.add_argument("--model", choices=MODEL_NAMES, default="trep")
    paths.add_argument("--count", type=_positive_int, default=40, help="number of paths (default 40)")
    paths.add_argument("--ds", type=_positive_float, default=0.2, help="largest step in joint space, rad")
    paths.add_argument("--csv", required=True, help="output file")
    paths.set_defaults(func=cmd_paths)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        args = parser.parse_args(["serve"])
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
