"""`pada servos` driven by the official ROBOTIS SDK (`dynamixel-sdk` from
PyPI, 4.x): every instruction the SDK sends, on both protocols, answered as
the e-Manual specifies (docs/reference/dynamixel.md; its § 6.1 lists
where the SDK and the e-Manual disagree and which pada follows).

The SDK is not pada's code and was not written from it: it opens the
virtual servos' pseudo-terminal through pyserial as it opens a U2D2.
Protocol 2.0: the example arm of files (examples/robots/arm2: an
XM430-W350 at ID 1, an XL430-W250 at ID 2). Protocol 1.0: LEO's seven
RX-28s (IDs 1-7) with the sensor device at ID 100.
"""


import dynamixel_sdk as dxl
import pytest

from conftest import REPO, start_servos, stop_servos

BAUD = 1_000_000
ARM = str(REPO / "examples" / "robots" / "arm2" / "robot.toml")
ARM_MODELS = {1: 1020, 2: 1060}  # XM430-W350, XL430-W250
X_IDS = list(ARM_MODELS)
IDS = list(range(1, 8))  # LEO's RX-28s
XM430 = 1020
RX28 = 28
# X series (docs/reference/dynamixel.md § 5).
LED, GOAL_PWM, PWM_LIMIT, OPERATING_MODE, TORQUE = 65, 100, 36, 11, 64
PRESENT_POSITION, PRESENT_VOLTAGE, HW_ERROR, REGISTERED = 132, 144, 70, 69
# RX-28 (docs/reference/rx28.md).
RX_ID, RX_LED, RX_MOVING_SPEED, RX_PRESENT_POSITION, RX_PRESENT_VOLTAGE = 3, 25, 32, 36, 42


class Servos:
    """`pada servos` on a pseudo-terminal, and the SDK's port on it."""

    def __init__(self, tmp_path, protocol, *extra):
        self.link = str(tmp_path / f"dxl{protocol}")
        robot = ARM if protocol == 2 else "leo"
        self.proc = start_servos(self.link, "--robot", robot, "--baud", str(BAUD), *extra)
        self.port = dxl.PortHandler(self.link)
        assert self.port.openPort()
        assert self.port.setBaudRate(BAUD)
        self.ph = dxl.PacketHandler(float(protocol))

    def close(self):
        self.port.closePort()
        return stop_servos(self.proc)


@pytest.fixture
def x_servos(tmp_path):
    s = Servos(tmp_path, 2)
    yield s
    s.close()


@pytest.fixture
def rx_servos(tmp_path):
    s = Servos(tmp_path, 1)
    yield s
    s.close()


# ---------------------------------------------------------------- Protocol 2.0


def test_ping_returns_each_model_number(x_servos):
    s = x_servos
    for i, number in ARM_MODELS.items():
        model, result, error = s.ph.ping(s.port, i)
        assert (result, error, model) == (dxl.COMM_SUCCESS, 0, number)
    model, result, _ = s.ph.ping(s.port, 42)
    assert result == dxl.COMM_RX_TIMEOUT, "nobody at ID 42"
    found, result = s.ph.broadcastPing(s.port)
    assert result == dxl.COMM_SUCCESS
    # Every servo, each with its model and firmware; nothing else.
    assert {i: tuple(found[i]) for i in found} == {i: (m, 46) for i, m in ARM_MODELS.items()}


