"""pada.Fatigue equals `pada mtbf` bit for bit (re-engagements and J in
f64) on three logs, one of them a Gymnasium Pendulum-v1 run."""

import json
import math

import gymnasium as gym
import numpy as np
import pytest

import pada
from conftest import run_pada


def write_log(path, torques, names):
    # float32 values written with float64's shortest repr: `pada mtbf`
    # parses each cell as f32 and recovers the same float32.
    with open(path, "w") as f:
        f.write(",".join(names) + "\n")
        for row in torques:
            f.write(",".join(repr(float(x)) for x in row) + "\n")


def same(a, b):
    """JSON writes inf as null."""
    if b is None:
        return math.isinf(a)
    return a == b


def compare(tmp_path, pada_bin, torques, rate, window=1200):
    torques = np.asarray(torques, dtype=np.float32)
    names = [f"j{i}" for i in range(torques.shape[1])]
    log = tmp_path / "log.csv"
    write_log(log, torques, names)
    out = json.loads(run_pada(pada_bin, "mtbf", "--torques", str(log), "--rate", str(rate), "--window", str(window), "--json"))
    f = pada.Fatigue(torques.shape[1], rate, window=window)
    f.add_many(torques)
    r = f.report()
    g = pada.Fatigue(torques.shape[1], rate, window=window)
    for row in torques:
        g.add(row)
    assert g.report() == r
    assert out["steps"] == r["steps"] == len(torques)
    for j, joint in enumerate(out["joints"]):
        rep = joint["report"]
        assert rep["reengagements"] == r["reengagements"][j]
        assert rep["damage"] == r["damage"][j], (rep["damage"], r["damage"][j])
        assert same(r["mtbf_s"][j], rep["mtbf_s"])
        w = rep["window"]
        assert w["reengagements"] == r["window_reengagements"][j]
        assert w["damage"] == r["window_damage"][j]
        assert same(r["window_mtbf_s"][j], w["mtbf_s"])
    assert same(r["robot_mtbf_s"], out["robot_mtbf_s"])
    assert same(r["robot_window_mtbf_s"], out["robot_window_mtbf_s"])
    return r


def test_random_bang_bang_log_equals_pada_mtbf(tmp_path, pada_bin):
    rng = np.random.default_rng(1)
    t = rng.choice([-1.5, 0.0, 1.5], size=(3000, 1))
    r = compare(tmp_path, pada_bin, t, 20.0)
    assert r["reengagements"][0] > 100


def test_three_joint_noisy_log_equals_pada_mtbf(tmp_path, pada_bin):
    rng = np.random.default_rng(7)
    t = np.cumsum(rng.normal(0, 0.4, size=(2500, 3)), axis=0) % 3.6 - 1.8
    r = compare(tmp_path, pada_bin, t, 30.0, window=500)
    assert min(r["reengagements"]) > 10


def test_gymnasium_pendulum_v1_run_equals_pada_mtbf(tmp_path, pada_bin):
    env = gym.make("Pendulum-v1")
    env.reset(seed=3)
    env.action_space.seed(3)
    torques = []
    for _ in range(1500):
        a = env.action_space.sample()
        torques.append(np.clip(a, -2.0, 2.0))
        _, _, te, tr, _ = env.step(a)
        if te or tr:
            env.reset()
    r = compare(tmp_path, pada_bin, np.array(torques), 20.0)
    assert r["reengagements"][0] > 100


def test_voltage_input_is_scaled():
    f = pada.Fatigue(1, 30.0, torque_per_volt=pada.RX28_TORQUE_PER_VOLT)
    g = pada.Fatigue(1, 30.0)
    for u in [10.7, -10.7] * 50:
        f.add(u)
        g.add(u * pada.RX28_TORQUE_PER_VOLT)
    assert f.report()["reengagements"] == g.report()["reengagements"]
    assert f.damage[0] == pytest.approx(g.damage[0], rel=1e-6)


def test_bad_input_names_the_argument_and_range():
    with pytest.raises(ValueError, match=r"rate_hz = 0(\.0)? is out of range: valid is 0 < rate_hz"):
        pada.Fatigue(1, 0.0)
    with pytest.raises(ValueError, match=r"rate_hz = -5"):
        pada.Fatigue(1, -5.0)
    with pytest.raises(ValueError, match=r"joints = 0 is out of range: valid is 1 <= joints <= 64"):
        pada.Fatigue(0, 20.0)
    with pytest.raises(ValueError, match=r"torque_per_volt"):
        pada.Fatigue(1, 20.0, torque_per_volt=-1.0)
    f = pada.Fatigue(2, 20.0)
    with pytest.raises(ValueError, match=r"(?i)torques\[1\] = nan is not finite"):
        f.add([0.5, float("nan")])
    with pytest.raises(ValueError, match=r"torques has 3 values, expected 2"):
        f.add([0.5, 1.0, 2.0])
    with pytest.raises(ValueError, match=r"torques has shape \(4, 3\): valid is \(steps, 2\)"):
        f.add_many(np.zeros((4, 3)))
    with pytest.raises(ValueError, match=r"(?i)torques\[2, 0\] = nan"):
        f.add_many(np.array([[0, 0], [1, 1], [np.nan, 0]]))
    assert f.steps == 0, "a refused input counts nothing"


