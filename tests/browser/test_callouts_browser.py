"""Labels never hide the arm nor each other, read from the rendered pixels of a real Chromium.

With the simulation paused and the page's view at rest, all read in one view: a reference frame with every
label hidden; the arm's pixels are those that change when the robot's meshes are hidden, a label's those that
change when it alone is shown; the reference is taken again last, and the view read again unless both agree.
The pixels under the page's elements over the canvas (the floating panel, a phone's sheet) are left out: a
label reaching one is cut by it. At a projector's, a laptop's and a phone's size, for the models whose labels
sat over the hand (boom7: "drag me" 37 % and the ghost's 68 % of their pixels over the arm, before the callouts), and
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
    dismiss_notifications,
    screenshot,
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


# Wait until the page has taken the nodes' visibility (its scene tree holds it, and a node's three.js object, if it
# has one, is set so; a label is drawn by the page's label renderer, which reads the tree every frame), then for
# ``frames`` more frames (it draws a change in the frame after it took it); false after ``timeout`` ms.
VISIBILITY_TAKEN = """([visible, frames, timeout]) => new Promise((done) => {
  const start = performance.now();
  let after = -1;
  const taken = () => {
    const tree = window.__viserSceneTree.getState(), objects = window.__viserMutable.nodeRefFromName;
    return Object.entries(visible).every(([name, want]) => {
      const node = tree[name], obj = objects[name];
      return node !== undefined && (node.effectiveVisibility ?? false) === want && (!obj || obj.visible === want);
    });
  };
  const step = () => {
    if (after < 0 && taken()) after = 0;
    if (after >= 0 && ++after > frames) return done(true);
    if (performance.now() - start > timeout) return done(false);
    requestAnimationFrame(step);
  };
  requestAnimationFrame(step);
})"""
# drawing pixels per page pixel of the 3-D canvas
DENSITY = "() => { const c = window.__viserMutable.canvas; return c.width / c.getBoundingClientRect().width; }"
# The boxes of the page's elements topmost at a grid of points of the canvas's part ``[x, y, width, height]`` (page
# px, grid step px), relative to it
OVER_CANVAS = """([x, y, width, height, step]) => {
  const canvas = window.__viserMutable.canvas, boxes = new Map();
  for (let v = step / 2; v < height; v += step)
    for (let u = step / 2; u < width; u += step) {
      const e = document.elementFromPoint(x + u, y + v);
      if (e !== null && e !== canvas && !boxes.has(e)) {
        const r = e.getBoundingClientRect();
        boxes.set(e, [r.left - x, r.top - y, r.right - x, r.bottom - y]);
      }
    }
  return [...boxes.values()];
}"""
OVER_CANVAS_STEP = 8
TRIES = 5  # views read per size: again while the view moved between its first and last frame


def show(page, shown: list, hidden: list) -> None:  # type: ignore[no-untyped-def]
    """Show the nodes ``shown``, hide ``hidden``, and wait until the page draws them so."""
    visible = {node.name: True for node in shown} | {node.name: False for node in hidden}
    for node in [*shown, *hidden]:
        node.visible = visible[node.name]
    assert page.evaluate(VISIBILITY_TAKEN, [visible, 2, 10_000]), f"the page never drew {visible}"


def canvas_clip(page) -> dict[str, int]:  # type: ignore[no-untyped-def]
    """The 3-D canvas's part inside the viewport, whole page pixels."""
    c = canvas_box(page)
    vw, vh = page.viewport_size["width"], page.viewport_size["height"]
    x0, y0 = int(max(c["x"], 0)), int(max(c["y"], 0))
    x1, y1 = int(min(c["x"] + c["w"], vw)), int(min(c["y"] + c["h"], vh))
    return {"x": x0, "y": y0, "width": x1 - x0, "height": y1 - y0}


def canvas_pixels(page, clip: dict[str, int]) -> np.ndarray:  # type: ignore[no-untyped-def]
    """The page's pixels in ``clip`` as drawn now, RGB ints (h, w, 3)."""
    return np.asarray(Image.open(io.BytesIO(page.screenshot(clip=clip))).convert("RGB")).astype(int)


