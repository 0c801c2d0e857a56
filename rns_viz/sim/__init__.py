"""Simulation of the full FSMS: plant dynamics, integrator, disturbances, logging."""

from rns_viz.sim.disturbance import ForcePulse, NoForce
from rns_viz.sim.log import StepLog
from rns_viz.sim.plant import Plant
from rns_viz.sim.simulator import SimulationDiverged, Simulator

__all__ = ["ForcePulse", "NoForce", "Plant", "SimulationDiverged", "Simulator", "StepLog"]
