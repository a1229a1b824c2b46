"""Check the built site as a reader without a network would see it.

``python scripts/check_site.py docs/_build/html`` (``make docs`` runs it):

1. every page loads its scripts, style sheets, images and frames from the site itself:
   an ``http(s)://`` or ``//`` address in a ``<script src>``, ``<link href>`` (style
   sheets, preloads, icons), ``<img src>`` or ``<iframe src>`` is an error (links to other
   sites, ``<a href>``, are not loads);
2. with ``--browser`` (headless Chromium, Debian's ``chromium``), each page that holds
   equations is opened with the network off (a new network namespace, ``unshare -n``; where
   that is not allowed, Chromium is pointed at a proxy that does not exist) and its
   rendered DOM read back: every equation must be typeset by MathJax (one
   ``mjx-container`` per ``math`` element) and none in error (``mjx-merror``);
3. with ``--screenshots DIR``, one PNG per page kind (front page, guide, methods, demo,
   reference, verification) is written to ``DIR`` for a person to look at.

Exit status 1 when a check fails (each failure printed), 0 otherwise. Hand-written: no
library checks a Sphinx site for network loads; Chromium is the browser.
"""

from __future__ import annotations

import argparse
import re
import shutil
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path

#: One page of each kind, for the screenshots (paths under the site's root).
PAGE_KINDS = {
    "front": "index.html",
    "quickstart": "guide/quickstart.html",
    "guide": "guide/results.html",
    "methods": "methods/problem.html",
    "demo": "demos/obstacle_c1.html",
    "gallery": "demos/index.html",
    "reference": "reference/api.html",
    "verification": "verification/benchmarks.html",
}

_REMOTE = re.compile(r"^(https?:)?//", re.I)


class _Loads(HTMLParser):
    """The addresses a page loads (not the ones it links to), and its math elements."""

    def __init__(self) -> None:
        super().__init__()
        self.loads: list[str] = []
        self.math = 0

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        a = dict(attrs)
        if tag in ("script", "img", "iframe", "source", "video", "audio") and a.get("src"):
            self.loads.append(str(a["src"]))
        if tag == "link" and a.get("href") and (a.get("rel") or "") != "canonical":
            self.loads.append(str(a["href"]))
        classes = (a.get("class") or "").split()
        if tag in ("span", "div") and "math" in classes:
            self.math += 1


def scan(page: Path) -> _Loads:
    """The loads and math elements of one HTML file."""
    parser = _Loads()
    parser.feed(page.read_text(encoding="utf-8"))
    return parser


def remote_loads(site: Path) -> list[str]:
    """``page: address`` for every load from another site."""
    found = []
    for page in sorted(site.rglob("*.html")):
        for address in scan(page).loads:
            if _REMOTE.match(address):
                found.append(f"{page.relative_to(site)}: loads {address}")
    return found


def _chromium() -> str | None:
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    return None


def _offline(argv: list[str]) -> list[str]:
    """``argv`` run without a network: in a new network namespace where allowed."""
    unshare = shutil.which("unshare")
    if unshare and subprocess.run([unshare, "-n", "true"], capture_output=True).returncode == 0:
        return [unshare, "-n", *argv]
    # No namespace (not root): a proxy that refuses every connection.
    return [*argv, "--proxy-server=127.0.0.1:9", "--proxy-bypass-list=<-loopback>"]


def _browser(chromium: str, *extra: str) -> list[str]:
    return [
        chromium,
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--hide-scrollbars",
        "--virtual-time-budget=15000",
        *extra,
    ]


def rendered_math(chromium: str, page: Path) -> tuple[int, int]:
    """(typeset equations, equations in error) of ``page`` opened offline."""
    argv = _offline(_browser(chromium, "--dump-dom", page.resolve().as_uri()))
    dom = subprocess.run(argv, capture_output=True, text=True, timeout=120).stdout
    return dom.count("<mjx-container"), dom.count("<mjx-merror")


def screenshot(chromium: str, page: Path, png: Path, width: int = 1280) -> None:
    """A PNG of ``page`` opened offline, ``width`` pixels wide (3 000 high)."""
    argv = _offline(
        _browser(chromium, f"--window-size={width},3000", f"--screenshot={png.resolve()}")
    )
    subprocess.run([*argv, page.resolve().as_uri()], capture_output=True, timeout=120)


def main(argv: list[str] | None = None) -> int:
    """Run the checks; print each failure; 1 if any."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("site", type=Path, help="the built HTML site (docs/_build/html)")
    parser.add_argument(
        "--browser", action="store_true", help="open every page with equations offline"
    )
    parser.add_argument("--screenshots", type=Path, help="write a PNG per page kind here")
    args = parser.parse_args(argv)
    failures = remote_loads(args.site)
    pages = sorted(args.site.rglob("*.html"))
    print(f"check_site: {len(pages)} pages, {len(failures)} loads from the network")
    chromium = _chromium() if (args.browser or args.screenshots) else None
    if (args.browser or args.screenshots) and chromium is None:
        failures.append("no Chromium (apt-get install chromium) for --browser/--screenshots")
    if args.browser and chromium:
        typeset = 0
        for page in pages:
            wanted = scan(page).math
            if not wanted:
                continue
            got, errors = rendered_math(chromium, page)
            typeset += got
            if got < wanted or errors:
                failures.append(
                    f"{page.relative_to(args.site)}: {got} of {wanted} equations typeset "
                    f"offline, {errors} in error"
                )
        print(f"check_site: {typeset} equations typeset offline")
    if args.screenshots and chromium:
        args.screenshots.mkdir(parents=True, exist_ok=True)
        for kind, rel in PAGE_KINDS.items():
            if (args.site / rel).is_file():
                screenshot(chromium, args.site / rel, args.screenshots / f"{kind}.png")
                screenshot(chromium, args.site / rel, args.screenshots / f"{kind}_narrow.png", 420)
        print(f"check_site: screenshots in {args.screenshots}")
    for failure in failures:
        print(f"check_site: {failure}", file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
