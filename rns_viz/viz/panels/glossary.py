"""The *Help* tab: the symbols on the screen in plain words, the paper's equations they come from, and
the keys. Plain words first, the symbol second, as everywhere in the app."""

from __future__ import annotations

from rns_viz.viz.scene.quantities import BASE_VIBRATION, HAND_MISS, MOMENTUM, REACTION

# (plain words, symbol, what it is, where in the paper)
GLOSSARY: tuple[tuple[str, str, str, str], ...] = (
    (
        BASE_VIBRATION.words,
        BASE_VIBRATION.symbol,
        f"how far the flexible base (beam, cart, boom tip) is bent from rest, {BASE_VIBRATION.unit}",
        "Eq. (1)",
    ),
    (
        REACTION.words,
        REACTION.symbol,
        f"the force the arm's motion puts on the base, −(H_bm θ'' + c_b), {REACTION.unit}; with a compensating "
        "arm, what both arms leave on it",
        "Eq. (1)",
    ),
    (
        MOMENTUM.words,
        f"{MOMENTUM.symbol} = H_bm θ'",
        f"the coupling momentum: what the joints' motion gives the base, {MOMENTUM.unit} (1 N·s = 1 kg·m/s); "
        "zero on a reactionless path",
        "Eq. (8)",
    ),
    (
        HAND_MISS.words,
        HAND_MISS.symbol,
        f"how far the hand is from where the control law (or the dragged target) sends it, {HAND_MISS.unit}",
        "",
    ),
    ("coupling inertia", "H_bm", "how the joints' motion couples into the base (a matrix)", "Eq. (1)"),
    (
        "reaction-free direction",
        "n",
        "the joint motion that pushes the base not at all (the reaction null space, one direction)",
        "Eq. (27)",
    ),
    (
        "speed along the path",
        "ū",
        "how fast the joints move along n, in 1/(kg·m·s); ∫ū dt is the position along the path, 1/(kg·m)",
        "Eq. (30)",
    ),
    ("reactionless path", "—", "a joint motion that never pushes the base: the crimson curve", "Sec. V"),
    (
        "hand Jacobian in the null space",
        "J̄",
        "how the hand moves when the joints move without pushing the base; where it loses rank the reachable "
        "region ends",
        "Eq. (24)",
    ),
    ("damping gain", "g_b", "how hard the arm fights the base's swing, 1/s", "Eqs. (15), (16), (30)"),
    (
        "joint gain",
        "g_m",
        "law (30): how firmly the joints are held to their reference (Joint hold); laws (15), (16): how strongly "
        "joint motion that pushes the base is damped (Joint damping), 1/s",
        "Eqs. (15), (16), (30)",
    ),
    ("decay rate", "σ_b", "how fast the base's swing dies out (bigger is faster), 1/s", "gain map"),
    (
        "ghost run (shadow run)",
        "—",
        "a second simulation with the same pushes but suppression the other way: the ghost, blue or red as its "
        "plot lines",
        "",
    ),
    ("drawn larger", "×", "the base's bend is drawn this many times larger than simulated (written beside it)", ""),
    ("× real time", "—", "simulated seconds per wall-clock second (1 = real time)", ""),
    ("symmetric log", "—", "a plot scale that shows µm and mm on one axis (and both signs)", ""),
)


# (label, key, modifier, what it does): the table the help tab shows
KEYS: tuple[tuple[str, str, str | None, str], ...] = (
    ("Pause / resume", "P", None, "freeze the simulation or let it run on"),
    ("Kick the base", "K", None, "push the base once (the kick size in the panel)"),
    ("Reset", "R", None, "back to the start (of the preset or lesson)"),
    ("Vibration suppression on/off", "V", None, "the arm damps the base's swing, or not"),
    ("Frame robot", "F", None, "your camera back on the robot (only your view)"),
    ("Jog target −x", "J", "shift", "move the hand's target one step"),
    ("Jog target +x", "L", "shift", "move the hand's target one step"),
    ("Jog target +y", "I", "shift", "move the hand's target one step"),
    ("Jog target −y", "K", "shift", "move the hand's target one step"),
    ("Jog target −z", "U", "shift", "move the hand's target one step (3-D models)"),
    ("Jog target +z", "O", "shift", "move the hand's target one step (3-D models)"),
)


def key_name(key: str, modifier: str | None) -> str:
    return f"Shift+{key}" if modifier == "shift" else key


def glossary_markdown() -> str:
    """The Help tab's text: the glossary as a list, then the keys."""
    words = "\n".join(
        f"- **{plain}** {'' if symbol == '—' else f'`{symbol}`'}: {what}{f' ({where})' if where else ''}."
        for plain, symbol, what, where in GLOSSARY
    )
    keys = "\n".join(f"- `{key_name(key, mod)}`: {label}" for label, key, mod, _ in KEYS)
    return (
        "Equations are those of Nenchev, Yoshida, Vichitkulsawat and Uchiyama, *Reaction null-space control "
        "of flexible structure mounted manipulator systems*, IEEE T-RA 15(6), 1999.\n\n"
        f"{words}\n\n**Keys** (click the scene first; W A S D Q E and the arrows move the camera):\n\n{keys}"
    )
