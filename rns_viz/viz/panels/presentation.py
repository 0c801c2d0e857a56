"""``rns-viz serve --present``: the screen for a projector. Larger text, wider docked plots, and only
the panel's folders a demonstration needs (the gain explorer, record and replay, the control law's
gains and the log download are hidden; everything else stays, keys included).

viser's ``configure_theme`` has no text size, so the page's root font size is raised with a style
element (the panel's and plots' sizes are in rem, so they scale with it); scene labels keep their size.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Protocol

import viser

TEXT_SCALE = 1.25  # root font size, times the browser's default
PRESENT_CSS = f"<style>html {{ font-size: {100 * TEXT_SCALE:g}%; }}</style>"
PLOTS_WIDTH_PX = 440  # the docked plots, wider for the larger text (1920 px projector: ~1100 px of scene)


class Hideable(Protocol):
    visible: bool


def present(gui: viser.GuiApi, plots_panel: viser.PanelHandle, hidden: Iterable[Hideable]) -> viser.GuiHtmlHandle:
    """Turn the page into the presentation screen; returns the style element added."""
    for element in hidden:
        element.visible = False
    plots_panel.set_width(PLOTS_WIDTH_PX)
    return gui.add_html(PRESENT_CSS)
