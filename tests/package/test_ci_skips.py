"""The conftest hook that, under CI, turns a skip for a missing import into a failure naming the package
(tests/conftest.py): run on a tiny generated test file with CI set and without, in pytest's own pytester."""
from __future__ import annotations

from pathlib import Path

import pytest

pytest_plugins = ["pytester"]

#: A test file with every kind of skip: a test and a fixture that need a module nobody has, a skip for another
#: reason, a PyYAML submodule that does not exist (its pip name differs from its import name), and a test that passes.
TESTS = '''
import pytest


@pytest.fixture
def nowhere():
    return pytest.importorskip("snakehead_nowhere_module")


def test_importorskip_in_the_test():
    pytest.importorskip("snakehead_nowhere_module")


def test_needs_a_fixture_that_skips(nowhere):
    pass


def test_other_skip():
    pytest.skip("Chromium is not installed")


def test_pip_name():
    pytest.importorskip("yaml.snakehead_nowhere")


def test_passes():
    pass
'''


@pytest.fixture
def tests(pytester: pytest.Pytester) -> pytest.Pytester:
    pytester.makeconftest((Path(__file__).resolve().parents[1] / "conftest.py").read_text())
    pytester.makepyfile(test_generated=TESTS)
    return pytester


@pytest.mark.parametrize("ci", [None, "0", "false"])
def test_without_ci_a_missing_import_is_a_listed_skip(tests: pytest.Pytester, monkeypatch: pytest.MonkeyPatch,
                                                      ci: str | None) -> None:
    if ci is None:
        monkeypatch.delenv("CI", raising=False)
    else:
        monkeypatch.setenv("CI", ci)
    result = tests.runpytest("-rs", "-p", "no:cacheprovider")
    result.assert_outcomes(passed=1, skipped=4)
    result.stdout.fnmatch_lines(["SKIPPED * could not import 'snakehead_nowhere_module'*"])
    assert result.ret == pytest.ExitCode.OK


@pytest.mark.parametrize("ci", ["true", "1"])
def test_under_ci_a_missing_import_fails_naming_the_package(tests: pytest.Pytester, monkeypatch: pytest.MonkeyPatch,
                                                            ci: str) -> None:
    monkeypatch.setenv("CI", ci)
    result = tests.runpytest("-rs", "-p", "no:cacheprovider")
    # in the test: a failure; in a fixture: an error at setup; a skip for another reason stays a skip
    result.assert_outcomes(passed=1, failed=2, errors=1, skipped=1)
    result.stdout.fnmatch_lines(["*missing test dependency 'snakehead_nowhere_module'*",
                                 "*missing test dependency 'pyyaml' (import 'yaml.snakehead_nowhere')*"])
    result.stdout.fnmatch_lines(["SKIPPED * Chromium is not installed"])
    assert result.ret == pytest.ExitCode.TESTS_FAILED


def test_a_module_level_skip_under_ci_is_a_collection_error(pytester: pytest.Pytester,
                                                            monkeypatch: pytest.MonkeyPatch) -> None:
    pytester.makeconftest((Path(__file__).resolve().parents[1] / "conftest.py").read_text())
    pytester.makepyfile(test_module_level="import pytest\n\npytest.importorskip('pinocchio_nowhere')\n\n\n"
                                          "def test_x():\n    pass\n")
    monkeypatch.delenv("CI", raising=False)
    pytester.runpytest("-p", "no:cacheprovider").assert_outcomes(skipped=1)
    monkeypatch.setenv("CI", "true")
    result = pytester.runpytest("-p", "no:cacheprovider")
    result.assert_outcomes(errors=1)
    result.stdout.fnmatch_lines(["*missing test dependency 'pinocchio_nowhere'*"])
    assert result.ret == pytest.ExitCode.INTERRUPTED
