"""The gain explorer in a real headless Chromium: the map appears beside the robot, its drawn pixels agree
with its numbers and its legend, a real mouse click on it applies the cell's gains, and screenshots go to
artifacts/gain_map_<model>.png."""

from __future__ import annotations

import io
import math
import re
import time
from collections.abc import Iterator

import numpy as np
import pytest
from PIL import Image
from playwright.sync_api import Page
from viser import ClientHandle

from rns_viz.analysis import GainMap
from rns_viz.live.runs.laws import LAW_LABELS
from rns_viz.viz.panels.gain_panel import QUANTITIES
from rns_viz.viz.scene.framing import main_panel_box
from rns_viz.viz.scene.fsms_scene import REFRAME_SETTLE_S
from rns_viz.viz.scene.gain_scene import (
    MISSING_RGB,
    UNSTABLE_HATCH,
    UNSTABLE_RGB,
    GainScene,
    axis_fraction,
    colours,
    map_rates,
    not_predictable,
)
from rns_viz.viz.scene.view_toggles import TOGGLES
from rns_viz.viz.server.app import RnsApp, start_app
from tests.browser.test_stage_browser import shown_size
from tests.support.browser import (
    browser_page,
    dismiss_notifications,
    each_model_app,  # noqa: F401 (the fixture 'app')
    hide_toasts,
    open_folder,
    screenshot,
    settle_for_picture,
    wait_for_frames,
    wait_for_nodes,
    wait_until,
)

TOGGLE_LABELS = {name: label for name, label, _, _ in TOGGLES}
PROJECT_JS = """(points) => {
    const m = window.__viserMutable;
    const node = m?.nodeRefFromName?.["/gain_map"];
    const camera = m?.camera;
    const canvas = [...document.querySelectorAll("canvas")].sort(
        (a, b) => b.clientWidth * b.clientHeight - a.clientWidth * a.clientHeight
    )[0];  // the scene's, not a plot's
    if (!node || !camera || !canvas) return null;
    node.updateWorldMatrix(true, false);
    const r = canvas.getBoundingClientRect();
    return points.map((p) => {
        const v = node.localToWorld(new node.position.constructor(p[0], p[1], p[2])).project(camera);
        return [r.left + (v.x + 1) / 2 * r.width, r.top + (1 - v.y) / 2 * r.height];
    });
}"""  # page pixels of points given in the map's frame, projected by the page's own camera


def screen_point(page: Page, local: tuple[float, float, float]) -> tuple[float, float] | None:
    """Page pixel of a point given in the map's frame, projected by the page's own camera."""
    pixels = page.evaluate(PROJECT_JS, [list(local)])
    return None if pixels is None else tuple(pixels[0])


SCENE_RECT_JS = """() => {
    const canvas = [...document.querySelectorAll("canvas")].sort(
        (a, b) => b.clientWidth * b.clientHeight - a.clientWidth * a.clientHeight
    )[0];
    const r = canvas.getBoundingClientRect();
    return [r.left, r.top, r.right, r.bottom];
}"""  # page pixels of the scene's canvas (between the docked panels)


def map_on_screen(page: Page, scene: GainScene) -> bool:
    """Every corner of the map inside the scene's canvas, as the page's camera sees it now."""
    half = 0.5 * scene.size
    corners = [screen_point(page, (x, y, 0.0)) for x in (-half, half) for y in (-half, half)]
    left, top, right, bottom = page.evaluate(SCENE_RECT_JS)
    return all(c is not None and left <= c[0] <= right and top <= c[1] <= bottom for c in corners)


