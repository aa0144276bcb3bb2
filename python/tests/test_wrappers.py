"""The wrappers: MtbfWrapper's info equals a Fatigue counter's, works under
gymnasium.vector; PadaWrapper restricts as Eq. 9 and its governor holds a
budget; the low-pass filter is Eq. 8; bad arguments raise."""

import math

import gymnasium as gym
import numpy as np
import pytest

import pada
from pada.wrappers import LowPassWrapper, MtbfWrapper, PadaWrapper


def test_mtbf_wrapper_info_equals_the_counter():
    env = MtbfWrapper(gym.make("Pendulum-v1"))
    assert env.rate_hz == 20.0
    env.reset(seed=0)
    env.action_space.seed(0)
    f = pada.Fatigue(1, 20.0)
    for _ in range(400):
        a = env.action_space.sample()
        _, _, te, tr, info = env.step(a)
        f.add(np.clip(a, -2, 2))
        assert info["damage"] == f.damage and info["mtbf_s"] == f.mtbf_s
        assert info["robot_mtbf_s"] == f.robot_mtbf_s
        if te or tr:
            ep = info["episode_mtbf"]
            assert ep["steps"] == 200 and ep["robot_mtbf_s"] > 0
            env.reset()
    assert env.report() == f.report()


def test_mtbf_wrapper_adds_to_episode_statistics_and_clips():
    env = MtbfWrapper(gym.wrappers.RecordEpisodeStatistics(gym.make("Pendulum-v1")))
    env.reset(seed=0)
    for k in range(200):
        _, _, te, tr, info = env.step(np.array([5.0 if k % 2 else -5.0], dtype=np.float32))
    assert tr and "mtbf_s" in info["episode"] and info["episode"]["mtbf_s"] == info["episode_mtbf"]["robot_mtbf_s"]
    g = pada.Fatigue(1, 20.0)
    for k in range(200):
        g.add(2.0 if k % 2 else -2.0)
    assert env.fatigue.damage == g.damage


def test_mtbf_wrapper_on_pada_env_counts_commanded_torques():
    env = MtbfWrapper(gym.make("pada/Leo-v0"))
    assert env.fatigue.joints_count == 4 and abs(env.rate_hz - 30.0) < 1e-3
    env.reset(seed=0)
    for k in range(30):
        _, _, _, _, info = env.step(np.array([k % 7, 6 - k % 7, 3]))
    assert len(info["mtbf_s"]) == 4 and info["robot_mtbf_s"] < math.inf


def test_mtbf_wrapper_under_gymnasium_vector():
    venv = gym.vector.SyncVectorEnv([lambda: MtbfWrapper(gym.make("Pendulum-v1")) for _ in range(2)])
    venv.reset(seed=0)
    for _ in range(10):
        _, _, _, _, info = venv.step(venv.action_space.sample())
    assert "robot_mtbf_s" in info and np.asarray(info["robot_mtbf_s"]).shape == (2,)


def test_voltage_map():
    env = MtbfWrapper(gym.make("Pendulum-v1"), torque=pada.wrappers.voltage(0.5))
    env.reset(seed=0)
    env.step(np.array([2.0], dtype=np.float32))
    env.step(np.array([-2.0], dtype=np.float32))
    f = pada.Fatigue(1, 20.0)
    f.add(1.0)
    f.add(-1.0)
    assert env.fatigue.damage == f.damage


def test_pada_wrapper_box_and_discrete():
    env = PadaWrapper(gym.make("Pendulum-v1"), 0.1)
    env.reset(seed=0)
    prev = 0.0
    for a in [2.0, 2.0, -2.0, 0.3]:
        _, _, _, _, info = env.step(np.array([a], dtype=np.float32))
        applied = float(info["pada_action"][0])
        assert abs(applied - prev) <= 0.4 + 1e-6
        prev = applied
    assert prev == pytest.approx(0.3)
    d = PadaWrapper(gym.make("pada/Pendulum-v0"), 0.5)
    d.reset(seed=0)
    _, _, _, _, info = d.step(2)
    assert info["pada_action"] == 2  # one level of 2 from the rest level 1
    m = PadaWrapper(gym.make("pada/Leo-v0"), 1 / 6)
    m.reset(seed=0)
    _, _, _, _, info = m.step(np.array([6, 0, 3]))
    assert info["pada_action"].tolist() == [4, 2, 3]


