"""Slow and hidden pages in a real headless Chromium: a page whose CPU is throttled is told
that its display is slowed, still operates the app, and loses the notice once it catches up; a tab
hidden and frozen for a while answers again once shown and shows the current state. No timing
thresholds: each step waits (generously) for what must happen."""

from __future__ import annotations

import re
import time
from collections.abc import Iterator

import pytest
from playwright.sync_api import Page

from rns_viz.live.loop.session import Session
from rns_viz.viz.scene.fsms_scene import FsmsScene
from rns_viz.viz.server.app import RnsApp
from tests.support.app_helpers import realtime_app
from tests.support.browser import browser_page, live_group, wait_for_nodes, wait_until

pytestmark = live_group  # the app meets slow and frozen pages: one such test at a time (tests/support/browser.py)
NOTICE = re.compile(r"Display slowed to \d+ Hz to keep up")
THROTTLE = 16  # times slower: the page's CPU (Chromium's emulation)
SLOW_S = 120.0  # s: what a throttled software-rendered page may take for one step
HIDE_JS = """(hidden) => {
    const state = hidden ? 'hidden' : 'visible';
    Object.defineProperty(document, 'hidden', {configurable: true, get: () => hidden});
    Object.defineProperty(document, 'visibilityState', {configurable: true, get: () => state});
    document.dispatchEvent(new Event('visibilitychange'));
}"""
SHOWN_TIME_JS = """() => {
    const m = /t = +(-?[0-9.]+) s/.exec(document.body.innerText);
    return m ? parseFloat(m[1]) : null;
}"""


@pytest.fixture
def trep_app() -> Iterator[RnsApp]:
    yield from realtime_app("trep")


def paced_client(app: RnsApp) -> int:
    """The page's client id, once the server has had its first answer."""
    wait_until(lambda: any(p.answered_once for p in app.pace.pages.values()), 60.0, "the page's first answer")
    return next(iter(app.pace.pages))


def record_kicks(s: Session) -> list[float]:
    """Simulated times (s) at which the session is asked for a kick from now on (the GUI callback's
    call, passed on)."""
    times: list[float] = []
    kick = s.kick

    def recorded(*args: object, **kwargs: object) -> None:
        times.append(s.snapshot().t)
        kick(*args, **kwargs)

    s.kick = recorded  # type: ignore[method-assign]
    return times


def shown_time(page: Page) -> float:
    """The simulated time the page's status line shows (s), -1 before it shows one."""
    t = page.evaluate(SHOWN_TIME_JS)
    return -1.0 if t is None else float(t)


def notice_shown(page: Page) -> bool:
    lines = page.get_by_text(NOTICE)
    return any(lines.nth(k).is_visible() for k in range(lines.count()))


def test_a_throttled_page_is_slowed_told_so_still_operates_and_recovers(trep_app: RnsApp) -> None:
    app, s = trep_app, trep_app.session
    with browser_page(app.server) as page:
        wait_for_nodes(page, {FsmsScene.BASE})
        client = paced_client(app)
        s.cyclic(True)  # a new picture every frame
        cdp = page.context.new_cdp_session(page)
        # 16x: a page that draws no pixels (tests/support/browser.py) still falls behind here at 4x, so this holds on a
        # machine several times faster; at 40x the slowed page took 2 minutes to click through the test
        cdp.send("Emulation.setCPUThrottlingRate", {"rate": THROTTLE})
        wait_until(lambda: app.pace.state(client)["notice"], SLOW_S, "the server to see the page fall behind")
        wait_until(lambda: notice_shown(page), SLOW_S, "the page to show the slowed-display notice", poll=1.0)

        # The slowed page still operates the app: its Kick reaches the simulation, and the page goes on
        # to show the state after it.
        kicks = record_kicks(s)
        page.get_by_role("button", name="Kick the base").click(timeout=SLOW_S * 1000)
        wait_until(lambda: kicks, SLOW_S, "the slowed page's kick")
        wait_until(lambda: shown_time(page) >= kicks[0], SLOW_S, "the slowed page to show the kick's time", poll=1.0)

        # Unthrottled and with less to draw, the page catches up: full rate again, notice gone.
        cdp.send("Emulation.setCPUThrottlingRate", {"rate": 1})
        s.cyclic(False)
        wait_until(lambda: not app.pace.state(client)["notice"], SLOW_S, "the page to catch up", poll=0.2)
        wait_until(lambda: not notice_shown(page), SLOW_S, "the notice to go from the page", poll=1.0)


def test_a_hidden_frozen_tab_answers_once_shown_and_shows_the_current_state(trep_app: RnsApp) -> None:
    app, s = trep_app, trep_app.session
    with browser_page(app.server) as page:
        wait_for_nodes(page, {FsmsScene.BASE})
        client = paced_client(app)
        s.cyclic(True)
        cdp = page.context.new_cdp_session(page)
        cdp.send("Debugger.enable")
        page.evaluate(HIDE_JS, True)
        cdp.send("Debugger.pause")  # the page's main thread stops, as in a frozen background tab
        wait_until(lambda: app.pace.state(client)["held"], 30.0, "the server to hold the frozen page's stream")
        time.sleep(2.0)  # the simulation runs on meanwhile (2 s of simulated time the page has not shown)
        cdp.send("Debugger.resume")
        cdp.send("Debugger.disable")
        page.evaluate(HIDE_JS, False)
        shown_at = s.snapshot().t
        wait_until(lambda: shown_time(page) >= shown_at, SLOW_S, "the page to show the present")
        wait_until(lambda: not app.pace.state(client)["held"], SLOW_S, "the page's answer")
        kicks = record_kicks(s)
        page.get_by_role("button", name="Kick the base").click(timeout=SLOW_S * 1000)
        wait_until(lambda: kicks, SLOW_S, "a kick from the shown page")
