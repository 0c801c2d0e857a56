"""Real-browser helpers: Debian chromium driven by Playwright against a local viser server.

Recipe (docs/testing-notes.md): ``/usr/bin/chromium`` (apt), never ``playwright install``; headless with
software rendering (SwiftShader), one browser per test process and a fresh context per page. Scene nodes are read from
the client's ``window.__viserMutable.nodeRefFromName`` (viser/client/src/App.tsx exposes it).
"""

from __future__ import annotations

import os
import time
import weakref
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import viser
from playwright.sync_api import Browser, ElementHandle, Page, Playwright, sync_playwright

from rns_viz.viz.server.app import TARGET_HANDLE, RnsApp, start_app
from tests.support.repo import REPO

CHROMIUM = Path("/usr/bin/chromium")
CHROMIUM_FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]
# Pages of tests that need no pixels draw nothing. Chromium's switch for it skips little on software WebGL
# (SwiftShader still rasterised the app's draws: ~0.19 s of CPU a frame at 1280x800), so such a page is
# also given NO_DRAWING_SCRIPT: WebGL's draw and clear calls return at once, while everything else runs
# (three.js builds and updates its scene graph, raycasts, uploads buffers; React and the panel as ever).
# A frame then costs ~0.025 s: a page at rest uses 2 % of a core instead of 20 %, and a Playwright call,
# which waits for the page's next frame, waits that much less. Pages whose pixels a test reads or saves
# for people to look at draw: ``draw=True``, and every page while pictures are made (RNS_VIZ_SCREENSHOTS,
# or RNS_VIZ_DRAW=1 for artifacts/ too).
NO_DRAWING = "--disable-gl-drawing-for-tests"
NO_DRAWING_SCRIPT = """
for (const context of [WebGLRenderingContext, WebGL2RenderingContext]) {
  for (const call of ["drawArrays", "drawElements", "drawArraysInstanced", "drawElementsInstanced",
                      "drawRangeElements", "clear"]) {
    const original = context.prototype[call];
    if (original) context.prototype[call] = function (...args) {
      if (window.__rnsDrawing) return original.apply(this, args);  // start_drawing(page)
    };
  }
}
"""
ARTIFACTS = REPO / "artifacts"
SKIP_REASON = f"real-browser test needs Debian chromium at {CHROMIUM} (apt-get install chromium)"


_DRAWING_PAGES: weakref.WeakSet[Page] = weakref.WeakSet()  # the pages that draw (draw=True or pictures wanted)


def pictures_wanted() -> bool:
    """Whether every page draws its scene (screenshots for the docs, or asked for)."""
    return "RNS_VIZ_SCREENSHOTS" in os.environ or os.environ.get("RNS_VIZ_DRAW") == "1"


def chromium_flags(draw: bool = False) -> list[str]:
    """The flags of a test's chromium: it draws its 3-D scene only if ``draw`` or pictures are wanted."""
    return CHROMIUM_FLAGS if draws(draw) else [*CHROMIUM_FLAGS, NO_DRAWING]


def draws(draw: bool) -> bool:
    """Whether a test's page draws its scene: asked for (``draw``), or pictures are wanted."""
    return draw or pictures_wanted()


def new_test_page(browser: Browser, width: int, height: int, draw: bool = False) -> Page:
    """A page of ``browser``: its WebGL draws nothing unless ``draw`` or pictures are wanted."""
    page = browser.new_page(viewport={"width": width, "height": height})
    if draws(draw):
        _DRAWING_PAGES.add(page)
    else:
        page.add_init_script(NO_DRAWING_SCRIPT)
    return page


def chromium_available() -> bool:
    return CHROMIUM.is_file()


