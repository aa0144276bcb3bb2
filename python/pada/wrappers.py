"""Gymnasium wrappers: the predicted gearbox life of any environment's
actions (``MtbfWrapper``, Eqs. 3–7), PADA (``PadaWrapper``, Eq. 9, also
driven by the wear governor with ``mtbf_budget=``) and the low-pass filter
(``LowPassWrapper``, Eq. 8)."""

import math

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from . import _pada

__all__ = ["MtbfWrapper", "PadaWrapper", "LowPassWrapper", "voltage"]


def voltage(torque_per_volt=_pada.RX28_TORQUE_PER_VOLT):
    """A ``torque=`` map for environments whose Box actions are motor
    voltages: the gear torque is ``torque_per_volt * U`` (the paper's linear
    law, Section IV; the default is LEO's RX-28 stall torque per volt,
    ≈ 0.167 N m/V)."""
    k = float(torque_per_volt)
    if not (math.isfinite(k) and k > 0):
        raise ValueError(f"torque_per_volt = {k} is out of range: valid is 0 < torque_per_volt < inf (N m per V)")

    def torque(action, obs):
        return np.asarray(action, dtype=np.float64).reshape(-1) * k

    torque.torque_per_volt = k
    return torque


def _is_pada_env(env):
    return getattr(env.unwrapped, "_pada_env", False)


def _rate_of(env, rate_hz):
    """The control rate: given, or the environment's ``dt`` (Gymnasium's
    classic-control and MuJoCo environments), or a pada environment's."""
    if rate_hz is None:
        u = env.unwrapped
        dt = getattr(u, "dt", None)
        if dt is None:
            fps = env.metadata.get("render_fps")
            if fps:
                dt = 1.0 / fps
        if dt is None:
            raise ValueError("rate_hz: the environment has no dt; give rate_hz (0 < rate_hz <= 1e6, control steps per second)")
        rate_hz = 1.0 / float(dt)
    rate_hz = float(rate_hz)
    if not (math.isfinite(rate_hz) and 0 < rate_hz <= 1e6):
        raise ValueError(f"rate_hz = {rate_hz} is out of range: valid is 0 < rate_hz <= 1000000 (Hz)")
    return rate_hz


class _TorqueSource:
    """Where a step's gear torques come from: the ``torque`` callable, a pada
    environment's commanded torques (the paper's, as ``pada run``'s
    ``mtbf_s``), or a Box action taken as torques (clipped to its bounds, as
    environments apply them)."""

    def __init__(self, env, torque, joints):
        self.fn = None
        self.from_info = False
        self.low = self.high = None
        space = env.action_space
        if torque is not None:
            if not callable(torque):
                raise ValueError("torque: valid is a callable (action, obs) -> gear torques, or None")
            self.fn = torque
            if joints is None:
                if isinstance(space, spaces.Box):
                    joints = int(np.prod(space.shape))
                else:
                    raise ValueError("joints: give the number of gearboxes (1..64) with a torque map on a non-Box action space")
        elif _is_pada_env(env):
            self.from_info = True
            joints = joints or env.unwrapped.spec_dict["gearboxes"]
        elif isinstance(space, spaces.Box):
            joints = joints or int(np.prod(space.shape))
            if int(np.prod(space.shape)) != joints:
                raise ValueError(f"joints = {joints}: a Box action of {int(np.prod(space.shape))} torques has that many gearboxes; give torque= to map it")
            self.low = [float(x) for x in np.broadcast_to(space.low, space.shape).reshape(-1)]
            self.high = [float(x) for x in np.broadcast_to(space.high, space.shape).reshape(-1)]
        else:
            raise ValueError(
                f"torque: the action space {space} is not a Box of torques; give torque=(action, obs) -> gear torques "
                "(pada.wrappers.voltage() for voltages)"
            )
        if not (isinstance(joints, (int, np.integer)) and 1 <= joints <= 64):
            raise ValueError(f"joints = {joints} is out of range: valid is 1 <= joints <= 64")
        self.joints = int(joints)
        self.box_1d = self.fn is None and not self.from_info and len(space.shape) == 1

    def torques(self, action, obs, info):
        if self.from_info:
            return info["commanded_torques"]
        if self.fn is not None:
            return self.fn(action, obs)
        return action if self.box_1d else np.asarray(action).reshape(-1)

    def worst(self, space):
        """The largest gear torque one action can command, for the governor."""
        if self.low is not None:
            return max(max(abs(x) for x in self.low), max(abs(x) for x in self.high))
        if self.fn is not None and isinstance(space, spaces.Box):
            corners = [np.broadcast_to(space.low, space.shape), np.broadcast_to(space.high, space.shape)]
            return max(float(np.max(np.abs(np.asarray(self.fn(c, None), dtype=np.float64)))) for c in corners)
        return None


