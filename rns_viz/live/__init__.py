"""The live session (no viser), in layers: each subpackage imports only those below it (import-linter
checks it, pyproject.toml's ``live-layers`` contract).

- :mod:`~rns_viz.live.loop`: the session other threads call, and the one loop that owns the state;
- :mod:`~rns_viz.live.teaching`, :mod:`~rns_viz.live.explorer`, :mod:`~rns_viz.live.outputs`: lessons,
  the gain explorer, and what is booked after every step (plots, readouts, reaction, recorder);
- :mod:`~rns_viz.live.runs`: the operated run and its shadow, their laws, kicks and divergence guard;
- :mod:`~rns_viz.live.operator` and :mod:`~rns_viz.live.jobs`: what the operator drives (references,
  targets, the operator lock), and slow work off the loop (worker thread, helper process);
- :mod:`~rns_viz.live.reach` and :mod:`~rns_viz.live.published`: where the arm can go without reaction,
  and the immutable records readers take (snapshot, recording, plot buffers).
"""
