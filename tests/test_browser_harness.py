"""The headless-browser harness (tests/browser.py): a page's script runs and draws, and what a
page does wrong is seen: a request leaving the machine (and refused), an uncaught error, an
inline script its Content-Security-Policy does not allow. A missing browser fails in CI."""
import asyncio
import base64
import hashlib
import pathlib
import re

import pytest

from tests import browser

pytest_plugins = ["pytester"]


def test_a_script_logs_and_draws_on_a_canvas(open_page):
    visit = open_page("""<!doctype html>
<canvas id="c" width="40" height="20"></canvas>
<script>
const g = document.getElementById("c").getContext("2d");
g.fillStyle = "rgb(200, 30, 90)"; g.fillRect(0, 0, 20, 20);
g.fillStyle = "rgb(10, 220, 40)"; g.fillRect(20, 0, 20, 20);
console.log("drawn", 2, "rectangles");
</script>""")
    # one read of the middle row (a second read would earn a console warning on readbacks)
    row = visit.page.evaluate(
        'Array.from(document.getElementById("c").getContext("2d").getImageData(0, 10, 40, 1).data)')
    assert row[5 * 4:6 * 4] == [200, 30, 90, 255]  # RGBA of the pixel (5, 10)
    assert row[35 * 4:36 * 4] == [10, 220, 40, 255]
    assert visit.console == [("log", "drawn 2 rectangles")]
    assert visit.requests == [visit.url]  # the page's own load, and nothing else
    visit.assert_quiet()


# a page that reaches out three ways; each attempt sets a flag once the page sees it fail
REACHING_OUT = """<!doctype html><body><script>
window.outcomes = {};
fetch("https://example.com/x").then(
    () => { outcomes.fetch = "fetched"; }, e => { outcomes.fetch = String(e); });
const img = document.createElement("img");
img.onload = () => { outcomes.img = "loaded"; };
img.onerror = () => { outcomes.img = "failed"; };
img.src = "http://example.com/y.png";
document.body.append(img);
const socket = new WebSocket("wss://example.com/z");
socket.onopen = () => { outcomes.socket = "open"; };
socket.onclose = () => { outcomes.socket = outcomes.socket || "closed"; };
</script>"""


def test_requests_leaving_the_machine_are_recorded_and_refused(open_page):
    visit = open_page(REACHING_OUT)
    visit.page.wait_for_function("Object.keys(window.outcomes).length === 3")
    outcomes = visit.page.evaluate("window.outcomes")
    assert outcomes["fetch"].startswith("TypeError")  # "Failed to fetch"
    assert outcomes["img"] == "failed"
    assert outcomes["socket"] == "closed"
    wanted = {"https://example.com/x", "http://example.com/y.png", "wss://example.com/z"}
    assert set(visit.network) == wanted
    assert set(visit.blocked) == wanted
    assert visit.requests[0] == visit.url
    # the check later tests rely on catches each of them
    with pytest.raises(AssertionError) as raised:
        visit.assert_quiet()
    for url in wanted:
        assert f"request: {url}" in str(raised.value)


def test_data_and_blob_urls_are_not_requests(open_page):
    visit = open_page("""<!doctype html><body><script>
const pixel = "data:image/gif;base64,R0lGODlhAQABAIAAAP///wAAACH5BAEAAAAALAAAAAABAAEAAAICRAEAOw==";
window.loaded = 0;
const svg = new Blob(["<svg xmlns='http://www.w3.org/2000/svg'/>"], {type: "image/svg+xml"});
for (const src of [pixel, URL.createObjectURL(svg)]) {
    const img = new Image();
    img.onload = () => { window.loaded += 1; };
    img.src = src;
    document.body.append(img);
}
</script>""")
    visit.page.wait_for_function("window.loaded === 2")
    assert visit.network == [] and visit.blocked == []
    visit.assert_quiet()


def test_an_uncaught_error_is_a_page_error(open_page):
    visit = open_page("""<!doctype html><script>
console.log("before");
window.missingFunction();
console.log("never");
</script><script>window.later = "ran";</script>""")
    assert visit.console == [("log", "before")]
    assert len(visit.errors) == 1
    assert visit.errors[0].startswith("TypeError: ") and "missingFunction" in visit.errors[0]
    assert visit.page.evaluate("window.later") == "ran"  # the next script still runs
    with pytest.raises(AssertionError, match="page error: TypeError"):
        visit.assert_quiet()


