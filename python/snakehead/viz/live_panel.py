"""What the live viewer (:mod:`.live`) records and says: each request's :class:`Replan` and each MuJoCo check's
:class:`DynamicsCheck`, the panel's texts, and :class:`ClientPanel`, each browser's own part of the panel.

The panel is shared where the state is: the plan's status, the motion shown and its errors, play, time and speed
(every browser watches the same robot move), and the buttons. What one browser chooses is its own
(:class:`ClientPanel`, made when it connects, dropped when it leaves): the target its "remove target" removes, the
file name its "save scene" saves to, and what became of its own actions and saves -- so one client can neither aim
another's save nor read what another saved.
"""
from __future__ import annotations

import threading
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Callable

from .._errors import InputError

if TYPE_CHECKING:
    from ..sim.simulate_plan import PlanSimulation
    from .live_nodes import LiveMotion


__all__ = ["Replan", "DynamicsCheck", "ClientPanel", "ClientPanels", "shown_text", "errors_text", "MOTION_WATCH_JS"]

@dataclass
class Replan:
    """One request (a target moved, added or removed) and what became of it. Times are epoch seconds
    (``time.time()``; a browser's ``Date.now() / 1000`` on the same machine compares with them): ``released``
    (the request), ``plan_started`` and ``planned`` (around ``snakehead.plan``), ``drawn`` (its motion's frames
    computed) and ``playing`` (its first frame sent to the browsers). ``superseded``: a newer request came while it
    was planned, so it was never shown. ``failure``: the plan's, if it failed; ``error``: what went wrong if
    planning raised or the motion is longer than the viewer plays (then nothing plays)."""

    number: int
    what: str
    released: float
    plan_started: float | None = None
    planned: float | None = None
    drawn: float | None = None
    playing: float | None = None
    superseded: bool = False
    failure: str | None = None
    error: str | None = None

    @property
    def settled(self) -> bool:
        """Done with: playing, dropped for a newer request, or failed with an error."""
        return self.playing is not None or self.superseded or self.error is not None

    @property
    def planning_s(self) -> float:
        """s spent in ``snakehead.plan``."""
        return _span(self.plan_started, self.planned)

    @property
    def latency_s(self) -> float:
        """s from the request to its motion playing (NaN if it never played)."""
        return _span(self.released, self.playing)

    @property
    def overhead_s(self) -> float:
        """The viewer's share of :attr:`latency_s`: everything but planning (waiting for the worker, drawing,
        sending)."""
        return self.latency_s - self.planning_s


def _span(start: float | None, end: float | None) -> float:
    return float("nan") if start is None or end is None else end - start


@dataclass
class DynamicsCheck:
    """The MuJoCo check of motion ``number``: its :class:`~snakehead.sim.simulate_plan.PlanSimulation`, or ``error``."""

    number: int
    simulation: PlanSimulation | None = None
    error: str | None = None
    seconds: float = float("nan")


@dataclass
class ClientPanel:
    """One browser's own part of the live viewer's panel (viser handles of that client's GUI): ``notice`` (what
    became of its last action), ``chosen`` (the target "remove target" removes), ``file`` (the name "save scene"
    saves to, in the viewer's save folder) and ``saved`` (what became of its last save)."""

    client_id: int
    notice: Any
    chosen: Any
    file: Any
    saved: Any

    def tell(self, text: str) -> None:
        self.notice.content = text