def test_gain_map_in_chromium(app: RnsApp) -> None:
    ex = app.renderer.explorer
    with browser_page(app.server, width=1500, height=900) as page:
        wait_until(lambda: ex.scene is not None and ex.scene.gain_map is not None, 60.0, "the gain map")
        wait_for_nodes(page, {GainScene.FRAME, GainScene.IMAGE, GainScene.NOW})
        dismiss_notifications(page)
        scene = ex.scene
        assert scene is not None and scene.gain_map is not None
        assert not scene.frame.visible  # out of the scene until its box is ticked
        # The user ticks the map; every camera then frames the robot with the map beside it.
        open_folder(page, "Show in the scene")
        page.get_by_role("checkbox", name=TOGGLE_LABELS["gain_map"]).click()
        wait_until(lambda: app.view.on("gain_map") and scene.frame.visible, 10.0, "the gain map shown")
        wait_until(lambda: map_on_screen(page, scene), 10.0, "the whole map in the page's view")
        gm = scene.gain_map
        # A real click on a stable cell applies it.
        i, j = 18, 30
        assert gm.stable[i, j]
        u, v = axis_fraction(gm.g_b, gm.g_b[i]), axis_fraction(gm.g_m, gm.g_m[j])
        pixel = screen_point(page, ((u - 0.5) * scene.size, (v - 0.5) * scene.size, 0.0))
        assert pixel is not None, "the page's camera or the map was not found"
        want = (float(gm.g_b[i]), float(gm.g_m[j]))

        def applied() -> bool:
            return (app.session.snapshot().settings.gains.g_b, app.session.snapshot().settings.gains.g_m) == want

        # A toast arriving late (a busy machine) can sit over the map's corner and take the click:
        # close toasts and click again, as a user would; the gains must then be the cell's.
        for _ in range(3):
            dismiss_notifications(page)
            page.mouse.click(*pixel)
            deadline = time.monotonic() + 10.0
            while not applied() and time.monotonic() < deadline:
                time.sleep(0.05)
            if applied():
                break
        assert applied(), f"a click in the browser did not apply {want}"
        wait_until(lambda: app.plot_updates > 5, 15.0, "live plot updates")
        page.mouse.move(5, 5)
        page.get_by_text("Gain explorer", exact=True).scroll_into_view_if_needed()
        dismiss_notifications(page)
        settle_for_picture(page, 40)
        path = screenshot(page, f"gain_map_{app.model_name}")
        assert path.stat().st_size > 10_000
        page.get_by_text("Root locus: g_m", exact=False).first.scroll_into_view_if_needed()
        settle_for_picture(page, 10)
        assert screenshot(page, f"gain_loci_{app.model_name}").stat().st_size > 10_000
        # The arm mode's map: the second subsystem of Sec. VIII.
        legend = ex.scene.legend
        app.controls.show(ex.quantity, next(k for k, q in QUANTITIES.items() if q == "arm"))
        wait_until(lambda: legend.text.startswith("σ_a"), 10.0, "the arm mode's map")
        settle_for_picture(page, 20)
        assert screenshot(page, f"gain_map_arm_{app.model_name}").stat().st_size > 10_000
        assert np.isfinite(app.session.gain_view().predicted)
        if app.model_name == "trep":  # predicted vs measured, after a kick from the page's button
            app.controls.show(ex.quantity, next(iter(QUANTITIES)))
            page.get_by_role("button", name="Kick the base").click()
            wait_until(lambda: app.session.gain_view().measured is not None, 30.0, "the measured decay")
            wait_until(lambda: "measured" in ex.predicted.content, 10.0, "the panel to show it")
            page.get_by_text("Map shows", exact=True).first.scroll_into_view_if_needed()  # (the text above re-renders)
            dismiss_notifications(page)
            settle_for_picture(page, 20)
            assert screenshot(page, "gain_measured_trep").stat().st_size > 10_000
            view = app.session.gain_view()
            print(f"predicted {view.predicted:.3f} 1/s, measured {view.measured.rate:.3f} 1/s")


# -- the drawn map against its numbers ---------------------------------------------------------------
COLOUR_TOLERANCE = 12  # per RGB channel: the legend's numbers are rounded to 3 digits; the page draws exactly
AGREEING_CELLS = 0.97  # of the cells read: the rest may sit under a mark drawn on the map
PICTURE_WAIT_S = 20.0  # s: for the page to draw a new map's picture


@pytest.fixture(params=["trep", "planar3r", "boom7"], name="map_app")
def each_model_map_app(request: pytest.FixtureRequest) -> Iterator[RnsApp]:
    app = start_app(request.param, port=0, verbose=False)
    app.view.show("gain_map")  # out of the scene by default
    yield app
    app.stop()


