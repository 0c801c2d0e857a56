"""The kick response's scans (rns_viz.analysis.modal_sums: tops refined from the parabola through their samples,
rows leaving the Newton batch as they settle, crossings started on the chord) give the same map as the scans
they replaced (tests/support/oracles/scan_reference.py: each top from its sample, the batch iterating until every
row settles): peak, time to 10 % and sigma_b at every stable cell of one default map per model, to rounding."""

from __future__ import annotations

import numpy as np
import pytest

from rns_viz.analysis import default_axes, kick, linearise, map_of
from rns_viz.model import FsmsModel
from tests.support.oracles import scan_reference

MAPS = [("trep", "velocity"), ("planar3r", "acceleration"), ("boom7", "acceleration")]


@pytest.mark.parametrize(("name", "law"), MAPS)
def test_the_map_matches_the_previous_scans(name: str, law: str, monkeypatch: pytest.MonkeyPatch) -> None:
    loop = linearise(FsmsModel.from_name(name), law)
    g_b, g_m = default_axes(law, 60)
    got = map_of(loop, g_b, g_m).modes
    monkeypatch.setattr(kick, "modal_sums", scan_reference)
    want = map_of(loop, g_b, g_m).modes
    assert np.array_equal(got.stable, want.stable)
    stable = got.stable
    assert stable.sum() > 1000  # the default map is mostly stable: the comparison covers thousands of cells
    for field in ("peak", "base_time_to_10pct", "base_decay_rate"):
        a, b = getattr(got, field)[stable], getattr(want, field)[stable]
        np.testing.assert_allclose(a, b, rtol=1e-9, atol=0.0, err_msg=f"{name} {law}: {field}")
    assert np.array_equal(got.reason, want.reason)
