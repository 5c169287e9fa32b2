"""The pipeline's scene lanes (snakehead.app.pipeline.run_scenes with Settings.parallel): scenes dealt one lane a
core, the other lanes forked before this process's controller exists; the same report as one process planning
every scene in turn."""
from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest

from snakehead.app import pipeline
from snakehead.app.pipeline import Settings, run_scenes, scene_lanes
from snakehead.scenes import paper_scene

# what differs from run to run: clocks, and where and when the report was made
_TIMES = {"planning_time_s", "run_time_s", "stages", "seconds", "time_s"}


def _timeless(x: object) -> object:
    if isinstance(x, dict):
        return {k: _timeless(v) for k, v in x.items() if k not in _TIMES}
    if isinstance(x, list):
        return [_timeless(v) for v in x]
    return x


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="lanes fork (Linux)")
@pytest.mark.parametrize("cores, parallel, lanes", [(2, True, [["a", "c"], ["b"]]), (8, True, [["a"], ["b"], ["c"]]),
                                                    (1, True, [["a", "b", "c"]]), (2, False, [["a", "b", "c"]])])
def test_scenes_are_dealt_one_lane_a_core(monkeypatch, cores, parallel, lanes):
    from snakehead.scenes import Scene, Target

    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: set(range(cores)), raising=False)
    scenes = [Scene(n, (Target("t", (0.4, 0.0, 0.3), (1.0, 0.0, 0.0)),)) for n in "abc"]
    assert [[s.name for s in lane] for lane in scene_lanes(scenes, Settings(parallel=parallel))] == lanes


@pytest.mark.skipif(not hasattr(os, "fork"), reason="lanes fork")
def test_lanes_write_the_report_one_process_writes(tmp_path: Path, monkeypatch) -> None:
    """The paper's two scenes planned (no MuJoCo, no figures) in two lanes and in one process: the same report
    entries and files; the second scene's stages come back from its lane."""
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0, 1}, raising=False)
    scenes = [paper_scene("spheres"), paper_scene("hole")]
    reports = {}
    for parallel in (True, False):
        progress = pipeline.Progress(quiet=True)
        reports[parallel] = run_scenes(scenes, tmp_path / str(parallel), progress=progress,
                                       settings=Settings(simulate=False, figures=False, parallel=parallel))
    lanes, one = reports[True], reports[False]
    assert list(lanes["scenarios"]) == ["spheres", "hole"]
    assert _timeless(lanes["scenarios"]) == _timeless(one["scenarios"])
    assert [e["duration_s"] for e in lanes["scenarios"].values()] == pytest.approx([20.8, 14.6], abs=0.05)
    stages = [st["stage"] for st in lanes["stages"]]
    assert any(st.startswith("hole: planning") for st in stages) and any(st.startswith("spheres: planning")
                                                                       for st in stages)
    # every core runs a lane: each lane makes its outputs itself (more processes would only share the cores)
    assert any("ROS 2" in st for st in stages) and not any(st.endswith("[in a second process]") for st in stages)
    for name, entry in lanes["scenarios"].items():
        for file in entry["files"]:
            assert (tmp_path / "True" / file).read_bytes() == (tmp_path / "False" / file).read_bytes(), file


@pytest.mark.skipif(not hasattr(os, "fork"), reason="figures beside fork")
def test_one_lane_makes_its_outputs_beside_it_on_a_spare_core(tmp_path: Path, monkeypatch) -> None:
    """One scene on two cores: what needs only the plan (here the ROS outputs) is made in a process beside the
    lane, on the core the lane leaves free."""
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0, 1}, raising=False)
    report = run_scenes([paper_scene("hole")], tmp_path, progress=pipeline.Progress(quiet=True),
                        settings=Settings(simulate=False, figures=False, parallel=True))
    assert any(st["stage"].startswith("hole: ROS 2") and st["stage"].endswith("[in a second process]")
               for st in report["stages"])
    assert (tmp_path / "hole.mcap").exists()
