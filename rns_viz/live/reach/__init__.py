"""Where a target may go: the reactionless reachable set (the library's, :mod:`rns_viz.paths`) as the operator's
region, the inside test and clamping to it, and the arm's reach."""
