"""An earlier build to compare this one with, in the same run: the tree of a git revision,
checked out once with `git worktree` under <target>/bench-data/ and kept for the next
bench run (`git worktree prune` forgets it once the folder is removed)."""

import os
import subprocess
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
DATA = Path(os.environ.get("CARGO_TARGET_DIR") or REPO / "target") / "bench-data"


def checkout(rev, folder):
    """The tree of `rev` in `folder` (made if missing); raises OSError or
    CalledProcessError without git or the revision."""
    tree = Path(folder) / f"baseline-{rev}"
    if not tree.exists():
        tree.parent.mkdir(parents=True, exist_ok=True)
        subprocess.run(["git", "-C", str(REPO), "worktree", "add", "--detach", str(tree), rev],
                       check=True, capture_output=True)
    return tree