def legend_scale(legend: str) -> tuple[float, float]:
    """The colour scale (1/s) the legend states: 'dark <lo> ... yellow <hi> 1/s'."""
    found = re.search(r"dark ([-+.\de]+) … yellow ([-+.\de]+) 1/s", legend)
    assert found, f"no colour scale in the legend {legend!r}"
    return float(found.group(1)), float(found.group(2))


def expected_colours(rates: np.ndarray, scale: tuple[float, float]) -> np.ndarray:
    """(B, G, 3): the legend's colour of each cell's rate (no such mode: the missing cells' grey)."""
    want = colours(rates, scale).astype(int)
    want[~np.isfinite(rates)] = MISSING_RGB
    return want


FACING_FILL = 0.9  # the faced map spans this fraction of the scene's narrower side: its edge cells stay clear
# of what borders the scene (the docked plots panel's resize grip reaches a few pixels into it)


def face_the_map(app: RnsApp, page: Page, scene: GainScene) -> None:
    """Put the page's camera in front of the map, at the distance where the map spans FACING_FILL of the
    scene's width or height below the floating main panel, whichever is narrower (the page's own field of
    view), its centre in the middle of that part of the scene."""
    client = next(iter(app.server.get_clients().values()))
    cam = client.camera
    wait_until(lambda: cam.update_timestamp > 0 and cam.image_width > 0, 10.0, "the page's camera")

    def settled() -> bool:  # the app framed the page long enough ago that what it reports now (the docked panels
        # take their widths over the first seconds) does not frame it again: a framing would move the faced camera
        framed = app.scene.framed_pages.get(client.client_id)
        if framed is None or app.scene.needs_framing(client):
            return False
        return time.monotonic() - framed[2] > REFRAME_SETTLE_S

    try:
        wait_until(settled, 30.0, "the page's own framing settled")
    except AssertionError as e:  # said, and the map faced anyway: a framing after this is faced again (below)
        print(f"\n{app.model_name}: {e} ({page_framing(app, client)})", end="")
    # The floating main panel minimised to its bar: its height follows its words (a long operator notice
    # made it reach over the map's top rows in CI); the map is faced below where it stands expanded.
    app.server.gui.main_panel.minimize()
    # the scene's own canvas as laid out now, between the docked panels (the camera's size may predate them)
    width, height = shown_size(page)
    panel = main_panel_box(width, height)
    below = panel[3] if panel is not None else 0.0  # px: the rows above are partly under the main panel
    free = height - below
    focal = 0.5 * height / math.tan(0.5 * cam.fov)  # px per unit of (offset / distance)
    distance = 0.5 * scene.size * focal / (FACING_FILL * 0.5 * min(width, free))
    ahead = -scene.rotation[:, 2]  # the camera looks along this, at the map
    up = np.asarray(cam.up_direction, dtype=float)
    up = up - (up @ ahead) * ahead
    up /= np.linalg.norm(up)
    shift = -0.5 * below / focal * distance * up  # the map's centre half the panel's rows down the page
    cam.position = scene.centre + distance * scene.rotation[:, 2] - shift
    cam.look_at = scene.centre - shift
    FACED[client.client_id] = (np.array(cam.position, dtype=float), (width, height))
    wait_for_frames(page, 10)


def page_framing(app: RnsApp, client: ClientHandle) -> str:
    """The page's last framing and what it reports now, in words (for a test's message)."""
    (fw, fh), position, when = app.scene.framed_pages[client.client_id]
    moved = not np.allclose(client.camera.position, position, atol=1e-4)
    return (
        f"framed {time.monotonic() - when:.1f} s ago for {fw}x{fh}, reports"
        f" {client.camera.image_width}x{client.camera.image_height}, camera moved since: {moved}"
    )


# client id -> where face_the_map put its camera (m), and the canvas's size (px) it faced the map for
FACED: dict[int, tuple[np.ndarray, tuple[int, int]]] = {}


