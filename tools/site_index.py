"""Write the documentation site's home page (docs/index.md) from the README: the same text, its links to
``docs/PAGE.md`` made relative to the site (``PAGE.md``), so that the site's landing page carries what the README
says (the set-up, the measured figures) and cannot drift from it (``tests/test_docs.py`` checks).

Usage: python tools/site_index.py
"""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def site_index(readme: str) -> str:
    """The README as the site's home page: ``](docs/X)`` links become ``](X)``; other links are left as they are."""
    return re.sub(r"\]\(docs/", "](", readme)


def main() -> None:
    (ROOT / "docs" / "index.md").write_text(
        site_index((ROOT / "README.md").read_text(encoding="utf-8")), encoding="utf-8"
    )


if __name__ == "__main__":
    main()
