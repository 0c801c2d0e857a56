"""The 3-D scene: the robot from its URDF, the elastic base, overlays (paths, reachable set, arrows,
ghost, rank and gain maps), the per-model style, the pure drawing shapes, the *Show in the scene*
toggles, and the export of a recording for viser's player."""