def face_again_if_framed(app: RnsApp, page: Page, scene: GainScene) -> None:
    """Face the map again if the app framed the page since (seen in CI on a busy machine: a framing landed
    after the map was faced, and the cells were 1.6 px apart) or the scene's canvas changed size since (seen
    in CI: the docked panels took their widths after the map was faced, and its left column went under one);
    says so."""
    client = next(iter(app.server.get_clients().values()))
    faced = FACED.get(client.client_id)
    if faced is None:
        return
    position, size = faced
    here = np.asarray(client.camera.position, dtype=float)
    moved = not np.allclose(here, position, atol=1e-4 * max(float(np.linalg.norm(position - scene.centre)), 1e-3))
    now = shown_size(page)
    resized = max(abs(now[0] - size[0]), abs(now[1] - size[1])) > 2
    if not (moved or resized):
        return
    why = page_framing(app, client) if moved else f"the canvas {size[0]}x{size[1]} -> {now[0]}x{now[1]} px"
    print(f"\n{app.model_name}: {why}: map faced again", end="")
    face_the_map(app, page, scene)


def screen_cells(page: Page, scene: GainScene, gm: GainMap) -> np.ndarray:
    """(B, G, 2) page pixels of the cells' centres, projected by the page's own camera (one call)."""
    us = np.array([axis_fraction(gm.g_b, g) for g in gm.g_b])
    vs = np.array([axis_fraction(gm.g_m, g) for g in gm.g_m])
    u, v = np.meshgrid(us, vs, indexing="ij")
    local = np.stack([(u - 0.5) * scene.size, (v - 0.5) * scene.size, np.zeros_like(u)], axis=-1)
    pixels = page.evaluate(PROJECT_JS, local.reshape(-1, 3).tolist())
    assert pixels is not None, "the page's camera or the map was not found"
    return np.asarray(pixels, dtype=float).reshape(gm.g_b.size, gm.g_m.size, 2)


def shown_on_canvas(page: Page, where: np.ndarray) -> np.ndarray:
    """(...,) bool: the page's topmost element at each pixel ``where`` (..., 2) is the scene's canvas (not a
    toast, a panel or a label over it)."""
    points = np.asarray(where, dtype=float).reshape(-1, 2).tolist()
    shown = page.evaluate(
        "(pts) => { const c = window.__viserMutable.canvas;"
        " return pts.map(([x, y]) => document.elementFromPoint(x, y) === c); }",
        points,
    )
    return np.asarray(shown, dtype=bool).reshape(np.asarray(where).shape[:-1])


def covering(page: Page, where: np.ndarray) -> str:
    """What the page shows topmost at the pixel ``where`` (2,): its tag and classes (for a failure's words)."""
    return str(
        page.evaluate(
            "([x, y]) => { const e = document.elementFromPoint(x, y);"
            " return e ? `${e.tagName.toLowerCase()}.${[...e.classList].join('.')}` : 'nothing (off the page)'; }",
            [float(where[0]), float(where[1])],
        )
    )


def read_pixels(page: Page, where: np.ndarray) -> np.ndarray:
    """(..., 3) colours of the page at the pixels ``where`` (..., 2): the median of the 3 x 3 around each."""
    shot = np.asarray(Image.open(io.BytesIO(page.screenshot())).convert("RGB")).astype(int)
    x, y = np.rint(where[..., 0]).astype(int), np.rint(where[..., 1]).astype(int)
    around = [shot[y + dy, x + dx] for dy in (-1, 0, 1) for dx in (-1, 0, 1)]
    return np.median(np.stack(around), axis=0)


def agreeing(gm: GainMap, drawn: np.ndarray, want: np.ndarray) -> np.ndarray:
    """(B, G) bool: each predictable cell drawn in its legend colour, each unstable one hatched grey (any
    grey between the hatching's two: 3 x 3 pixels may span a stripe). The cells the map marks not
    predictable (faded, hatched) are left out: :func:`read_cells` does not read them."""
    lo, hi = min(UNSTABLE_RGB[0], UNSTABLE_HATCH[0]), max(UNSTABLE_RGB[0], UNSTABLE_HATCH[0])
    grey = (np.ptp(drawn, axis=-1) <= COLOUR_TOLERANCE) & (drawn[..., 0] >= lo - COLOUR_TOLERANCE)
    grey &= drawn[..., 0] <= hi + COLOUR_TOLERANCE
    return np.where(gm.stable, np.abs(drawn - want).max(axis=-1) <= COLOUR_TOLERANCE, grey)


