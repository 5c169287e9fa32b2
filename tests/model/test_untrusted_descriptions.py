"""Descriptions that are not trusted run no code and read only the robot's folders (SECURITY.md).

Each payload here ran code, read a file or the environment before xacro's evaluator was replaced (issue 37); each
test checks that it is refused with an InputError naming what was refused, that nothing ran (no marker file), that
nothing it reached shows in the message, and that the same features a real description uses still expand.
"""
from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from snakehead import InputError, SnakeRobot
from snakehead.model.description import MeshResolver, read_description
from snakehead.model.robot_folders import RobotFolders
from snakehead.samples.published import write_robot

LAMBDA_PAYLOAD = ("${(lambda: [c for c in ().__class__.__base__.__subclasses__() if c.__name__ == '_wrap_close'][0]"
                  ".__init__.__globals__['system']('touch {marker}'))()}")


def _xacro(folder: Path, body: str, name: str = "robot.urdf.xacro") -> Path:
    """A small xacro file in ``folder``: one link whose name is ``body`` (where the payloads go)."""
    path = folder / name
    path.write_text(textwrap.dedent(f"""\
        <?xml version="1.0"?>
        <robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">
          <link name="{body}"/>
        </robot>
        """), encoding="utf-8")
    return path


def _refused(path: Path, match: str, **kwargs: object) -> str:
    with pytest.raises(InputError, match=match) as info:
        read_description(path, **kwargs)  # type: ignore[arg-type]
    message = str(info.value)
    assert os.fspath(path) in message  # the line names the file
    return message


def test_a_lambda_that_reaches_os_system_is_refused_and_runs_nothing(tmp_path: Path) -> None:
    marker = tmp_path / "ran"
    path = _xacro(tmp_path, LAMBDA_PAYLOAD.replace("{marker}", os.fspath(marker)))
    _refused(path, "lambda is not allowed")
    assert not marker.exists()


@pytest.mark.parametrize("expression", [
    "().__class__", "''.__class__.__mro__", "[c for c in ().__class__.__bases__]", "'%s'.format(1)",
    "type(1)", "vars()", "getattr(1, 'real')", "eval('1')", "__import__('os')", "(x := 1)",
    "python.type(1)", "xacro.__dict__", "math.__loader__"])
def test_escapes_from_the_expression_are_refused(tmp_path: Path, expression: str) -> None:
    path = _xacro(tmp_path, "${" + expression + "}")
    _refused(path, "not allowed|not defined|cannot be used|not a function")


@pytest.mark.parametrize("name", ["exec", "eval", "open", "__import__", "globals"])
def test_eval_substitution_has_no_builtins_beyond_the_safe_ones(tmp_path: Path, name: str) -> None:
    """xacro's $(eval) ran Python's eval with the full builtins (its lexer ends $(...) at the first ')', so a
    payload calls them through properties); here such names are simply not defined."""
    _refused(_xacro(tmp_path, f"$(eval {name})"), "not defined|names starting with")


@pytest.mark.parametrize("expression", ["exec('import os')", "'{0.__class__}'.format(1)", "f'{1}'",
                                        "open('/etc/hostname').read()"])
def test_what_xacro_cannot_quote_is_refused_by_the_evaluator_too(expression: str) -> None:
    """Expressions with braces or parentheses that xacro 2.1's lexer cannot carry inside ${...} or $(...): the
    evaluator refuses them itself, whatever a later lexer lets through."""
    from snakehead.model.safe_expression import ExpressionError, evaluate

    with pytest.raises(ExpressionError, match="not allowed|not defined|not a function"):
        evaluate(expression, lambda name: {}[name])


def test_load_yaml_outside_the_robot_folders_is_refused_without_its_content(tmp_path: Path) -> None:
    outside = tmp_path / "secret.yaml"
    outside.write_text("token: s3cr3t-value\n", encoding="utf-8")
    folder = tmp_path / "robot"
    folder.mkdir()
    path = _xacro(folder, "${xacro.load_yaml('" + os.fspath(outside) + "')}")
    message = _refused(path, "outside the robot's folders")
    assert "s3cr3t" not in message
    _refused(_xacro(folder, "${xacro.load_yaml('/etc/hostname')}"), "outside the robot's folders")


