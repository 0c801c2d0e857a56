"""Simulation of the full FSMS: plant dynamics, integrator, disturbances, logging, the arm's reaction on its base."""

from rns_viz.sim.disturbance import ForcePulse, NoForce
from rns_viz.sim.log import StepLog
from rns_viz.sim.plant import Plant
from rns_viz.sim.reaction import ReactionProbe
from rns_viz.sim.simulator import SimulationDiverged, Simulator

__all__ = ["ForcePulse", "NoForce", "Plant", "ReactionProbe", "SimulationDiverged", "Simulator", "StepLog"]
