"""Arms from a maintained package of robot descriptions, mounted on a bundled model's base.

A parameter file may name a packaged arm (``[model] arm = "example-robot-data/panda"``): the arm's
own URDF (links, inertias, limits, meshes) then replaces the arm of the file's URDF at the fixed
mount joint, and the composed URDF is written to a cache file, because where the package lives is
known only when the model loads. The package is an optional extra (``pip install 'rns-viz[panda]'``);
without it :class:`RobotPackageMissing` says what to install.

Composition keeps the bundled URDF's base (its elastic coordinates and the tip inertia) up to the
mount joint, drops what hangs below the mount, hangs the packaged arm's root link there, and fixes
the packaged hand's finger joints where they are at zero (a rigid hand: the fingers' mass stays on
the hand). Mesh references (``package://NAME/...``) become absolute paths into the installed package.
"""

from __future__ import annotations

import hashlib
import importlib.metadata
import os
import tempfile
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from functools import cache
from pathlib import Path

MOUNT_JOINT = "mount"  # the fixed joint of a bundled URDF that carries its arm
_PACKAGE_URL = "package://"


class RobotPackageMissing(LookupError):
    """The package of robot descriptions that an arm comes from is not installed."""


@dataclass(frozen=True)
class PackagedArm:
    """Where a packaged arm's URDF is, and which of its joints are held fixed (the hand)."""

    distribution: str  # the PyPI distribution that installs it
    extra: str  # rns-viz's optional extra that installs the distribution
    share: str  # the package's data directory inside the installed distribution
    urdf: str  # the arm's URDF, relative to ``share``
    root_link: str  # the arm's first link, hung on the mount
    fixed_joints: tuple[str, ...]  # movable joints held at zero (a gripper's fingers)


PACKAGED_ARMS = {
    # The Franka Emika Panda as example-robot-data ships it (franka_description's panda.urdf:
    # 7 revolute joints panda_joint1..7, the hand with two prismatic fingers, visual .dae meshes).
    "example-robot-data/panda": PackagedArm(
        distribution="example-robot-data",
        extra="panda",
        share="cmeel.prefix/share/example-robot-data",
        urdf="robots/panda_description/urdf/panda.urdf",
        root_link="panda_link0",
        fixed_joints=("panda_finger_joint1", "panda_finger_joint2"),
    ),
}


def packaged_arm(name: str) -> PackagedArm:
    if name not in PACKAGED_ARMS:
        raise KeyError(f"unknown packaged arm {name!r}; known: {', '.join(PACKAGED_ARMS)}")
    return PACKAGED_ARMS[name]


def share_dir(arm: PackagedArm) -> Path:
    """The installed package's data directory; RobotPackageMissing with the install command if absent."""
    hint = f"{arm.distribution} is not installed: pip install 'rns-viz[{arm.extra}]'"
    try:
        located = importlib.metadata.distribution(arm.distribution).locate_file(arm.share)
    except importlib.metadata.PackageNotFoundError:
        raise RobotPackageMissing(hint) from None
    path = Path(str(located))
    if not (path / arm.urdf).is_file():
        raise RobotPackageMissing(f"{hint} (no {arm.urdf} under {path})")
    return path


@cache
def is_installed(name: str) -> bool:
    """Whether the packaged arm ``name`` can be loaded (its package is installed); asked once per process."""
    try:
        share_dir(packaged_arm(name))
    except RobotPackageMissing:
        return False
    return True