def test_read_and_write_round_trip(x_servos):
    s = x_servos
    assert s.ph.write1ByteTxRx(s.port, 2, LED, 1) == (dxl.COMM_SUCCESS, 0)
    value, result, error = s.ph.read1ByteTxRx(s.port, 2, LED)
    assert (value, result, error) == (1, dxl.COMM_SUCCESS, 0)
    # Two and four bytes: PWM Limit (EEPROM, torque off), Homing Offset.
    result, error = s.ph.write2ByteTxRx(s.port, 2, PWM_LIMIT, 700)
    assert (result, error) == (dxl.COMM_SUCCESS, 0)
    assert s.ph.read2ByteTxRx(s.port, 2, PWM_LIMIT) == (700, dxl.COMM_SUCCESS, 0)
    result, error = s.ph.write4ByteTxRx(s.port, 2, 20, 4096)
    assert (result, error) == (dxl.COMM_SUCCESS, 0)
    assert s.ph.read4ByteTxRx(s.port, 2, 20) == (4096, dxl.COMM_SUCCESS, 0)
    # The supply the robot's definition names (the arm's 12 V), in 0.1 V.
    assert s.ph.read2ByteTxRx(s.port, 2, PRESENT_VOLTAGE) == (120, dxl.COMM_SUCCESS, 0)
    # A write to the broadcast ID: done everywhere, no answer.
    s.ph.write1ByteTxOnly(s.port, dxl.BROADCAST_ID, LED, 0)
    assert [s.ph.read1ByteTxRx(s.port, i, LED)[0] for i in X_IDS] == [0, 0]


def test_out_of_range_writes_get_the_e_manuals_error_numbers(x_servos):
    s = x_servos
    # Data Range Error (0x04): Goal PWM beyond its range ±885.
    assert s.ph.write2ByteTxRx(s.port, 1, GOAL_PWM, 886) == (dxl.COMM_SUCCESS, 0x04)
    # Data Limit Error (0x06): within its range, beyond PWM Limit.
    assert s.ph.write2ByteTxRx(s.port, 1, PWM_LIMIT, 500) == (dxl.COMM_SUCCESS, 0)
    assert s.ph.write2ByteTxRx(s.port, 1, GOAL_PWM, 600) == (dxl.COMM_SUCCESS, 0x06)
    # Data Length Error (0x05): one byte of a two-byte item.
    assert s.ph.write1ByteTxRx(s.port, 1, GOAL_PWM, 1) == (dxl.COMM_SUCCESS, 0x05)
    # Access Error (0x07): a read-only item, and EEPROM with torque on.
    assert s.ph.write4ByteTxRx(s.port, 1, PRESENT_POSITION, 0) == (dxl.COMM_SUCCESS, 0x07)
    assert s.ph.write1ByteTxRx(s.port, 1, TORQUE, 1) == (dxl.COMM_SUCCESS, 0)
    assert s.ph.write1ByteTxRx(s.port, 1, OPERATING_MODE, 16) == (dxl.COMM_SUCCESS, 0x07)
    assert s.ph.write1ByteTxRx(s.port, 1, TORQUE, 0) == (dxl.COMM_SUCCESS, 0)
    assert s.ph.write1ByteTxRx(s.port, 1, OPERATING_MODE, 16) == (dxl.COMM_SUCCESS, 0)
    # Nothing was written by a refused write.
    assert s.ph.read2ByteTxRx(s.port, 1, GOAL_PWM) == (0, dxl.COMM_SUCCESS, 0)
    # A read past the table: Access Error, no data.
    _, result, error = s.ph.read1ByteTxRx(s.port, 1, 700)
    assert (result, error) == (dxl.COMM_SUCCESS, 0x07)


def test_sync_write_and_sync_reads(x_servos):
    s = x_servos
    write = dxl.GroupSyncWrite(s.port, s.ph, PWM_LIMIT, 2)
    for i in X_IDS:
        assert write.addParam(i, [(600 + i) & 0xFF, (600 + i) >> 8])
    assert write.txPacket() == dxl.COMM_SUCCESS
    read = dxl.GroupSyncRead(s.port, s.ph, PWM_LIMIT, 2)
    for i in X_IDS:
        assert read.addParam(i)
    assert read.txRxPacket() == dxl.COMM_SUCCESS
    assert [read.getData(i, PWM_LIMIT, 2) for i in X_IDS] == [600 + i for i in X_IDS]
    # Fast Sync Read: one combined reply of every servo's block.
    fast = dxl.GroupSyncRead(s.port, s.ph, PRESENT_VOLTAGE, 2)
    for i in X_IDS:
        assert fast.addParam(i)
    assert fast.fastSyncRead() == dxl.COMM_SUCCESS
    assert [fast.getData(i, PRESENT_VOLTAGE, 2) for i in X_IDS] == [120] * 2