@pytest.mark.parametrize("extension", ["$(env HOME)", "$(optenv HOME nobody)", "$(cwd)"])
def test_the_environment_is_not_read(tmp_path: Path, extension: str, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("HOME", "/home/the-users-home")
    message = _refused(_xacro(tmp_path, extension), "is not allowed: an untrusted description")
    assert "the-users-home" not in message and "trust_xacro=True" in message


def test_a_trusted_description_is_xacro_as_it_is(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SNAKEHEAD_TEST_NAME", "from_the_environment")
    path = _xacro(tmp_path, "$(env SNAKEHEAD_TEST_NAME)_${(lambda: 7)()}")
    text = read_description(path, trust_xacro=True).text
    assert 'name="from_the_environment_7"' in text
    _refused(path, "is not allowed: an untrusted description")  # and the default still refuses it


@pytest.mark.parametrize("include", ["/etc/passwd", "../outside.xacro", "/dev/zero", "link.xacro"])
def test_includes_stay_in_the_robot_folders(tmp_path: Path, include: str) -> None:
    folder = tmp_path / "robot"
    folder.mkdir()
    outside = tmp_path / "outside.xacro"
    outside.write_text('<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="x"/></robot>', encoding="utf-8")
    (folder / "link.xacro").symlink_to(outside)  # inside by name, outside once resolved
    path = folder / "robot.urdf.xacro"
    path.write_text(f'<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="a"/>'
                    f'<xacro:include filename="{include}"/></robot>', encoding="utf-8")
    _refused(path, "outside the robot's folders")


@pytest.mark.parametrize("expression, bound", [("'x' * 10**9", "repetition"), ("10**10**10", "too large"),
                                               ("[i for i in range(10**7)]", "range of"),
                                               ("'%999999999d' % 1", "format width"),
                                               ("[[j for j in range(1000)] for i in range(2000)]", "steps")])
def test_expressions_are_bounded(tmp_path: Path, expression: str, bound: str) -> None:
    _refused(_xacro(tmp_path, "${" + expression + "}"), bound)


def test_what_real_descriptions_use_still_expands(tmp_path: Path) -> None:
    """Macros with block parameters, properties (lazy and from arguments), math, conditionals, comprehensions,
    $(find) through [packages], namespaced includes, YAML with dotted access, $(eval), $(dirname)."""
    package = tmp_path / "snake_description"
    (package / "urdf").mkdir(parents=True)
    (package / "config").mkdir()
    (package / "config" / "module.yaml").write_text("module:\n  length: 0.1\n  limits: [-1.5708, 1.5708]\n")
    (package / "urdf" / "module.xacro").write_text(textwrap.dedent("""\
        <robot xmlns:xacro="http://www.ros.org/wiki/xacro">
          <xacro:property name="cfg" value="${xacro.load_yaml('../config/module.yaml')}"/>
          <xacro:macro name="module" params="i parent *origin yaw:=^|true">
            <joint name="j${i}" type="revolute">
              <parent link="${parent}"/><child link="m${i}"/>
              <xacro:insert_block name="origin"/>
              <axis xyz="${'0 0 1' if yaw else '0 1 0'}"/>
              <limit lower="${cfg.module.limits[0]}" upper="${cfg['module']['limits'][1]}" effort="1" velocity="1"/>
            </joint>
            <link name="m${i}"/>
          </xacro:macro>
        </robot>
        """))
    path = package / "urdf" / "snake.urdf.xacro"
    path.write_text(textwrap.dedent("""\
        <robot name="snake" xmlns:xacro="http://www.ros.org/wiki/xacro">
          <xacro:arg name="n" default="2"/>
          <xacro:property name="n" value="$(arg n)"/>
          <xacro:property name="half_pi" value="${radians(90)}"/>
          <xacro:property name="later" value="${length * 2}" lazy_eval="true"/>
          <xacro:property name="length" value="${math.sqrt(0.01)}"/>
          <xacro:include filename="$(find snake_description)/urdf/module.xacro" ns="parts"/>
          <link name="m0"/>
          <xacro:parts.module i="1" parent="m0" yaw="${n > 1}">
            <origin xyz="${later} 0 0" rpy="0 ${half_pi} 0"/>
          </xacro:parts.module>
          <xacro:if value="${n == 2}">
            <link name="tip_${'_'.join([str(k) for k in python.range(n)])}_$(eval n * 3)"/>
            <joint name="tip_joint" type="fixed"><parent link="m1"/><child link="tip_0_1_6"/></joint>
          </xacro:if>
          <xacro:unless value="${n == 2}"><link name="never"/></xacro:unless>
          <link name="here_${len('$(dirname)') > 0}"/>
          <joint name="here_joint" type="fixed"><parent link="m1"/><child link="here_True"/></joint>
        </robot>
        """))
    text = read_description(path, {"n": 2}, packages={"snake_description": package}).text
    assert 'name="tip_0_1_6"' in text and "never" not in text and 'name="here_True"' in text
    assert 'lower="-1.5708"' in text and 'upper="1.5708"' in text and 'xyz="0 0 1"' in text
    assert 'xyz="0.2 0 0"' in text and 'rpy="0 1.5707963267948966 0"' in text


def test_the_published_xacro_style_loads_by_default(tmp_path: Path) -> None:
    robot = SnakeRobot.from_file(write_robot("xacro", tmp_path))
    assert robot.n_joints > 10


@pytest.mark.parametrize("mesh", ["file:///etc/passwd", "/etc/passwd", "package://snake/../../../etc/passwd",
                                  "../outside.stl", "inside_link.stl"])
def test_mesh_paths_stay_in_the_robot_folders(tmp_path: Path, mesh: str) -> None:
    folder = tmp_path / "robot"
    (folder / "snake").mkdir(parents=True)
    (tmp_path / "outside.stl").write_text("solid x\nendsolid x\n")
    (folder / "inside_link.stl").symlink_to(tmp_path / "outside.stl")
    resolver = MeshResolver(folder, RobotFolders((folder,), {"snake": folder / "snake"}))
    with pytest.raises(InputError, match="outside the robot's folders"):
        resolver.resolve(mesh, "link 'm0'")


def test_a_mesh_inside_a_package_is_found(tmp_path: Path) -> None:
    package = tmp_path / "pkg"
    (package / "meshes").mkdir(parents=True)
    (package / "meshes" / "m.stl").write_text("solid x\nendsolid x\n")
    resolver = MeshResolver(tmp_path, RobotFolders((tmp_path / "urdf",), {"pkg": package}))
    assert resolver.resolve("package://pkg/meshes/m.stl", "link 'm0'") == (package / "meshes" / "m.stl").resolve()


def test_a_downloaded_scene_cannot_run_its_xacro(tmp_path: Path) -> None:
    """`snakehead plan --scene downloaded.toml`: the scene names a robot file, which names a xacro with the lambda
    payload. The command stops with exit 2 (bad input) and the payload never runs."""
    robot_file = write_robot("xacro", tmp_path)
    xacro_path = next(tmp_path.glob("*.xacro"))
    marker = tmp_path / "ran"
    payload = LAMBDA_PAYLOAD.replace("{marker}", os.fspath(marker))
    text = xacro_path.read_text(encoding="utf-8")
    xacro_path.write_text(text.replace("<robot ", f'<robot data-x="{payload}" ', 1), encoding="utf-8")
    scene = tmp_path / "downloaded.toml"
    scene.write_text(f'robot = "{robot_file.name}"\n[[targets]]\nname = "t"\nposition = [0.1, 0.5, 0.3]\ndirection = [0, 1, 0]\n',
                     encoding="utf-8")
    run = subprocess.run([sys.executable, "-m", "snakehead", "plan", "--scene", os.fspath(scene), "--out",
                          os.fspath(tmp_path / "out")], capture_output=True, text=True, timeout=300)
    assert run.returncode == 2, run.stderr
    assert "lambda is not allowed" in run.stderr
    assert not marker.exists()


@pytest.mark.parametrize("expression", [
    "1 + 2 * 3 - 4 / 5 // 1 % 3 ** 2", "-(2 ** -3) + abs(-1.5)", "pi / 2 + sin(radians(30)) * math.cos(0)",
    "'0 0 1' if 3 % 2 == 1 else '0 1 0'", "1 < 2 <= 2 != 3 and not (0 or '')", "[x * 2 for x in range(5) if x != 2]",
    "[a + b for a, b in zip([1, 2], (3, 4))]", "' '.join([str(v) for v in [1, 2]])",
    "'a b c'.split()[1:]", "{'k': [1, 2]}['k'][-1]", "len('abc') + max(1, 2) + min([3, 4]) + round(2.567, 2)",
    "sorted({3, 1, 2})", "python.sum(map(float, ['1', '2.5']))", "'%s_%d' % ('j', 3)", "tuple(reversed([1, 2]))",
    "int('7') + float('0.5') + bool(1)", "divmod(7, 2)[0] | 4 ^ 1 & 3", "{'a': 1}.get('b', 2)", "None is None"])
def test_allowed_expressions_agree_with_python(expression: str) -> None:
    """The restricted evaluator gives Python's own value for what it allows (Python's eval is the reference)."""
    import math
    import types

    from snakehead.model.safe_expression import SAFE_NAMES, evaluate

    names = {**SAFE_NAMES, "math": math, "python": types.SimpleNamespace(**SAFE_NAMES["python"]), "__builtins__": {}}
    reference = eval(expression, names)  # the reference: Python itself, on expressions that are safe
    value = evaluate(expression, lambda name: {}[name])
    assert value == (list(reference) if isinstance(reference, (zip, map, filter)) else reference)


def test_trust_must_be_said_with_a_boolean(tmp_path: Path) -> None:
    from snakehead import InputTypeError

    with pytest.raises(InputTypeError, match="trust_xacro must be True or False, got 'yes'"):
        read_description(_xacro(tmp_path, "m0"), trust_xacro="yes")  # type: ignore[arg-type]
