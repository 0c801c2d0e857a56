"""The *Paper presets* folder's words and rows: each button's hint, the served model's row, the loaded
preset's description and what to look at."""

from __future__ import annotations

import viser

from rns_viz.scenarios import LIVE_SCENARIOS
from rns_viz.viz.panels.model_menu import ModelMenu


def preset_hint(names: tuple[str, ...]) -> str:
    """One click loads a figure's experiment; what each button is, in the paper's figure order."""
    what = "; ".join(f"{name}: {LIVE_SCENARIOS[name].description.split(': ', 1)[-1]}" for name in names)
    units = "Gains in 1/s, u-bar in 1/(kg m s)."
    return f"One click loads a figure's experiment (law, gains, motion, kicks, model). {what}. {units}"


def show_presets(presets: dict[str, viser.GuiButtonGroupHandle], menu: ModelMenu, model_key: str) -> None:
    """One row of presets per heading: models sharing a heading (boom7 and boom-panda: the same boom) share
    its row, which shows the served model's presets, else those of the first such model in the menu."""
    served = menu.source_key(model_key)
    shown: dict[str, str] = {}  # heading -> the key whose presets it shows
    for key in presets:
        heading = menu.presets_heading(key)
        if heading not in shown or key == served:
            shown[heading] = key
    for key, group in presets.items():
        visible = shown[menu.presets_heading(key)] == key
        if group.visible != visible:
            group.visible = visible


def preset_description(name: str | None) -> str:
    if name is None:
        return ""
    preset = LIVE_SCENARIOS[name]
    return f"**{name}**: {preset.description}.\n\n**Look at:** {preset.look} Reset restarts it."
