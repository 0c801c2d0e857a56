"""boom7's boom against a finite-element model of the same tube (tests/support/oracles/tube_fe.py).

The six tip coordinates carry the tube by Guyan's static condensation: the tip stiffness K_b
(boom7.toml) and the mass of the static deflection shapes (boom7.urdf, link boom_tube). A
200-element model of the tube with the same plate and the same locked arm at the tip (their 6 x 6
inertia from pinocchio, on the URDF without the tube's link) is the reference for the locked-arm
modes: the model's first four are within 1.5 % of it; its fifth and sixth, and the tube's own higher
modes, are what six tip coordinates cannot carry (boom7.toml and docs/models.md say so, with these numbers).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pinocchio as pin
import pytest

from rns_viz.analysis.locked import locked_modes
from rns_viz.model import FsmsModel
from tests.support.oracles.tube_fe import Tube, condensed, modes

TUBE = Tube(E=68.9e9, G=26.0e9, rho=2700.0, length=4.0, outer_diameter=0.100, wall=0.002)  # boom7.toml's
ELEMENTS = 200
DOCUMENTED_HZ = (1.620, 1.626, 13.16, 15.31, 30.5, 157.0)  # boom7.toml and docs/models.md: the locked-arm modes


def without_tube(model: FsmsModel) -> pin.Model:
    """boom7's pinocchio model with the tube's link removed: the plate and the arm alone at the tip."""
    root = ET.parse(model.spec.urdf_path).getroot()
    for link in [e for e in root.findall("link") if e.get("name") == "boom_tube"]:
        root.remove(link)
    for joint in [e for e in root.findall("joint") if e.find("child").get("link") == "boom_tube"]:
        root.remove(joint)
    return pin.buildModelFromXML(ET.tostring(root, encoding="unicode"))


def tip_inertias(model: FsmsModel) -> tuple[np.ndarray, np.ndarray]:
    """(plate + locked arm, the tube's link): 6 x 6 inertias at the tip, (x, y, z, rx, ry, rz), theta_0."""
    q = model.q(model.spec.default_configuration)
    whole = model.mass_matrix(q, model.pin_model.createData())[:6, :6]
    bare = without_tube(model)
    rigid = pin.crba(bare, bare.createData(), q)[:6, :6]
    return rigid, whole - rigid


def test_the_tip_stiffness_is_the_tubes_static_condensation(boom7: FsmsModel) -> None:
    K, _ = condensed(TUBE, ELEMENTS)
    assert np.abs(K - boom7.K_b).max() <= 1e-5 * np.abs(boom7.K_b).max()


def test_the_tube_link_is_the_tubes_guyan_mass(boom7: FsmsModel) -> None:
    """Every entry of the condensed mass, rotary terms and the y-rz, z-ry couplings included; axially one
    rigid body has one mass for all three translations, 156/420 of the tube where Guyan gives 140/420."""
    _, M = condensed(TUBE, ELEMENTS)
    _, tube = tip_inertias(boom7)
    axial = np.zeros((6, 6), dtype=bool)
    axial[0, 0] = True
    assert np.abs(tube - M)[~axial].max() <= 1e-5 * np.abs(M).max()
    assert M[1, 5] < -1.0 and M[5, 5] > 1.0  # kg m, kg m^2: what the lumped tip mass left out
    assert tube[0, 0] == pytest.approx(M[0, 0] * 156 / 140, rel=1e-5)
    assert M[0, 0] == pytest.approx(TUBE.mass / 3, rel=1e-9)


def test_locked_modes_against_a_converged_finite_element_model(boom7: FsmsModel) -> None:
    rigid, _ = tip_inertias(boom7)
    fe = modes(TUBE, ELEMENTS, rigid, 12)
    assert np.allclose(modes(TUBE, ELEMENTS // 2, rigid, 12).frequency_hz, fe.frequency_hz, rtol=1e-4)  # converged
    model = locked_modes(boom7, boom7.spec.default_configuration).frequency_hz
    assert np.allclose(model, DOCUMENTED_HZ, rtol=5e-3)
    error = model / fe.frequency_hz[:6] - 1
    # physical: both first bending modes, torsion, the x-z bending with the tip turning about y
    assert np.all(np.abs(error[:4]) <= 0.015), error
    # the tip turning about z: 17 % stiffer than the tube's mode it stands for, most of whose energy is the tube's
    assert 0.10 <= error[4] <= 0.20 and fe.tip_share[4] < 0.4, (error[4], fe.tip_share[4])
    # the tube's own bending from 43 Hz on (little of it on the tip) has no tip coordinate at all
    assert fe.frequency_hz[5] < model[5] and fe.tip_share[5] < 0.3
    # the model's sixth mode is the axial one: within 15 % of the tube's mode of the largest axial energy
    axial = int(np.argmax(fe.coordinate_share[:, 0]))
    assert fe.coordinate_share[axial, 0] > 0.8
    assert model[5] == pytest.approx(fe.frequency_hz[axial], rel=0.15)