# CI sets RNS_VIZ_REQUIRE_BROWSER=1: there a missing chromium fails the browser tests instead of
# skipping them.
requires_chromium = pytest.mark.skipif(
    not chromium_available() and os.environ.get("RNS_VIZ_REQUIRE_BROWSER") != "1", reason=SKIP_REASON
)
# The tests run in pytest-xdist workers (pyproject's addopts), each taking the next test when it is free.
# A test whose subject is how the app meets the wall clock (a page too slow for its stream, a frozen tab:
# rns_viz.viz.server.page_pacing) joins the "live" group: those run in one worker, one at a time, so two of
# them never compete for the cores. Browser tests and real-time apps otherwise spread over the workers: each
# waits for what must happen with a generous timeout, never for a rate, and a page at rest draws nothing.
live_group = pytest.mark.xdist_group("live")
# A real-browser test that timed out waiting for the page runs once more, as Playwright's own runner does on CI:
# how long a software-drawn page takes depends on the machine and what else it runs (the suite's other worker).
# Only a wait that ran out is retried (wait_until's message, Playwright's TimeoutError); a wrong pixel, number or
# word fails at once. A retried test shows as R in the progress line and "rerun" in the summary.
retried_when_slow = pytest.mark.flaky(reruns=1, only_rerun=[r"^AssertionError: timed out after ", r"^TimeoutError: "])
# What every real-browser test gets, applied by tests/conftest.py to the tests in tests/browser/.
browser_marks = [pytest.mark.browser, requires_chromium, retried_when_slow]


def wait_until(condition: Callable[[], object], timeout: float, what: str, poll: float = 0.05) -> None:
    """Poll ``condition`` until it is truthy; AssertionError naming ``what`` after ``timeout`` s."""
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout} s waiting for {what}")
        time.sleep(poll)


def wait_for_clients(app: Any, count: int, what: str, timeout: float = 10.0) -> None:
    """Wait until ``count`` clients are connected AND the app's connect handler has registered them
    with the operator lock (viser lists a client before its connect callbacks have run)."""
    wait_until(lambda: len(app.server.get_clients()) == count and len(app.lock.clients()) == count, timeout, what)


@contextmanager
def local_server() -> Iterator[viser.ViserServer]:
    """A viser server on a free port bound to 127.0.0.1, stopped afterwards."""
    server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    try:
        yield server
    finally:
        server.stop()


class SharedChromium:
    """One Playwright driver and one Chromium per kind (drawing its scene or not: the flag is the browser's)
    for the whole test process, launched on first use and closed when the test session ends
    (tests/conftest.py). Every page still gets a browser context of its own (its own storage and cache, as a
    fresh profile gave), so tests stay apart; what they share is the start of a driver and a browser (about
    a second each time, and that much CPU taken from the other worker)."""

    def __init__(self) -> None:
        self._playwright: Playwright | None = None
        self._browsers: dict[bool, Browser] = {}

    def browser(self, draw: bool) -> Browser:
        """The running Chromium of this kind, launched (again, if it went away) when needed."""
        draw = draws(draw)
        if self._playwright is None:
            self._playwright = sync_playwright().start()
        browser = self._browsers.get(draw)
        if browser is None or not browser.is_connected():
            browser = self._playwright.chromium.launch(
                executable_path=str(CHROMIUM), args=chromium_flags(draw), headless=True
            )
            self._browsers[draw] = browser
        return browser

    def close(self) -> None:
        for browser in self._browsers.values():
            if browser.is_connected():
                browser.close()
        self._browsers.clear()
        if self._playwright is not None:
            self._playwright.stop()
            self._playwright = None


CHROMIUMS = SharedChromium()


@contextmanager
def url_page(
    url: str, width: int = 1280, height: int = 800, timeout: float = 30.0, draw: bool = False
) -> Iterator[Page]:
    """A page of the shared Chromium showing ``url``, in a browser context of its own that is closed
    afterwards; its 3-D scene is drawn only if ``draw`` (or pictures are wanted, :func:`pictures_wanted`)."""
    page = new_test_page(CHROMIUMS.browser(draw), width, height, draw)
    try:
        page.goto(url, timeout=timeout * 1000)
        yield page
    finally:
        page.context.close()


