"""pada's simulated robots as Gymnasium environments, stepped by the same
Rust code as ``pada run`` (same dynamics, reward, terminations, time step
and time limit):

- ``pada/Pendulum-v0`` — the simulated inverted pendulum of Section VII
  (2 kg at 0.2 m, ±1.5 N m in three torques, 20 Hz, 3 s episodes);
- ``pada/PhysicalPendulum-v0`` — the model of the paper's physical pendulum
  (voltages, 33 Hz);
- ``pada/Leo-v0`` — the rapier3d LEO of Section VIII: 7 voltage levels in
  [−10.7, 10.7] V on the three learned joints (``MultiDiscrete([7, 7, 7])``),
  or continuous voltages with ``continuous=True``; 30 Hz, 25 s episodes;
- ``pada/Robot-v0`` — a robot of your own, from its ``robot.toml`` and URDF:
  ``gym.make("pada/Robot-v0", robot="path/robot.toml")``. Its observation,
  voltage levels, reward, ends, period, episode length and gearboxes are the
  file's, stepped by the same Rust as ``pada run --robot`` (docs/python.md).

Every environment takes level indices (``Discrete``/``MultiDiscrete``), or
with ``continuous=True`` the motor's commands (``Box`` over its range).
``info`` holds ``commanded_torques`` (the paper's gear torque per gearbox,
from the command: ``pada run``'s ``mtbf_s``) and ``gearbox_torques`` (the
simulation's: ``physical_mtbf_s``); LEO adds ``walked_distance_m``. The
starts are the fixed poses ``pada run`` uses, so a seed changes nothing in
the dynamics; ``reset(seed=…)`` seeds ``np_random`` as Gymnasium does.

``LeoVector(n)`` steps n LEOs in parallel threads with the GIL released.
"""

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from . import _pada

__all__ = ["PendulumEnv", "PhysicalPendulumEnv", "LeoEnv", "RobotEnv", "LeoVector"]


class _PadaEnv(gym.Env):
    _robot = None
    metadata = {"render_modes": []}
    _pada_env = True

    def __init__(self, continuous=False, render_mode=None):
        self._init(self._robot, continuous, render_mode)

    def _init(self, robot, continuous, render_mode):
        if render_mode is not None:
            raise ValueError(f"render_mode = {render_mode!r}: valid is None (pada's environments do not render; use `pada render`)")
        if not isinstance(continuous, bool):
            raise ValueError(f"continuous = {continuous!r}: valid is True or False")
        self._core = _pada.PlantEnv(robot, continuous)
        spec = self._core.spec()
        self.spec_dict = spec
        self.continuous = continuous
        self.dt = spec["control_period_s"]
        self.metadata = {"render_modes": [], "render_fps": 1.0 / self.dt}
        self.levels = [np.asarray(v, dtype=np.float32) for v in spec["levels"]]
        n_obs = len(spec["state_low"])
        low = np.full(n_obs, -np.inf, dtype=np.float32)
        high = np.full(n_obs, np.inf, dtype=np.float32)
        self.observation_space = spaces.Box(low, high, dtype=np.float32)
        if continuous:
            self.action_space = spaces.Box(
                np.array([v[0] for v in self.levels], dtype=np.float32),
                np.array([v[-1] for v in self.levels], dtype=np.float32),
                dtype=np.float32,
            )
            self.rest_action = None
        elif len(self.levels) == 1:
            self.action_space = spaces.Discrete(len(self.levels[0]))
            self.rest_action = int(np.argmin(np.abs(self.levels[0])))
        else:
            self.action_space = spaces.MultiDiscrete([len(v) for v in self.levels])
            self.rest_action = np.array([int(np.argmin(np.abs(v))) for v in self.levels], dtype=np.int64)
        self._step = self._core.step

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        obs = self._core.reset(int(self.np_random.integers(0, 2**63 - 1)))
        return np.array(obs, dtype=np.float32), {}

    def step(self, action):
        if not self.continuous and isinstance(self.action_space, spaces.Discrete):
            if isinstance(action, np.ndarray):
                if action.shape not in ((), (1,)):
                    raise ValueError(f"action has shape {action.shape}: valid is one level index 0 <= action < {self.action_space.n}")
                action = action.reshape(-1)[0]
            if isinstance(action, (float, np.floating)) and float(action) != int(action):
                raise ValueError(f"action = {action} is not a level index: valid is an integer 0 <= action < {self.action_space.n}")
            action = int(action)
        obs, reward, terminated, truncated = self._step(action)
        info = {
            "commanded_torques": self._core.commanded_torques(),
            "gearbox_torques": self._core.gearbox_torques(),
        }
        walked = self._core.walked_distance_m()
        if walked is not None:
            info["walked_distance_m"] = walked
        fault = self._core.fault()
        if fault is not None:
            info["fault"] = fault
        return np.array(obs, dtype=np.float32), reward, terminated, truncated, info


class PendulumEnv(_PadaEnv):
    """The simulated inverted pendulum of Section VII (``pada run --task
    pendulum``): observation [θ (wrapped), θ̇], actions the torques
    {−1.5, 0, 1.5} N m (or a Box over [−1.5, 1.5]), reward −5θ² − 0.1θ̇² − u²,
    20 Hz, 60-step (3 s) episodes that start hanging down."""

    _robot = "pendulum"


