"""The suite's skip policy (tests/conftest.py, docs/testing.md): with ``CI`` set a skip is an
error unless its reason is on the short allowed list; without it, skips are skips; xfail is never
touched; optional packages are imported inside the tests that need them."""
import ast
import re
from pathlib import Path

import pytest

from tests import conftest as policy

pytest_plugins = ["pytester"]


def _run(pytester, *args):
    """An inner run, without the plugins of the outer one (Hypothesis takes seconds to load)."""
    return pytester.runpytest("-p", "no:hypothesispytest", "-p", "no:cacheprovider", *args)

TESTS = Path(__file__).resolve().parent
ROOT = TESTS.parent

# a file of tests that skip in every way pytest has, with allowed and unexpected reasons
SKIPS = '''
import sys
import pytest

def test_unexpected_skip():
    pytest.skip("the network is down")

@pytest.mark.skipif(True, reason="no GPU here")
def test_unexpected_skipif():
    pass

@pytest.mark.skip
def test_unexpected_bare_skip():
    pass

def test_allowed_skip():
    pytest.skip("root may write anywhere")

@pytest.mark.skipif(True, reason="the bot sandbox's checks here are Linux's")
def test_allowed_skipif():
    pass

def test_allowed_skip_with_a_measured_tail():
    pytest.skip("numpy's 2-vector dot rounds neither plain nor fused here (17 of 20000)")

@pytest.fixture
def skipping_fixture():
    pytest.skip("a fixture gave up")

def test_unexpected_skip_in_a_fixture(skipping_fixture):
    pass

@pytest.mark.xfail(reason="known bug")
def test_xfail_mark():
    assert False

def test_xfail_call():
    pytest.xfail("known bug, imperatively")

@pytest.mark.xfail(reason="fixed", strict=False)
def test_xpass():
    pass

def test_passes():
    pass

def test_missing_optional_package(optional):
    optional("a_package_that_is_not_installed_anywhere")

def test_present_optional_package(optional):
    assert optional("json.decoder").JSONDecoder
'''

UNEXPECTED = ["test_unexpected_skip", "test_unexpected_skipif", "test_unexpected_bare_skip",
              "test_unexpected_skip_in_a_fixture", "test_missing_optional_package"]


@pytest.fixture
def suite(pytester):
    """A scratch project with the suite's own conftest and the file of skips."""
    pytester.makeconftest((TESTS / "conftest.py").read_text())
    pytester.makepyfile(test_skips=SKIPS)
    return pytester


def _outcomes(result):
    """{test name: its outcomes} from a ``-v`` run's lines ``file::name OUTCOME``."""
    out = {}
    for line in result.outlines:
        m = re.match(r"\S+::(\w+) (PASSED|FAILED|ERROR|SKIPPED|XFAIL|XPASS)\b", line)
        if m:
            out.setdefault(m.group(1), set()).add(m.group(2))
    return out


def test_with_ci_set_an_unexpected_skip_fails_and_an_allowed_one_skips(suite, monkeypatch):
    monkeypatch.setenv("CI", "1")
    result = _run(suite, "-v", "-rA")
    # 3 unexpected skips in the call or the marks fail; the fixture's and the optional
    # package's are errors at setup; xfail is untouched
    result.assert_outcomes(passed=2, failed=2, errors=3, skipped=3, xfailed=2, xpassed=1)
    got = _outcomes(result)
    for name in UNEXPECTED:
        assert got[name] & {"FAILED", "ERROR"}, (name, got.get(name))
    for name in ["test_allowed_skip", "test_allowed_skipif",
                 "test_allowed_skip_with_a_measured_tail"]:
        assert got[name] == {"SKIPPED"}, (name, got.get(name))
    text = result.stdout.str()
    assert "skipped in CI" in text and "the network is down" in text and "no GPU here" in text
    assert "optional package a_package_that_is_not_installed_anywhere is not installed" in text
    assert result.ret == pytest.ExitCode.TESTS_FAILED


def test_without_ci_every_skip_is_a_skip(suite, monkeypatch):
    monkeypatch.delenv("CI", raising=False)
    result = _run(suite, "-rA")
    result.assert_outcomes(passed=2, skipped=8, xfailed=2, xpassed=1)
    assert result.ret == pytest.ExitCode.OK


@pytest.mark.parametrize("value, refused", [("1", True), ("true", True), ("", False),
                                            ("0", False), ("false", False)])