@contextmanager
def browser_page(
    server: viser.ViserServer, width: int = 1280, height: int = 800, timeout: float = 30.0, draw: bool = False
) -> Iterator[Page]:
    """A Playwright page showing ``server``, yielded once the client has connected (:func:`url_page`)."""
    with url_page(f"http://127.0.0.1:{server.get_port()}/", width, height, timeout, draw) as page:
        wait_until(lambda: len(server.get_clients()) > 0, timeout, "the browser to connect to viser")
        yield page


def scene_node_names(page: Page) -> set[str]:
    """Names of the scene nodes the client has mounted."""
    return set(page.evaluate("() => Object.keys(window.__viserMutable?.nodeRefFromName ?? {})"))


def local_position(page: Page, name: str) -> list[float] | None:
    """Position of a mounted node relative to its parent node, in viser's coordinates, or None.

    (``matrixWorld`` would include the client's z-up root rotation; the local position does not.)
    """
    return page.evaluate(
        """(name) => {
            const obj = window.__viserMutable?.nodeRefFromName?.[name];
            return obj ? [obj.position.x, obj.position.y, obj.position.z] : null;
        }""",
        name,
    )


def dismiss_notifications(page: Page) -> None:
    """Close the client's toasts (e.g. "Software WebGL rendering detected") before a screenshot: a click
    on each close button in one call (a software-rendered page answers each Playwright action only after
    its next frame, so one locator click per toast took ~1 s)."""
    page.evaluate("() => document.querySelectorAll('.mantine-Notification-closeButton').forEach((b) => b.click())")


# Toasts sit at the page's top-left, over the scene: one that arrives on a busy machine while a test reads the
# scene's pixels (or is still leaving after a close) is read as part of the drawing.
HIDE_TOASTS_CSS = ".mantine-Notifications-root { display: none !important; }"


def hide_toasts(page: Page) -> ElementHandle:
    """Hide the page's toasts from now on (for a test that reads the scene's pixels); the returned style
    element's removal shows them again."""
    return page.add_style_tag(content=HIDE_TOASTS_CSS)


def open_folder(page: Page, label: str) -> None:
    """Click the title of the panel folder ``label``, not a text that names it (a lesson or a hint names a
    folder in *italics*: an ``em`` of the same words)."""
    page.get_by_text(label, exact=True).and_(page.locator(":not(em, strong, code)")).click()


def wait_for_nodes(page: Page, names: set[str], timeout: float = 30.0) -> None:
    """Wait until every name in ``names`` is mounted in the page's scene."""
    missing: set[str] = set(names)

    def ready() -> bool:
        missing.clear()
        missing.update(names - scene_node_names(page))
        return not missing

    try:
        wait_until(ready, timeout, "scene nodes")
    except AssertionError:
        raise AssertionError(f"scene nodes never appeared in the browser: {sorted(missing)}") from None


def wait_for_frames(page: Page, frames: int = 30) -> None:
    """Let the page render ``frames`` animation frames (software rendering is slow)."""
    page.evaluate(
        """(n) => new Promise((done) => {
            let k = 0;
            const step = () => (++k >= n ? done(null) : requestAnimationFrame(step));
            requestAnimationFrame(step);
        })""",
        frames,
    )


def start_drawing(page: Page, frames: int = 3) -> None:
    """Give a page opened without drawing its WebGL draw and clear calls back from now on, and wait
    ``frames`` frames (for a test that reads the scene's pixels only at its end). Chromium's switch,
    set at launch, stays on: the page then draws as a ``draw=False`` page did before the script."""
    page.evaluate("() => { window.__rnsDrawing = true; }")
    _DRAWING_PAGES.add(page)
    wait_for_frames(page, frames)


def settle_for_picture(page: Page, frames: int) -> None:
    """Before a screenshot: ``frames`` animation frames on a page that draws its scene (``draw=True``, or
    pictures wanted), so the picture shows it settled; 2 on a page that draws no pixels, whose picture
    shows the panel, which the page has laid out by then (each software-rendered frame took ~0.2 s)."""
    wait_for_frames(page, frames if page in _DRAWING_PAGES else 2)


