"""Per-model defaults in one table: the law and gains the app starts with, kick sizes, drawing scale.

The paper's experiments (rns_viz.scenarios) use the paper's gains; these are what the live app offers
first. Units: gains as in :class:`~rns_viz.control.Gains`, forces N, durations s.

Why these gains. Law (30), TREP: g_b = 24, g_m = 20 as in Fig. 10. Laws (15)/(16): with the joints'
motion outside the RNS damped by G_m and the base by g_b, the base closed loop (1-DOF base, stiffness
k, no structural damping) has the characteristic polynomial
    H_b s^3 + H_b (G_m + g_b) s^2 + k s + k G_m,
whose slowest root decays fastest near g_b = 10, G_m = 2 for TREP (about 4 /s). The 3R would decay
fastest near g_b = 2.5, G_m = 0.4 (0.92 /s), but absorbing a 5 N kick then shifts the arm's
centre of mass so far (by about H_b g_b x_b / G_m) that the arm, holding its end effector, runs into a
singularity of J-bar = J P_RNS; G_m = 1 (Fig. 3's value) decays at 0.37 /s and keeps the end effector
on target.

Kicks. "An arbitrary external force" (Sec. VII-D): a half-sine push on the base along x. TREP:
0.8 N for 0.1 s, an impulse of 0.051 N s, about 5 mm of deflection. The 3R: 5 N for 0.2 s on its
31 kg base (0.64 N s, about 1.1 cm); law (15) absorbs a deflection by moving the arm's centre of
mass, so a much larger kick needs more than the arm's reach and drives it into H_bm = 0.

trep2 (TREP with a compensating second arm, Sec. III-B): only the compensating law, resolved
acceleration like (15), with TREP's (15) gains g_b = 10 (now through the compensator alone) and
G_m = 2 on the coupling momentum; TREP's kick (the beam and tip are TREP's). The task target moves
at 0.1 m/s (half the task arm's reach per second): the compensator, about 1.1 times as fast as the
task arm to cancel it, then turns at 1-2 rad/s, far below its joints' URDF velocity limits
(20 rad/s), above which the app says the compensator is asked too much.

boom7 (the spatial model): law (15) with g_b = 10, G_m = 2 on all six
tip modes (the kick preset's, rns_viz.scenarios); kicks of 5 N, 0.1 s (the preset's lateral size:
about 1.5 mm of a 4 m boom with the arm held, drawn 50x). Its kick needs a direction: along the first
base coordinate alone it would push the stiff axial mode (157 Hz, 1e-7 m).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from rns_viz.control import Gains, LawKind
from rns_viz.params import model_source


@dataclass(frozen=True)
class ModelDefaults:
    law: LawKind  # the law the app starts with
    gains: dict[LawKind, Gains] = field(default_factory=dict)  # per law; others get FALLBACK_GAINS
    kick_peak_N: float = 1.0  # the kick button's default peak force
    kick_duration_s: float = 0.1  # half-sine duration of a kick
    kick_range_N: float = 5.0  # the kick slider's half range
    kick_axis: int = 0  # the base coordinate a kick pushes along first (the panel's choice, the gain map's kick)
    exaggeration: float = 10.0  # drawn deflection factor
    target_speed_m_s: float = 0.5  # speed limit of the smoothed end-effector target

    def gains_for(self, law: LawKind) -> Gains:
        return self.gains.get(law, FALLBACK_GAINS)


FALLBACK_GAINS = Gains(g_b=10.0, g_m=1.0)
# m: a kick about a rotational base coordinate is the moment of the kick's force at this lever arm
# (boom7: the slider's 20 N give 2 N m). A moment equal to the force in N would be a lever of 1 m, and
# 5 N m about the boom's z axis asks the suppressing arm to spin at over 100 rad/s (the run stops).
KICK_LEVER_M = 0.1

MODEL_DEFAULTS: dict[str, ModelDefaults] = {
    "trep": ModelDefaults(
        law="velocity",
        gains={
            "velocity": Gains(g_b=24.0, g_m=20.0),
            "acceleration": Gains(g_b=10.0, g_m=2.0),
            "torque": Gains(g_b=10.0, g_m=2.0),
        },
        kick_peak_N=0.8,
        kick_duration_s=0.1,
        kick_range_N=5.0,
        exaggeration=10.0,
    ),
    "planar3r": ModelDefaults(
        law="acceleration",
        gains={
            "acceleration": Gains(g_b=2.5, g_m=1.0),
            "torque": Gains(g_b=2.5, g_m=1.0),
            "velocity": Gains(g_b=2.5, g_m=1.0),
        },
        kick_peak_N=5.0,
        kick_duration_s=0.2,
        kick_range_N=50.0,
        exaggeration=20.0,
    ),
    "boom7": ModelDefaults(
        law="acceleration",
        gains={"acceleration": Gains(g_b=10.0, g_m=2.0), "torque": Gains(g_b=10.0, g_m=2.0)},
        kick_peak_N=5.0,
        kick_duration_s=0.1,
        kick_range_N=20.0,
        kick_axis=1,  # y: sideways, where the boom is soft (along x it is stiff)
        exaggeration=50.0,
    ),
    "trep2": ModelDefaults(
        law="acceleration",
        gains={"acceleration": Gains(g_b=10.0, g_m=2.0)},
        kick_peak_N=0.8,
        kick_duration_s=0.1,
        kick_range_N=5.0,
        exaggeration=10.0,
        target_speed_m_s=0.1,
    ),
}
MODEL_DEFAULTS["boom-panda"] = MODEL_DEFAULTS["boom7"]  # the same boom and a Panda of the same kinematics and mass
GENERIC_DEFAULTS = ModelDefaults(law="acceleration")


def defaults_for(model: str) -> ModelDefaults:
    """The defaults of a bundled model (by name or model key); a model from a parameter file gets generic ones."""
    return MODEL_DEFAULTS.get(model_source(model), GENERIC_DEFAULTS)