def test_an_error_thrown_later_is_a_page_error_too(open_page):
    visit = open_page("""<!doctype html><script>
setTimeout(() => { window.thrown = true; throw new RangeError("out of range"); }, 0);
</script>""")
    visit.page.wait_for_function("window.thrown === true")
    visit.page.evaluate("new Promise(requestAnimationFrame)")  # the error's event follows
    assert visit.errors == ["RangeError: out of range"]


def test_csp_hash_is_the_base64_sha256_of_the_exact_text():
    assert browser.csp_hash("") == "'sha256-47DEQpj8HBSa+/TImW+5JCeuQeRkm5NMpJWZG3hSuFU='"
    script = "window.a = 1;\n"
    digest = base64.b64encode(hashlib.sha256(script.encode()).digest()).decode()
    assert browser.csp_hash(script) == f"'sha256-{digest}'"
    assert browser.csp_hash(script) != browser.csp_hash(script.strip())


def test_a_content_security_policy_hash_lets_one_inline_script_run(open_page):
    allowed = """
document.addEventListener("securitypolicyviolation",
    e => window.violations.push([e.violatedDirective, e.blockedURI]));
window.violations = [];
window.allowedRan = true;
"""
    refused = "window.refusedRan = true;"
    visit = open_page(f"""<!doctype html>
<meta http-equiv="Content-Security-Policy" content="script-src {browser.csp_hash(allowed)}">
<script>{allowed}</script>
<script>{refused}</script>""")
    visit.page.wait_for_function("window.violations.length > 0")
    assert visit.page.evaluate("window.allowedRan") is True
    assert visit.page.evaluate("window.refusedRan") is None  # undefined: it never ran
    assert visit.page.evaluate("window.violations") == [["script-src-elem", "inline"]]
    assert any("Content Security Policy" in text for text in visit.console_errors)
    assert visit.errors == []


def test_the_browser_between_tests_leaves_asyncio_free(browser_session):
    """Playwright's sync API marks its event loop as running; with the browser kept for the
    session, the other tests of the process must still be able to run an event loop."""
    async def answer():
        await asyncio.sleep(0)
        return 42

    assert asyncio.run(answer()) == 42
    loop = asyncio.new_event_loop()
    try:
        assert loop.run_until_complete(answer()) == 42
    finally:
        loop.close()


def test_the_browser_is_the_system_s(chromium, browser_session):
    assert browser_session.executable == browser.find_chromium()
    assert re.fullmatch(r"\d+(\.\d+)+", chromium.version)


def test_the_browser_is_found_where_named(tmp_path):
    fake = tmp_path / "my-chromium"
    fake.write_text("#!/bin/sh\n")
    fake.chmod(0o755)
    assert browser.find_chromium({browser.CHROMIUM_ENV: str(fake)}) == str(fake)
    assert browser.find_chromium({browser.CHROMIUM_ENV: str(tmp_path / "none")}) is None


# a scratch project: the suite's rules (a skip is an error in CI) and the browser fixtures
MISSING = "def test_a_page(open_page):\n    open_page('<p>hello</p>')\n"


@pytest.mark.parametrize("ci", ["1", ""])
def test_a_missing_browser_fails_in_ci_and_skips_elsewhere(pytester, monkeypatch, ci):
    conftest = (pathlib.Path(__file__).parent / "conftest.py").read_text()
    pytester.makeconftest(conftest + "\npytest_plugins = ['tests.browser']\n")
    pytester.makepyfile(test_missing=MISSING)
    monkeypatch.setenv(browser.CHROMIUM_ENV, str(pytester.path / "no-such-chromium"))
    monkeypatch.setenv("CI", ci)
    result = pytester.runpytest("-p", "no:hypothesispytest", "-p", "no:cacheprovider", "-rA")
    if ci:
        result.assert_outcomes(errors=1)
        result.stdout.fnmatch_lines(["*Chromium is not installed*CI is set*"])
    else:
        result.assert_outcomes(skipped=1)
        result.stdout.fnmatch_lines(["*Chromium is not installed*"])
