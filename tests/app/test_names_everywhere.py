"""Names are data, everywhere they are shown (issue: hostile input, names).

A name -- a scene's, a target's, a phase's, a frame's -- is decided once where it enters
(:func:`snakehead._validate.name_text`): one line of printable text, at most MAX_NAME_CHARS characters. Control,
format, surrogate and line-separator characters (newline, tab, NUL, escape, bidirectional overrides...) are an
InputError naming the field; everything else (``$\\frac{$``, ``<script>``, ``|``, backticks, backslashes, any
script) is a valid name that every writer shows literally: matplotlib (no mathtext), Markdown (summary.md: no markup,
a table row keeps its columns), HTML (the viewer's page: no element), JSON, the viewer's scene file and its scene
tree. A scene's name also names files, so it is a portable file name besides.

Hypothesis draws the names (markup, mathtext, HTML, Markdown, unicode and control characters) and runs each through
every figure function and report writer that shows one, on small synthetic inputs (a generated 8-joint snake, an
11-sample motion): a few seconds per test. Examples are drawn from a fixed seed as in test_properties.py; set
SNAKEHEAD_FUZZ_EXAMPLES=N to draw N random cases per test instead.
"""
from __future__ import annotations

import html
import json
import os
import re
import subprocess
import sys
import types
import unicodedata
import warnings
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, example, given, settings
from hypothesis import strategies as st
from matplotlib import cbook
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.text import Text

from snakehead import BasePlacement, SnakeRobot
from snakehead._errors import InputError
from snakehead._validate import MAX_NAME_BYTES, MAX_NAME_CHARS, file_name_part
from snakehead.app import report as rep
from snakehead.collision import body_collisions as coll
from snakehead.dynamics import stability
from snakehead.geometry.obstacles import BoxObstacle
from snakehead.model.generate import SnakeSpec, snake_urdf
from snakehead.planning.plan_result import Plan, TargetResult
from snakehead.scenes.scene import Scene, Target, load_scene, scene_from_dict

_EXAMPLES = int(os.environ.get("SNAKEHEAD_FUZZ_EXAMPLES", "0"))

#: A glyph missing from matplotlib's font is drawn as a box, with a warning: a name in any script is still a name.
pytestmark = pytest.mark.filterwarnings("ignore:Glyph .* missing from font")


def fuzz(examples: int) -> Any:
    """As test_properties.fuzz: ``examples`` cases from a fixed seed, or SNAKEHEAD_FUZZ_EXAMPLES random ones."""
    return settings(max_examples=_EXAMPLES or examples, derandomize=not _EXAMPLES, deadline=None, database=None,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                           HealthCheck.filter_too_much, HealthCheck.function_scoped_fixture],
                    print_blob=False)


# ------------------------------------------------------------------------------------------------------------
# the names
# ------------------------------------------------------------------------------------------------------------
#: Names that broke or passed markup into an output, and their kin.
HOSTILE = ["$\\frac{$", "$\\sqrt{$", "$x$", "$$", "\\$", "a\\", "\\", "\\\\|", "<script>alert(1)</script>",
           "<img src=x onerror=alert(1)>", "<!--", "&lt;b&gt;", "a|b", "| x |", "`code`", "``", "**bold**", "_x_",
           "~~s~~", "# heading", "- item", "+ item", "1. one", "3) three", "> quote", "[l](javascript:x)",
           "![i](x.png)", "---", "=", "   four spaces", "trailing  ", "%s {0} {{}}", "名前 🐍", "Ω ‖ √ ∑",
           "e\u0301",
           "\u05e9\u05dc\u05d5\u05dd", "x" * MAX_NAME_CHARS, "-" * MAX_NAME_CHARS, "a:b", "NUL", "con.txt", "..", ".",
           "a/b", "a\\b"]
#: Names that must be refused, with the field named.
REFUSED = ["line\nbreak", "tab\there", "nul\x00", "esc\x1b[31m", "del\x7f", "c1\x85", "\u202eevil", "zero\u200bwidth",
           "sep\u2028x", "para\u2029x", "\ud800", "", " ", "\t", "x" * (MAX_NAME_CHARS + 1)]
MARKUP = "$\\{}^_<>|`*#&;[]()!~-+=.:/ \n\t\x00\x1b\u202e\u200bab1é🐍"

