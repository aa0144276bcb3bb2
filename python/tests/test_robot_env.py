"""A robot of files as a Gymnasium environment (``pada/Robot-v0``): it
passes Gymnasium's checker, and it is the environment ``pada run --robot``
learns in — every reward and observation of a recorded ``pada run`` trial
comes out again when its actions are replayed."""

import shutil

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import pada
import pada.envs  # noqa: F401  (registers the environments)

from conftest import REPO, run_pada

ARM2 = REPO / "examples" / "robots" / "arm2" / "robot.toml"


def test_check_env_passes_on_arm2():
    env = gym.make("pada/Robot-v0", robot=str(ARM2))
    # arm2: two joints of five voltage levels, observing both angles.
    assert env.action_space == gym.spaces.MultiDiscrete([5, 5])
    assert env.observation_space.shape == (2,)
    assert env.unwrapped.dt == pytest.approx(0.03)
    check_env(env.unwrapped, skip_render_check=True)


def test_check_env_passes_on_arm2_continuous():
    env = gym.make("pada/Robot-v0", robot=ARM2, continuous=True)
    assert env.action_space.low.tolist() == [-2.0, -2.0]
    check_env(env.unwrapped, skip_render_check=True)


def test_replayed_actions_give_pada_runs_rewards(pada_bin, tmp_path):
    """`pada run --robot` records trial 0 (PADA, learning and test
    episodes); the environment, driven through the same levels, gives every
    reward and observation bit for bit, and ends the same episodes."""
    telemetry = tmp_path / "arm2.bin"
    run_pada(pada_bin, "run", "--robot", str(ARM2), "--algo", "pada", "--delta", "1", "--trials", "1",
             "--seconds", "30", "--seed", "3", "--telemetry", str(telemetry), "--out", str(tmp_path / "run"))
    steps = pada.read_telemetry(telemetry)["steps"]
    env = gym.make("pada/Robot-v0", robot=ARM2)
    levels = env.unwrapped.levels
    compared = ends = 0
    action = None
    for k, kind in enumerate(steps["kind"]):
        recorded = np.asarray(steps["state"][k], dtype=np.float32).tolist()
        if kind == "start":
            obs, _ = env.reset(seed=k)
            assert obs.tolist() == recorded, f"row {k}: the start pose"
        else:
            # A step row holds the reward and state of the action chosen on
            # the row before it.
            obs, reward, terminated, truncated, _ = env.step(action)
            assert np.float32(reward) == np.float32(steps["reward"][k]), f"row {k}: reward"
            assert obs.tolist() == recorded, f"row {k}: observation"
            assert (terminated or truncated) == (kind != "step"), f"row {k}: {kind}"
            compared += 1
            ends += terminated or truncated
        output = steps["output"][k]
        if kind != "timeout":
            # The voltage of each joint, as its level's index.
            action = [int(np.flatnonzero(lv == np.float32(v))[0]) for lv, v in zip(levels, output)]
    assert compared == 1400 and ends == 7, (compared, ends)


def test_a_soft_limit_ends_the_episode_and_names_the_joint(tmp_path):
    """arm2 with a shoulder soft limit at ±0.3 rad and no end before it:
    driving the shoulder at +2 V reaches it, the episode terminates, and
    info names the fault, where `pada run --robot` would stop the trial."""
    shutil.copy(ARM2.parent / "arm2.urdf", tmp_path / "arm2.urdf")
    text = ARM2.read_text().replace(
        'urdf = "shoulder"\nservo = "XM430-W350"\nid = 1\n',
        'urdf = "shoulder"\nservo = "XM430-W350"\nid = 1\nsoft_limit_rad = [-0.3, 0.3]\n',
    )
    assert "soft_limit_rad" in text
    robot = tmp_path / "robot.toml"
    robot.write_text(text)
    env = gym.make("pada/Robot-v0", robot=robot)
    env.reset(seed=0)
    for k in range(200):
        obs, _, terminated, truncated, info = env.step([4, 2])
        if terminated:
            break
    assert terminated and not truncated, "the shoulder never reached its soft limit"
    assert info["fault"] == "soft-limit: joint shoulder (servo id 1)", info
    assert abs(obs[0]) >= 0.29, obs


@pytest.mark.parametrize(
    "robot, words",
    [
        ("no/such/robot.toml", ["no/such/robot.toml", "cannot read"]),
        (3, ["valid is the path of a robot.toml"]),
    ],
)
def test_a_robot_that_does_not_load_raises_one_clear_error(robot, words):
    with pytest.raises(ValueError) as e:
        gym.make("pada/Robot-v0", robot=robot)
    for w in words:
        assert w in str(e.value), str(e.value)
