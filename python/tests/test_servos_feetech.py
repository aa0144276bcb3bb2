"""`pada servos --chain sts3215:1-6` (an SO-101's six Feetech STS3215s,
IDs 1-6) driven by clients that are not pada's and were not written from
it: Feetech's Python SDK as LeRobot installs it (PyPI `feetech-servo-sdk`,
module `scservo_sdk`) and pollen-robotics' `rustypot` (PyPI, its Rust
driver behind Python bindings). Each opens the virtual servos'
pseudo-terminal as it opens the SO-101's USB adapter.

Both libraries' defaults, read before use: `scservo_sdk.PacketHandler(0)`
is the STS/SMS series' little-endian order (1 would be the SCS series'
big-endian); its `ping` is a PING followed by a READ of the model number
at address 3; `GroupSyncRead` sends SYNC READ (0x82) and reads one status
packet per ID in order. `rustypot.Sts3215PyController(port, baud,
timeout)` converts positions to radians about the middle (2048) and
speeds with sign bit 15. The memory map: docs/reference/feetech.md.
"""

import math
import time

import pytest
import rustypot
import scservo_sdk as scs

from conftest import start_servos, stop_servos

BAUD = 1_000_000
IDS = list(range(1, 7))
STS3215 = 777
MODEL_NUMBER, TORQUE_ENABLE, GOAL_POSITION, GOAL_VELOCITY = 3, 40, 42, 46
P_COEFFICIENT, LOCK, PRESENT_POSITION, PRESENT_VOLTAGE, STATUS = 21, 55, 56, 62, 65
PRESENT_BLOCK_LEN = 8  # position, velocity, load, voltage, temperature


class Chain:
    """`pada servos --chain` on a pseudo-terminal."""

    def __init__(self, tmp_path, *extra):
        self.link = str(tmp_path / "so101")
        self.proc = start_servos(self.link, "--chain", "sts3215:1-6", "--baud", str(BAUD), *extra)

    def close(self):
        return stop_servos(self.proc)


@pytest.fixture
def chain(tmp_path):
    c = Chain(tmp_path)
    yield c
    c.close()


@pytest.fixture
def sdk(chain):
    port = scs.PortHandler(chain.link)
    assert port.openPort()
    assert port.setBaudRate(BAUD)
    yield port, scs.PacketHandler(0)
    port.closePort()


def settle(port, ph, ids, address, want, seconds=3.0):
    """Reads `address` of `ids` until each is `want` (the position loop
    takes its time), and returns the last reading."""
    deadline = time.time() + seconds
    while True:
        got = [ph.read2ByteTxRx(port, i, address)[0] for i in ids]
        if got == want or time.time() > deadline:
            return got
        time.sleep(0.05)


# -------------------------------------------------------- feetech-servo-sdk


def test_ping_finds_the_six_servos_and_their_model(sdk):
    port, ph = sdk
    for i in IDS:
        assert ph.ping(port, i) == (STS3215, scs.COMM_SUCCESS, 0)
    model, result, _ = ph.ping(port, 7)
    assert result == scs.COMM_RX_TIMEOUT, "nobody at ID 7"


def test_read_and_write(sdk):
    port, ph = sdk
    assert ph.read2ByteTxRx(port, 3, MODEL_NUMBER) == (STS3215, scs.COMM_SUCCESS, 0)
    # The SO-101 follower's 7.4 V supply, in 0.1 V.
    assert ph.read1ByteTxRx(port, 3, PRESENT_VOLTAGE) == (74, scs.COMM_SUCCESS, 0)
    # LeRobot's configuration writes: Lock off, a lower P gain (EEPROM).
    assert ph.write1ByteTxRx(port, 3, LOCK, 0) == (scs.COMM_SUCCESS, 0)
    assert ph.write1ByteTxRx(port, 3, P_COEFFICIENT, 16) == (scs.COMM_SUCCESS, 0)
    assert ph.read1ByteTxRx(port, 3, P_COEFFICIENT) == (16, scs.COMM_SUCCESS, 0)
    # Position mode: torque on, a goal; the servo moves there.
    assert ph.read2ByteTxRx(port, 3, PRESENT_POSITION) == (2048, scs.COMM_SUCCESS, 0)
    assert ph.write1ByteTxRx(port, 3, TORQUE_ENABLE, 1) == (scs.COMM_SUCCESS, 0)
    assert ph.write2ByteTxRx(port, 3, GOAL_POSITION, 3000) == (scs.COMM_SUCCESS, 0)
    assert settle(port, ph, [3], PRESENT_POSITION, [3000]) == [3000]
    # REG WRITE is held until ACTION (broadcast: no answer).
    assert ph.regWriteTxRx(port, 3, GOAL_POSITION, 2, [0x00, 0x04]) == (scs.COMM_SUCCESS, 0)
    assert ph.read2ByteTxRx(port, 3, GOAL_POSITION)[0] == 3000
    assert ph.action(port, scs.BROADCAST_ID) == scs.COMM_SUCCESS
    assert settle(port, ph, [3], PRESENT_POSITION, [1024]) == [1024]


