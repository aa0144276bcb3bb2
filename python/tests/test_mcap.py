"""`pada capture --mcap` read by the Python `mcap` reader, and the live
`--foxglove` server read by a `websockets` client speaking Foxglove's
protocol: the counts per channel equal `pada capture --json` on the same
stream, every message is valid against its channel's JSON Schema, a
damaged stream still gives a valid file with its losses counted, and a
client subscribed during a `pada run` receives every message of every
channel."""

import asyncio
import importlib
import json
import os
import signal
import subprocess
from collections import Counter
from pathlib import Path

import pytest

from conftest import REPO, run_pada


def need(module):
    """A test package; under CI=true a missing one fails."""
    try:
        return importlib.import_module(module)
    except ImportError:
        if os.environ.get("CI") == "true":
            pytest.fail(f"{module} is not installed (`cargo xtask test` installs it in its venv)")
        pytest.skip(f"{module} is not installed")


SIL = REPO / "tests" / "data" / "sil-pendulum-3s.bin"
# LEO on f429-sdram in QEMU: `pada sil --task leo --board f429-sdram --seconds 3`
# (telemetry.bin; wire protocol 7), a board with a claim table.
SIL_LEO = REPO / "tests" / "data" / "sil-leo-3s.bin"


def damaged(clean):
    """The stream with three frames' middle bytes changed, one frame cut
    out and a burst of garbage, as a serial line damages one."""
    ends = [i + 1 for i, b in enumerate(clean) if b == 0]
    starts = [0] + ends[:-1]
    n = len(ends)
    out = bytearray()
    for k, (a, b) in enumerate(zip(starts, ends)):
        if k == n // 3:
            out += bytes((x * 73) & 0xFF | 1 for x in range(1, 38)) + b"\x00"
        if k == n // 2:
            continue
        frame = bytearray(clean[a:b])
        if k in (n // 10, n // 4, 3 * n // 4):
            i = len(frame) // 2
            frame[i] = 0x7F if frame[i] == 0xFF else frame[i] + 1
        out += frame
    return bytes(out)


@pytest.fixture(scope="module")
def recordings(tmp_path_factory, pada_bin):
    """name -> (the MCAP file, `pada capture --json` of its stream)."""
    d = tmp_path_factory.mktemp("mcap")
    leo = d / "leo.bin"
    run_pada(pada_bin, "run", "--task", "leo", "--algo", "pada", "--delta", "0.1667", "--trials", "1",
             "--seconds", "20", "--out", str(d / "run"), "--telemetry", str(leo))
    (d / "damaged.bin").write_bytes(damaged(SIL.read_bytes()))
    out = {}
    for name, stream in [("leo", leo), ("sil", SIL), ("sil-leo", SIL_LEO), ("damaged", d / "damaged.bin")]:
        mcap = d / f"{name}.mcap"
        summary = json.loads(run_pada(pada_bin, "capture", "--file", str(stream), "--mcap", str(mcap), "--json"))
        out[name] = (mcap, summary)
    return out


def read(path):
    reader_mod = need("mcap.reader")
    with open(path, "rb") as f:
        reader = reader_mod.make_reader(f)
        messages = [(s, c, m) for s, c, m in reader.iter_messages(log_time_order=False)]
        meta = {m.name: dict(m.metadata) for m in reader.iter_metadata()}
        summary = reader.get_summary()
    return messages, meta, summary


def expected_counts(summary, gearboxes, scene):
    m = summary["messages"]
    link = summary["link"]
    want = {
        "/hello": m["hello"], "/step": m["step"], "/episode": m["episode"], "/health": m["health"],
        "/safety/state": m["state"], "/safety/fault": m["fault"],
        # A /link message at every lost frame, sequence gap and health
        # report, and one at the end.
        "/link": summary["bad_frames"] + link["seq_gaps"] + m["health"] + 1,
    }
    for k in range(gearboxes):
        want[f"/fatigue/{k}"] = m["step"]
    if scene:
        want["/scene"] = m["step"]
    return {k: v for k, v in want.items() if v}


@pytest.mark.parametrize(
    "name,gearboxes,scene", [("leo", 4, True), ("sil", 1, True), ("sil-leo", 4, True), ("damaged", 1, True)]
)
def test_counts_per_channel_equal_the_capture_summary(recordings, name, gearboxes, scene):
    path, summary = recordings[name]
    messages, meta, file_summary = read(path)
    counts = Counter(c.topic for _, c, _ in messages)
    want = expected_counts(summary, gearboxes, scene)
    for topic, n in want.items():
        assert counts[topic] == n, (topic, counts)
    # Policy reports and the other events make the summary's "other"; a
    # checkpoint transfer's frames (chunks, requests and the board's report
    # that ends it) are one /checkpoint message each transfer.
    transfers = [json.loads(m.data) for _, c, m in messages if c.topic == "/checkpoint"]
    reported = sum(t["reported"] for t in transfers)
    assert counts["/policy"] + counts["/event"] + reported == summary["messages"]["other"]
    assert sum(t["requests"] for t in transfers) == summary["messages"]["restore_wanted"]
    assert sum(t["chunks"] for t in transfers if t["direction"] == "save") == summary["messages"]["checkpoint_chunk"]
    assert set(counts) <= set(want) | {"/policy", "/event", "/governor", "/claims", "/checkpoint"}, counts
    # The claim table's occupancy beside each health report of a claim table.
    assert counts["/claims"] in (0, summary["messages"]["health"])
    if summary["latest"].get("table"):
        assert counts["/claims"] == summary["messages"]["health"]
    if name == "sil-leo":
        # The board's claim table reports its occupancy with every health.
        assert summary["latest"]["table"]["slots"] == 1 << 21
        assert counts["/claims"] == summary["messages"]["health"] > 0
        # At boot it asked the host for its checkpoint (none in a capture
        # of a file): one restore, one message.
        assert [(t["direction"], t["requests"], t["outcome"]) for t in transfers] == [("restore", 1, "no-checkpoint")]
    # The file's own statistics agree with what was read.
    stats = file_summary.statistics
    by_id = {c.id: c.topic for c in file_summary.channels.values()}
    assert {by_id[i]: n for i, n in stats.channel_message_counts.items()} == dict(counts)
    assert meta["pada"]["version"] and len(meta["pada"]["config_hash"]) == 8
    assert int(meta["pada.link"]["bad_frames"]) == summary["bad_frames"]
    assert int(meta["pada.link"]["frames"]) == summary["link"]["frames"]


@pytest.mark.parametrize("name", ["leo", "sil", "sil-leo", "damaged"])
def test_every_message_is_valid_against_its_channels_schema(recordings, name):
    jsonschema = need("jsonschema")
    path, _ = recordings[name]
    messages, _, _ = read(path)
    validators = {}
    for schema, channel, message in messages:
        assert channel.message_encoding == "json" and schema.encoding == "jsonschema"
        if schema.id not in validators:
            s = json.loads(schema.data)
            jsonschema.Draft202012Validator.check_schema(s)
            validators[schema.id] = jsonschema.Draft202012Validator(s)
        validators[schema.id].validate(json.loads(message.data))
    assert len(validators) >= 7  # hello, step, fatigue, episode, policy, link, scene at least


def test_the_leo_scene_draws_torso_legs_and_feet(recordings):
    path, _ = recordings["leo"]
    messages, _, _ = read(path)
    scenes = [json.loads(m.data) for _, c, m in messages if c.topic == "/scene"]
    lines = scenes[-1]["entities"][0]["lines"]
    assert len(lines) == 5  # floor, two legs with their feet, torso, arm
    legs = [ln for ln in lines if len(ln["points"]) == 8]
    assert len(legs) == 2 and {p["y"] for p in legs[0]["points"]} != {p["y"] for p in legs[1]["points"]}
    # The stance heel stands on the floor (z = 0), and nothing is below it.
    assert min(p["z"] for ln in lines for p in ln["points"]) >= -0.05


def test_a_damaged_stream_gives_a_valid_file_with_its_losses(recordings):
    path, summary = recordings["damaged"]
    assert summary["bad_frames"] >= 3 and summary["link"]["seq_gaps"] >= 1
    messages, _, _ = read(path)
    events = Counter(json.loads(m.data)["event"] for _, c, m in messages if c.topic == "/link")
    assert events["lost"] == summary["bad_frames"]
    assert events["gap"] == summary["link"]["seq_gaps"]
    last = [json.loads(m.data) for _, c, m in messages if c.topic == "/link"][-1]
    assert last["event"] == "end"
    for k, v in summary["link"].items():
        assert last[k] == v, k


async def live_session(pada_bin, tmp):
    websockets = need("websockets.asyncio.client")
    watch = await asyncio.create_subprocess_exec(
        pada_bin, "watch", "--listen", "tcp:127.0.0.1:0", "--serve", "127.0.0.1:0",
        "--foxglove", "tcp:127.0.0.1:0", "--json",
        stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    listen = ws_addr = None
    while listen is None or ws_addr is None:
        line = (await asyncio.wait_for(watch.stderr.readline(), 30)).decode()
        assert line, "watch ended before announcing its addresses"
        if "waiting for a telemetry sender on tcp:" in line:
            listen = line.split("on tcp:")[1].split()[0]
        if "ws://" in line:
            ws_addr = line.split("ws://")[1].split()[0]
    received = Counter()
    async with websockets.connect(f"ws://{ws_addr}", subprotocols=["foxglove.sdk.v1", "foxglove.websocket.v1"],
                                  max_size=None) as ws:
        assert ws.subprotocol in ("foxglove.sdk.v1", "foxglove.websocket.v1")
        info = json.loads(await ws.recv())
        assert info["op"] == "serverInfo"
        adv = json.loads(await ws.recv())
        assert adv["op"] == "advertise"
        topics = {c["id"]: c["topic"] for c in adv["channels"]}
        await ws.send(json.dumps({"op": "subscribe",
                                  "subscriptions": [{"id": i, "channelId": i} for i in topics]}))
        await asyncio.sleep(0.3)
        run = await asyncio.create_subprocess_exec(
            pada_bin, "run", "--task", "pendulum", "--algo", "pada", "--delta", "0.5", "--trials", "1",
            "--seconds", "60", "--out", str(tmp / "run"), "--telemetry", f"tcp:{listen}", "--json",
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        async def stop_after_run():
            assert await run.wait() == 0
            await asyncio.sleep(1.0)
            watch.send_signal(signal.SIGINT)
        stopper = asyncio.ensure_future(stop_after_run())
        async for msg in ws:
            if isinstance(msg, bytes):
                assert msg[0] == 1
                sub = int.from_bytes(msg[1:5], "little")
                json.loads(msg[13:])
                received[topics[sub]] += 1
        await stopper
    out, _ = await watch.communicate()
    return received, json.loads(out), ws.subprotocol


def test_a_foxglove_client_receives_every_channel_during_a_run(pada_bin, tmp_path):
    received, summary, _ = asyncio.run(asyncio.wait_for(live_session(pada_bin, tmp_path), 300))
    m = summary["messages"]
    assert m["step"] > 1000
    assert received["/step"] == m["step"] and received["/scene"] == m["step"]
    assert received["/fatigue/0"] == m["step"]
    assert received["/episode"] == m["episode"] and received["/hello"] == m["hello"] == 1
    assert received["/link"] == m["health"] + summary["bad_frames"] + summary["link"]["seq_gaps"] + 1
    assert summary["foxglove"]["dropped"] == 0 and summary["foxglove"]["clients"] == 1
    assert summary["foxglove"]["sent"] == sum(received.values())