class PhysicalPendulumEnv(_PadaEnv):
    """The model of the paper's physical pendulum (``pada run --task
    physical-pendulum``): voltage actions, 33 Hz."""

    _robot = "physical-pendulum"


class LeoEnv(_PadaEnv):
    """The rapier3d LEO walking task of Section VIII (``pada run --task
    leo``): the 10-D mirrored observation, 7 voltage levels on stance hip,
    swing hip and swing knee (``continuous=True``: voltages in
    [−10.7, 10.7] V), reward −1 − 3E + 300ΔL − 125·[fall], falls terminate,
    750-step (25 s) episodes at 30 Hz."""

    _robot = "leo"


class RobotEnv(_PadaEnv):
    """A robot of files (``pada run --robot PATH``): ``RobotEnv(robot,
    continuous=False)`` with ``robot`` the path of its ``robot.toml`` (its
    URDF beside it, as the file names it). The observation is the file's
    ``[[observe]]`` signals in order; the actions are one level index per
    joint of ``[action]`` (``continuous=True``: voltages within the levels'
    range); the reward and the episode's ends are the file's rules; a joint
    past its soft limit ends the episode (``terminated``) and names itself in
    ``info["fault"]``, where ``pada run --robot`` ends its trial. A file that
    does not load raises ``ValueError`` with pada's message (the file, the
    line, the field and its valid values)."""

    def __init__(self, robot, continuous=False, render_mode=None):
        import os

        if not isinstance(robot, (str, os.PathLike)):
            raise ValueError(f"robot = {robot!r}: valid is the path of a robot.toml")
        path = os.fspath(robot)
        # A path the Rust side tells from a built-in robot's name.
        if not (path.endswith(".toml") or "/" in path):
            path = os.path.join(".", path)
        self._robot = path
        self._init(path, continuous, render_mode)


class LeoVector(gym.vector.VectorEnv):
    """n LEO environments stepped in parallel Rust threads with the GIL
    released (``pada/Leo-v0`` each). An episode that ends is reset in the
    same step (Gymnasium's same-step autoreset): the returned observation is
    the new episode's first, ``info["final_obs"]`` holds the last one (NaN
    rows for environments that did not end) and ``info["_final_obs"]`` which
    ended. ``info["commanded_torques"]`` is ``(n, 4)``.

    ``LeoVector(n, continuous=False)``, ``1 <= n <= 1024``.
    """

    metadata = {"autoreset_mode": "SameStep"}

    def __init__(self, n, continuous=False):
        if not isinstance(n, (int, np.integer)) or isinstance(n, bool):
            raise ValueError(f"n = {n!r}: valid is an integer 1 <= n <= 1024")
        single = LeoEnv(continuous=continuous)
        self._core = _pada.LeoVectorCore(int(n), "leo", continuous)
        try:
            from gymnasium.vector import AutoresetMode

            self.metadata = {"autoreset_mode": AutoresetMode.SAME_STEP}
        except ImportError:  # older Gymnasium
            pass
        self.num_envs = int(n)
        self.single_observation_space = single.observation_space
        self.single_action_space = single.action_space
        self.observation_space = gym.vector.utils.batch_space(single.observation_space, self.num_envs)
        self.action_space = gym.vector.utils.batch_space(single.action_space, self.num_envs)
        self._obs_dim = self._core.obs_dim
        self._gearboxes = self._core.gearboxes
        self.dt = single.dt
        self.spec_dict = single.spec_dict

    def reset(self, *, seed=None, options=None):
        if seed is not None:
            self._np_random, _ = gym.utils.seeding.np_random(seed)
        raw = self._core.reset(None if seed is None else int(seed))
        return np.frombuffer(raw, dtype=np.float32).reshape(self.num_envs, self._obs_dim).copy(), {}

    def step(self, actions):
        a = np.asarray(actions, dtype=np.float64)
        if a.shape != self.action_space.shape:
            raise ValueError(f"actions has shape {a.shape}: valid is {self.action_space.shape} (one action per environment)")
        obs, rewards, term, trunc, last, torques = self._core.step(a.reshape(-1).tolist())
        n = self.num_envs
        obs = np.frombuffer(obs, dtype=np.float32).reshape(n, self._obs_dim).copy()
        term = np.asarray(term, dtype=bool)
        trunc = np.asarray(trunc, dtype=bool)
        info = {
            "final_obs": np.frombuffer(last, dtype=np.float32).reshape(n, self._obs_dim).copy(),
            "_final_obs": term | trunc,
            "commanded_torques": np.frombuffer(torques, dtype=np.float64).reshape(n, self._gearboxes).copy(),
        }
        return obs, np.asarray(rewards, dtype=np.float64), term, trunc, info


def _register():
    for name, cls in (
        ("Pendulum-v0", "PendulumEnv"),
        ("PhysicalPendulum-v0", "PhysicalPendulumEnv"),
        ("Leo-v0", "LeoEnv"),
        ("Robot-v0", "RobotEnv"),
    ):
        env_id = f"pada/{name}"
        if env_id not in gym.registry:
            gym.register(id=env_id, entry_point=f"pada.envs:{cls}", disable_env_checker=False)


_register()