def test_what_counts_as_ci_set(suite, monkeypatch, value, refused):
    monkeypatch.setenv("CI", value)
    result = _run(suite, "-k", "unexpected_skip and not fixture and not skipif")
    assert result.parseoutcomes().get("failed", 0) == (1 if refused else 0)


MODULE_SKIPS = {
    "test_unexpected_module": 'import pytest\n'
                              'np = pytest.importorskip("a_package_that_is_not_installed")\n'
                              'def test_a():\n    pass\n',
    "test_allowed_module": 'import pytest\n'
                           'pytest.skip("not a git checkout: no file list", '
                           'allow_module_level=True)\n'
                           'def test_b():\n    pass\n',
    "test_unexpected_pytestmark": 'import pytest\n'
                                  'pytestmark = pytest.mark.skip(reason="not today")\n'
                                  'def test_c():\n    pass\n',
}


@pytest.mark.parametrize("name, ci, outcomes", [
    ("test_unexpected_module", "1", dict(errors=1)),
    ("test_unexpected_module", "", dict(skipped=1)),
    ("test_allowed_module", "1", dict(skipped=1)),
    ("test_allowed_module", "", dict(skipped=1)),
    ("test_unexpected_pytestmark", "1", dict(errors=1)),
    ("test_unexpected_pytestmark", "", dict(skipped=1)),
])
def test_a_module_skipped_at_collection_is_caught_too(pytester, monkeypatch, name, ci, outcomes):
    pytester.makeconftest((TESTS / "conftest.py").read_text())
    pytester.makepyfile(**{name: MODULE_SKIPS[name]})
    monkeypatch.setenv("CI", ci)
    result = _run(pytester)
    result.assert_outcomes(**outcomes)
    if outcomes.get("errors"):
        result.stdout.fnmatch_lines(["*skipped in CI*"])


def test_an_optional_package_that_fails_to_import_is_an_error_not_a_skip(pytester,
                                                                         monkeypatch):
    """A package that is installed but breaks on import (a bad wheel) fails, CI or not."""
    pytester.makeconftest((TESTS / "conftest.py").read_text())
    pytester.makepyfile(broken_wheel="import a_dependency_that_is_missing\n",
                        test_broken='def test_it(optional):\n    optional("broken_wheel")\n')
    pytester.syspathinsert()
    monkeypatch.delenv("CI", raising=False)
    result = _run(pytester)
    result.assert_outcomes(failed=1)
    result.stdout.fnmatch_lines(["*ModuleNotFoundError*a_dependency_that_is_missing*"])


def test_the_allowed_list_is_documented_and_each_reason_is_used():
    doc = (ROOT / "docs" / "testing.md").read_text()
    sources = "\n".join(p.read_text() for p in TESTS.rglob("*.py")
                        if p.name not in ("conftest.py", "test_skip_policy.py")
                        or p.parent != TESTS)
    for kind, start in policy.ALLOWED_SKIPS:
        assert f"`{start}`" in doc, f"docs/testing.md does not list {start!r}"
        assert start in sources, f"no test skips with {start!r}: drop it from ALLOWED_SKIPS"
    assert "tests/conftest.py" in (ROOT / "README.md").read_text() or \
        "docs/testing.md" in (ROOT / "README.md").read_text()


def _module_level_importorskips(path):
    """Line numbers of ``pytest.importorskip`` calls outside any function or class."""
    tree = ast.parse(path.read_text())
    lines = []
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            continue
        for sub in ast.walk(node):
            if isinstance(sub, ast.Call) and isinstance(sub.func, ast.Attribute) and \
                    sub.func.attr == "importorskip":
                lines.append(sub.lineno)
    return lines


def test_no_test_module_skips_whole_on_an_import():
    found = {str(p.relative_to(ROOT)): lines for p in sorted(TESTS.rglob("test_*.py"))
             if (lines := _module_level_importorskips(p))}
    assert found == {}, "import optional packages inside the tests (the optional fixture)"


def test_the_module_level_check_sees_a_module_level_importorskip(tmp_path):
    """Positive control for the check above."""
    p = tmp_path / "test_x.py"
    p.write_text('import pytest\nrebound = pytest.importorskip("rebound")\n'
                 'def test_a():\n    pytest.importorskip("PIL")\n')
    assert _module_level_importorskips(p) == [2]


def test_ci_run_sets_ci():
    assert re.search(r"^export CI=1$", (ROOT / ".ci" / "run").read_text(), re.M)
