"""Slow work off the simulation loop: the helper process that computes path tables, reachable sets and
linearisations (a one-process pool of concurrent.futures, rns_viz.live.jobs.helper), the worker thread
that calls it, and the epoch-tagged requests of the loop."""