names = st.one_of(st.sampled_from(HOSTILE + REFUSED),
                  st.text(alphabet=MARKUP, min_size=0, max_size=12),
                  st.text(min_size=0, max_size=20),  # any unicode but lone surrogates, control characters included
                  st.text(alphabet=st.characters(codec="utf-8", exclude_categories=("Cc", "Cf", "Zl", "Zp")),
                          min_size=1, max_size=30))


def refused(name: str) -> bool:
    """Whether the rule refuses ``name`` as a name (as a test oracle, written apart from the code)."""
    return (not name.strip() or len(name) > MAX_NAME_CHARS
            or any(unicodedata.category(c) in ("Cc", "Cf", "Cs", "Zl", "Zp") for c in name))


def scene_unless_refused(name: str) -> Scene | None:
    """:func:`make_scene` of ``name``, or None once the boundary is seen to refuse a name the rule refuses."""
    if refused(name):
        with pytest.raises(InputError, match=r"a target's name (must be a name|is \d+ characters long|.* holds U\+)"):
            make_scene(name)
        return None
    return make_scene(name)


def as_scene_name(name: str) -> str:
    """``name`` where it can name files, else a stand-in (the figures then show the name as a target's)."""
    try:
        return file_name_part(name, "a scene's name")
    except InputError:
        return "scene $x$ `1`"


# ------------------------------------------------------------------------------------------------------------
# small synthetic inputs
# ------------------------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def robot() -> SnakeRobot:
    return SnakeRobot.from_urdf(snake_urdf(SnakeSpec(n_joints=8, markers={"p0": 3, "b0": 4})), base_end="p0",
                                neck_end="b0", head_tip="head_tip")


@pytest.fixture(scope="module")
def motion(robot) -> dict:
    base = BasePlacement(0.0, 0.0, 0.0)
    t = np.linspace(0.0, 1.0, 11)
    q_end = np.zeros(robot.n_joints)
    q_end[robot.parts.neck] = -0.3
    q = t[:, None] * q_end
    return dict(base=base, t=t, q=q, stability=stability.dynamic_stability(robot, t, q, base, contact="ground"),
                ground_clearance=coll.ground_clearance(robot, q, base)[:, robot.lifted_links].min(1))


def make_scene(name: str, scene_name: str | None = None) -> Scene:
    """A scene of one target named ``name`` (a sphere) and a box; InputError where ``name`` is no name."""
    target = Target(name, [0.3, 0.1, 0.2], [1.0, 0.0, 0.0], sphere_diameter=0.04)
    return Scene(scene_name or as_scene_name(name), (target,),
                 obstacles=(BoxObstacle.from_yaw([0.3, 0.3, 0.05], [0.1, 0.1, 0.1], 0.0),))


def make_plan(robot: SnakeRobot, motion: dict, scene: Scene) -> Plan:
    """A made-up plan of ``scene`` as the planner names its parts: the states are labelled by the target's name."""
    tg = scene.targets[0]
    solution = types.SimpleNamespace(success=True, message=f"reached {tg.name}", position_error_m=1e-4,
                                     direction_error_deg=0.1, stage="segmented")
    q = motion["q"]
    return Plan(name=scene.name, robot=robot, base=motion["base"], t=motion["t"], q=q,
                qd=np.gradient(q, motion["t"], axis=0),
                states=[("initial state", 0.0, q[0]), (f"{tg.name} (1/2)", 0.5, q[5]), (tg.name, 1.0, q[-1])],
                targets=[TargetResult(tg.name, tg.position, tg.direction, 1.0, solution)],
                stability=motion["stability"], ground_clearance=motion["ground_clearance"],
                obstacles=list(scene.obstacles), scene=scene, notes=[f"note on {tg.name}"])


