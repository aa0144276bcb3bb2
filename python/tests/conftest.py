"""Shared helpers: the `pada` command the results are compared with."""

import json
import os
import shutil
import signal
import subprocess
import time
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


def start_servos(link, *args):
    """Starts `pada servos --port LINK ARGS… --json` and waits for its
    port's link; returns the process."""
    proc = subprocess.Popen([pada_binary(), "servos", "--port", str(link), *args, "--json"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.time() + 30
    while not os.path.exists(link):
        if proc.poll() is not None or time.time() > deadline:
            raise RuntimeError(f"pada servos did not start: {proc.stderr.read()}")
        time.sleep(0.02)
    return proc


def stop_servos(proc):
    """Interrupts `pada servos` as Ctrl-C does; returns its JSON summary."""
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=30)
    assert proc.returncode == 0, err
    return json.loads(out)
