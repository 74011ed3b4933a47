"""Write the published schema of model files (src/gyrocomp/calibration/model.schema.json) from
:func:`gyrocomp.calibration.schema.build_schema` at the current schema version (``tests/calibration`` checks that the
shipped file is what this writes).

Usage: python tools/model_schema.py
"""

from __future__ import annotations

import json
from pathlib import Path

from gyrocomp.calibration import SCHEMA_VERSION
from gyrocomp.calibration.schema import SCHEMA_FILE, build_schema

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    path = ROOT / "src" / "gyrocomp" / "calibration" / SCHEMA_FILE
    path.write_text(json.dumps(build_schema(SCHEMA_VERSION), indent=1) + "\n", encoding="utf-8")
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