class ClientPanels:
    """Every connected browser's :class:`ClientPanel`, by viser client id: made on connect (:meth:`bind`), dropped
    on disconnect. ``say``: the shared status line, for what has no browser to be told to."""

    def __init__(self, say: Callable[[str], None]) -> None:
        self._say = say
        self._panels: dict[int, ClientPanel] = {}
        self._lock = threading.Lock()

    def bind(self, server: Any, status: Any, targets: tuple[Any, Any], files: tuple[Any, Any],
             now: Callable[[], tuple[tuple[str, ...], str]]) -> None:
        """Make a panel for each browser that connects to ``server``: its notice under ``status``, its target menu
        before the button ``targets[1]`` in the folder ``targets[0]``, its file box before and its save line after
        the button ``files[1]`` in the folder ``files[0]``. ``now()``: the targets' names and the file name to
        start from."""

        def connected(client: Any) -> None:
            names, file_name = now()
            gui = client.gui
            notice = gui.add_markdown("", order=status.order + 0.5)
            with targets[0]:
                chosen = gui.add_dropdown("target", names, order=targets[1].order - 0.5)
            with files[0]:
                file = gui.add_text("file", initial_value=file_name, order=files[1].order - 0.5)
                saved = gui.add_markdown("", order=files[1].order + 0.5)
            with self._lock:
                self._panels[client.client_id] = ClientPanel(client.client_id, notice, chosen, file, saved)
            chosen.options = now()[0]  # the targets may have changed while it was made

        def left(client: Any) -> None:
            with self._lock:
                self._panels.pop(client.client_id, None)

        server.on_client_connect(connected)
        server.on_client_disconnect(left)

    def of(self, client: Any) -> ClientPanel | None:
        """The panel of viser's ``client`` (None: no client, or its panel is not made yet)."""
        with self._lock:
            return None if client is None else self._panels.get(client.client_id)

    def all(self) -> list[ClientPanel]:
        with self._lock:
            return list(self._panels.values())

    def set_targets(self, names: tuple[str, ...]) -> None:
        """The targets' names in every browser's menu."""
        for panel in self.all():
            panel.chosen.options = names

    def tell(self, client: Any, text: str) -> None:
        """Say ``text`` to the browser ``client`` alone (to all, in the shared status, when it has no panel)."""
        panel = self.of(client)
        if panel is not None:
            panel.tell(text)
        elif text:
            self._say(text)

    def reported(self, client: Any, action: Callable[[], Any]) -> bool:
        """Run a panel's or a gizmo's action for ``client``; a mistake of the user's (InputError) is told to that
        browser (its notice cleared when the action is done). Whether it was done."""
        try:
            action()
        except InputError as exc:
            self.tell(client, f"**Not done:** {exc}")
            return False
        self.tell(client, "")
        return True


def shown_text(record: Replan, motion: LiveMotion) -> str:
    """The panel's line on the motion shown (the browser test reads "motion N playing" in it)."""
    plan = motion.plan
    text = (f"**Plan {record.number}** ({record.what}): planned in {record.planning_s:.2f} s; motion "
            f"{record.number} playing ({motion.duration_s:.1f} s).")
    if plan.relocation is not None:
        r = plan.relocation.base
        text += f" The base lies elsewhere first (x {r.x:.3f} m, y {r.y:.3f} m, yaw {r.yaw:.2f} rad)."
    if record.failure is not None:
        text += f"\n\n**Failed:** {record.failure}"
    return text


def errors_text(motion: LiveMotion, check: DynamicsCheck | None) -> str:
    """The plan's errors, and beside them MuJoCo's when the last check was of this motion."""
    plan = motion.plan
    pos = max((tg.position_error_m for tg in plan.targets), default=float("nan"))
    ang = max((tg.direction_error_deg for tg in plan.targets), default=float("nan"))
    rows = [("position error", f"{1000 * pos:.2f} mm"), ("direction error", f"{ang:.2f}°"),
            ("ZMP", f"{1000 * plan.min_zmp_margin_m:.1f} mm inside at least")]
    sim = None if check is None or check.number != motion.number else check
    if sim is not None and sim.simulation is not None:
        m = sim.simulation
        cells = [f"{1000 * m.position_error_m:.2f} mm", f"{m.direction_error_deg:.2f}°",
                 "inside" if m.zmp_inside else "**leaves the polygon**"]
    else:
        cells = ["-"] * 3
    lines = ["| | planned | MuJoCo |", "|---|---|---|"]
    lines += [f"| {name} | {value} | {cell} |" for (name, value), cell in zip(rows, cells)]
    if sim is not None and sim.error is not None:
        lines.append(f"\nMuJoCo: {sim.error}")
    elif check is not None and sim is None:
        lines.append(f"\n(the last MuJoCo check was of motion {check.number})")
    return "\n".join(lines)


#: JavaScript for measuring the viewer in a browser (tests/viz/test_live_viewer.py, bench/live_latency.py): the time
#: (Date.now(), ms) each "motion N playing" first appears in the panel, and the second frame painted after it.
MOTION_WATCH_JS = """
window.__motions = {};
const seen = () => {
  const m = document.body.textContent.match(/motion (\\d+) playing/);
  if (m && !(m[1] in window.__motions)) {
    const entry = {text: Date.now()};
    window.__motions[m[1]] = entry;
    requestAnimationFrame(() => requestAnimationFrame(() => { entry.painted = Date.now(); }));
  }
};
new MutationObserver(seen).observe(document.body, {subtree: true, childList: true, characterData: true});
seen();
"""