def screenshot(page: Page, name: str) -> Path:
    """Save a PNG of the page to ``artifacts/<name>.png`` and return its path."""
    ARTIFACTS.mkdir(exist_ok=True)
    path = ARTIFACTS / f"{name}.png"
    page.screenshot(path=str(path))
    return path


@pytest.fixture(params=["trep", pytest.param("planar3r", marks=pytest.mark.docs)], name="app")
def each_model_app(request: pytest.FixtureRequest) -> Iterator[RnsApp]:
    """The app of each bundled planar model on a free port (import this fixture into a test module). The 3R's
    pass over the same page is on demand (``-m docs``, with its screenshots): the default run drives the 3R's
    page in the lesson, scene and plots browser tests and its app through the protocol (tests/app/test_app.py)."""
    app = start_app(request.param, port=0, verbose=False)
    yield app
    app.stop()


def click_track(page: Page, label: str, fraction: float) -> None:
    """Click the track of the slider labelled ``label`` at ``fraction`` of its width (one action, not many
    key presses: a software-rendered page answers each input only after its next frame)."""
    row = page.get_by_text(label, exact=True).locator("xpath=ancestor::*[.//*[@role='slider']][1]")
    thumb = row.get_by_role("slider")
    thumb.scroll_into_view_if_needed()
    track = thumb.locator("xpath=ancestor::div[contains(@class, 'mantine-Slider-root')][1]")
    box = track.bounding_box()
    assert box is not None
    page.mouse.click(box["x"] + fraction * box["width"], box["y"] + 0.5 * box["height"])


# Screen position (px) of a point on a scene node's local x axis, ``offset`` m from its origin: the
# client's camera matrices applied to the node's world matrix (three.js, column-major).
PROJECT = """([name, offset]) => {
  const m = window.__viserMutable, obj = m.nodeRefFromName[name], cam = m.camera;
  obj.updateWorldMatrix(true, false);
  cam.updateMatrixWorld();
  const e = obj.matrixWorld.elements;
  const p = [e[12] + offset * e[0], e[13] + offset * e[1], e[14] + offset * e[2], 1];
  const mul = (M, v) => [0, 1, 2, 3].map((r) => M[r] * v[0] + M[4 + r] * v[1] + M[8 + r] * v[2] + M[12 + r] * v[3]);
  const c = mul(cam.projectionMatrix.elements, mul(cam.matrixWorldInverse.elements, p));
  const rect = m.canvas.getBoundingClientRect();
  return [rect.left + ((c[0] / c[3] + 1) / 2) * rect.width, rect.top + ((1 - c[1] / c[3]) / 2) * rect.height];
}"""


DRAG_STEP_S = 0.1  # s between the drag's ten mouse moves: a hand's pace (a whole drag in about a second)


def drag_handle_along_x(page: Page, app: RnsApp, pixels: float = 0.0, metres: float = 0.0) -> None:
    """Press on the handle's x arrow (60 % of its length out: beyond the plane handles, which reach 37 % and,
    seen edge-on, are drawn over the arrow's first third), move along it by ``pixels`` on the screen or by
    what moves the handle ``metres`` in the scene (the pixels per metre read off the camera the page has), in
    about a second (not at the pace of the page's frames, which depends on how fast the machine draws),
    release."""
    x0, y0 = page.evaluate(PROJECT, [TARGET_HANDLE, 0.6 * app.handle.scale])
    x1, y1 = page.evaluate(PROJECT, [TARGET_HANDLE, 0.75 * app.handle.scale])
    length = max(float(np.hypot(x1 - x0, y1 - y0)), 1e-9)  # px for 0.15 handle scales along x
    d = np.array([x1 - x0, y1 - y0]) / length
    if metres:
        pixels = metres * length / (0.15 * app.handle.scale)
    page.mouse.move(x0, y0)
    page.mouse.down()
    for k in range(1, 11):
        page.mouse.move(x0 + d[0] * pixels * k / 10, y0 + d[1] * pixels * k / 10)
        wait_for_frames(page, 2)
        page.wait_for_timeout(1000 * DRAG_STEP_S)
    page.mouse.up()
