"""Check that the documentation site works opened as files: headless Chromium loads ``SITE/index.html?q=WORD``
from ``file://`` (no server, no network) and Material's search must list results for each word.

Usage: python tools/check_site_search.py [SITE] (default ``site``, what ``make docs`` builds); exit 1 when a word
finds nothing, 2 when Chromium is missing (``apt-get install chromium``).
"""

from __future__ import annotations

import re
import subprocess
import sys
import tempfile
from pathlib import Path

from browser import FLAGS, chromium as find_chromium  # tools/browser.py, beside this script

#: words every build of the site must find (pages on the fit, the noise, the errors)
WORDS = ("allan", "hysteresis", "symbolic")
#: what a user types after a message, and the page that must come first for it
FIRST = {"no such file": "errors.html"}


def search_page(site: Path, word: str, chromium: str) -> str:
    """The DOM of the site's index opened from files with Material's search for ``word``."""
    with tempfile.TemporaryDirectory() as profile:
        dom = subprocess.run(
            [
                chromium,
                *FLAGS,
                f"--user-data-dir={profile}",
                "--virtual-time-budget=15000",
                "--dump-dom",
                f"{(site / 'index.html').resolve().as_uri()}?q={word}",
            ],
            capture_output=True,
            text=True,
            timeout=120,
        ).stdout
    return dom


def first_result(site: Path, words: str, chromium: str) -> str | None:
    """The address of the first document Material's search lists for ``words`` (relative to the site), or None."""
    found = re.search(r'<a href="([^"]*)" class="md-search-result__link"', search_page(site, words, chromium))
    return None if found is None else found.group(1)


def results(site: Path, word: str, chromium: str) -> int:
    """How many documents Material's search says match ``word`` on the site opened from files."""
    dom = search_page(site, word, chromium)
    found = re.search(r"md-search-result__meta\">\s*(\d+|One|No) matching document", dom)
    if not found:
        return 0
    return {"One": 1, "No": 0}.get(found.group(1), None) or int(found.group(1))


def main() -> int:
    site = Path(sys.argv[1] if len(sys.argv) > 1 else "site")
    chromium = find_chromium()
    if chromium is None:
        print("check_site_search: no chromium (apt-get install chromium)", file=sys.stderr)
        return 2
    failed = [w for w in WORDS if results(site, w, chromium) == 0]
    for word in WORDS:
        print(f"search from file:// for {word!r}: {'nothing found' if word in failed else 'found'}")
    for words, page in FIRST.items():
        first = first_result(site, words.replace(" ", "+"), chromium)
        ok = first is not None and page in first
        print(f"search from file:// for {words!r}: first {first!r} ({'as expected' if ok else f'expected {page}'})")
        failed += [] if ok else [words]
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
