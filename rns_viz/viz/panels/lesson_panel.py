"""The *Lessons* folder: the lesson in progress (title, equation, explanation, task, progress, ✓ when
done), Previous / Next / Stop, and a chooser over every lesson of every model, showing the lesson running
or else the first lesson of the model served.

The lessons and their checks live in :mod:`rns_viz.live.teaching.lessons`; this panel only starts and stops
them through the session and shows ``snapshot().lesson``. Refreshed by the render thread at 5 Hz.
"""

from __future__ import annotations

import traceback
from collections.abc import Callable, Iterable
from pathlib import Path

import viser

from rns_viz.live.loop.session import Session
from rns_viz.live.published.snapshot import LessonStatus, Snapshot
from rns_viz.live.teaching.lessons import lessons_for
from rns_viz.params import MODEL_NAMES, model_source, param_file_for
from rns_viz.viz.clients.connections import Connections
from rns_viz.viz.scene.view_toggles import ViewToggles

# What each lesson draws (the rest can be ticked by hand): only what the lesson has explained so far,
# so TREP's first lesson shows no ghost (its suppression is lesson 4's subject) and no n (lesson 3's).
BASICS = ("reaction", "trail", "labels")
LESSON_VIEWS: dict[str, tuple[str, ...]] = {
    "trep-spring": BASICS,
    "trep-pushing-motion": (*BASICS, "coupling"),
    "trep-reactionless-path": (*BASICS, "coupling", "null_vector", "path_arrows"),
    "trep-suppression": (*BASICS, "coupling", "ghost"),
    "trep-weakest-point": (*BASICS, "coupling", "null_vector", "path_arrows"),
    "trep-move-and-suppress": (*BASICS, "coupling", "null_vector", "path_arrows", "ghost"),
    "3r-tracking": (*BASICS, "coupling", "reach"),
    "3r-reachable-set": (*BASICS, "reach"),
    "3r-absorb-kick": (*BASICS, "coupling", "reach", "ghost"),
    "boom7-six-modes": (*BASICS, "ghost"),
    "boom7-path": (*BASICS, "coupling", "null_vector", "path_arrows"),
    "boom7-forces-only": (*BASICS, "coupling"),
}
NO_LESSON = (
    "No lesson running. Pick one under *Lesson* and press *Start*, or press *Next* for lesson 1. Each lesson "
    "loads a state, gives you a task and tells you when the simulation shows it done."
)
LAST_DONE = "That was the last lesson of this model: pick another under *Lesson* and press *Start*."


def lesson_choices(keys: Iterable[str] = MODEL_NAMES) -> dict[str, tuple[str, int]]:
    """The chooser's entries, ``"TREP 1. The base is a spring"`` -> (model key, lesson number): the lessons of
    every model in ``keys`` (each model's ``[app] lessons``, its ``[app] short_label`` in front)."""
    choices = {}
    for key in keys:
        short = param_file_for(key).app.short_label or Path(model_source(key)).stem
        for i, lesson in enumerate(lessons_for(key)):
            choices[f"{short} {i + 1}. {lesson.title}"] = (key, i + 1)
    return choices


def chooser_entry(status: LessonStatus | None, model: str, choices: dict[str, tuple[str, int]]) -> str:
    """The chooser's entry: the lesson running, else lesson 1 of model ``model`` (a model key), else of the first
    model with lessons."""
    wanted = (status.model, status.number) if status is not None else (model_source(model), 1)
    return next((k for k, v in choices.items() if v == wanted), next(iter(choices)))


def lesson_markdown(status: LessonStatus | None) -> str:
    """The panel text for a lesson status (or the invitation when none runs)."""
    if status is None:
        return NO_LESSON
    mark = " ✓" if status.done else ""
    then = "Press *Next* for the next lesson." if status.number < status.count else LAST_DONE  # (Next: disabled)
    progress = f"**Done.** {then}" if status.done else status.progress
    return (
        f"**Lesson {status.number} of {status.count}: {status.title}**{mark}\n\n"
        f"{status.text}\n\n**Task:** {status.task}\n\n**Look at:** {status.look}\n\n{progress}\n\n"
        f"*In the paper: {status.equation}*"
    )


