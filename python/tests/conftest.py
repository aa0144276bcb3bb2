"""Shared helpers: the `pada` command the results are compared with."""

import os
import shutil
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


def pada_binary():
    """The `pada` command: $PADA_BIN, else the workspace's debug or release
    build, else `pada` on PATH. Under CI=true a missing binary fails."""
    env = os.environ.get("PADA_BIN")
    candidates = [Path(env)] if env else []
    candidates += [REPO / "target" / "debug" / "pada", REPO / "target" / "release" / "pada"]
    for c in candidates:
        if c.is_file() and os.access(c, os.X_OK):
            return str(c)
    on_path = shutil.which("pada")
    if on_path:
        return on_path
    msg = "the pada command is not built (cargo build -p pada, or set PADA_BIN; `cargo xtask test` sets it)"
    if os.environ.get("CI") == "true":
        pytest.fail(msg)
    pytest.skip(msg)


@pytest.fixture(scope="session")
def pada_bin():
    return pada_binary()


def run_pada(binary, *args):
    out = subprocess.run([binary, *args], check=True, capture_output=True, text=True, timeout=600)
    return out.stdout
