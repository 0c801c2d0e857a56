"""The live session's boundary and its loop: :class:`~rns_viz.live.loop.session.Session` is what other
threads call; its typed commands (:mod:`~rns_viz.live.loop.commands`, the one input check) are applied
between steps by the loop-owned :class:`~rns_viz.live.loop.state.LiveState`, which also ticks the runs,
paces them to the wall clock, replays recordings and publishes a snapshot after each step."""