def make_loop_run(robot: SnakeRobot, motion: dict, scene: Scene) -> Any:
    """A made-up closed loop of ``scene``: a gait (a ground phase), then the target's move and hold, named as
    snakehead.closed_loop.loop names them."""
    from snakehead.closed_loop.loop import LoopRun, Phase

    t, q = motion["t"], motion["q"]
    roots = np.repeat(np.eye(4)[None], len(t), axis=0)
    roots[:, 0, 3] = np.linspace(-0.2, 0.0, len(t))
    ground = types.SimpleNamespace(t=t, root_truth=roots, root_estimate=roots.copy(), q=np.zeros_like(q))
    head = types.SimpleNamespace(t=t, root_pose=np.repeat(roots[-1:], len(t), axis=0), q=q,  # the head phases
                                 qdot=np.gradient(q, t, axis=0), base=motion["base"])
    name = scene.targets[0].name
    phases = [Phase("serpenoid forward (head, 1 x 1.00)", "gait", 0.0, 1.0, None, ground),
              Phase(name, "move", 1.0, 1.5), Phase(f"{name} (hold)", "hold", 1.5, 2.0)]
    return LoopRun(robot=robot, scene=scene, start=motion["base"], believed_start=motion["base"], q_start=q[0],
                   phases=phases, fixes=[], plan=None, head=head, metrics=None, head_t0_s=1.0, corrections=0,
                   planning_time_s=0.0, notes=[f"loop note on {name}"], failure=f"target {name!r} out of reach")


def make_map(base: str, tip: str) -> Any:
    """A 2 x 2 x 2 reachability map between frames named ``base`` and ``tip``."""
    from snakehead.kinematics.reachability.reachability_map import ReachabilityMap

    ids = np.arange(8)
    i, j, k = np.unravel_index(ids, (2, 2, 2))
    return ReachabilityMap(centers=np.column_stack([i, j, k]) * 0.05 + 0.025, solved=np.array([0, 1, 2, 3, 4, 5, 6, 8]),
                           voxel_ids=ids, tried=8, grid_origin=np.zeros(3), grid_size=0.1, grid_shape=(2, 2, 2),
                           hull_voxels=8, chain_hash="x", base=base, tip=tip, params={"voxel_size": 0.05})