def compose(base_urdf: str, arm_urdf: str, arm: PackagedArm, share: Path) -> str:
    """URDF text: ``base_urdf`` up to its mount joint, the packaged arm hung on the mount.

    ``share``: the package's data directory; ``package://NAME/rest`` resolves to ``share/../NAME/rest``.
    """
    base = ET.fromstring(base_urdf)
    arm_root = ET.fromstring(arm_urdf)
    mount = next((j for j in base.iter("joint") if j.get("name") == MOUNT_JOINT), None)
    if mount is None or mount.get("type") != "fixed":
        raise ValueError(f"the base URDF has no fixed joint named {MOUNT_JOINT!r} to carry the arm")
    old_arm = _link_of(mount, "child")
    below = set(_subtree_links(base, old_arm))
    for link in [e for e in base.findall("link") if e.get("name") in below]:
        base.remove(link)
    for joint in list(base.findall("joint")):
        if joint is not mount and _link_of(joint, "parent") not in _links(base):
            base.remove(joint)
    mount.find("child").set("link", arm.root_link)
    for element in arm_root:
        if element.tag in ("link", "joint", "material"):
            base.append(element)
    for joint in base.iter("joint"):
        if joint.get("name") in arm.fixed_joints:
            joint.set("type", "fixed")
            for tag in ("axis", "limit", "mimic", "dynamics", "safety_controller"):
                for child in joint.findall(tag):
                    joint.remove(child)
    for mesh in base.iter("mesh"):
        mesh.set("filename", _resolve(mesh.get("filename", ""), share))
    header = (
        f" Composed by rns_viz.robots: {base.get('name')}'s base with the arm of {arm.distribution} "
        f"({arm.urdf}) on its joint {MOUNT_JOINT!r}; the fingers {', '.join(arm.fixed_joints)} fixed at zero. "
    )
    base.insert(0, ET.Comment(header))
    return ET.tostring(base, encoding="unicode")


def _link_of(joint: ET.Element, tag: str) -> str:
    """The link a joint's <parent> or <child> names; ValueError naming the joint if it has none."""
    element = joint.find(tag)
    if element is None or not element.get("link"):
        raise ValueError(f"<joint name={joint.get('name')!r}> has no <{tag} link=...>")
    return element.get("link")


def _links(robot: ET.Element) -> set[str]:
    return {link.get("name") for link in robot.findall("link")}


def _subtree_links(robot: ET.Element, root: str) -> list[str]:
    """``root`` and every link below it."""
    children: dict[str, list[str]] = {}
    for joint in robot.findall("joint"):
        children.setdefault(_link_of(joint, "parent"), []).append(_link_of(joint, "child"))
    out, stack = [], [root]
    while stack:
        link = stack.pop()
        if link not in out:  # a malformed file may close a loop
            out.append(link)
            stack.extend(children.get(link, []))
    return out


def _resolve(filename: str, share: Path) -> str:
    if not filename.startswith(_PACKAGE_URL):
        return filename
    package, _, rest = filename[len(_PACKAGE_URL) :].partition("/")
    return str((share.parent / package / rest).resolve())


def composed_urdf(base_urdf_path: Path, arm_name: str, share: Path | None = None) -> Path:
    """Compose the packaged arm ``arm_name`` onto ``base_urdf_path`` and return the cached URDF file.

    ``share``: the package's data directory (default: the installed package's).
    """
    arm = packaged_arm(arm_name)
    share = share_dir(arm) if share is None else share
    text = compose(base_urdf_path.read_text(), (share / arm.urdf).read_text(), arm, share)
    digest = hashlib.sha256(text.encode()).hexdigest()[:16]
    name = f"{base_urdf_path.stem}-{arm_name.replace('/', '-')}-{digest}.urdf"
    for directory in (_cache_dir(), Path(tempfile.gettempdir()) / "rns_viz"):
        path = directory / name
        try:
            if not path.is_file() or path.read_text() != text:
                directory.mkdir(parents=True, exist_ok=True)
                partial = path.with_suffix(f".{os.getpid()}.tmp")
                partial.write_text(text)
                partial.replace(path)  # atomic: a reader sees the old file or the whole new one
            return path
        except OSError:
            continue
    raise OSError(f"cannot write the composed URDF {name} to {_cache_dir()} or the temporary directory")


def _cache_dir() -> Path:
    root = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(root) / "rns_viz"
