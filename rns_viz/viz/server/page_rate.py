"""How often one browser gets the scene and the plots: a rate that follows the page's answer time.

Pure logic (no viser, no clock of its own: every call is given ``now`` in seconds), driven by
:mod:`rns_viz.viz.server.page_pacing`. The server asks each page a small question (a ping) and times the
answer. A page answers after it has applied everything sent before the question, so the answer
time is how old the state it shows is. Part of it is the page's own time to draw one frame (a
software-rendered page needs a frame to answer at all): the quickest of its recent answers. The
rest is a queue. The rule is additive-increase / multiplicative-decrease on both:

- an answer slower than ``SLOW_ANSWER_S`` (the page shows a state over a second old), or a queue
  over ``QUEUE_GROWS_S``: halve the rate;
- an answer within ``FAST_ANSWER_S`` and a queue under ``QUEUE_EMPTY_S``: raise the rate by half
  (plus 2 Hz) up to the full rate (from 1 Hz back to full in 7 answers, about 2 s);
- otherwise keep it; a page that is slow but builds no queue keeps its rate;
- a question unanswered for ``SLOW_ANSWER_S`` (or two of the page's quickest answers): send at
  ``MIN_HZ`` until the answer comes, which then sets the rate;
- a question unanswered for ``HOLD_S`` (or four of the page's quickest answers, if longer): the
  page is frozen, hidden or very busy; send it nothing until it answers (then it gets the latest
  state at once, never the backlog).
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field

FULL_HZ = 60.0  # the render thread's own frame rate: a page at this rate is not paced at all
MIN_HZ = 1.0  # a page that answers at all gets at least this
SLOW_ANSWER_S = 1.0  # s: an answer slower than this halves the rate ...
QUEUE_GROWS_S = 0.25  # s: ... and so does a queue this long (answer minus the quickest recent one)
FAST_ANSWER_S = 0.5  # s: the rate rises after an answer within this ...
QUEUE_EMPTY_S = 0.1  # s: ... with a queue under this
BASE_ANSWERS = 20  # the quickest of this many recent answers is the page's own time to answer
RAISE_FACTOR, RAISE_STEP_HZ, LOWER_FACTOR = 1.5, 2.0, 0.5
HOLD_S, HOLD_BASES = 2.0, 4.0  # s without an answer (or this many quickest answers): send nothing more
NOTICE_BELOW_HZ = 30.0  # the page is told it is slowed below this rate (or while held) ...
NOTICE_GONE_HZ = 45.0  # ... until it is back at this rate (hysteresis: no flicker around one value)


@dataclass
class PaceController:
    """The rate of one page; ``ping_sent`` / ``ping_answered`` feed it, ``wait_s`` gates the sending."""

    hz: float = FULL_HZ
    asked_at: float | None = None  # s, when the oldest unanswered question was sent
    last_answer_s: float = 0.0
    noticed: bool = False  # whether the page is currently told that it is slowed
    recent: deque[float] = field(default_factory=lambda: deque(maxlen=BASE_ANSWERS))  # s, answer times

    def base_s(self) -> float:
        """The page's own time to answer (s): the quickest recent answer (0 before any)."""
        return min(self.recent, default=0.0)

    def ping_sent(self, now: float) -> None:
        """A question went out (the oldest unanswered one is what counts)."""
        if self.asked_at is None:
            self.asked_at = now

    def ping_answered(self, now: float) -> float:
        """The page answered: adapt the rate to the answer time and the queue (s); returns the answer time."""
        answer_s = 0.0 if self.asked_at is None else max(0.0, now - self.asked_at)
        self.asked_at = None
        self.last_answer_s = answer_s
        self.recent.append(answer_s)
        queue_s = answer_s - self.base_s()
        if answer_s > SLOW_ANSWER_S or queue_s > QUEUE_GROWS_S:
            self.hz = max(MIN_HZ, self.hz * LOWER_FACTOR)
        elif answer_s < FAST_ANSWER_S and queue_s < QUEUE_EMPTY_S:
            self.hz = min(FULL_HZ, self.hz * RAISE_FACTOR + RAISE_STEP_HZ)
        return answer_s

    def held(self, now: float) -> bool:
        """True while a question has been unanswered for HOLD_S (or HOLD_BASES quickest answers) or longer."""
        return self.asked_at is not None and now - self.asked_at >= max(HOLD_S, HOLD_BASES * self.base_s())

    def interval_s(self) -> float:
        """Least time between two windows sent to the page (0: not paced)."""
        return 0.0 if self.hz >= FULL_HZ else 1.0 / self.hz

    def wait_s(self, now: float, since_last_send_s: float) -> float:
        """How long to wait before sending the page its next window (0: send now). While held, the
        question is asked again later, so a short wait that is checked again."""
        if self.held(now):
            return math.inf
        interval = self.interval_s()
        if self.asked_at is not None and now - self.asked_at > max(SLOW_ANSWER_S, 2.0 * self.base_s()):
            interval = 1.0 / MIN_HZ  # an answer is late already: slow down before it comes (or the hold)
        return max(0.0, interval - since_last_send_s)

    def shown_hz(self) -> int:
        """The rate the notice states (whole Hz)."""
        return max(1, round(self.hz))

    def update_notice(self, now: float) -> bool:
        """Whether the page should show the slowed-display notice now (with hysteresis: shown below
        NOTICE_BELOW_HZ or while held, hidden again from NOTICE_GONE_HZ on)."""
        if self.held(now) or self.hz < NOTICE_BELOW_HZ:
            self.noticed = True
        elif self.hz >= NOTICE_GONE_HZ:
            self.noticed = False
        return self.noticed