def read_cells(gm: GainMap) -> np.ndarray:
    """(B, G) bool: the cells drawn in a legend colour or hatched grey (all but the not-predictable ones)."""
    return ~not_predictable(gm)


def check_drawn_map(app: RnsApp, page: Page, quantity: str, hovered: bool = False) -> tuple[int, int]:
    """The map drawn in the page agrees cell by cell with the legend's colour of each cell's rate; the
    cells of the highest and the lowest rate show the legend's two ends. ``hovered``: with the mouse on
    the map, as when a person picks a cell (viser's hover outline once tinted the whole map yellow).
    Returns the fastest cell (i, j)."""
    ex = app.renderer.explorer
    scene = ex.scene
    assert scene is not None and scene.gain_map is not None
    # The marks on the map (now, the paper's points, axis names) are hidden while its pixels are read.
    marks = [scene.now, *scene._ticks, *scene._paper]  # (what covers cells)
    for mark in marks:
        mark.visible = False  # type: ignore[attr-defined]
    labels_were = app.view.on("labels")  # callouts keep off the map, but their layout lags the view set here
    app.view.show("labels", False)
    # The page loads a new map's PNG into a texture in its own time (seconds on a busy machine): read
    # until the drawing agrees or PICTURE_WAIT_S has passed; a wrong picture never agrees.
    centre = screen_point(page, (0.0, 0.0, 0.0))
    assert centre is not None
    page.mouse.move(*(centre if hovered else (5.0, 5.0)))
    toasts_hidden = hide_toasts(page)  # a toast arriving late sat over the fastest cell (top-left) in CI
    deadline = time.monotonic() + PICTURE_WAIT_S
    while True:
        face_again_if_framed(app, page, scene)
        dismiss_notifications(page)  # a toast arriving late (a busy machine) sits over part of the map
        wait_for_frames(page, 10)
        gm, scale = scene.gain_map, legend_scale(scene.legend.text)  # (the map of the pose now)
        cells = screen_cells(page, scene, gm)  # (where the page's camera is now)
        spacing = np.linalg.norm(cells[1, 0] - cells[0, 0])
        if spacing < 6.0 and time.monotonic() < deadline:
            continue  # the view changed under the test (framed again): faced again at the top
        assert spacing >= 6.0, f"cells {spacing:.1f} px apart: too small to read one pixel block each"
        drawn = read_pixels(page, cells)
        rates = map_rates(gm, quantity)  # type: ignore[arg-type]
        want = expected_colours(rates, scale)
        on_canvas = shown_on_canvas(page, cells)  # (a toast arriving late sits over part of the map)
        read = read_cells(gm) & on_canvas
        agree = agreeing(gm, drawn, want)
        if (agree[read].mean() >= AGREEING_CELLS and on_canvas.all()) or time.monotonic() > deadline:
            break
    toasts_hidden.evaluate("(style) => style.remove()")
    for mark in marks:
        mark.visible = True  # type: ignore[attr-defined]
    app.view.show("labels", labels_were)
    if not (read.sum() > 0.2 * read.size and agree[read].mean() >= AGREEING_CELLS):
        screenshot(page, f"gain_map_disagrees_{app.model_name}_{quantity}")
    bad = tuple(np.argwhere(read & ~agree)[0]) if not agree[read].all() else None
    assert read.sum() > 0.2 * read.size, f"{quantity}: only {read.sum()} cells drawn in legend colours to read"
    assert agree[read].mean() >= AGREEING_CELLS, (
        f"{quantity}: only {agree[read].mean():.0%} of the {read.sum()} cells read show their legend colour "
        f"(e.g. cell {bad} drawn {drawn[bad]}, its legend colour {want[bad]})"
    )
    coloured = gm.predictable & np.isfinite(rates) & (rates > 0)  # the cells the colour scale spans
    fastest = np.unravel_index(np.argmax(np.where(coloured, rates, -np.inf)), rates.shape)
    slowest = np.unravel_index(np.argmin(np.where(coloured, rates, np.inf)), rates.shape)
    bottom, top = colours(np.array(scale), scale).astype(int)  # the legend's dark and yellow ends
    for (i, j), end, name in ((fastest, top, "highest"), (slowest, bottom, "lowest")):
        if not on_canvas[i, j]:
            screenshot(page, f"gain_map_covered_{app.model_name}_{quantity}")
        assert on_canvas[i, j], f"{quantity}: the cell of the {name} rate is under {covering(page, cells[i, j])}"
        assert np.abs(drawn[i, j] - end).max() <= COLOUR_TOLERANCE, (
            f"{quantity}: the cell of the {name} rate ({rates[i, j]:.3g} 1/s at g_b {gm.g_b[i]:.3g}, g_m "
            f"{gm.g_m[j]:.3g}) is drawn {drawn[i, j]}, the legend's {name} end is {end}"
        )
    # The check tells an upside-down map: the fastest cell's mirror across the g_m axis has another colour.
    mirror = want[fastest[0], gm.g_m.size - 1 - fastest[1]]
    assert np.abs(mirror - top).max() > 4 * COLOUR_TOLERANCE, "this map looks the same upside down"
    return int(fastest[0]), int(fastest[1])


