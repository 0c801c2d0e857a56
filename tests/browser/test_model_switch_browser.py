"""Model switches in a real headless Chromium: after TREP -> trep2 -> TREP the page poses every node of the
arm as the server does. (viser's page keeps the pose of a node it still has when a node of that name is
created again, and the rebuild's removal can reach it merged into the create: the page kept trep2's joint
angle on TREP's link 2 and the target where trep2's was, until the rebuild resent the poses.)"""

from __future__ import annotations

import numpy as np
from playwright.sync_api import Page

from rns_viz.viz.server.app import RnsApp, start_app
from tests.support.browser import browser_page, wait_for_nodes, wait_until

POSES = """(names) => names.map((n) => {
  const o = window.__viserMutable?.nodeRefFromName?.[n];
  return o ? [o.position.x, o.position.y, o.position.z, o.quaternion.w, o.quaternion.x, o.quaternion.y,
              o.quaternion.z] : null;
})"""


def misposed(app: RnsApp, page: Page) -> list[str]:
    """Nodes under /base mounted in the page whose pose is not the server's (labels are not mounted)."""
    handles = {n: h for n, h in app.server.scene._handle_from_node_name.items() if n.startswith("/base")}
    names = sorted(handles)
    out = []
    for name, pose in zip(names, page.evaluate(POSES, names), strict=True):
        if pose is None:
            continue
        h, p = handles[name], np.asarray(pose)
        same_turn = np.allclose(h.wxyz, p[3:], atol=1e-4) or np.allclose(h.wxyz, -p[3:], atol=1e-4)
        if not (np.allclose(h.position, p[:3], atol=1e-4) and same_turn):
            out.append(f"{name}: page {np.round(p, 3)}, server {np.round(np.r_[h.position, h.wxyz], 3)}")
    return out


def test_after_switching_back_the_page_poses_the_arm_as_the_server() -> None:
    app = start_app("trep", port=0, realtime=False, verbose=False)
    try:
        assert app.session.wait_background()
        with browser_page(app.server) as page:
            wait_for_nodes(page, {"/base/link1/link2"})
            for model in ("trep2", "trep"):
                app.session.switch_model(model)
                app.session.advance(0.01)
                assert app.session.wait_background()
                app.session.advance(0.01)
                wait_until(lambda model=model: app.model_name == model, 30.0, f"the scene of {model}")
                wait_for_nodes(page, {"/base/link1/link2"} | ({"/base/c_link1"} if model == "trep2" else set()))
                wrong: list[str] = []

                def posed(wrong: list[str] = wrong) -> bool:
                    wrong[:] = misposed(app, page)
                    return not wrong

                try:
                    wait_until(posed, 30.0, f"the page to pose {model}'s scene as the server")
                except AssertionError:
                    raise AssertionError("\n".join(wrong)) from None
    finally:
        app.stop()