class MtbfWrapper(gym.Wrapper):
    """Predicts how long the gearboxes last under the actions taken
    (Eqs. 3–7): a :class:`pada.Fatigue` counter fed every step's gear
    torques.

    ``MtbfWrapper(env, *, joints=None, torque=None, rate_hz=None, window=1200)``

    - ``torque``: a callable ``(action, obs) -> gear torques`` (one per
      gearbox, N m). The default takes a Box action as the torques (clipped
      to the space's bounds); for voltages use
      ``torque=pada.wrappers.voltage(k)`` (``k`` N m per V, LEO's RX-28 by
      default). On pada's own environments the default is the commanded
      torque of ``pada run``'s ``mtbf_s``.
    - ``joints``: the number of gearboxes (default: the action's size).
    - ``rate_hz``: control steps per second (default ``1/env.unwrapped.dt``).

    Every step's ``info`` gets ``damage`` and ``mtbf_s`` (lists, one per
    gearbox: the damage J and predicted MTBF in s since the wrapper was
    made) and ``robot_mtbf_s`` (the weakest gearbox's). At an episode's end
    ``info["episode_mtbf"]`` holds the episode's own ``damage``, ``mtbf_s``,
    ``robot_mtbf_s`` and ``steps``, and, under
    ``RecordEpisodeStatistics``, ``info["episode"]`` gets ``mtbf_s`` and
    ``damage`` too. ``report()`` is the counter's (as ``pada mtbf``).
    Works under ``gymnasium.vector`` (one counter per sub-environment).
    """

    def __init__(self, env, *, joints=None, torque=None, rate_hz=None, window=_pada.PAPER_WINDOW_STEPS):
        super().__init__(env)
        from . import Fatigue

        self._source = _TorqueSource(env, torque, joints)
        self.rate_hz = _rate_of(env, rate_hz)
        self.fatigue = Fatigue(self._source.joints, self.rate_hz, window=window)
        if self._source.low is not None:
            self.fatigue.set_clip(self._source.low, self._source.high)
        self._add = self.fatigue.add_to_info
        self._torques = self._source.torques
        # A 1-D Box of torques goes to the counter as it is (no Python call).
        self._direct = self._source.box_1d
        self._ep_damage = [0.0] * self._source.joints
        self._ep_start = 0

    def reset(self, **kwargs):
        self._ep_damage = self.fatigue.damage
        self._ep_start = self.fatigue.steps
        return self.env.reset(**kwargs)

    def step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(action)
        self._add(action if self._direct else self._torques(action, obs, info), info)
        if terminated or truncated:
            self._episode_end(info)
        return obs, reward, terminated, truncated, info

    def _episode_end(self, info):
        steps = self.fatigue.steps - self._ep_start
        damage = [a - b for a, b in zip(self.fatigue.damage, self._ep_damage)]
        elapsed = steps / self.rate_hz
        mtbf = [elapsed / d if d > 0 else math.inf for d in damage]
        ep = {"damage": damage, "mtbf_s": mtbf, "robot_mtbf_s": min(mtbf), "steps": steps}
        info["episode_mtbf"] = ep
        if isinstance(info.get("episode"), dict):
            info["episode"]["mtbf_s"] = ep["robot_mtbf_s"]
            info["episode"]["damage"] = max(damage)

    def report(self):
        """The counter's report (:meth:`pada.Fatigue.report`)."""
        return self.fatigue.report()


def _check_delta(name, value):
    v = float(value)
    if not (math.isfinite(v) and 0 < v <= 1):
        raise ValueError(f"{name} = {value} is out of range: valid is 0 < {name} <= 1 (a fraction of the action range, as --{name})")
    return v