def random_steps(env, steps):
    """The info of the last of `steps` random actions on `env` (seed 0),
    reset after each episode."""
    env.reset(seed=0)
    env.action_space.seed(0)
    for _ in range(steps):
        _, _, te, tr, info = env.step(env.action_space.sample())
        if te or tr:
            env.reset()
    return info


def test_pada_wrapper_governor_holds_the_budget():
    budget = 3000.0
    env = PadaWrapper(MtbfWrapper(gym.make("Pendulum-v1")), mtbf_budget=budget, torque=None)
    info = random_steps(env, 4000)
    g = info["governor"]
    assert g["moves"] > 0 and g["window_mtbf_s"] >= budget * 0.9
    finfo = random_steps(MtbfWrapper(gym.make("Pendulum-v1")), 4000)
    assert finfo["robot_mtbf_s"] < budget < info["robot_mtbf_s"]


def test_lowpass_is_eq_8():
    env = LowPassWrapper(gym.make("Pendulum-v1"), 0.25)
    env.reset(seed=0)
    u = 0.0
    for a in [2.0, 2.0, -2.0]:
        env.step(np.array([a], dtype=np.float32))
        u = 0.25 * a + 0.75 * u
        assert env._u[0] == pytest.approx(u)
    gov = LowPassWrapper(gym.make("Pendulum-v1"), mtbf_budget=500.0)
    assert gov.alpha == pytest.approx(0.1)


def test_wrapper_arguments_are_checked():
    with pytest.raises(ValueError, match=r"delta = 1.5 is out of range: valid is 0 < delta <= 1"):
        PadaWrapper(gym.make("Pendulum-v1"), 1.5)
    with pytest.raises(ValueError, match=r"delta = 0 is out of range"):
        PadaWrapper(gym.make("Pendulum-v1"), 0)
    with pytest.raises(ValueError, match=r"mtbf_budget = -1(\.0)? is out of range: valid is 0 < mtbf_budget <= 1e10"):
        PadaWrapper(gym.make("Pendulum-v1"), mtbf_budget=-1.0)
    with pytest.raises(ValueError, match=r"rate_hz = 0(\.0)? is out of range: valid is 0 < rate_hz"):
        MtbfWrapper(gym.make("Pendulum-v1"), rate_hz=0.0)
    with pytest.raises(ValueError, match=r"alpha = 2 is out of range"):
        LowPassWrapper(gym.make("Pendulum-v1"), 2)
    with pytest.raises(ValueError, match=r"torque: the action space Discrete"):
        MtbfWrapper(gym.make("CartPole-v1"))
    env = PadaWrapper(gym.make("Pendulum-v1"), 0.5)
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"action = .* is outside the action space: valid is Box"):
        env.step(np.array([3.0], dtype=np.float32))
    g = pada.WearGovernor(100.0, 20.0, joints=1, levels=3, worst_torque=1.5)
    with pytest.raises(ValueError, match=r"(?i)torques = nan is not finite"):
        g.observe(float("nan"))
    with pytest.raises(ValueError, match=r"joints = 5 is out of range: valid is 1 <= joints <= 4"):
        pada.WearGovernor(100.0, 20.0, joints=5, levels=3, worst_torque=1.5)
    with pytest.raises(ValueError, match=r"restricts"):
        pada.WearGovernor(100.0, 20.0, joints=1, levels=3, worst_torque=1.5, restricts="beta")
