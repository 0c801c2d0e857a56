"""What the scene tests share: how far points lie from drawn line segments."""

from __future__ import annotations

import numpy as np


def distance_to_segments(points: np.ndarray, segments: np.ndarray) -> np.ndarray:
    """Each point's distance (m) to the nearest of the segments (K, 2, 3): a test oracle."""
    a, b = segments[:, 0], segments[:, 1]
    ab = b - a
    rel = points[:, None, :] - a[None]
    t = np.clip(np.einsum("pkj,kj->pk", rel, ab) / np.maximum(np.einsum("kj,kj->k", ab, ab), 1e-300), 0.0, 1.0)
    return np.linalg.norm(rel - t[..., None] * ab[None], axis=2).min(axis=1)
