"""The URDF of a model: structural checks with messages that name the element, then pinocchio's model of it."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin

from rns_viz.params import ModelFileError, ModelSpec


def check_urdf(path: Path) -> None:
    """Structural checks with messages naming the element, before pinocchio (whose errors do not)."""
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as exc:
        line, column = exc.position
        raise ModelFileError(f"{path}: not well-formed XML at line {line}, column {column}") from None
    if root.tag != "robot":
        raise ModelFileError(f"{path}: the root element must be <robot>, got <{root.tag}>")
    links = {link.get("name") for link in root.iter("link")}
    for joint in root.iter("joint"):
        name = joint.get("name")
        kind = joint.get("type")
        where = f"{path}: <joint name={name!r}>"
        if kind not in ("revolute", "continuous", "prismatic", "fixed", "floating", "planar"):
            raise ModelFileError(f"{where}: unknown type {kind!r}")
        for tag in ("parent", "child"):
            element = joint.find(tag)
            if element is None or element.get("link") not in links:
                link = None if element is None else element.get("link")
                raise ModelFileError(f"{where}: <{tag} link={link!r}> names no <link> of this robot")
        if kind in ("revolute", "prismatic") and joint.find("limit") is None:
            raise ModelFileError(f"{where}: a {kind} joint needs a <limit> element")
    for link in root.iter("link"):
        mass = link.find("inertial/mass")
        if mass is not None:
            try:
                value = float(mass.get("value", "nan"))
            except ValueError:
                value = float("nan")
            if not (np.isfinite(value) and value >= 0):
                raise ModelFileError(f"{path}: <link name={link.get('name')!r}> <mass value=...> must be >= 0")


def build_pinocchio_model(spec: ModelSpec) -> pin.Model:
    """The pinocchio model of a parameter file's URDF, its gravity set; a clear message for a URDF it cannot use."""
    path = spec.urdf_path
    if not path.is_file():
        raise ModelFileError(f"{spec.param_path}: [model] urdf: no file {path}")
    check_urdf(path)
    try:
        model = pin.buildModelFromUrdf(str(path))
    except (RuntimeError, ValueError) as exc:
        raise ModelFileError(f"{path}: pinocchio cannot read this URDF ({str(exc).strip()})") from None
    model.gravity.linear[:] = spec.gravity
    return model
