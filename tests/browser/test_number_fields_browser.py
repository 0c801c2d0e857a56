"""Numbers typed in a real headless Chromium: key by key into the g_b box, as a person types. Each is
applied exactly or refused with a toast, and the box then shows the value in force; no slider shows
viser's own number box (it turned ``1e9`` into 19)."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from playwright.sync_api import Locator, Page

from rns_viz.viz.panels.number_field import shown
from rns_viz.viz.server.app import RnsApp, start_app
from tests.support.browser import browser_page, dismiss_notifications, open_folder, wait_until

FOLDERS = ("Control law and gains", "Model and view", "Record and replay")  # closed at first


@pytest.fixture
def app() -> Iterator[RnsApp]:
    app = start_app("trep", port=0, verbose=False)
    yield app
    app.stop()


def box_of(page: Page, label: str) -> Locator:
    """The text box under the slider labelled ``label`` (the first text input after its track)."""
    track = page.get_by_text(label, exact=True).locator("xpath=ancestor::*[.//*[@role='slider']][1]")
    return track.locator("xpath=following::input[contains(@class, 'mantine-TextInput-input')][1]")


def type_keys(page: Page, box: Locator, text: str) -> None:
    box.click()
    box.press("Control+A")
    box.press_sequentially(text, delay=60)  # key by key, as a person types
    page.mouse.move(5, 5)


def test_typed_gains_are_applied_exactly_or_refused_with_a_message(app: RnsApp) -> None:
    gains = lambda: app.session.snapshot().settings.gains  # noqa: E731
    told: list[str] = []
    original = app.connections.notify

    def record(client, title, body, level):  # type: ignore[no-untyped-def]
        told.append(body)
        original(client, title, body, level)

    app.connections.notify = record  # type: ignore[method-assign]
    with browser_page(app.server, width=1400, height=900) as page:
        dismiss_notifications(page)
        for folder in FOLDERS:
            open_folder(page, folder)
        # No slider shows viser's own number box; under each track is a text box showing its value.
        thumbs = page.get_by_role("slider")
        assert thumbs.count() >= 8  # TREP, law (30): kick, path, ū speed, g_b, g_m, drawn ×, replay N s, replay ×
        for k in range(thumbs.count()):
            if not thumbs.nth(k).is_visible():
                continue
            root = thumbs.nth(k).locator("xpath=ancestor::div[contains(@class, 'mantine-Slider-root')][1]")
            assert not root.locator("xpath=following-sibling::*[contains(@class, 'NumberInput')]").is_visible()
            typed = root.locator("xpath=following::input[not(contains(@class, 'NumberInput'))][1]")
            assert "TextInput" in (typed.get_attribute("class") or "") and typed.is_visible()
        box = box_of(page, "Base damping g_b (1/s)")
        box.scroll_into_view_if_needed()
        for text, message in (
            ("1e9", "Base damping g_b must be from 0 to 1\u202f000\u202f000 1/s, not 10⁹"),
            ("NaN", "Base damping g_b must be a finite number from 0 to 1\u202f000\u202f000 1/s, not NaN"),
            ("-5", "Base damping g_b must be from 0 to 1\u202f000\u202f000 1/s, not −5"),
            ("abc", "Base damping g_b: 'abc' is not a number"),
        ):
            old = gains().g_b
            dismiss_notifications(page)
            type_keys(page, box, text)
            toast = page.locator(".mantine-Notification-root").filter(has_text=message)
            toast.first.wait_for(timeout=10_000)
            wait_until(lambda old=old: box.input_value() == shown(old), 10.0, f"the box to show {old} again")
            assert gains().g_b == old
        for text, value in (("-0", 0.0), ("1e-3", 0.001), ("12.5", 12.5)):
            before = len(told)
            type_keys(page, box, text)
            wait_until(lambda v=value: gains().g_b == v, 10.0, f"g_b = {value} from {text!r}")
            wait_until(lambda v=value: box.input_value() == shown(v), 10.0, f"the box to show {value}")
            assert told[before:] == [], told[before:]
        # A value typed into g_m far beyond its slider's range is the number typed.
        type_keys(page, box_of(page, "Joint hold g_m (1/s)"), "2.5e3")
        wait_until(lambda: gains().g_m == 2500.0, 10.0, "g_m = 2500 from '2.5e3'")
        # the slider widens to show it when the render thread next writes the panel
        wait_until(lambda: app.gui.gains["g_m"].max >= 2500.0, 10.0, "g_m's slider to reach 2500")
