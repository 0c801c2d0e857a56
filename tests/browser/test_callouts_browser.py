"""Labels never hide the arm nor each other, read from the rendered pixels of a real Chromium.

With the simulation paused and the page's view at rest: a label's pixels are the frame with it drawn minus
the frame without it; the arm's pixels the frame with the robot's meshes minus the frame without them (all
labels hidden). At a projector's, a laptop's and a phone's size, for the models whose labels sat over the
hand (boom7: "drag me" 37 % and the ghost's 68 % of their pixels over the arm, before the callouts), and
TREP and trep2. Pictures: artifacts/callouts_<model>_<w>x<h>.png.
"""

from __future__ import annotations

import contextlib
import io
import time

import numpy as np
import pytest
import viser
from PIL import Image

from rns_viz.viz.server.app import RnsApp, start_app
from tests.browser.test_stage_browser import at_rest, canvas_box, reported_size, reports, shown_size
from tests.support.browser import (
    browser_page,
    hide_toasts,
    screenshot,
    wait_for_frames,
    wait_for_nodes,
    wait_until,
)

SIZES = ((1920, 1080), (1366, 768), (390, 844))
CHANGED = 30  # a pixel differs between two frames when its R + G + B differ by more than this
# A label's pixels over the arm: at most this fraction (its anti-aliased rim may touch a link's edge)
OVER_ARM = 0.02


def shown_labels(app: RnsApp) -> dict[str, viser.LabelHandle]:
    """Every label drawn in the scene with words (the gain map's are off in the first look)."""
    nodes = app.server.scene._handle_from_node_name  # viser keeps no public list of its nodes
    return {
        name: h
        for name, h in nodes.items()
        if isinstance(h, viser.LabelHandle) and h.visible and h.text.strip() and not name.startswith("/gain_map")
    }


def laid_out_for(app: RnsApp, client) -> bool:  # type: ignore[no-untyped-def]
    """Whether the callouts' last layout was for the page's current size and view (the camera it last reported,
    its projected points then still where the layout saw them)."""
    scene, layout = app.renderer.callouts, app.renderer.callouts.callouts
    seen, cam = layout._laid_out, client.camera
    if seen is None or not seen[1] or tuple(seen[1][0][:2]) != (cam.image_width, cam.image_height):
        return False
    live = [c for c in layout.items.values() if c.shown and c.point is not None]
    pages = scene.pages()
    return bool(pages) and layout._same(layout._seen(live, pages, scene.solids(), scene.texts()))


# The page's panels over the scene (the floating main panel; a phone's sheet, whose live plots redraw while the
# page is read) and its toasts: their pixels are not the scene's.
OVERLAYS = ".mantine-Paper-root, .mantine-Notifications-root"


def covered(page, box: dict[str, float], shape: tuple[int, int]) -> np.ndarray:  # type: ignore[no-untyped-def]
    """(h, w) bool: the pixels of the canvas's visible part (``box``, clipped to ``shape``) under a panel."""
    rects = page.evaluate(
        "(sel) => [...document.querySelectorAll(sel)].filter((e) => getComputedStyle(e).visibility !== 'hidden')"
        ".map((e) => e.getBoundingClientRect()).map((r) => [r.left, r.top, r.right, r.bottom])",
        OVERLAYS,
    )
    mask = np.zeros(shape, dtype=bool)
    x0, y0 = max(box["x"], 0.0), max(box["y"], 0.0)
    for left, top, right, bottom in rects:
        c0, r0 = max(int(np.floor(left - x0)), 0), max(int(np.floor(top - y0)), 0)
        c1, r1 = int(np.ceil(right - x0)), int(np.ceil(bottom - y0))
        if c1 > 0 and r1 > 0:
            mask[r0:r1, c0:c1] = True
    return mask


def canvas_pixels(page) -> np.ndarray:  # type: ignore[no-untyped-def]
    """The 3-D canvas's visible part, RGB ints (h, w, 3), once two frames half a second apart are the same
    (the page's camera glides to a new view for a while, by less than a pixel a frame at its end); the pixels
    under a panel are -1 (not the scene's, and never changed)."""

    def grab() -> np.ndarray:
        wait_for_frames(page, 4)
        c = canvas_box(page)
        vw, vh = page.viewport_size["width"], page.viewport_size["height"]
        x0, y0 = int(max(c["x"], 0)), int(max(c["y"], 0))
        x1, y1 = int(min(c["x"] + c["w"], vw)), int(min(c["y"] + c["h"], vh))
        img = np.asarray(Image.open(io.BytesIO(page.screenshot())).convert("RGB")).astype(int)[y0:y1, x0:x1]
        img[covered(page, c, img.shape[:2])] = -1
        return img

    before = grab()
    deadline = time.monotonic() + 20.0
    while True:
        time.sleep(0.5)
        now = grab()
        if changed(before, now).sum() == 0 or time.monotonic() > deadline:
            return now
        before = now