def test_bulk_read_and_bulk_write(x_servos):
    s = x_servos
    write = dxl.GroupBulkWrite(s.port, s.ph)
    for i in X_IDS:
        if i % 2:
            assert write.addParam(i, LED, 1, [1])
        else:
            assert write.addParam(i, PWM_LIMIT, 2, [100 + i, 0])
    assert write.txPacket() == dxl.COMM_SUCCESS
    # Read back by Bulk Read, then by Fast Bulk Read of the same.
    for send in (dxl.GroupBulkRead.txRxPacket, dxl.GroupBulkRead.fastBulkRead):
        read = dxl.GroupBulkRead(s.port, s.ph)
        for i in X_IDS:
            assert read.addParam(i, LED, 1) if i % 2 else read.addParam(i, PWM_LIMIT, 2)
        assert send(read) == dxl.COMM_SUCCESS
        got = [read.getData(i, LED, 1) if i % 2 else read.getData(i, PWM_LIMIT, 2) for i in X_IDS]
        assert got == [1 if i % 2 else 100 + i for i in X_IDS], send.__name__


def test_reg_write_action_reboot_clear_and_factory_reset(x_servos):
    s = x_servos
    result, error = s.ph.regWriteTxRx(s.port, 2, LED, 1, [1])
    assert (result, error) == (dxl.COMM_SUCCESS, 0)
    assert s.ph.read1ByteTxRx(s.port, 2, REGISTERED) == (1, dxl.COMM_SUCCESS, 0)
    assert s.ph.read1ByteTxRx(s.port, 2, LED)[0] == 0, "held until ACTION"
    assert s.ph.action(s.port, dxl.BROADCAST_ID) == dxl.COMM_SUCCESS
    assert s.ph.read1ByteTxRx(s.port, 2, LED)[0] == 1
    # Clear Multi-Turn: the joint stands still, so it succeeds.
    assert s.ph.clearMultiTurn(s.port, 2) == (dxl.COMM_SUCCESS, 0)
    # Reboot: RAM back to its initial values (the LED off), EEPROM kept.
    assert s.ph.write2ByteTxRx(s.port, 2, PWM_LIMIT, 321) == (dxl.COMM_SUCCESS, 0)
    assert s.ph.reboot(s.port, 2) == (dxl.COMM_SUCCESS, 0)
    assert s.ph.read1ByteTxRx(s.port, 2, LED)[0] == 0
    assert s.ph.read2ByteTxRx(s.port, 2, PWM_LIMIT)[0] == 321
    # Factory reset keeping ID and baud rate: the EEPROM's initial values.
    assert s.ph.factoryReset(s.port, 2, 0x02) == (dxl.COMM_SUCCESS, 0)
    assert s.ph.read2ByteTxRx(s.port, 2, PWM_LIMIT)[0] == 885
    assert s.ph.ping(s.port, 2)[:2] == (ARM_MODELS[2], dxl.COMM_SUCCESS)


def test_a_hardware_alert_sets_bit_7_until_a_reboot(tmp_path):
    s = Servos(tmp_path, 2, "--fault", "error-bits:at=0:servo=1:bits=overload")
    try:
        model, result, error = s.ph.ping(s.port, 1)
        assert (model, result) == (XM430, dxl.COMM_SUCCESS)
        assert error & 0x80, "the Alert bit"
        assert s.ph.read1ByteTxRx(s.port, 1, HW_ERROR)[0] == 0x20, "overload"
        # Torque stays off after the shutdown, until a reboot.
        assert s.ph.write1ByteTxRx(s.port, 1, TORQUE, 1)[1] & 0x7F == 0x01
        assert s.ph.reboot(s.port, 1)[0] == dxl.COMM_SUCCESS
        assert s.ph.ping(s.port, 1)[2] == 0
    finally:
        summary = s.close()
    assert any(e["what"] == "alert" and e["id"] == 1 for e in summary["events"])


