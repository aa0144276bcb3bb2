"""pada's environments: check_env passes, the trajectory is pada run's
environment's, bad actions raise, LeoVector matches single environments."""

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import pada
from pada import _pada

IDS = {"pada/Pendulum-v0": "pendulum", "pada/PhysicalPendulum-v0": "physical-pendulum", "pada/Leo-v0": "leo"}


@pytest.mark.parametrize("env_id", list(IDS))
def test_check_env_passes(env_id):
    check_env(gym.make(env_id).unwrapped, skip_render_check=True)


def test_check_env_passes_continuous_leo():
    check_env(gym.make("pada/Leo-v0", continuous=True).unwrapped, skip_render_check=True)


@pytest.mark.parametrize("env_id", list(IDS))
def test_1000_steps_equal_pada_runs_environment(env_id):
    env = gym.make(env_id)
    space = env.action_space
    space.seed(5)
    actions = [space.sample() for _ in range(1000)]
    flat = [[float(x) for x in np.atleast_1d(a)] for a in actions]
    ref = _pada.reference_rollout(IDS[env_id], flat, False, 11)
    obs, _ = env.reset(seed=11)
    ends = 0
    for k, (a, (r_obs, r_rew, r_term, r_trunc)) in enumerate(zip(actions, ref)):
        obs, rew, term, trunc, _ = env.step(a)
        assert obs.tolist() == np.array(r_obs, dtype=np.float32).tolist(), f"step {k}"
        assert (rew, term, trunc) == (r_rew, r_term, r_trunc), f"step {k}"
        if term or trunc:
            ends += 1
            obs, _ = env.reset()
    assert ends >= 1 or env_id == "pada/Leo-v0"


def test_same_seed_same_trajectory():
    runs = []
    for _ in range(2):
        env = gym.make("pada/Leo-v0")
        env.reset(seed=3)
        env.action_space.seed(3)
        runs.append([env.step(env.action_space.sample())[0].tolist() for _ in range(50)])
    assert runs[0] == runs[1]


def test_time_limit_and_step_size_are_pada_runs():
    env = gym.make("pada/Pendulum-v0")
    assert env.unwrapped.dt == 0.05
    env.reset(seed=0)
    for k in range(1, 61):
        _, _, term, trunc, _ = env.step(1)
        assert not term
        assert trunc == (k == 60)


def test_bad_actions_raise():
    env = gym.make("pada/Pendulum-v0").unwrapped
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"action\[0\] = 3 is out of range: valid is 0 <= action\[0\] < 3"):
        env.step(3)
    with pytest.raises(ValueError, match=r"not a level index"):
        env.step(1.5)
    leo = gym.make("pada/Leo-v0", continuous=True).unwrapped
    leo.reset(seed=0)
    with pytest.raises(ValueError, match=r"action\[1\] = 20(\.0)? is out of range: valid is -10.7 <= action\[1\] <= 10.7"):
        leo.step(np.array([0.0, 20.0, 0.0], dtype=np.float32))
    with pytest.raises(ValueError, match=r"(?i)action\[0\] = nan"):
        leo.step(np.array([np.nan, 0.0, 0.0], dtype=np.float32))
    with pytest.raises(ValueError, match=r"action has 2 values, expected 3"):
        leo.step(np.zeros(2, dtype=np.float32))
    with pytest.raises(ValueError, match=r'robot = "cartpole" is not valid: valid is "pendulum"'):
        _pada.PlantEnv("cartpole", False)


def test_leo_vector_equals_single_envs():
    vec = pada.envs.LeoVector(2)
    obs, _ = vec.reset(seed=0)
    singles = [gym.make("pada/Leo-v0") for _ in range(2)]
    for s in singles:
        s.reset(seed=0)
    rng = np.random.default_rng(0)
    for k in range(120):
        a = rng.integers(0, 7, size=(2, 3))
        obs, rew, term, trunc, info = vec.step(a)
        for i, s in enumerate(singles):
            o, r, te, tr, inf = s.step(a[i])
            if te or tr:
                assert info["_final_obs"][i]
                assert info["final_obs"][i].tolist() == o.tolist()
                o, _ = s.reset()
            assert obs[i].tolist() == o.tolist(), (k, i)
            assert rew[i] == r and term[i] == te and trunc[i] == tr
            assert info["commanded_torques"][i].tolist() == inf["commanded_torques"]
    with pytest.raises(ValueError, match=r"actions has shape \(3, 3\)"):
        vec.step(np.zeros((3, 3)))
    with pytest.raises(ValueError, match=r"action\[0\] = 9 is out of range"):
        vec.step(np.full((2, 3), 9))
    with pytest.raises(ValueError, match=r"n = 0 is out of range: valid is 1 <= n <= 1024"):
        pada.envs.LeoVector(0)