def covered(page, clip: dict[str, int]) -> np.ndarray:  # type: ignore[no-untyped-def]
    """(h, w) bool: the pixels of ``clip`` under an element drawn over the canvas (the floating panel, whose
    notices change as the page's pace does)."""
    boxes = page.evaluate(OVER_CANVAS, [clip["x"], clip["y"], clip["width"], clip["height"], OVER_CANVAS_STEP])
    over = np.zeros((clip["height"], clip["width"]), dtype=bool)
    for x0, y0, x1, y1 in boxes:
        over[max(int(y0), 0) : max(int(np.ceil(y1)), 0), max(int(x0), 0) : max(int(np.ceil(x1)), 0)] = True
    return over


def changed(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.abs(a - b).sum(axis=2) > CHANGED


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


def pixels_at_rest(page, meshes: list, labels: list) -> tuple[np.ndarray, list[np.ndarray], np.ndarray]:  # type: ignore[no-untyped-def]
    """The arm's pixels and each label's, all read in one view (``labels`` hidden, ``meshes`` shown), and the
    pixels under the page's elements over the canvas (left out of both): a reference frame; the arm's pixels
    are those that change when ``meshes`` are hidden, a label's those that change when it alone is shown; the
    reference again last. Read anew while the two references differ (the page's camera still gliding, by a
    pixel at its end)."""
    clip = canvas_clip(page)
    for _ in range(TRIES):
        over = covered(page, clip)
        reference = canvas_pixels(page, clip)
        show(page, [], meshes)
        arm = changed(reference, canvas_pixels(page, clip))
        frames, back, gone = [], meshes, []  # each step shows the label alone: what the step before hid comes back
        for label in labels:
            show(page, [*back, label], gone)
            frames.append(canvas_pixels(page, clip))
            back, gone = [], [label]
        show(page, back, gone)
        again = canvas_pixels(page, clip)
        over |= covered(page, clip)
        if not (changed(reference, again) & ~over).any():
            return arm & ~over, [changed(frame, reference) & ~over for frame in frames], over
        print("\nthe view moved while it was read: read again", end="")
    raise AssertionError("the view kept changing while the arm and the labels were shown and hidden")


@pytest.mark.parametrize("model", ["boom7", "trep", "trep2", "planar3r"])
def test_labels_keep_off_the_arm_and_each_other(model: str) -> None:
    app = start_app(model, port=0, verbose=False)
    try:
        joints = [name for name in app.scene.robot.node_names[app.model.m :] if name]
        # drawn at the screen's density throughout (viser's switch for it): viser otherwise lowers a page's density
        # while it draws slowly, and raises it again, which changes every pixel between two frames of one view
        with browser_page(app.server, SIZES[0][0], SIZES[0][1], draw=True, query="?fixedDpr=1") as page:
            wait_for_nodes(page, set(joints))
            dismiss_notifications(page)
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
                assert abs(page.evaluate(DENSITY) - 1.0) < 0.01, "the page draws at the screen's density"
                labels = shown_labels(app)
                items = app.renderer.callouts.callouts.items
                callouts = {name: item.label for name, item in items.items() if item.shown}
                # every label written is a callout: the base's, "drag me", the ghost's, the clamp or spring (and
                # the 3R's region edge)
                assert {"base", "drag_me", "ghost"} <= set(callouts), sorted(callouts)
                assert all(any(h is c for c in callouts.values()) for h in labels.values()), sorted(labels)
                named = {callouts[name].text for name in ("base", "drag_me", "ghost")}
                screenshot(page, f"callouts_{model}_{w}x{h}")
                show(page, [], list(labels.values()))
                arm, label_masks, over = pixels_at_rest(page, app.scene.robot.meshes, list(labels.values()))
                print(f"\n{model} {w}x{h}: {over.mean():.1%} of the scene under the page's elements", end="")
                # the pixels beside an element over the canvas: a label reaching them is cut by it
                beside = np.zeros_like(over)
                beside[1:] |= over[:-1]
                beside[:-1] |= over[1:]
                beside[:, 1:] |= over[:, :-1]
                beside[:, :-1] |= over[:, 1:]
                show(page, list(labels.values()), [])
                assert arm.sum() > 1000, "the arm is drawn"
                masks = {handle.text: mask for handle, mask in zip(labels.values(), label_masks, strict=True)}
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
                    assert not (mask & beside).any(), (w, h, text, "cut by an element over the scene")
                texts = list(masks)
                for i, a in enumerate(texts):
                    for b in texts[i + 1 :]:
                        assert not (masks[a] & masks[b]).any(), (w, h, a, b)

    finally:
        app.stop()
