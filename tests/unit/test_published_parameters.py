"""The bundled arms and bases carry the published numbers, read from the files against tables here.

- The Panda of boom7.urdf: joint limits as Franka Emika publishes them ("Limits for Panda",
  frankaemika.github.io/docs/control_parameters.html; the same in franka_description); link masses
  and link 1's identified inertia Izz by Gaz et al. (IEEE RA-L 4(4), 2019); link 1's other inertia
  entries, which no fixed-base identification sees, from Franka Emika's CAD values scaled to Gaz et
  al.'s mass (the URDF's header says why). boom-panda's packaged Panda has the same limits.
- TREP: Table I (links) and Table II (base) of Nenchev et al. 1999; trep2's task arm is TREP's.
- The planar 3R: Sec. VI.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pinocchio as pin
import pytest

from rns_viz.model import FsmsModel
from tests.support.oracles.closed_forms import L1, L2, LG1, LG2, M1, M2

# Franka Emika, "Limits for Panda": rad, rad/s, N m
PANDA_POSITION = [(-2.8973, 2.8973), (-1.7628, 1.7628), (-2.8973, 2.8973), (-3.0718, -0.0698),
                  (-2.8973, 2.8973), (-0.0175, 3.7525), (-2.8973, 2.8973)]  # fmt: skip
PANDA_VELOCITY = [2.1750, 2.1750, 2.1750, 2.1750, 2.6100, 2.6100, 2.6100]
PANDA_TORQUE = [87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0]
# Gaz et al. 2019 (franka_description): link masses (kg), links 1-7, and link 1's Izz (kg m^2)
GAZ_MASS = [4.970684, 0.646926, 3.228604, 3.587895, 1.225946, 1.666555, 0.735522]
HAND_MASS = 0.73  # kg, franka_description's hand, fixed to link 7
GAZ_LINK1_IZZ = 0.009117
# Franka Emika's CAD values for link 1 (franka_description robots/fer/inertials.yaml): kg, kg m^2
CAD_LINK1_MASS = 2.7907
CAD_LINK1 = {"xx": 0.01564782655, "yy": 0.01439883526, "xy": 0.00000531236, "xz": -0.00003676721, "yz": -0.00248480843}


def arm_limits(model: pin.Model, first: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Lower, upper position, velocity and effort limits of the 7 joints from index ``first`` (pinocchio's v order)."""
    sl = slice(first, first + 7)
    return (model.lowerPositionLimit[sl], model.upperPositionLimit[sl], model.velocityLimit[sl], model.effortLimit[sl])


def assert_panda_limits(model: pin.Model, first: int) -> None:
    lower, upper, velocity, effort = arm_limits(model, first)
    np.testing.assert_array_equal(np.column_stack([lower, upper]), PANDA_POSITION)
    np.testing.assert_array_equal(velocity, PANDA_VELOCITY)
    np.testing.assert_array_equal(effort, PANDA_TORQUE)


def test_boom7s_panda_has_the_published_joint_limits(boom7: FsmsModel) -> None:
    assert_panda_limits(boom7.pin_model, boom7.m)


def test_boom_pandas_packaged_arm_has_the_published_joint_limits(boom_panda: FsmsModel) -> None:
    assert_panda_limits(boom_panda.pin_model, boom_panda.m)  # (skipped without the extra rns-viz[panda])


def test_boom7s_panda_has_gaz_et_al_masses_and_link1_izz_and_cad_link1_inertia(boom7: FsmsModel) -> None:
    inertias = [boom7.pin_model.inertias[boom7.m + 1 + i] for i in range(7)]
    np.testing.assert_allclose(
        [body.mass for body in inertias[1:]], [*GAZ_MASS[1:6], GAZ_MASS[6] + HAND_MASS], rtol=1e-12
    )
    link1 = inertias[0]  # link 1 alone (joint1's body: no fixed child)
    assert link1.mass == pytest.approx(GAZ_MASS[0], rel=1e-12)
    I = link1.inertia  # about link 1's centre of mass, in its frame
    assert I[2, 2] == pytest.approx(GAZ_LINK1_IZZ, rel=1e-12)
    scale = GAZ_MASS[0] / CAD_LINK1_MASS  # the same radii of gyration
    for (i, j), key in {(0, 0): "xx", (1, 1): "yy", (0, 1): "xy", (0, 2): "xz", (1, 2): "yz"}.items():
        assert I[i, j] == pytest.approx(scale * CAD_LINK1[key], rel=1e-3, abs=1e-8), key
    assert np.all(np.linalg.eigvalsh(I) > 0)
    principal = np.linalg.eigvalsh(I)
    assert principal[0] + principal[1] >= principal[2]  # a physical rigid body (triangle inequality)


def test_trep_is_table_i_and_table_ii(bundled_model: Callable[[str], FsmsModel]) -> None:
    """Link lengths l_1, l_2 (m), centres of mass lg_1, lg_2 (m), masses m_1, m_2 and the tip mass m_b
    (kg), k_b (N/m); the beam is 0.5 m long (its tip at 0.5 m); no base damping is given (D_b = 0)."""
    for name in ("trep", "trep2"):
        model = bundled_model(name)
        pm = model.pin_model
        j1, j2 = pm.getJointId("joint1"), pm.getJointId("joint2")
        assert pm.jointPlacements[j2].translation == pytest.approx([L1, 0.0, 0.0])
        frame = pm.frames[pm.getFrameId("ee")]
        assert frame.placement.translation == pytest.approx([L2, 0.0, 0.0])
        assert [pm.inertias[j].mass for j in (j1, j2)] == pytest.approx([M1, M2], rel=1e-12)
        assert [pm.inertias[j].lever[0] for j in (j1, j2)] == pytest.approx([LG1, LG2], rel=1e-12)
        base = pm.getJointId("base_x")
        assert pm.jointPlacements[base].translation == pytest.approx([0.0, 0.5, 0.0])  # beam length
        assert pm.inertias[base].mass == pytest.approx(0.795, rel=1e-12)  # tip mass m_b
        assert model.K_b[0, 0] == 77.9218 and model.D_b[0, 0] == 0.0


def test_planar3r_is_section_vi(planar3r: FsmsModel) -> None:
    """m_b = 1 kg, d_b = 0.1 N s/m, k_b = 100 N/m; links 1 m, 10 kg at each link centre, no link inertia."""
    model = planar3r
    pm = model.pin_model
    assert pm.inertias[1].mass == 1.0 and model.K_b[0, 0] == 100.0 and model.D_b[0, 0] == 0.1
    for j in range(2, 5):
        body = pm.inertias[j]
        assert body.mass == 10.0 and body.lever == pytest.approx([0.5, 0.0, 0.0])
        assert np.all(body.inertia == 0.0)
        if j > 2:
            assert pm.jointPlacements[j].translation == pytest.approx([1.0, 0.0, 0.0])
    assert pm.frames[pm.getFrameId("ee")].placement.translation == pytest.approx([1.0, 0.0, 0.0])
