"""The quantities the screen names, each with one name and one unit in every place it is shown.

Plain words first, the symbol second (as everywhere in the app), and one SI unit: the readouts, the
*Show in the scene* toggles, the chart titles, the scene's labels and the *Help* tab take their words
from here, so a quantity is called the same on every model.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Quantity:
    words: str  # plain words, lower case (capitalised where they open a label)
    symbol: str  # plain text: x_b, |e|
    html_symbol: str  # the same in HTML: x<sub>b</sub>
    unit: str  # SI

    @property
    def name(self) -> str:
        """Words and symbol, as a label or Help writes them: "base vibration x_b"."""
        return f"{self.words} {self.symbol}"

    @property
    def html_name(self) -> str:
        """Words and symbol in HTML, as a readout writes them: "base vibration x<sub>b</sub>"."""
        return f"{self.words} {self.html_symbol}"


BASE_VIBRATION = Quantity("base vibration", "x_b", "x<sub>b</sub>", "m")  # Eq. (1)
MOMENTUM = Quantity("momentum handed to the base", "L", "L", "N·s")  # L = H_bm θ', Eq. (8); 1 N·s = 1 kg·m/s
HAND_MISS = Quantity("hand's miss", "|e|", "|e|", "m")  # how far the hand is from where it is sent
REACTION = Quantity("reaction on the base", "F_b", "F<sub>b</sub>", "N")  # −(H_bm θ'' + c_b), Eq. (1)
QUANTITIES = (BASE_VIBRATION, MOMENTUM, HAND_MISS, REACTION)