def applied_gains(app: RnsApp) -> tuple[float, float]:
    gains = app.session.snapshot().settings.gains
    return gains.g_b, gains.g_m


def test_the_drawn_map_agrees_with_its_numbers_legend_and_clicks(map_app: RnsApp) -> None:
    app = map_app
    ex = app.renderer.explorer
    laws = {"trep": ("velocity", "torque"), "planar3r": ("acceleration", "velocity"), "boom7": ("acceleration",)}
    laws = laws[app.model_name]
    with browser_page(app.server, width=1280, height=800, draw=True) as page:
        for law in laws:
            if app.session.snapshot().settings.law != law:
                app.controls.show(app.gui.law, LAW_LABELS[law])
                app.session.set_law(law)
            wait_until(
                lambda law=law: (
                    ex.scene is not None
                    and ex.scene.gain_map is not None
                    and ex.scene.gain_map.loop.law == law
                    and ex.scene.frame.visible
                ),
                120.0,
                f"the gain map of law {law}",
            )
            wait_for_nodes(page, {GainScene.FRAME, GainScene.IMAGE})
            dismiss_notifications(page)
            scene = ex.scene
            assert scene is not None
            face_the_map(app, page, scene)
            for quantity in ("base", "arm"):
                app.controls.show(ex.quantity, next(k for k, q in QUANTITIES.items() if q == quantity))
                sym = "σ_a" if quantity == "arm" else "σ_b"
                legend = scene.legend
                wait_until(lambda s=sym, h=legend: h.text.startswith(s), 10.0, f"the {quantity} map")
                wait_for_frames(page, 10)
                i, j = check_drawn_map(app, page, quantity)
                if quantity == "base":
                    check_drawn_map(app, page, quantity, hovered=True)
            # A click on the fastest (arm) cell's drawn position applies that cell's gains.
            gm = scene.gain_map
            assert gm is not None
            want = (float(gm.g_b[i]), float(gm.g_m[j]))
            u, v = axis_fraction(gm.g_b, want[0]), axis_fraction(gm.g_m, want[1])
            pixel = screen_point(page, ((u - 0.5) * scene.size, (v - 0.5) * scene.size, 0.0))
            assert pixel is not None
            dismiss_notifications(page)
            page.mouse.click(*pixel)
            wait_until(lambda w=want: applied_gains(app) == w, 10.0, f"the click to apply {want}")
        settle_for_picture(page, 10)
        screenshot(page, f"gain_map_facing_{app.model_name}")