# ------------------------------------------------------------------------------------------------------------
# what "shown literally" means, per writer
# ------------------------------------------------------------------------------------------------------------
def drawn_texts(fig: Figure) -> list[str]:
    """Draw ``fig`` with Agg (a failure raises) and return what each of its texts shows: no text may be parsed as
    mathtext, so each shows its string with matplotlib's ``\\$`` unescaped."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a glyph missing from the font is drawn as a box, with a warning
        FigureCanvasAgg(fig).draw()
    shown = []
    for text in fig.findobj(Text):
        raw = text.get_text()
        if not raw:
            continue
        shown.append(raw if cbook.is_math_text(raw) else raw.replace("\\$", "$"))
    return shown


def assert_shown_literally(fig: Figure, name: str) -> None:
    """``fig`` draws, shows ``name`` as it is, and no text that holds it is read as math."""
    shown = drawn_texts(fig)
    assert any(name in s for s in shown), f"{name!r} is not shown in {shown}"
    for text in fig.findobj(Text):
        raw = text.get_text()
        assert not (cbook.is_math_text(raw) and name in raw.replace("\\$", "$")), f"read as math: {raw!r}"


def cells(row: str) -> list[str]:
    """The cells of a summary table row: the separators are " | "; a pipe in a cell is always escaped (``\\|``)."""
    assert row.startswith("| ") and row.endswith(" |"), row
    return row[2:-2].split(" | ")


def unescaped_pipes(line: str) -> int:
    """The pipes of a table row that GFM splits cells at: those not escaped by a backslash that is not escaped."""
    return len(re.findall(r"(?<!\\)\|", line.replace("\\\\", "")))


def rendered_markdown(text: str) -> Any:
    """summary.md as a GitHub-like renderer makes it (tables, strikethrough, raw HTML on), parsed."""
    markdown_it = pytest.importorskip("markdown_it")
    bs4 = pytest.importorskip("bs4")
    page = markdown_it.MarkdownIt("commonmark", {"html": True}).enable(["table", "strikethrough"]).render(text)
    return bs4.BeautifulSoup(page, "html.parser")


# ------------------------------------------------------------------------------------------------------------
# 1. the boundary: one rule for every name
# ------------------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", REFUSED)
def test_control_characters_are_refused_naming_the_field(name, tmp_path):
    with pytest.raises(InputError, match="a target's name"):
        Target(name, [0.3, 0.1, 0.2], [1.0, 0.0, 0.0])
    with pytest.raises(InputError, match=r"scene, targets\[0\]: name"):
        scene_from_dict({"targets": [{"name": name, "position": [0.3, 0.1, 0.2], "direction": [1, 0, 0]}]})
    with pytest.raises(InputError, match="a scene's name"):
        Scene.from_targets([([0.3, 0.1, 0.2], [1.0, 0.0, 0.0])], name=name)


@pytest.mark.parametrize("name", HOSTILE)
def test_printable_names_are_names(name):
    assert Target(name, [0.3, 0.1, 0.2], [1.0, 0.0, 0.0]).name == name  # kept as it is, not normalised


@pytest.mark.parametrize("name, why", [("../x", "'/'"), ("a/b", "'/'"), ("a\\b", "'\\\\\\\\'"), ("..", "a name"),
                                       (".", "a name"), ("a:b", "':'"), ("<script>", "'<', '>'"), ("a|b", "'|'"),
                                       ("what?", "'\\?'"), ("NUL", "device name"), ("con.txt", "device name"),
                                       ("Lpt1 ", "device name"), ("é" * 51, "102 bytes"), ("x\ny", "U\\+000A")])
def test_scene_names_are_portable_file_names(name, why):
    with pytest.raises(InputError, match=f"a scene's name.*{why}"):
        Scene(name, (Target("a", [0.3, 0.1, 0.2], [1.0, 0.0, 0.0]),))


def test_two_scenes_may_not_write_the_same_files(tmp_path):
    """Scene names that differ only in case or Unicode normalisation are one file on macOS and Windows: the second
    scene's outputs (and its report entry, for equal names) would replace the first's. Refused before any work."""
    from snakehead.app.pipeline import run_scenes

    t = Target("a", [0.3, 0.1, 0.2], [1.0, 0.0, 0.0])
    for a, b in (("Hole", "hole"), ("caf\u00e9", "cafe\u0301"), ("same", "same")):
        with pytest.raises(InputError, match="two scenes"):
            run_scenes([Scene(a, (t,)), Scene(b, (t,))], tmp_path / "out")
    assert not (tmp_path / "out").exists()


@fuzz(300)
@given(name=names)
def test_every_name_is_refused_or_kept(name):
    """The property at the boundary: a name is refused (InputError naming the field) exactly when the rule says so,
    and kept unchanged otherwise; a file's name field the same, with the file and entry named."""
    entry = {"name": name, "position": [0.3, 0.1, 0.2], "direction": [1.0, 0.0, 0.0]}
    if refused(name):
        with pytest.raises(InputError, match="a target's name"):
            Target(name, [0.3, 0.1, 0.2], [1.0, 0.0, 0.0])
        with pytest.raises(InputError, match=r"^scene file 'x.toml', targets\[0\]: name"):
            scene_from_dict({"targets": [entry]}, where="scene file 'x.toml'")
        return
    assert Target(name, [0.3, 0.1, 0.2], [1.0, 0.0, 0.0]).name == name
    assert scene_from_dict({"targets": [entry]}).targets[0].name == name
    try:
        scene_name = file_name_part(name, "a scene's name")
    except InputError as exc:
        assert str(exc).startswith("a scene's name")
        return
    assert scene_name == name and name not in (".", "..") and not set(name) & set('/\\<>:"|?*')
    assert len(name.encode("utf-8")) <= MAX_NAME_BYTES


def _toml_string(text: str) -> str:
    """``text`` as a TOML basic string (JSON's escapes, which TOML shares, and DEL escaped as TOML wants)."""
    return json.dumps(text, ensure_ascii=False).replace("\x7f", "\\u007f")


@fuzz(40)
@given(name=names, scene_name=names)
def test_scene_files_refuse_or_keep_names(name, scene_name, tmp_path_factory):
    """Through a real scene file: the target's and the scene's names are kept, or the file is refused with an
    InputError naming the file and the field."""
    assume(not any(unicodedata.category(c) == "Cs" for c in name + scene_name))  # not in a UTF-8 file
    folder = tmp_path_factory.mktemp("scene")
    path = folder / "scene.toml"
    path.write_text(f"name = {_toml_string(scene_name)}\n[[targets]]\nname = {_toml_string(name)}\n"
                    "position = [0.3, 0.1, 0.2]\ndirection = [1.0, 0.0, 0.0]\n", encoding="utf-8")
    try:
        scene = load_scene(path)
    except InputError as exc:
        message = str(exc)
        assert message.startswith(f"scene file {str(path)!r}") and "\n" not in message
        assert ("targets[0]: name" if refused(name) else "a scene's name") in message, message
        return
    assert not refused(name) and not refused(scene_name)
    assert scene.targets[0].name == name and scene.name == scene_name