class _Restriction:
    """PADA's reach on one action space (Eq. 9): Box dimensions move at most
    Δ·(high − low), discrete ones at most ⌊Δ·(n − 1)⌋ levels (pada's rule
    on uniform levels)."""

    def __init__(self, space, rest):
        self.space = space
        if isinstance(space, spaces.Box):
            self.kind = "box"
            self.low = np.broadcast_to(space.low, space.shape).astype(np.float64)
            self.high = np.broadcast_to(space.high, space.shape).astype(np.float64)
            if not (np.all(np.isfinite(self.low)) and np.all(np.isfinite(self.high))):
                raise ValueError("env.action_space: PADA needs a bounded Box (finite low and high)")
            self.range = self.high - self.low
            self.rest = np.clip(np.zeros(space.shape), self.low, self.high)
        elif isinstance(space, spaces.Discrete):
            self.kind = "discrete"
            self.n = int(space.n)
            self.start = int(space.start)
            self.rest = self.start + (self.n - 1) // 2 if rest is None else rest
        elif isinstance(space, spaces.MultiDiscrete):
            self.kind = "multidiscrete"
            self.nvec = np.asarray(space.nvec, dtype=np.int64)
            self.start = np.asarray(getattr(space, "start", np.zeros_like(self.nvec)), dtype=np.int64)
            self.rest = self.start + (self.nvec - 1) // 2 if rest is None else np.asarray(rest)
        else:
            raise ValueError(f"env.action_space: valid is Box, Discrete or MultiDiscrete, got {space}")
        self.levels = None
        if self.kind == "discrete":
            self.levels = self.n
        elif self.kind == "multidiscrete":
            self.levels = int(self.nvec.max())

    def limit(self, prev, action, delta):
        if self.kind == "box":
            a = np.asarray(action, dtype=np.float64)
            step = delta * self.range
            out = np.clip(a, prev - step, prev + step)
            return np.clip(out, self.low, self.high).astype(self.space.dtype)
        if self.kind == "discrete":
            reach = int(math.floor(delta * (self.n - 1) * (1 + 1e-4)))
            a = int(action)
            return np.int64(min(max(a, prev - reach), prev + reach))
        reach = np.floor(delta * (self.nvec - 1) * (1 + 1e-4)).astype(np.int64)
        a = np.asarray(action, dtype=np.int64)
        return np.clip(a, prev - reach, prev + reach).astype(self.space.dtype)


class PadaWrapper(gym.Wrapper):
    """PADA (Eq. 9): every action is restricted to within Δ of the previous
    one, Δ a fraction of the action range as ``pada run --delta``.

    ``PadaWrapper(env, delta)`` or ``PadaWrapper(env, mtbf_budget=seconds,
    ...)``

    - Box actions: each dimension moves at most ``Δ·(high − low)``;
      Discrete and MultiDiscrete: at most ``⌊Δ·(n − 1)⌋`` levels. The first
      action of an episode is restricted around the rest action (the level
      nearest 0, as pada's policies start).
    - ``mtbf_budget``: the wear governor of ``pada run --mtbf-budget`` (the
      core's Rust code) moves Δ over the ladder ``k/(levels − 1)`` so that
      the predicted MTBF (Eqs. 3–7) over the last 1200 actions stays at or
      above the budget (s). It starts at the floor and relaxes as the budget
      allows. ``torque``, ``joints`` and ``rate_hz`` are as for
      :class:`MtbfWrapper`; ``levels`` is the ladder's size for Box actions
      (default 11: Δ in steps of 0.1); ``worst_torque`` the largest gear
      torque one action can command (default: from the Box bounds).

    ``info["pada_delta"]`` is the Δ in force, ``info["pada_action"]`` the
    action applied; with a governor, ``info["governor"]`` its status every
    step.
    """

    def __init__(self, env, delta=None, *, mtbf_budget=None, levels=None, torque=None, joints=None, rate_hz=None, worst_torque=None):
        super().__init__(env)
        if (delta is None) == (mtbf_budget is None):
            raise ValueError("delta, mtbf_budget: give exactly one (delta: 0 < delta <= 1; mtbf_budget: 0 < mtbf_budget <= 1e10 s)")
        rest = getattr(env.unwrapped, "rest_action", None)
        self._r = _Restriction(env.action_space, rest)
        self.governor = None
        if delta is not None:
            self.delta = _check_delta("delta", delta)
        else:
            self._source = _TorqueSource(env, torque, joints)
            if self._source.joints > 4:
                raise ValueError(f"joints = {self._source.joints} is out of range: the governor follows 1 <= joints <= 4 gearboxes")
            if levels is None:
                levels = self._r.levels or 11
            worst = worst_torque if worst_torque is not None else (
                env.unwrapped.spec_dict["worst_torque"] if _is_pada_env(env) else self._source.worst(env.action_space)
            )
            if worst is None:
                raise ValueError("worst_torque: give the largest gear torque one action can command (0 < worst_torque < inf, N m)")
            self.governor = _pada.WearGovernor(
                float(mtbf_budget), _rate_of(env, rate_hz), joints=self._source.joints, levels=int(levels),
                worst_torque=float(worst), restricts="delta",
            )
            self.delta = self.governor.parameter
        self._prev = self._r.rest

    def reset(self, **kwargs):
        self._prev = self._r.rest
        return self.env.reset(**kwargs)

    def step(self, action):
        if not self.action_space.contains(action):
            raise ValueError(f"action = {action!r} is outside the action space: valid is {self.action_space}")
        a = self._r.limit(self._prev, action, self.delta)
        obs, reward, terminated, truncated, info = self.env.step(a)
        self._prev = a
        info["pada_delta"] = self.delta
        info["pada_action"] = a
        if self.governor is not None:
            moved = self.governor.observe(self._source.torques(a, obs, info))
            if moved is not None:
                self.delta = moved
            info["governor"] = self.governor.status()
        return obs, reward, terminated, truncated, info


