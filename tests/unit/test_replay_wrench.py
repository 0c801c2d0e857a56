"""The reaction's columns in a recording: one for a 1-DOF base, one per base row otherwise."""

from __future__ import annotations

from rns_viz.live.published.recording import reaction_columns


def test_a_recording_keeps_every_row_of_the_reaction() -> None:
    assert reaction_columns(1) == ("reaction",)  # a 1-DOF base: one column, its name unchanged
    assert reaction_columns(6) == tuple(f"reaction_{i}" for i in range(1, 7))