def test_the_command_line_refuses_a_name_with_a_newline(tmp_path):
    """Exit 2 with one line naming the file and the field, before any work (it was read into every output)."""
    scene = tmp_path / "bad.toml"
    scene.write_text('[[targets]]\nname = "a\\n<script>"\nposition = [0.3, 0.1, 0.2]\ndirection = [1.0, 0.0, 0.0]\n')
    r = subprocess.run([sys.executable, "-m", "snakehead", "plan", "--scene", str(scene), "--out",
                        str(tmp_path / "out"), "--no-sim", "--fast"], capture_output=True, text=True, timeout=300)
    assert r.returncode == 2, r.stderr[-2000:]
    lines = [line for line in r.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and "targets[0]: name" in lines[0] and "U+000A" in lines[0], r.stderr
    assert not (tmp_path / "out").exists()


# ------------------------------------------------------------------------------------------------------------
# 2. figures: every function that shows a name, drawn with Agg
# ------------------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["$\\frac{$", "a$b$c \\$x$", "$\\sqrt{$ <b>|`"])
def test_the_closed_loops_figures_show_names_as_they_are(robot, motion, name):
    """The finding: the loop's figures put target and phase names into matplotlib unescaped; ``$\\frac{$`` made the
    path figure and the GIF fail to draw (exit 2 after the whole loop had run)."""
    from snakehead.viz import loop_figures as loop_plots

    run = make_loop_run(robot, motion, make_scene(name, "scene"))
    assert_shown_literally(loop_plots.plot_ground_path(run), name)
    anim = loop_plots.animate_loop(run, max_frames=3, dpi=30)
    assert len(list(anim.images())) == 3
    assert any(name in label.replace("\\$", "$") for label in anim._labels)  # the clock's text, frame by frame
    assert_shown_literally(anim.figure, name)  # the last frame: the target's hold


@fuzz(12)
@given(name=names)
@example(name="$\\frac{$")
@example(name="<script>alert(1)</script>|`x`")
def test_every_figure_shows_a_name_literally(robot, motion, name):
    """Every figure function of snakehead.viz that shows a scene's, a target's, a phase's or a frame's name: drawn
    with Agg without an error, the name shown as it is (no text parsed as math); a name that is no name is refused
    where it enters."""
    from snakehead.viz import animation, body
    from snakehead.viz import loop_figures as loop_plots
    from snakehead.viz import reachability_figures as ws

    scene = scene_unless_refused(name)
    if scene is None:
        return
    plan = make_plan(robot, motion, scene)
    small = dict(dpi=30)
    fig = body.plot_snapshots(plan, n_panels=3, columns=3)
    fig.set_dpi(30)
    assert_shown_literally(fig, name)
    if scene.name == name:  # the scene's name, in the title and the clock
        assert any(name in s for s in drawn_texts(fig))
    anim = animation.animate(plan, max_frames=2, size=(3.0, 2.4), **small)
    frames = list(anim.images())
    assert len(frames) == 2
    assert_shown_literally(anim.figure, plan.name)
    run = make_loop_run(robot, motion, scene)
    fig = loop_plots.plot_ground_path(run, size=(4.0, 3.5))
    fig.set_dpi(30)
    assert_shown_literally(fig, name)
    anim = loop_plots.animate_loop(run, max_frames=2, size=(3.0, 2.4), **small)
    assert len(list(anim.images())) == 2
    assert_shown_literally(anim.figure, scene.name)
    fig = ws.figure_map(make_map(name, name + " tip"))  # the map's frame names, retitled "(a) ..."
    fig.set_dpi(30)
    assert_shown_literally(fig, f"(a) {name} \u2192 {name} tip")


def test_the_head_solutions_message_is_shown_as_it_is(robot):
    """A solution without a neck goal shows its message: text, not math."""
    from snakehead.viz import body

    q = np.zeros(robot.n_joints)
    solution = types.SimpleNamespace(q=q, base=BasePlacement(), desired_frame=np.eye(4), neck=None, neck_goal=None,
                                     position_error_m=0.0, direction_error_deg=0.0, static_margin_m=0.0,
                                     message="no goal for $\\frac{$")
    fig = body.plot_head_solution(robot, solution)
    fig.set_dpi(30)
    assert_shown_literally(fig, "no goal for $\\frac{$")


def test_the_pipelines_titles_show_names_as_they_are(robot, motion, tmp_path):
    """The pipeline's own titles (snapshots, momenta, ZMP; the description or the scene's name) with a hostile
    description and target name: the files are written."""
    from snakehead.app.pipeline import FAST, Progress
    from snakehead.app.scene_outputs import write_dynamics_figures, write_loop_figures, write_plan_outputs

    scene = Scene("scene $1$ `x`", (Target("$\\frac{$ <script>", [0.3, 0.1, 0.2], [1.0, 0.0, 0.0]),),
                  description="costs $\\frac{$ | <b>bold</b>\nsecond line")
    plan = make_plan(robot, motion, scene)
    progress = Progress(quiet=True)
    files = write_plan_outputs(scene, plan, tmp_path, FAST, progress, False)
    files += write_dynamics_figures(scene, plan, None, tmp_path, progress)
    files += write_loop_figures(scene, make_loop_run(robot, motion, scene), tmp_path, {"max_frames": 2}, progress)
    assert len(files) == 8
    for f in files:
        assert (tmp_path / f).stat().st_size > 0 and (tmp_path / f).parent == tmp_path
    page = (tmp_path / "scene $1$ `x`.html").read_text()
    title = re.search("<title>(.*?)</title>", page, re.S).group(1)
    assert "<" not in title and html.unescape(title) == "snakehead: " + scene.description


@pytest.fixture(scope="module")
def plain_page(robot, motion) -> str:
    from snakehead.viz import viewer

    return viewer.html_page(viewer.viewer_scene(make_plan(robot, motion, make_scene("plain")), title="plain"))


# ------------------------------------------------------------------------------------------------------------
# 3. the reports: summary.md, report.json, the viewer's page and scene file
# ------------------------------------------------------------------------------------------------------------
def make_report(robot, motion, scene: Scene) -> dict:
    from snakehead.app.pipeline import loop_entry

    plan = make_plan(robot, motion, scene)
    name = scene.name
    entry = rep.scenario_entry(plan, None, extra={"files": [f"{name}_trajectory.csv", f"{name}.gif"]})
    loop = loop_entry(make_loop_run(robot, motion, Scene(name + " loop", scene.targets)), [f"{name}_path.png"])
    return {"command": "plan", "scenarios": {name: entry, name + " loop": loop},
            "settings": {"map": f"/maps/{name}.npz"}, "notes": [f"run note on {scene.targets[0].name}"],
            "stages": [{"stage": f"{name}: planning {scene.targets[0].name}", "seconds": 1.5}]}


def check_summary(text: str, scene: Scene) -> None:
    """summary.md of a report on ``scene`` shows every name literally and every table keeps its columns."""
    name, target = scene.name, scene.targets[0].name
    lines = text.split("\n")
    # every table row has the columns of its header: no name adds or hides a cell
    for k, line in enumerate(lines):
        if line.startswith("|"):
            start = k
            while start > 0 and lines[start - 1].startswith("|"):
                start -= 1
            assert unescaped_pipes(line) == unescaped_pipes(lines[start]), (lines[start], line)
    rows = [cells(line) for line in lines if line.startswith("| ") and target.strip() and
            cells(line)[0] == rep.markdown_text(target)]
    assert len(rows) == 2 and [len(r) for r in rows] == [4, 4]  # the target's row and its move's phase row
    # as a GitHub-like renderer shows it: the names as text, no element from them
    soup = rendered_markdown(text)
    allowed = {"h1", "h2", "p", "table", "thead", "tbody", "tr", "th", "td", "ul", "li", "code"}
    assert {t.name for t in soup.find_all(True)} <= allowed, {t.name for t in soup.find_all(True)} - allowed
    headings = [h.get_text() for h in soup.find_all("h2")]
    assert headings[0].startswith(f"{name.strip()}: ") and headings[1] == f"{name} loop: NOT successful".strip()
    tables = soup.find_all("table")
    targets_table = tables[0]
    (phases_table,) = [t for t in tables if t.find("th").get_text() == "phase"]
    first = [tr.find_all("td") for tr in targets_table.find_all("tr")[1:]]
    assert len(first) == 1 and len(first[0]) == 4 and first[0][0].get_text() == target.strip()
    assert [tr.find_all("td")[0].get_text() for tr in phases_table.find_all("tr")[1:]] == \
        ["serpenoid forward (head, 1 x 1.00)", target.strip(), f"{target} (hold)".strip()]
    items = [li.get_text() for li in soup.find_all("li")]
    assert not any("s of motion" in item for item in items)  # a loop without a plan: "- s of motion" was a list
    assert f"note on {target}".strip() in items and f"run note on {target}".strip() in items
    codes = [c.get_text() for c in soup.find_all("code")]
    assert f"{name}_trajectory.csv" in codes and f"{name}.gif" in codes and f"{name}_path.png" in codes


@fuzz(25)
@given(name=names)
@example(name="<script>alert(1)</script>")
@example(name="a|b\\")
@example(name="`x` | $y$")
def test_summary_shows_names_literally(robot, motion, name):
    scene = scene_unless_refused(name)
    if scene is None:
        return
    report = make_report(robot, motion, scene)
    text = rep.summary_markdown(rep.jsonable(report))
    check_summary(text, scene)
    # report.json keeps the names exactly
    back = json.loads(json.dumps(rep.jsonable(report), allow_nan=False))
    assert back["scenarios"][scene.name]["targets"][0]["name"] == name


@pytest.mark.parametrize("name", ["<script>alert(1)</script>", "a|b", "a\\", "`code`", "- item", "12. x", "# h",
                                  "&lt;", "$\\frac{$", "~~s~~", "[l](javascript:x)"])
def test_summary_escapes_the_known_hostile_names(robot, motion, name, tmp_path):
    """The finding: a target named ``<script>`` passed into summary.md as HTML, a ``|`` added a column."""
    scene = make_scene(name)
    path = rep.write_summary(make_report(robot, motion, scene), tmp_path / "summary.md")
    text = path.read_text()
    check_summary(text, scene)
    prose = "\n".join(line for line in text.split("\n") if not line.startswith("Files: "))  # code spans: literal
    assert not re.search(r"(?<!\\)[<&]", prose.replace("\\\\", ""))  # every "<" and "&" escaped: no HTML


@fuzz(6)
@given(name=names)
@example(name="<script>alert(1)</script>")
@example(name="a/b </title><script>x</script>")
def test_the_viewer_shows_names_as_text(robot, motion, plain_page, name, tmp_path_factory):
    """The viewer's page: the title is escaped HTML, the names are inside the recorded scene (base64), never markup;
    the viewer's scene file keeps the names; a "/" in a target's name stays in its node of the scene tree."""
    from snakehead.viz import viewer

    scene = scene_unless_refused(name)
    if scene is None:
        return
    plan = make_plan(robot, motion, scene)
    data = viewer.viewer_scene(plan, title=name)
    page = viewer.html_page(data)
    title = re.search("<title>(.*?)</title>", page, re.S).group(1)
    assert "<" not in title and ">" not in title and html.unescape(title) == f"snakehead: {name}"
    def untitled(page: str) -> str:
        return page[:page.index("<title>")] + page[page.index("</title>") + len("</title>"):]

    rest, plain = untitled(page), untitled(plain_page)  # the rest is viser's page and the scene in base64
    assert rest.count("<") == plain.count("<") and rest.count("<script") == plain.count("<script")
    folder = tmp_path_factory.mktemp("viewer")
    back = viewer.load_viewer_scene(viewer.save_viewer_scene(data, folder / "x_viewer.npz"))
    assert back.title == name and back.target_names.tolist() == [name] and back.name == scene.name
    assert "/" not in viewer.node_name(name)


def test_a_viewer_scene_file_with_a_control_character_is_refused(robot, motion, tmp_path):
    """A viewer scene is read from a file (snakehead view DIR): its names are input like a scene file's."""
    from snakehead.viz import viewer

    data = viewer.viewer_scene(make_plan(robot, motion, make_scene("ok")), title="ok")
    path = viewer.save_viewer_scene(data, tmp_path / "x_viewer.npz")
    with np.load(path) as f:
        arrays = dict(f)
    arrays["target_names"] = np.array(["evil\x1b[2J"])
    np.savez(tmp_path / "bad_viewer.npz", **arrays)
    with pytest.raises(InputError, match=r"bad_viewer.npz: target_names\[0\] .* U\+001B"):
        viewer.load_viewer_scene(tmp_path / "bad_viewer.npz")
