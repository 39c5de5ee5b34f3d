"""The checkout the tests run in, and cargo's target folder."""

import os
from pathlib import Path

REPO = Path(__file__).resolve().parents[3]


def target_dir():
    """$CARGO_TARGET_DIR, else <repo>/target."""
    return Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
