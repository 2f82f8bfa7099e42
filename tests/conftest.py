"""The whole suite's rules: no silent skips in CI, and optional packages imported where needed.

When the environment variable ``CI`` is set (``.ci/run`` sets it), a skipped test, or a test
module skipped as a whole at collection, is an error unless its reason starts with one of the
reasons in ``ALLOWED_SKIPS`` below. docs/testing.md describes the rule and the list. An expected
failure (xfail) is not a skip and is left alone.

Tests get an optional package (Pillow, pygame, Gymnasium, JAX, ...) from the ``optional``
fixture inside the test, never with a module-level ``pytest.importorskip``: when the package
is missing only the tests that use it skip, and in CI that skip is an error.

This file is self-contained (tests/test_skip_policy.py runs it in a scratch directory).
"""
import importlib
import os

import pytest

# The only skip reasons allowed in CI (docs/testing.md), each the start of a reason: kind, text.
ALLOWED_SKIPS = (
    ("Linux-only", "the bot sandbox's checks here are Linux's"),
    ("Linux-only", "confined bots are checked on Linux"),
    ("not a git checkout", "not a git checkout"),
    ("root", "root may write anywhere"),
    ("machine-dependent", "numpy longdouble is no wider than double here"),
    ("machine-dependent", "numpy's 2-vector dot rounds neither plain nor fused here"),
)

OPTIONAL_MISSING = "optional package {name} is not installed"


def ci_is_set(environ=None):
    """True when ``CI`` is set to anything but empty, ``0``, ``false`` or ``no``."""
    value = (os.environ if environ is None else environ).get("CI", "")
    return value.strip().lower() not in ("", "0", "false", "no")


def allowed_skip(reason):
    """The kind of an allowed skip reason (see ``ALLOWED_SKIPS``), or None."""
    for kind, start in ALLOWED_SKIPS:
        if reason.startswith(start):
            return kind
    return None


def skip_reason(report):
    """The reason a skipped test or collector report gives, without pytest's ``Skipped: ``."""
    longrepr = report.longrepr
    if isinstance(longrepr, tuple) and len(longrepr) == 3:
        reason = str(longrepr[2])
    else:  # pragma: no cover - pytest gives skips as (path, line, message)
        reason = str(longrepr)
    return reason[len("Skipped: "):] if reason.startswith("Skipped: ") else reason


def _refuse_unexpected_skip(report, what):
    if not report.skipped or hasattr(report, "wasxfail") or not ci_is_set():
        return
    reason = skip_reason(report)
    if allowed_skip(reason) is None:
        report.outcome = "failed"
        report.longrepr = (f"{what} skipped in CI (CI={os.environ.get('CI')!r}) for a reason "
                           f"not on the allowed list (tests/conftest.py ALLOWED_SKIPS, "
                           f"docs/testing.md): {reason}")


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    _refuse_unexpected_skip(outcome.get_result(), "test")


@pytest.hookimpl(hookwrapper=True)
def pytest_make_collect_report(collector):
    outcome = yield
    _refuse_unexpected_skip(outcome.get_result(), "module")


def import_optional(name):
    """The module ``name``; a skip (an error in CI) when the package is not installed.

    Only a missing package skips: an installed one that fails to import (a broken wheel, a
    missing dependency of it, an error in our code) raises as usual."""
    try:
        return importlib.import_module(name)
    except ModuleNotFoundError as error:
        missing = error.name or ""
        if missing and (name == missing or name.startswith(missing + ".")):
            pytest.skip(OPTIONAL_MISSING.format(name=missing))
        raise


@pytest.fixture(scope="session")
def optional():
    """``optional("PIL.Image")``: import an optional package inside the test that needs it."""
    return import_optional