class LowPassWrapper(gym.Wrapper):
    """The low-pass filter of Eq. 8 on Box actions: the applied action is
    ``u_t = α·a_t + (1 − α)·u_{t−1}``, starting from the rest action (0
    clipped into the bounds) at every reset; α = 1 is no filtering.

    ``LowPassWrapper(env, alpha)`` or ``LowPassWrapper(env,
    mtbf_budget=seconds, ...)``: with a budget the wear governor moves α
    over the paper's ladder (0.1 … 1) as ``pada run --algo lowpass
    --mtbf-budget`` does. ``info["lowpass_alpha"]`` is the α in force.
    """

    def __init__(self, env, alpha=None, *, mtbf_budget=None, torque=None, joints=None, rate_hz=None, worst_torque=None):
        super().__init__(env)
        if not isinstance(env.action_space, spaces.Box):
            raise ValueError(f"env.action_space: the low-pass filter needs a Box action space, got {env.action_space}")
        if (alpha is None) == (mtbf_budget is None):
            raise ValueError("alpha, mtbf_budget: give exactly one (alpha: 0 < alpha <= 1; mtbf_budget: 0 < mtbf_budget <= 1e10 s)")
        self._r = _Restriction(env.action_space, None)
        self.governor = None
        if alpha is not None:
            self.alpha = _check_delta("alpha", alpha)
        else:
            self._source = _TorqueSource(env, torque, joints)
            worst = worst_torque if worst_torque is not None else (
                env.unwrapped.spec_dict["worst_torque"] if _is_pada_env(env) else self._source.worst(env.action_space)
            )
            if worst is None:
                raise ValueError("worst_torque: give the largest gear torque one action can command (0 < worst_torque < inf, N m)")
            self.governor = _pada.WearGovernor(
                float(mtbf_budget), _rate_of(env, rate_hz), joints=self._source.joints, levels=2,
                worst_torque=float(worst), restricts="alpha",
            )
            self.alpha = self.governor.parameter
        self._u = self._r.rest

    def reset(self, **kwargs):
        self._u = self._r.rest
        return self.env.reset(**kwargs)

    def step(self, action):
        if not self.action_space.contains(action):
            raise ValueError(f"action = {action!r} is outside the action space: valid is {self.action_space}")
        u = self.alpha * np.asarray(action, dtype=np.float64) + (1 - self.alpha) * self._u
        u = np.clip(u, self._r.low, self._r.high)
        self._u = u
        a = u.astype(self.action_space.dtype)
        obs, reward, terminated, truncated, info = self.env.step(a)
        info["lowpass_alpha"] = self.alpha
        if self.governor is not None:
            moved = self.governor.observe(self._source.torques(a, obs, info))
            if moved is not None:
                self.alpha = moved
            info["governor"] = self.governor.status()
        return obs, reward, terminated, truncated, info