def test_sync_write_and_sync_read_the_whole_chain(sdk):
    port, ph = sdk
    on = scs.GroupSyncWrite(port, ph, TORQUE_ENABLE, 1)
    goal = scs.GroupSyncWrite(port, ph, GOAL_POSITION, 2)
    targets = {i: 1000 + 300 * i for i in IDS}
    for i in IDS:
        assert on.addParam(i, [1])
        assert goal.addParam(i, [scs.SCS_LOBYTE(targets[i]), scs.SCS_HIBYTE(targets[i])])
    assert on.txPacket() == scs.COMM_SUCCESS
    assert goal.txPacket() == scs.COMM_SUCCESS
    # Each servo's Goal Position is its own entry's.
    assert [ph.read2ByteTxRx(port, i, GOAL_POSITION)[0] for i in IDS] == [targets[i] for i in IDS]
    settle(port, ph, IDS, PRESENT_POSITION, [targets[i] for i in IDS])
    # One SYNC READ of the present block: six status packets, in order.
    read = scs.GroupSyncRead(port, ph, PRESENT_POSITION, PRESENT_BLOCK_LEN)
    for i in IDS:
        assert read.addParam(i)
    assert read.txRxPacket() == scs.COMM_SUCCESS
    for i in IDS:
        assert read.isAvailable(i, PRESENT_POSITION, 2)
        assert read.getData(i, PRESENT_POSITION, 2) == targets[i]
        assert read.getData(i, PRESENT_VOLTAGE, 1) == 74
        assert read.getData(i, PRESENT_POSITION + 2, 2) == 0, "at rest: velocity 0"


def test_an_overload_alarm_reaches_the_error_byte_and_unloads(tmp_path):
    c = Chain(tmp_path, "--fault", "error-bits:at=0:servo=2:bits=overload")
    port = scs.PortHandler(c.link)
    assert port.openPort() and port.setBaudRate(BAUD)
    ph = scs.PacketHandler(0)
    assert ph.write1ByteTxRx(port, 2, TORQUE_ENABLE, 1)[0] == scs.COMM_SUCCESS
    value, result, error = ph.read1ByteTxRx(port, 2, STATUS)
    assert result == scs.COMM_SUCCESS
    assert value & 0x20 and error & 0x20, "overload: Status bit 5 and the answer's ERROR bit 5"
    assert ph.read1ByteTxRx(port, 2, TORQUE_ENABLE)[0] == 0, "the servo unloads"
    assert ph.read1ByteTxRx(port, 1, STATUS) == (0, scs.COMM_SUCCESS, 0), "its neighbour is fine"
    port.closePort()
    summary = c.close()
    assert any(e["id"] == 2 and e["what"] == "unloaded" for e in summary["events"])


# ------------------------------------------------------------------ rustypot


def test_rustypot_drives_the_same_chain(chain):
    c = rustypot.Sts3215PyController(chain.link, BAUD, 0.1)
    for i in IDS:
        assert c.ping(i)
        assert c.read_model_number(i) == [STS3215]
    assert not c.ping(7)
    c.sync_write_torque_enable(IDS, [True] * 6)
    goals = [0.5 * (-1) ** i for i in IDS]
    c.sync_write_goal_position(IDS, goals)
    # rustypot writes radians about the middle: 0.5 rad is 326 steps
    # (within the one step its rounding may take).
    raw = [int.from_bytes(b, "little") for b in c.sync_read_raw_data(IDS, GOAL_POSITION, 2)]
    for r, g in zip(raw, goals):
        assert abs(r - (2048 + g * 4096 / (2 * math.pi))) <= 1, (raw, goals)
    deadline = time.time() + 3
    while True:
        present = c.sync_read_present_position(IDS)
        if all(abs(p - g) < 0.01 for p, g in zip(present, goals)) or time.time() > deadline:
            break
        time.sleep(0.05)
    assert all(abs(p - g) < 0.01 for p, g in zip(present, goals)), (present, goals)
