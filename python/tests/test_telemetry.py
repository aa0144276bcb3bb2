"""read_telemetry's frame and loss counts equal `pada capture --json`'s, on
a clean stream of `pada run --telemetry` and on a damaged copy."""

import csv
import json
from pathlib import Path

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


def test_checkpoints_are_one_entry_per_save_and_restore(pada_bin, tmp_path):
    # The SIL recording of LEO on f429-sdram: its board asked the host for
    # the checkpoint it keeps at boot (one request, none kept), as pada
    # capture's one checkpoint-restore row.
    path = Path(__file__).resolve().parents[2] / "tests" / "data" / "sil-leo-3s.bin"
    t = check_counts(pada_bin, path)
    c = t["checkpoints"]
    assert list(c["direction"]) == ["restore"] and list(c["outcome"]) == ["no-checkpoint"]
    assert list(c["requests"]) == [1] and list(c["generation"]) == [-1] and c["link_s"][0] > 0
    csv_path = tmp_path / "leo.csv"
    run_pada(pada_bin, "capture", "--file", str(path), "--out", str(csv_path))
    rows = [r for r in csv.DictReader(csv_path.open()) if r["kind"].startswith("checkpoint-")]
    assert [(r["kind"], r["outcome"], r["bytes"]) for r in rows] == [("checkpoint-restore", "no-checkpoint", str(c["bytes"][0]))]


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
