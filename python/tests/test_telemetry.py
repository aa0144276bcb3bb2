"""read_telemetry's frame and loss counts equal `pada capture --json`'s, on
a clean stream of `pada run --telemetry` and on a damaged copy."""

import json

import numpy as np
import pytest

import pada
from conftest import run_pada


@pytest.fixture(scope="module")
def stream(tmp_path_factory, pada_bin):
    d = tmp_path_factory.mktemp("tele")
    path = d / "run.bin"
    run_pada(pada_bin, "run", "--task", "pendulum", "--algo", "sarsa", "--trials", "1", "--seconds", "60", "--out", str(d / "out"), "--telemetry", str(path))
    return path


def check_counts(pada_bin, path):
    t = pada.read_telemetry(path)
    cap = json.loads(run_pada(pada_bin, "capture", "--file", str(path), "--json"))
    assert t["link"] == cap["link"]
    assert t["messages"] == cap["messages"]
    assert t["bad_frames"] == cap["bad_frames"]
    assert len(t["steps"]["step"]) == cap["messages"]["step"]
    assert len(t["episodes"]["index"]) == cap["messages"]["episode"]
    return t


def test_clean_stream(stream, pada_bin):
    t = check_counts(pada_bin, stream)
    assert t["link"]["frames"] > 1000 and t["bad_frames"] == 0
    s = t["steps"]
    assert s["state"].shape == (len(s["step"]), 2) and s["damage"].shape[1] == 1
    assert np.all(np.diff(s["damage"][:, 0]) >= 0)
    assert set(np.unique(s["mode"])) <= {"learning", "testing"}


def test_damaged_stream(stream, pada_bin, tmp_path):
    data = bytearray(stream.read_bytes())
    for k in range(100, len(data), 997):
        data[k] ^= 0x5A
    bad = tmp_path / "bad.bin"
    bad.write_bytes(bytes(data[: len(data) - 7]))
    t = check_counts(pada_bin, bad)
    assert t["bad_frames"] > 0


def test_bad_path(tmp_path):
    with pytest.raises(OSError, match="cannot read"):
        pada.read_telemetry(tmp_path / "missing.bin")
    with pytest.raises(ValueError, match="is a directory"):
        pada.read_telemetry(tmp_path)
