"""Tests that drive a real headless Chromium: Debian's ``chromium``, through Playwright.

``conftest.py`` at the top of the repository loads this module as a plugin, so any test module
can ask for its fixtures (docs/testing.md, "In a browser"):

- ``chromium``: the browser (a Playwright ``Browser``), launched once per test process, so once
  per pytest-xdist worker, on the system's executable (``find_chromium``).
- ``open_page``: ``open_page(html)`` writes the HTML string to a file in the test's ``tmp_path``
  and opens it; ``open_page(path)`` (a ``pathlib.Path``) opens that file. Each page gets a
  browser context of its own, closed after the test, and comes back as a ``Visit``: the page
  and what it did (console messages, uncaught errors, the requests it made). No request
  leaves the machine: http, https and WebSocket requests are recorded and refused.

When the browser is missing the tests that use it skip, and fail when ``CI`` is set (a skip
in CI is an error, tests/conftest.py); Playwright itself comes through the ``optional``
fixture, as every optional package does.

``csp_hash(script)`` is the Content-Security-Policy source that lets exactly that inline
script run.
"""
import asyncio
import base64
import hashlib
import os
import pathlib
import re
import shutil
import time
from dataclasses import dataclass, field

import pytest

#: an executable to use instead of the ones ``find_chromium`` looks for
CHROMIUM_ENV = "NBODY_CHROMIUM"

#: where the browser is looked for, in order: Debian's browser binary itself (the ``chromium``
#: command is a shell script that adds the flags of /etc/chromium.d, which the tests do not
#: want), then the command on ``PATH``
CHROMIUM_CANDIDATES = ("/usr/lib/chromium/chromium", "chromium", "chromium-browser")

#: the requests refused (besides the page's own file, ``file:``, ``data:`` and ``blob:`` URLs
#: never reach the routes): everything that would leave the machine
OUTSIDE = re.compile(r"^(https?|wss?)://", re.IGNORECASE)

#: URLs that are not requests: the content is in the URL, or in the page's memory
NOT_REQUESTS = ("data:", "blob:")

#: milliseconds a Playwright call waits before it fails (its default is 30 s): a page that
#: never becomes ready fails its test sooner
TIMEOUT_MS = 10_000

#: the marker every test that uses the browser gets (``pytest -m browser``)
MARKER = "browser"


def csp_hash(script_text):
    """``'sha256-...'``: the Content-Security-Policy source allowing the inline script whose
    text, between ``<script>`` and ``</script>``, is exactly ``script_text``."""
    digest = hashlib.sha256(script_text.encode("utf-8")).digest()
    return "'sha256-" + base64.b64encode(digest).decode("ascii") + "'"


def find_chromium(environ=None):
    """The path of the Chromium executable, or None: ``NBODY_CHROMIUM`` when set, else the
    first of ``CHROMIUM_CANDIDATES`` found."""
    environ = os.environ if environ is None else environ
    if environ.get(CHROMIUM_ENV):
        return shutil.which(environ[CHROMIUM_ENV])
    for name in CHROMIUM_CANDIDATES:
        path = shutil.which(name)
        if path is not None:
            return path
    return None


def _missing(what):
    """A test that needs the browser cannot have it: a failure in CI, else a skip."""
    from tests.conftest import ci_is_set

    if ci_is_set():
        pytest.fail(f"{what}, and CI is set: the browser tests must run in CI (.ci/run installs "
                    f"Debian's chromium package with apt-get)", pytrace=False)
    pytest.skip(f"{what} (apt-get install chromium, or set {CHROMIUM_ENV})")


@dataclass
class Session:
    """One Playwright driver and one browser for the test process."""

    playwright: object
    browser: object
    executable: str
    launch_seconds: float
    loop: object = None  # Playwright's event loop, marked running only while a test uses it

    def lend(self):
        """Mark Playwright's loop running again, for a test that uses the browser."""
        asyncio._set_running_loop(self.loop)

    def park(self):
        """Clear the mark, so that the other tests find no running event loop.

        Playwright's sync API leaves its event loop marked as the thread's running loop after
        each call; with the browser kept for the whole session that would make
        ``asyncio.run`` and ``loop.run_until_complete`` fail in every later test of the
        worker. Between calls the loop runs nothing, so the mark can be cleared and set again
        before the next call."""
        asyncio._set_running_loop(None)


