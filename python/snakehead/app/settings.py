"""How the pipeline runs (:class:`Settings`), what ``--fast`` changes (:data:`FAST`), and where a run from lying
straight starts by default (:data:`PAPER_START`)."""
from __future__ import annotations

import importlib.util
from dataclasses import dataclass

__all__ = ["FAST", "NORMAL", "PAPER_START", "Settings", "mujoco_available"]

#: What ``fast`` changes: animations with fewer frames.
FAST = {"max_frames": 30}
NORMAL = {"max_frames": 100}

#: ``start`` of :func:`~snakehead.app.pipeline.run_scenes` for the paper's "current state": lying straight where the
#: curl into the bending state alone brings the base to the scene's placement (Fig. 17a before 17b).
PAPER_START = "paper"


def mujoco_available() -> bool:
    """Whether MuJoCo (the optional ``sim`` extra) is installed; found without importing it."""
    return importlib.util.find_spec("mujoco") is not None


@dataclass
class Settings:
    """How the pipeline runs. method/seed: the head IK's; fast: see FAST; simulate: run the MuJoCo check;
    figures: write figures, the animation and the 3-D viewer's page; parallel: draw what needs only the plan in a
    second process while MuJoCo simulates (Linux); relocation: let the plan move the base (by locomotion, first)
    when the targets need it; sensing: the closed loop's (:data:`snakehead.closed_loop.loop.SENSING`, with
    ``--start``)."""

    method: str = "rotated"
    seed: int | None = 1
    fast: bool = False
    simulate: bool = True
    figures: bool = True
    parallel: bool = True
    relocation: bool = True
    sensing: str = "onboard"

    def as_dict(self) -> dict:
        """The settings as the report has them (with the animations' frames and whether MuJoCo simulates)."""
        s = FAST if self.fast else NORMAL
        return {"method": self.method, "seed": self.seed, "fast": bool(self.fast), "animation_frames": s["max_frames"],
                "relocation": bool(self.relocation), "sensing": self.sensing,
                "simulation": bool(self.simulate and mujoco_available())}
