"""Building blocks of the live session (no viser): references the operator moves, kicks, pacing,
plot buffers, the background worker and the law set-up. :mod:`rns_viz.session` puts them together."""
