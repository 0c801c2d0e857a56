"""Gain analysis: the closed loop of the simulator linearised in the gains (g_b, g_m).

- :func:`linearise` -> :class:`LinearLoop`, A(g_b, g_m) = A0 + g_b A_b + g_m A_m about a rest configuration;
- :func:`modes_of` -> :class:`Modes`, poles split into the base group and the arm group;
- :func:`gain_map` / :func:`map_of` -> :class:`GainMap`, :func:`root_locus` -> :class:`Locus`;
- :func:`loops_along` + :func:`authority` -> :class:`Authority` along a path (:func:`joined` of runs);
  :func:`fit_decay` -> :class:`DecayFit`;
- :class:`Kick` (:func:`default_kick`): the push whose response a map predicts; :func:`measure_kick` reads a log alike.
"""

from rns_viz.analysis.authority import (
    Authority,
    DecayFit,
    KickMeasure,
    authority,
    fit_decay,
    joined,
    loops_along,
    measure_kick,
)
from rns_viz.analysis.gain_map import (
    G_M_MEANING,
    GAIN_RANGE,
    PAPER_GAINS,
    GainMap,
    Locus,
    PaperGains,
    default_axes,
    gain_map,
    map_of,
    root_locus,
)
from rns_viz.analysis.kick import Kick, default_kick
from rns_viz.analysis.linear import EQUATIONS, ClosedLoop, LinearLoop, build_law, law_kind, linearise
from rns_viz.analysis.modes import BASE_SHARE, Modes, modes_of

__all__ = [
    "BASE_SHARE",
    "EQUATIONS",
    "GAIN_RANGE",
    "G_M_MEANING",
    "PAPER_GAINS",
    "Authority",
    "ClosedLoop",
    "DecayFit",
    "GainMap",
    "Kick",
    "KickMeasure",
    "LinearLoop",
    "Locus",
    "Modes",
    "PaperGains",
    "authority",
    "build_law",
    "default_axes",
    "default_kick",
    "fit_decay",
    "gain_map",
    "joined",
    "law_kind",
    "linearise",
    "loops_along",
    "map_of",
    "measure_kick",
    "modes_of",
    "root_locus",
]
