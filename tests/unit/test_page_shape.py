"""Which pages count as a phone's: the server sees a page's scene in drawing pixels (CSS px times the
screen's density, lowered by viser while a page draws slowly), so the rule must give the same answer for
a page at any density."""

from __future__ import annotations

import pytest

from rns_viz.viz.scene.framing import NARROW_BAND, band_for, framing_holds, is_narrow, main_panel_box

PHONES = [(390, 844), (430, 932), (412, 785), (360, 800), (390, 664)]  # CSS px, upright, toolbars or not
DESKTOPS = [(536, 800), (622, 768), (696, 900), (1176, 1080)]  # the scene between the docked panels


@pytest.mark.parametrize("density", [1.0, 0.875, 2.0, 3.0])
def test_a_phone_is_narrow_and_a_desktop_wide_at_any_density(density: float) -> None:
    for w, h in PHONES:
        size = (w * density, h * density)
        assert is_narrow(*size) and band_for(*size) == NARROW_BAND and main_panel_box(*size) is None, size
    for w, h in DESKTOPS:
        size = (w * density, h * density)
        assert not is_narrow(*size) and band_for(*size) == (-1.0, 1.0) and main_panel_box(*size) is not None, size


def test_no_size_yet_is_not_narrow() -> None:
    assert not is_narrow(0, 0) and not is_narrow(390, 0)


def test_a_paced_pages_panel_covers_its_slowed_line_too() -> None:
    """The slowed-display line joins the floating panel of a paced page: the box the labels keep clear of grows
    by its height there, and only there (a phone's panel is a sheet below the band: no box either way)."""
    from rns_viz.viz.scene.framing import NOTICE_HEIGHT_PX, main_panel_box

    plain, slowed = main_panel_box(614, 768), main_panel_box(614, 768, notice=True)
    assert plain is not None and slowed is not None
    assert slowed[:3] == plain[:3] and slowed[3] == plain[3] + NOTICE_HEIGHT_PX
    assert main_panel_box(390, 844, notice=True) is None


@pytest.mark.parametrize("density", [0.75, 0.875, 2.0])
def test_a_framing_holds_through_a_density_change_and_not_through_a_new_shape(density: float) -> None:
    """A page framed at one size keeps the framing when viser changes its drawing density (the size scales,
    the shape stays) or the size moves by rounding; a new shape (a phone turned wide, a panel docked) does not."""
    framed = (614.0, 768.0)
    assert framing_holds(framed, (614.0, 768.0)) and framing_holds(framed, (619.0, 764.0))
    assert framing_holds(framed, (round(614 * density), round(768 * density)))
    assert not framing_holds(framed, (390.0 * density, 844.0 * density))
    assert not framing_holds(framed, (1366.0 * density, 768.0 * density))
