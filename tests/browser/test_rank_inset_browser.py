"""The rank-loss inset in a real headless Chromium: ticking *Rank loss of H_bm* shows the joint-plane
picture (300 px, decoded by the browser) with its sentence on why; screenshot of the panel to
``artifacts/screenshots/rank_inset_trep.png`` (``RNS_VIZ_SCREENSHOTS=docs/screenshots`` for the docs).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from rns_viz.viz.panels.rank_inset import SIZE_PX
from rns_viz.viz.scene.fsms_scene import FsmsScene
from rns_viz.viz.server.app import start_app
from tests.support.browser import (
    ARTIFACTS,
    browser_page,
    dismiss_notifications,
    settle_for_picture,
    wait_for_nodes,
    wait_until,
)

SHOTS = Path(os.environ.get("RNS_VIZ_SCREENSHOTS", ARTIFACTS / "screenshots"))

IMAGE_SIZE = """(label) => {
  const folder = [...document.querySelectorAll('*')].find((e) => e.textContent.trim() === label);
  let box = folder;
  while (box && !box.querySelector('img')) box = box.parentElement;
  const img = box && box.querySelector('img');
  return img && img.complete ? [img.naturalWidth, img.naturalHeight] : null;
}"""


def test_rank_inset_in_chromium() -> None:
    app = start_app("trep", port=0, verbose=False)
    try:
        panel = app.rank_inset
        with browser_page(app.server, width=1400, height=900) as page:
            wait_for_nodes(page, {FsmsScene.BASE, "/base/link1"})
            dismiss_notifications(page)
            app.view.boxes["rank"].value = True  # as the operator's tick does (the box's own callback is tested)
            wait_until(lambda: panel.updates > 0 and panel.folder.visible, 30.0, "the inset")
            title = page.get_by_text("Rank loss in joint space", exact=True)
            title.scroll_into_view_if_needed()
            wait_until(
                lambda: page.evaluate(IMAGE_SIZE, "Rank loss in joint space") == [SIZE_PX, SIZE_PX],
                20.0,
                "the picture decoded in the browser",
            )
            assert page.get_by_text("Blue dot: the arm now", exact=False).first.is_visible()
            assert panel.theta is not None and np.all(np.isfinite(panel.theta))
            settle_for_picture(page, 10)
            SHOTS.mkdir(parents=True, exist_ok=True)
            folder = title.locator("xpath=ancestor::*[.//img][1]")
            folder.evaluate("(e) => e.scrollIntoView({block: 'center'})")
            settle_for_picture(page, 5)
            box = folder.bounding_box()
            assert box is not None
            clip = {"x": box["x"] - 8, "y": box["y"] - 12, "width": box["width"] + 16, "height": box["height"] + 20}
            page.screenshot(path=str(SHOTS / "rank_inset_trep.png"), clip=clip)
            assert (SHOTS / "rank_inset_trep.png").stat().st_size > 10_000
    finally:
        app.stop()
