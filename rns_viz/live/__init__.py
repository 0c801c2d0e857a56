"""The live session (no viser): :mod:`rns_viz.live.session` is the boundary other threads call;
typed commands (:mod:`~rns_viz.live.commands`) are applied by the loop-owned
:class:`~rns_viz.live.state.LiveState`, which holds the run pair (:mod:`~rns_viz.live.runs`), the
operator and its references (:mod:`~rns_viz.live.operator`, :mod:`~rns_viz.live.references`),
background geometry (:mod:`~rns_viz.live.background`) and what is published (:mod:`~rns_viz.live.outputs`)."""