@pytest.fixture(scope="session")
def browser_session(optional):
    """The test process's Playwright and browser, launched the first time a test needs them
    and closed at the end of the session."""
    sync_api = optional("playwright.sync_api")
    executable = find_chromium()
    if executable is None:
        where = os.environ.get(CHROMIUM_ENV) or ", ".join(CHROMIUM_CANDIDATES)
        _missing(f"Chromium is not installed: none of {where} found")
    start = time.perf_counter()
    playwright = sync_api.sync_playwright().start()
    try:
        browser = playwright.chromium.launch(
            executable_path=executable, headless=True,
            # no host name resolves: a request the routes missed would still stay here
            args=["--host-resolver-rules=MAP * ~NOTFOUND"])
    except BaseException:
        playwright.stop()
        asyncio._set_running_loop(None)
        raise
    session = Session(playwright, browser, executable, time.perf_counter() - start,
                      loop=asyncio._get_running_loop())
    session.park()
    yield session
    session.lend()
    try:
        browser.close()
    finally:
        playwright.stop()
        session.park()


@pytest.fixture
def chromium(browser_session):
    """The browser, for this test (its loop lent to the test, ``Session.park``)."""
    browser_session.lend()
    try:
        yield browser_session.browser
    finally:
        browser_session.park()


@dataclass
class Visit:
    """A page opened by ``open_page`` and what it has done so far."""

    page: object  # the Playwright Page
    url: str
    console: list = field(default_factory=list)  # (type, text): "log", "error", "warning", ...
    errors: list = field(default_factory=list)  # uncaught exceptions: "Name: message"
    requests: list = field(default_factory=list)  # URL of every request, the page's own first
    blocked: list = field(default_factory=list)  # URL of every request refused

    @property
    def network(self):
        """The requests besides the page's own load: a self-contained page makes none."""
        return [url for url in self.requests
                if url != self.url and not url.lower().startswith(NOT_REQUESTS)]

    @property
    def console_errors(self):
        return [text for kind, text in self.console if kind == "error"]

    def assert_quiet(self):
        """No console error, no uncaught exception, no request besides the page's own."""
        problems = [f"console error: {text}" for text in self.console_errors] + \
            [f"page error: {text}" for text in self.errors] + \
            [f"request: {url}" for url in self.network]
        assert not problems, f"{self.url}:\n" + "\n".join(problems)


def _record(visit, context, page):
    page.on("console", lambda message: visit.console.append((message.type, message.text)))
    page.on("pageerror", lambda error: visit.errors.append(f"{error.name}: {error.message}"))
    # the context's requests: the page's, its workers' and any window it opens
    context.on("request", lambda request: visit.requests.append(request.url))

    def refuse(route):
        visit.blocked.append(route.request.url)
        route.abort("blockedbyclient")

    def refuse_socket(socket):  # a WebSocket fires no "request": recorded here
        visit.requests.append(socket.url)
        visit.blocked.append(socket.url)
        socket.close(code=1008, reason="no network in tests")

    context.route(OUTSIDE, refuse)
    context.route_web_socket(OUTSIDE, refuse_socket)


@pytest.fixture
def open_page(chromium, tmp_path):
    """``open_page(html_or_path, name="page.html")`` -> ``Visit``, once the page has loaded.

    A ``str`` is the page's HTML, written to ``tmp_path / name``; a ``pathlib.Path`` is a file
    opened where it is (relative paths from the current directory). What the page does after
    its load event is recorded as it happens: wait for the page's own sign that it is done
    (``visit.page.wait_for_function``) before asserting on the lists."""
    contexts = []
    count = 0

    def open_(html_or_path, name="page.html"):
        nonlocal count
        if isinstance(html_or_path, os.PathLike):
            path = pathlib.Path(html_or_path).resolve()
        elif isinstance(html_or_path, str):
            count += 1
            folder = tmp_path if count == 1 else tmp_path / f"page-{count}"
            folder.mkdir(exist_ok=True)
            path = folder / name
            path.write_text(html_or_path, encoding="utf-8")
        else:
            raise TypeError(f"open_page takes an HTML str or a pathlib.Path, not "
                            f"{type(html_or_path).__name__}")
        if not path.is_file():
            raise FileNotFoundError(path)
        context = chromium.new_context(service_workers="block")
        contexts.append(context)
        context.set_default_timeout(TIMEOUT_MS)
        page = context.new_page()
        visit = Visit(page, path.as_uri())
        _record(visit, context, page)
        page.goto(visit.url, wait_until="load")
        return visit

    yield open_
    for context in contexts:
        context.close()


def pytest_collection_modifyitems(items):
    """Every test that uses the browser is marked ``browser``."""
    for item in items:
        if "browser_session" in getattr(item, "fixturenames", ()):
            item.add_marker(MARKER)
