"""Reading a recorded telemetry stream (``pada run --telemetry FILE``, or a
board's raw serial output) into numpy arrays."""

import json

import numpy as np

from . import _pada


def _ragged(rows, dtype):
    width = max((len(r) for r in rows), default=0)
    out = np.full((len(rows), width), np.nan if dtype == np.float64 else 0, dtype=dtype)
    for i, r in enumerate(rows):
        out[i, : len(r)] = r
    return out


def read_telemetry(path):
    """Decodes the telemetry stream at ``path`` with ``pada capture``'s
    decoder. Returns a dict:

    - ``steps``: one entry per ``Step`` frame — ``step``, ``time_ms``,
      ``episode``, ``mode`` ("learning"/"testing"), ``kind`` ("start",
      "step", "absorbing", "timeout"), ``action``, ``reward``, ``td_error``,
      ``explored``, ``loop_us``, and the 2-D ``state``, ``output``,
      ``damage`` (J per learned joint, Eq. 7) and ``reengagements``;
    - ``episodes``: ``index``, ``mode``, ``return``, ``length``,
      ``weights_checksum``;
    - ``checkpoints``: one entry per save and per restore of a checkpoint
      the host keeps (LEO on the F429 streams its 8 MiB table in up to
      65 543 chunks), as ``pada capture``'s ``checkpoint-save`` and
      ``checkpoint-restore`` CSV rows: ``direction`` ("save"/"restore"),
      ``generation`` (-1: none loaded), ``bytes`` (the image), ``chunks``,
      ``requests`` (a restore's), ``link_s`` (seconds on the 921 600-baud
      telemetry link; in a recording a restore's answers, which go to the
      board, are not counted) and ``outcome``;
    - ``link``: frames, bytes and every kind of loss, ``bad_frames`` and
      ``messages`` (frames by message) — the counts ``pada capture --json``
      reports for the same file.

    Raises ``OSError`` when the file cannot be read and ``ValueError`` for
    a directory.
    """
    raw = _pada.read_telemetry(str(path))
    s = raw["steps"]
    steps = {
        "step": np.asarray(s["step"], dtype=np.uint32),
        "time_ms": np.asarray(s["time_ms"], dtype=np.uint32),
        "episode": np.asarray(s["episode"], dtype=np.uint32),
        "mode": np.asarray(s["mode"], dtype="<U8"),
        "kind": np.asarray(s["kind"], dtype="<U9"),
        "action": np.asarray(s["action"], dtype=np.uint32),
        "reward": np.asarray(s["reward"], dtype=np.float64),
        "td_error": np.asarray(s["td_error"], dtype=np.float64),
        "explored": np.asarray(s["explored"], dtype=bool),
        "loop_us": np.asarray(s["loop_us"], dtype=np.uint32),
        "state": _ragged(s["state"], np.float64),
        "output": _ragged(s["output"], np.float64),
        "damage": _ragged(s["damage"], np.float64),
        "reengagements": _ragged(s["reengagements"], np.int64),
    }
    e = raw["episodes"]
    episodes = {
        "index": np.asarray(e["index"], dtype=np.uint32),
        "mode": np.asarray(e["mode"], dtype="<U8"),
        "return": np.asarray(e["return"], dtype=np.float64),
        "length": np.asarray(e["length"], dtype=np.uint32),
        "weights_checksum": np.asarray(e["weights_checksum"], dtype=np.uint32),
    }
    summary = json.loads(raw["summary_json"])
    c = summary["checkpoints"]
    checkpoints = {
        "direction": np.asarray([t["direction"] for t in c], dtype="<U7"),
        "generation": np.asarray([-1 if t["generation"] is None else t["generation"] for t in c], dtype=np.int64),
        "bytes": np.asarray([t["bytes"] for t in c], dtype=np.uint32),
        "chunks": np.asarray([t["chunks"] for t in c], dtype=np.uint32),
        "requests": np.asarray([t["requests"] for t in c], dtype=np.uint32),
        "link_s": np.asarray([t["link_s"] for t in c], dtype=np.float64),
        "outcome": np.asarray([t["outcome"] for t in c], dtype=str),
    }
    return {
        "steps": steps,
        "episodes": episodes,
        "checkpoints": checkpoints,
        "link": summary["link"],
        "bad_frames": summary["bad_frames"],
        "messages": summary["messages"],
    }
