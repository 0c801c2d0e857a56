"""The app's panels: every GUI element, built once by :func:`make_gui`.

Three places (see the comment in :func:`make_gui`): *Live plots* docked left; *Controls* docked right
(the status line, lessons, *Operate*, *Paper presets*, *Readouts*, *Reactionless path* or
*Target*, *Control law and gains*, *Model and view*, the rest), with a *Help* tab; viser's main panel,
small and floating, with *Frame robot* (and each page's operator seat). Labels carry units; hints
explain the symbols. Model-specific elements are shown or hidden by the app, and their words set per
model (rns_viz.viz.panels.model_words).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import viser
import viser.uplot

from rns_viz.defaults import defaults_for
from rns_viz.live.loop.commands import LIVE_LAWS as LAW_KINDS
from rns_viz.live.loop.wall_clock import SPEEDS
from rns_viz.live.runs.laws import LAW_LABELS
from rns_viz.scenarios import FIG11_FAST_S, FIG11_SLOW_S, presets_for
from rns_viz.viz.panels.glossary import glossary_markdown
from rns_viz.viz.panels.live_plots import LivePlots
from rns_viz.viz.panels.model_menu import ModelMenu
from rns_viz.viz.panels.number_field import NumberField, hide_slider_boxes
from rns_viz.viz.panels.preset_rows import preset_hint, show_presets
from rns_viz.viz.scene.framing import MAIN_PANEL_PX

PLOTS_WIDTH_PX = 360  # the docked plots' width: a 1366 px screen keeps ~600 px of scene between the panels
CONTROLS_WIDTH_PX = 384  # the docked controls' width (viser's "large" control panel)
SPEED_LABELS = {0.125: "1/8×", 0.25: "1/4×", 0.5: "1/2×", 1.0: "1×", 2.0: "2×"}

# g_m's label under each law: joint damping in (15)/(16), the pull to the joint reference in (30)
G_M_LABELS: dict[str, str] = {
    "acceleration": "Joint damping g_m (1/s)",
    "torque": "Joint damping g_m (1/s)",
    "velocity": "Joint hold g_m (1/s)",
}
# (name, label, min, max, step, hint) of every gain slider; units in the labels.
GAIN_SLIDERS: tuple[tuple[str, str, float, float, float, str], ...] = (
    (
        "g_b",
        "Base damping g_b (1/s)",
        0.0,
        50.0,
        0.1,
        "How hard the arm fights the base's swing (1/s): bigger damps faster. g_b of Eqs. (15), (16), (30).",
    ),
    (
        "g_m",
        "Joint hold g_m (1/s)",  # relabelled with the law: G_M_LABELS
        0.0,
        100.0,
        0.1,
        "How firmly the joints are held (1/s). Two meanings: joint damping in laws (15)/(16), "
        "the pull back to the path in law (30).",
    ),
    (
        "G_p",
        "Hand pull G_p (1/s²)",
        0.0,
        2000.0,
        1.0,
        "How strongly the hand is pulled to the target (1/s²), Eq. (24) (end-effector tracking).",
    ),
    (
        "G_d",
        "Hand damping G_d (1/s)",
        0.0,
        500.0,
        1.0,
        "How much the hand's motion is damped (1/s), Eq. (24) (end-effector tracking).",
    ),
    (
        "k_p",
        "Joint stiffness k_p (1/s²)",
        0.0,
        2000.0,
        1.0,
        "How stiffly the joints follow the path's reference (1/s²), laws (15)/(16) (along a reactionless path).",
    ),
    (
        "k_d",
        "Joint damping k_d (1/s)",
        0.0,
        200.0,
        0.5,
        "How much the joints' following is damped (1/s), laws (15)/(16) (along a reactionless path).",
    ),
)


@dataclass
class GuiElements:
    """Handles of everything in the panel (the app reads and wires them; tests find them here)."""

    status: viser.GuiHtmlHandle
    frame_robot: viser.GuiButtonHandle
    kick: viser.GuiButtonHandle
    kick_peak: NumberField
    suppression: viser.GuiCheckboxHandle
    pause: viser.GuiButtonHandle
    step: viser.GuiButtonHandle
    reset: viser.GuiButtonHandle
    speed: viser.GuiDropdownHandle
    readouts: viser.GuiHtmlHandle
    plots: LivePlots
    plots_panel: viser.PanelHandle
    controls_panel: viser.PanelHandle
    controls_tab: viser.GuiTabHandle  # the app adds its other folders inside it (``with gui.controls_tab:``)
    path_folder: viser.GuiFolderHandle
    sigma: NumberField
    play_slow: viser.GuiButtonHandle
    play_fast: viser.GuiButtonHandle
    cyclic: viser.GuiButtonHandle
    point_to_point: viser.GuiButtonHandle
    ubar_speed: NumberField
    target_folder: viser.GuiFolderHandle
    target_text: viser.GuiMarkdownHandle
    target_speed: NumberField
    gains_folder: viser.GuiFolderHandle
    law: viser.GuiDropdownHandle
    gains: dict[str, NumberField]
    presets: dict[str, viser.GuiButtonGroupHandle]  # model key -> its presets, in the menu's order
    preset_paused: viser.GuiCheckboxHandle
    preset_info: viser.GuiMarkdownHandle
    model: viser.GuiDropdownHandle
    menu: ModelMenu
    exaggeration: NumberField
    auto_exaggeration: viser.GuiCheckboxHandle
    shadow: viser.GuiCheckboxHandle
    download: viser.GuiButtonHandle

    @property
    def plot_xb(self) -> viser.GuiUplotHandle:
        """The linear x_b chart shown now (its legend names the served model's two runs)."""
        return self.plots.xb

    @property
    def plot_L(self) -> viser.GuiUplotHandle:
        return self.plots.L

    @property
    def plot_error(self) -> viser.GuiUplotHandle:
        """The end-effector error chart shown now (its unit suits the data)."""
        return self.plots.error


def make_gui(server: viser.ViserServer, model: str, menu: ModelMenu | None = None) -> GuiElements:
    """Build the panel for ``model`` (its kick range and exaggeration; ``menu``: the models offered, by
    default the bundled ones); the app wires the callbacks."""
    menu = menu or ModelMenu((model,))
    gui = server.gui
    gui.configure_theme(control_width="large", show_logo=False, dark_mode=False)
    # Three places. The live plots dock left, in view beside the robot whatever the controls are scrolled
    # to; the status line and the controls dock right in a panel of their own; viser's main panel keeps only
    # Frame robot and who operates (a page's own), floating small in the scene's top right corner (callouts
    # keep off it). On a phone viser shows the main panel as a sheet over the page, opened: it is short this
    # way, and the two panels are sections under it (the plots opened, so a watcher sees the base plot; the
    # controls closed until tapped).
    x, y, width = MAIN_PANEL_PX
    gui.main_panel.float(x=x, y=y, width=width)
    hide_slider_boxes(gui)  # every slider's value is shown and typed in its NumberField's box
    controls_panel = gui.add_panel(order=-1.0)  # first of the phone's sections: a short bar when closed
    controls_tab = controls_panel.add_tab("Controls", viser.Icon.ADJUSTMENTS)
    with controls_panel.add_tab("Help: words and keys", viser.Icon.HELP):
        gui.add_markdown(glossary_markdown())
    controls_panel.dock_right()
    controls_panel.set_width(CONTROLS_WIDTH_PX)
    plots_panel = gui.add_panel(order=0.0)
    with plots_panel.add_tab("Live plots (last 10 s)", viser.Icon.CHART_LINE):
        plots = LivePlots(gui)
    plots_panel.dock_left()
    plots_panel.set_width(PLOTS_WIDTH_PX)
    plots_panel.expand()  # on a phone too (panels there start closed)
    frame_robot = gui.add_button(
        "Frame robot",
        icon=viser.Icon.FOCUS_CENTERED,
        hint="Your camera back on the robot, framed for your screen (key F). Moves only your own view.",
    )
    with controls_tab:
        status = gui.add_html("")  # first in the controls (on a phone: closed, the base plot higher up)
        elements = _controls(gui, model, menu)
    return GuiElements(
        status=status,
        frame_robot=frame_robot,
        plots=plots,
        plots_panel=plots_panel,
        controls_panel=controls_panel,
        controls_tab=controls_tab,
        menu=menu,
        **elements,
    )


def _controls(gui: viser.GuiApi, model: str, menu: ModelMenu) -> dict[str, Any]:
    """The controls panel's own elements, by the names of :class:`GuiElements`."""
    defaults = defaults_for(model)
    gui.add_markdown(
        "**Try:** a *Paper preset*, then *Resume*; *Kick the base* with suppression on and off; "
        "drag the handle labelled **drag me** in the scene (its arrows or its square)."
    )
    with gui.add_folder("Operate"):
        kick = gui.add_button(
            "Kick the base",
            icon=viser.Icon.HAND_FINGER,
            color="red",
            hint="Push the base once with a short force pulse (size below, N); the shadow run gets the same push.",
        )
        kick_peak = NumberField(
            gui,
            "Kick strength, peak force (N)",
            min=-defaults.kick_range_N,
            max=defaults.kick_range_N,
            step=0.1,
            initial_value=defaults.kick_peak_N,
            hint="Peak of the half-sine force pulse on the base (N); the app says more per model.",
            bounded=True,  # read at the next kick
        )
        suppression = gui.add_checkbox(
            "Vibration suppression",
            True,
            hint="On: the arm moves to damp the base's swing (the g_b term). The ghost has it the other way.",
        )
        pause = gui.add_button(
            "Pause", icon=viser.Icon.PLAYER_PAUSE, hint="Freeze the simulation; press again to go on."
        )
        step = gui.add_button(
            "Step 1 ms", icon=viser.Icon.PLAYER_TRACK_NEXT, hint="Pauses, then advances one 1 ms step."
        )
        reset = gui.add_button(
            "Reset", icon=viser.Icon.REFRESH, hint="Back to the start (of the preset, if one is loaded)."
        )
    with gui.add_folder("Paper presets"):
        presets = {}
        for key in menu.keys.values():  # each model's presets ([app] presets), under its heading
            names = presets_for(key)
            if names:
                heading = menu.presets_heading(key)
                presets[key] = gui.add_button_group(heading, names, hint=preset_hint(names))
        show_presets(presets, menu, model)
        preset_paused = gui.add_checkbox(
            "Start paused",
            True,
            hint="A preset waits at t = 0 for Resume, so its kick and motion happen with the plots in view.",
        )
        preset_info = gui.add_markdown("")
    with gui.add_folder("Readouts"):
        readouts = gui.add_html("")
    with gui.add_folder("Reactionless path") as path_folder:
        gui.add_markdown(
            "Drag the handle labelled **drag me** in the scene: the end effector moves along its current "
            "reactionless path (crimson) to the point nearest the handle. Or scrub the path position."
        )
        sigma = NumberField(
            gui,
            "Position along the path ∫ū dt (1/(kg·m))",
            min=-80.0,
            max=80.0,
            step=0.1,
            initial_value=0.0,
            hint="Where the arm is along its reactionless path; the paper's ∫ū dt of Eq. (30), in 1/(kg·m). "
            "The line below says it in joint angles.",
            bounded=True,  # the path's range (the loop would take any number to its nearest end)
        )
        play_slow = gui.add_button(
            f"Play path slowly ({FIG11_SLOW_S:g} s)",
            icon=viser.Icon.PLAYER_PLAY,
            hint="Move the arm along the whole reactionless path in this many seconds (Fig. 11 a).",
        )
        play_fast = gui.add_button(
            f"Play path fast ({FIG11_FAST_S:g} s)",
            icon=viser.Icon.PLAYER_PLAY,
            hint="The same path, fast: the base still stays still (Fig. 11 b).",
        )
        point_to_point = gui.add_button(
            "Same end points, joint space",
            icon=viser.Icon.ARROWS_RIGHT_LEFT,
            hint="Fig. 11(b): a point-to-point joint motion ('link 2 only' from the start pose) between the end "
            "points of 'Play path fast', at the same speed. Watch the base.",
        )
        cyclic = gui.add_button(
            "Start cyclic motion",
            icon=viser.Icon.REPEAT,
            hint="Go round the path again and again at the ū speed below.",
        )
        ubar_speed = NumberField(
            gui,
            "Speed along the path ū (1/(kg·m·s))",
            min=1.0,
            max=100.0,
            step=1.0,
            initial_value=30.0,
            hint="How fast the arm moves along the path, the paper's ū in 1/(kg·m·s) (Fig. 12 uses 30); "
            "the line above turns it into joint speeds.",
            bounded=False,
        )
    with gui.add_folder("Target") as target_folder:
        target_text = gui.add_markdown("")  # how the handle works for the model served (model_words)
        target_speed = NumberField(
            gui,
            "Target speed (m/s)",
            min=0.05,
            max=2.0,
            step=0.05,
            initial_value=0.5,
            hint="Speed limit of the smoothed target.",
            bounded=False,
        )
    with gui.add_folder("Control law and gains", expand_by_default=False) as gains_folder:
        law = gui.add_dropdown(
            "Law",
            tuple(LAW_LABELS[k] for k in LAW_KINDS),
            initial_value=LAW_LABELS["velocity"],
            hint="Which of the paper's control laws drives the arm: joint accelerations (15), torques (16) "
            "or velocities (30).",
        )
        gains = {
            name: NumberField(gui, label, min=lo, max=hi, step=step, initial_value=lo, hint=hint, bounded=False)
            for name, label, lo, hi, step, hint in GAIN_SLIDERS
        }
    with gui.add_folder("Model and view", expand_by_default=False):
        model_dd = gui.add_dropdown(
            "Model",
            menu.labels,
            initial_value=menu.label(model),
            hint="The bundled models (each labelled by its parameter file) and the files given with --model "
            "(rns-viz serve --model FILE.toml).",
        )
        exaggeration = NumberField(
            gui,
            "Base deflection drawn ×",
            min=1.0,
            max=100.0,
            step=1.0,
            initial_value=defaults.exaggeration,
            hint="The base deflection is drawn this many times larger than simulated (written beside the base). "
            "Typing a factor fixes it (Auto off).",
            bounded=True,  # only drawn
        )
        auto_exaggeration = gui.add_checkbox(
            "Auto deflection scale",
            defaults.auto_exaggeration,
            hint="The factor follows the motion: the recent largest base deflection is drawn at about a tenth "
            "of the arm's reach (1-2-5 steps up to ×10000), so µm and mm both show.",
        )
        speed = gui.add_dropdown(
            "Speed",
            tuple(SPEED_LABELS[s] for s in SPEEDS),
            initial_value="1×",
            hint="Simulated seconds per wall-clock second.",
        )
        shadow = gui.add_checkbox(
            "Ghost run (suppression the other way)",
            True,
            hint="The shadow run: a second simulation with the same inputs and kicks and suppression the other way: "
            "the ghost (blue: suppression on, red: off, as the plot lines) and the second plot lines.",
        )
    download = gui.add_button(
        "Download log (CSV)",
        icon=viser.Icon.DOWNLOAD,
        hint="The last 20 s of the simulation, one row per 1 ms step, SI units (the documentation lists the columns).",
    )
    return dict(
        kick=kick,
        kick_peak=kick_peak,
        suppression=suppression,
        pause=pause,
        step=step,
        reset=reset,
        speed=speed,
        readouts=readouts,
        path_folder=path_folder,
        sigma=sigma,
        play_slow=play_slow,
        play_fast=play_fast,
        cyclic=cyclic,
        point_to_point=point_to_point,
        ubar_speed=ubar_speed,
        target_folder=target_folder,
        target_text=target_text,
        target_speed=target_speed,
        gains_folder=gains_folder,
        law=law,
        gains=gains,
        presets=presets,
        preset_paused=preset_paused,
        preset_info=preset_info,
        model=model_dd,
        exaggeration=exaggeration,
        auto_exaggeration=auto_exaggeration,
        shadow=shadow,
        download=download,
    )
