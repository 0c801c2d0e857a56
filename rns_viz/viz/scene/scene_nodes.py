"""The scene's nodes, and a rebuild for another model that leaves nothing of the old one in any browser.

Why a rebuild needs care (viser 1.1.1): the server keeps one buffer of scene messages for all clients,
in which a node's *create* and *remove* messages share a slot, so removing a node and adding one of the
same name before a client has read the removal leaves that client only the create. viser's page treats
a create for a name it still has as an update of that node and keeps its pose, and the server sends no
pose for a new node whose pose is the default (identity, origin). After TREP -> trep2 -> TREP the page
kept trep2's joint angle on TREP's link 2. :func:`resend_poses` sends the pose of every rebuilt node that
had a namesake before, whatever it is, so each page shows the server's scene.
"""

from __future__ import annotations

import viser


def node_names(server: viser.ViserServer) -> set[str]:
    """Names of the server's scene nodes. viser 1.1 keeps its handles in a registry it does not expose
    otherwise; an empty set if that ever moves (then nothing is resent, as before this module)."""
    registry = getattr(server.scene, "_handle_from_node_name", None)
    return set(registry) if isinstance(registry, dict) else set()


def resend_poses(server: viser.ViserServer, names: set[str]) -> None:
    """Send the pose of the nodes ``names`` again, also where it equals a new node's default.

    viser sends a pose only when it changes, so each is set to another value first, then back; inside one
    ``atomic()`` block no window leaves in between, and the second message replaces the first in the
    buffer (they share a slot): each client receives the true pose once."""
    with server.atomic():
        for name in sorted(names):
            handle = server.scene.get_handle_by_name(name)
            if handle is None:
                continue
            position, wxyz = handle.position.copy(), handle.wxyz.copy()
            handle.position = position + 1.0
            handle.position = position
            handle.wxyz = -wxyz  # the same rotation, another quaternion: it is sent
            handle.wxyz = wxyz
