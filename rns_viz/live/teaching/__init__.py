"""Teaching: the guided lessons (text, the paper's equation, a state to load and a measured check), the
lesson in progress, and the rank-deficiency views the scene and its inset draw."""