def test_a_client_at_another_baud_rate_gets_no_answer(tmp_path):
    s = Servos(tmp_path, 2)
    try:
        assert s.port.setBaudRate(57600)
        assert s.ph.ping(s.port, 1)[1] == dxl.COMM_RX_TIMEOUT
        assert s.port.setBaudRate(BAUD)
        assert s.ph.ping(s.port, 1)[1] == dxl.COMM_SUCCESS
    finally:
        summary = s.close()
    assert summary["wrong_rates"] == [57600] and summary["wrong_rate_bytes"] > 0


# ---------------------------------------------------------------- Protocol 1.0


def test_rx28_ping_read_write_sync_write_and_bulk_read(rx_servos):
    s = rx_servos
    for i in IDS:
        model, result, error = s.ph.ping(s.port, i)
        assert (model, result, error) == (RX28, dxl.COMM_SUCCESS, 0)
    assert s.ph.write1ByteTxRx(s.port, 5, RX_LED, 1) == (dxl.COMM_SUCCESS, 0)
    assert s.ph.read1ByteTxRx(s.port, 5, RX_LED) == (1, dxl.COMM_SUCCESS, 0)
    assert s.ph.read1ByteTxRx(s.port, 5, RX_PRESENT_VOLTAGE) == (140, dxl.COMM_SUCCESS, 0)
    write = dxl.GroupSyncWrite(s.port, s.ph, RX_MOVING_SPEED, 2)
    for i in IDS:
        assert write.addParam(i, [i, 0])
    assert write.txPacket() == dxl.COMM_SUCCESS
    read = dxl.GroupBulkRead(s.port, s.ph)
    for i in IDS:
        assert read.addParam(i, RX_MOVING_SPEED, 2)
    # dynamixel-sdk 4.1.0's GroupBulkRead.txPacket passes Protocol 1.0's
    # bulkReadTx a fourth argument it does not take (a TypeError in the
    # SDK, before anything is sent; docs/reference/dynamixel.md): the
    # packet handler's own BULK_READ, then the group's receive.
    read.makeParam()
    assert s.ph.bulkReadTx(s.port, read.param, len(IDS) * 3) == dxl.COMM_SUCCESS
    assert read.rxPacket() == dxl.COMM_SUCCESS
    assert [read.getData(i, RX_MOVING_SPEED, 2) for i in IDS] == IDS
    # Reg Write and Action.
    assert s.ph.regWriteTxRx(s.port, 6, RX_LED, 1, [1]) == (dxl.COMM_SUCCESS, 0)
    assert s.ph.read1ByteTxRx(s.port, 6, RX_LED)[0] == 0
    assert s.ph.action(s.port, dxl.BROADCAST_ID) == dxl.COMM_SUCCESS
    assert s.ph.read1ByteTxRx(s.port, 6, RX_LED)[0] == 1


def test_rx28_out_of_range_write_is_a_range_error(rx_servos):
    s = rx_servos
    # Range Error, bit 3 (0x08): ID 254 (0-253), Moving Speed 2048 (0-2047).
    assert s.ph.write1ByteTxRx(s.port, 2, RX_ID, 254) == (dxl.COMM_SUCCESS, 0x08)
    assert s.ph.write2ByteTxRx(s.port, 2, RX_MOVING_SPEED, 2048) == (dxl.COMM_SUCCESS, 0x08)
    # A read-only item, and a read past the table.
    assert s.ph.write2ByteTxRx(s.port, 2, RX_PRESENT_POSITION, 0) == (dxl.COMM_SUCCESS, 0x08)
    assert s.ph.read1ByteTxRx(s.port, 2, 60)[1:] == (dxl.COMM_SUCCESS, 0x08)
    # Nothing written.
    assert s.ph.ping(s.port, 2)[1] == dxl.COMM_SUCCESS
    assert s.ph.read2ByteTxRx(s.port, 2, RX_MOVING_SPEED)[0] == 0
    # Factory reset: the RX-28 comes back at ID 1, 57,142 bps: deaf here.
    assert s.ph.factoryReset(s.port, 7) == (dxl.COMM_SUCCESS, 0)
    assert s.ph.ping(s.port, 7)[1] == dxl.COMM_RX_TIMEOUT