TABLE_I = {
    "theta_bl_rad": 0.01, "k_nm_per_rad": 106.0, "d": -0.262, "sigma_f_mpa": 4402.0,
    "b_mm": 4.0, "m_n_mm": 0.4, "d_w_mm": 18.5, "y_fa": 2.15, "y_sa": 2.0,
    "y_epsilon": 1.22, "y_beta": 1.0, "teeth": 45,
}


def test_default_gearbox_is_table_i():
    f = pada.Fatigue(2, 20.0)
    assert f.gearbox == ["RX-28", "RX-28"]
    assert f.gearbox_estimate == [False, False]
    g = pada.Fatigue(2, 20.0, gearbox="rx-28")
    h = pada.Fatigue(2, 20.0, gearbox=dict(TABLE_I))
    for row in [[1.5, -0.3], [-1.5, 0.3]] * 40:
        f.add(row)
        g.add(row)
        h.add(row)
    assert f.damage == g.damage == h.damage
    assert f.report()["gearbox"] == ["RX-28", "RX-28"]


def test_named_gearbox_equals_pada_mtbf_gearbox(tmp_path, pada_bin):
    rng = np.random.default_rng(5)
    torques = rng.choice([-1.2, 0.0, 1.2], size=(800, 2)).astype(np.float32)
    log = tmp_path / "log.csv"
    write_log(log, torques, ["a", "b"])
    out = json.loads(run_pada(pada_bin, "mtbf", "--torques", str(log), "--rate", "20",
                              "--gearbox", "XM430-W350,XL330-M288", "--json"))
    f = pada.Fatigue(2, 20.0, gearbox=["xm430-w350", "XL330-M288"])
    f.add_many(torques)
    r = f.report()
    assert r["gearbox"] == ["XM430-W350", "XL330-M288"]
    assert r["gearbox_estimate"] == [True, True]
    for j, joint in enumerate(out["joints"]):
        assert joint["gearbox"]["name"] == r["gearbox"][j]
        assert joint["gearbox"]["estimate"] is True
        assert joint["report"]["damage"] == r["damage"][j]
        assert joint["report"]["reengagements"] == r["reengagements"][j]
    # A different gearbox gives a different damage for the same torques.
    t = pada.Fatigue(2, 20.0)
    t.add_many(torques)
    assert t.damage[0] != r["damage"][0]


def test_gearbox_file_and_dict_agree(tmp_path, pada_bin):
    fields = dict(TABLE_I, b_mm=3.0)
    toml = "\n".join(f"{k} = {v!r}" for k, v in fields.items()) + "\n"
    path = tmp_path / "mine.toml"
    path.write_text(toml)
    torques = np.array([[1.5], [-1.5]] * 30, dtype=np.float32)
    log = tmp_path / "log.csv"
    write_log(log, torques, ["a"])
    out = json.loads(run_pada(pada_bin, "mtbf", "--torques", str(log), "--gearbox", str(path), "--json"))
    f = pada.Fatigue(1, 20.0, gearbox=str(path))
    g = pada.Fatigue(1, 20.0, gearbox=fields)
    f.add_many(torques)
    g.add_many(torques)
    assert f.damage == g.damage
    assert out["joints"][0]["report"]["damage"] == f.damage[0]


def test_bad_gearbox_names_the_problem():
    with pytest.raises(ValueError, match=r"gearbox: unknown gearbox \"XM999\": valid are RX-28, MX-28, XM430-W350, XL430-W250, XL330-M288"):
        pada.Fatigue(1, 20.0, gearbox="XM999")
    with pytest.raises(ValueError, match=r"gearbox: invalid b_mm = -1: valid is 0 < b_mm < inf \(mm\)"):
        pada.Fatigue(1, 20.0, gearbox=dict(TABLE_I, b_mm=-1.0))
    with pytest.raises(ValueError, match=r"gearbox: missing field `teeth`"):
        pada.Fatigue(1, 20.0, gearbox={k: v for k, v in TABLE_I.items() if k != "teeth"})
    with pytest.raises(ValueError, match=r"gearbox: 2 gearboxes for 3 joints"):
        pada.Fatigue(3, 20.0, gearbox=["RX-28", "MX-28"])
    with pytest.raises(ValueError, match=r"gearbox: int is not a gearbox"):
        pada.Fatigue(1, 20.0, gearbox=3)