def changed(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(h, w) bool: the scene's pixels that differ between two frames (a pixel under a panel in either, -1,
    is not the scene's: a panel that grew or shrank in between changes no scene pixel)."""
    return (np.abs(a - b).sum(axis=2) > CHANGED) & (a[..., 0] >= 0) & (b[..., 0] >= 0)


def pixels_of(page, nodes: list) -> np.ndarray:  # type: ignore[no-untyped-def]
    """The pixels that change when ``nodes`` (hidden) are shown: frame shown minus frame hidden, taken again
    while the frame hidden before and after differ (the page's camera still settling by a pixel)."""
    for _ in range(6):
        before = canvas_pixels(page)
        for node in nodes:
            node.visible = True
        shown = canvas_pixels(page)
        for node in nodes:
            node.visible = False
        if not changed(before, canvas_pixels(page)).any():
            return changed(shown, before)
    raise AssertionError("the view kept changing while nodes were shown and hidden")


@pytest.mark.parametrize("model", ["boom7", "trep", "trep2", "planar3r"])
def test_labels_keep_off_the_arm_and_each_other(model: str) -> None:
    app = start_app(model, port=0, verbose=False)
    try:
        joints = [name for name in app.scene.robot.node_names[app.model.m :] if name]
        with browser_page(app.server, width=SIZES[0][0], height=SIZES[0][1], draw=True) as page:
            wait_for_nodes(page, set(joints))
            hide_toasts(page)  # the test reads the scene's pixels: a toast arriving later would be read as drawing
            client = next(iter(app.server.get_clients().values()))
            app.session.pause()
            # the overlays a background job computes (boom7's and trep2's reachable set) drawn before any picture
            drawn = lambda: app.renderer._seen.overlay_version == app.session.snapshot().overlay_version  # noqa: E731
            wait_until(
                lambda: app.session.overlays().model == app.session.snapshot().settings.model and drawn(),
                60.0,
                "the overlays drawn",
            )
            for w, h in SIZES:
                page.set_viewport_size({"width": w, "height": h})
                wait_until(lambda w=w: shown_size(page)[0] <= w, 10.0, f"the canvas laid out at {w}x{h}")
                try:
                    wait_until(lambda: reports(client, page), 20.0, f"the page's size at {w}x{h}")
                except AssertionError as e:
                    raise AssertionError(f"{e}: reported {reported_size(client)}, shown {shown_size(page)}") from e
                app.frame_robot(client)
                with contextlib.suppress(AssertionError):  # a view still gliding shows in the pixels below
                    wait_until(lambda: at_rest(page, joints, app), 15.0, f"the view at rest at {w}x{h}")
                # the labels laid out for this page as it now stands (on a busy machine the render thread can be
                # seconds behind the view: labels placed for the previous size would be read at this one)
                wait_until(lambda: laid_out_for(app, client), 30.0, f"the labels laid out at {w}x{h}")
                time.sleep(0.5)  # a layout (every 0.25 s) for this view
                labels = shown_labels(app)
                items = app.renderer.callouts.callouts.items
                callouts = {name: item.label for name, item in items.items() if item.shown}
                # every label written is a callout: the base's, "drag me", the ghost's, the clamp or spring (and
                # the 3R's region edge)
                assert {"base", "drag_me", "ghost"} <= set(callouts), sorted(callouts)
                assert all(any(h is c for c in callouts.values()) for h in labels.values()), sorted(labels)
                named = {callouts[name].text for name in ("base", "drag_me", "ghost")}
                screenshot(page, f"callouts_{model}_{w}x{h}")
                for handle in labels.values():
                    handle.visible = False
                meshes = app.scene.robot.meshes
                for mesh in meshes:
                    mesh.visible = False
                arm = pixels_of(page, meshes)
                for mesh in meshes:
                    mesh.visible = True
                assert arm.sum() > 1000, "the arm is drawn"
                masks = {handle.text: pixels_of(page, [handle]) for handle in labels.values()}
                for handle in labels.values():
                    handle.visible = True
                for text, mask in masks.items():
                    over = (mask & arm).sum() / max(mask.sum(), 1)
                    print(f"\n{model} {w}x{h} {text!r}: {mask.sum()} px, {over:.1%} over the arm", end="")
                    assert over <= OVER_ARM, (w, h, text, over)
                    rows, cols = np.nonzero(mask)
                    if text not in named and not len(rows):
                        continue  # a fixed part's name outside this view (boom7's clamp, 4 m away)
                    assert len(rows), (w, h, text, "not drawn")
                    # whole: not cut by the scene's edges (beyond them: the docked panels or the page's edge)
                    inside = cols.min() > 0 and cols.max() < mask.shape[1] - 1 and rows.min() > 0
                    assert inside and rows.max() < mask.shape[0] - 1, (w, h, text, "cut at the scene's edge")
                texts = list(masks)
                for i, a in enumerate(texts):
                    for b in texts[i + 1 :]:
                        assert not (masks[a] & masks[b]).any(), (w, h, a, b)

    finally:
        app.stop()