class LessonPanel:
    """Widgets of the Lessons folder and their callbacks (operator only)."""

    def __init__(
        self,
        server: viser.ViserServer,
        session: Session,
        connections: Connections,
        order: float | None = None,
        view: ViewToggles | None = None,
        models: Iterable[str] = MODEL_NAMES,
    ) -> None:
        self.session, self.connections, self.view = session, connections, view
        self.choices = lesson_choices(models)  # of the models in the menu
        self._names = {v: lessons_for(v[0])[v[1] - 1].name for v in self.choices.values()}  # (model, number) -> name
        gui = server.gui
        with gui.add_folder("Lessons", order=order):
            self.text = gui.add_markdown(NO_LESSON)
            self.previous = gui.add_button("Previous", icon=viser.Icon.PLAYER_SKIP_BACK, hint="The lesson before.")
            self.next = gui.add_button(
                "Next", icon=viser.Icon.PLAYER_SKIP_FORWARD, hint="The next lesson (lesson 1 when none runs)."
            )
            self.stop = gui.add_button("Stop lesson", icon=viser.Icon.PLAYER_STOP, hint="Leave the lesson mode.")
            self.chooser = gui.add_dropdown(
                "Lesson",
                tuple(self.choices),
                hint="Every lesson of every model; Start loads the chosen one (and its model).",
            )
            self.start = gui.add_button("Start", icon=viser.Icon.PLAYER_PLAY, hint="Start the lesson chosen above.")
        self._wire(self.previous, lambda c: self._step(-1, c))
        self._wire(self.next, lambda c: self._step(+1, c))
        self._wire(self.stop, lambda c: session.stop_lesson(c))
        self._wire(self.start, self._start_chosen)
        self._shown = NO_LESSON
        self._for: tuple[tuple[str, int] | None, str] | None = None  # (lesson, model source) the chooser was set for

    def _wire(self, button: viser.GuiButtonHandle, act: Callable[[int | None], None]) -> None:
        @button.on_click
        def _(event: viser.GuiEvent) -> None:
            client = event.client
            if not self.connections.allowed(client):
                self.connections.refuse_watcher(client)
                return
            try:
                act(None if client is None else client.client_id)
            except ValueError as exc:
                self.connections.notify(client, "Lesson not started", str(exc), "warning")
            except Exception as exc:  # never let a click kill the server
                traceback.print_exc()
                self.connections.notify(client, "Lesson not started", f"{type(exc).__name__}: {exc}", "error")

    def _step(self, direction: int, client: int | None) -> None:
        snap = self.session.snapshot()
        status = snap.lesson
        if status is None:
            offering = {model for model, _ in self.choices.values()}
            model = snap.settings.model if snap.settings.model in offering else next(iter(self.choices.values()))[0]
            self.session.start_lesson(model, 1, client)
            return
        number = status.number + direction
        if 1 <= number <= status.count:
            self.session.start_lesson(status.model, number, client)
        else:
            raise ValueError("that was the last lesson" if direction > 0 else "this is the first lesson")

    def _start_chosen(self, client: int | None) -> None:
        choice = self.choices.get(self.chooser.value)
        if choice is None:
            raise ValueError(f"no lesson named {self.chooser.value!r}")
        self.session.start_lesson(*choice, client=client)

    def refresh(self, snap: Snapshot) -> None:
        """Show the lesson in progress (render thread, at text rate)."""
        text = lesson_markdown(snap.lesson)
        if text != self._shown:
            self._shown = text
            self.text.content = text
        status = snap.lesson
        shown = None if status is None else (status.model, status.number)
        now = (shown, model_source(snap.settings.model))
        if now != self._for:  # the chooser follows the lesson started (by any button or the CLI) or the model
            started = self._for is None or shown != self._for[0]
            self._for = now
            name = chooser_entry(status, snap.settings.model, self.choices)
            if self.chooser.value != name:
                self.chooser.value = name
            views = LESSON_VIEWS.get(self._names.get(shown, "")) if shown is not None else None
            if started and self.view is not None and views is not None:
                self.view.show_only(views)
        _set_disabled(self.previous, status is None or status.number <= 1)
        _set_disabled(self.next, status is not None and status.number >= status.count)
        _set_disabled(self.stop, status is None)


def _set_disabled(button: viser.GuiButtonHandle, disabled: bool) -> None:
    if button.disabled != disabled:  # send only changes
        button.disabled = disabled
