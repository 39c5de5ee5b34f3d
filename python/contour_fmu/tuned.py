"""Plumbing: a `ccc-tune` result applied to the ContourCCC2D FMU as start values.

`ccc-tune --out tuned.json` writes {"factors": {"ke": ..., "kde": ..., "kp": ...,
"ki": ..., "kd": ...}, "settings": {...}, ...}; the FMU's parameters are fuzzy.<name>.
"""

import json
from pathlib import Path

FACTORS = ("ke", "kde", "kp", "ki", "kd")


def start_values(tuned_json):
    """ContourCCC2D start values ({"fuzzy.ke": ..., ...}) from a ccc-tune JSON file."""
    document = json.loads(Path(tuned_json).read_text())
    factors = document["factors"]
    missing = [name for name in FACTORS if name not in factors]
    if missing:
        raise ValueError(f"{tuned_json}: no factor {', '.join(missing)} in 'factors'")
    return {f"fuzzy.{name}": float(factors[name]) for name in FACTORS}
