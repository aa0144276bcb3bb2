"""The Python package's speed targets, measured (a benchmark, not a test):

1. one pada/Leo-v0 step from Python against the Rust step alone (the same
   plant stepped in a Rust loop, `pada._pada.bench_rust_steps`), target
   ratio <= 1.25;
2. LeoVector(2) steps per second against one environment's, target >= 1.7
   on 2 cores;
3. what MtbfWrapper adds per step, target <= 2 us (on Pendulum-v1 and on a
   trivial environment whose step costs almost nothing).

    python python/benchmarks/speed.py [--steps N] [--repeats R]

Each figure is the best (smallest time, largest rate) of R repeats, the
two sides of a ratio taken in alternation within one run: on a shared,
loaded machine the best repeat is the one least disturbed by others.
"""

import argparse
import os
import time

import gymnasium as gym
import numpy as np

import pada
from pada import _pada
from pada.wrappers import MtbfWrapper


def leo_actions(n, seed=0):
    rng = np.random.default_rng(seed)
    return rng.integers(0, 7, size=(n, 3))


def python_leo(actions):
    env = gym.make("pada/Leo-v0").unwrapped  # no checker/order wrappers: the env's own step
    env.reset(seed=0)
    step = env.step
    t = time.perf_counter()
    for a in actions:
        _, _, te, tr, _ = step(a)
        if te or tr:
            env.reset()
    return (time.perf_counter() - t) / len(actions)


def vector_rate(n, steps, actions):
    vec = pada.envs.LeoVector(n)
    vec.reset(seed=0)
    acts = np.stack([actions[(np.arange(n) * 7 + k) % len(actions)] for k in range(steps)])
    t, c = time.perf_counter(), time.process_time()
    for k in range(steps):
        vec.step(acts[k])
    wall = time.perf_counter() - t
    return n * steps / wall, (time.process_time() - c) / wall


class Null(gym.Env):
    observation_space = gym.spaces.Box(-1.0, 1.0, (1,), np.float32)
    action_space = gym.spaces.Box(-2.0, 2.0, (1,), np.float32)
    dt = 0.05
    _obs = np.zeros(1, np.float32)

    def reset(self, *, seed=None, options=None):
        return self._obs, {}

    def step(self, action):
        return self._obs, 0.0, False, False, {}


def per_step(env, actions):
    env.reset(seed=0)
    step = env.step
    t = time.perf_counter()
    for a in actions:
        step(a)
    return (time.perf_counter() - t) / len(actions)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--steps", type=int, default=3000)
    p.add_argument("--repeats", type=int, default=5)
    args = p.parse_args()
    print(f"cores: {os.cpu_count()}, load average: {os.getloadavg()}")
    acts = leo_actions(args.steps)
    rust, py = [], []
    for _ in range(args.repeats):
        rust.append(_pada.bench_rust_steps("leo", acts.tolist(), args.steps))
        py.append(python_leo(acts))
    r, q = min(rust), min(py)
    print(f"1. Leo-v0 step: Rust alone {r * 1e6:.1f} us, from Python {q * 1e6:.1f} us, ratio {q / r:.3f} (target <= 1.25)")
    one, two = [], []
    for _ in range(args.repeats):
        one.append(vector_rate(1, args.steps // 2, acts))
        two.append(vector_rate(2, args.steps // 2, acts))
    (a, ca), (b, cb) = max(one), max(two)
    print(
        f"2. LeoVector: 1 env {a:.0f} steps/s, LeoVector(2) {b:.0f} steps/s, ratio {b / a:.2f} (target >= 1.7); "
        f"cores used (CPU time / wall time) {ca:.2f} and {cb:.2f}"
    )
    n = 20_000
    for name, make in (("trivial env", Null), ("Pendulum-v1", lambda: gym.make("Pendulum-v1").unwrapped)):
        rng = np.random.default_rng(0)
        box = rng.uniform(-2, 2, size=(n, 1)).astype(np.float32)
        bare, wrapped = [], []
        for _ in range(4 * args.repeats):
            bare.append(per_step(make(), box))
            wrapped.append(per_step(MtbfWrapper(make()), box))
        x, y = min(bare), min(wrapped)
        print(f"3. MtbfWrapper on {name}: {x * 1e6:.2f} us bare, {y * 1e6:.2f} us wrapped, adds {(y - x) * 1e6:.2f} us/step (target <= 2)")


if __name__ == "__main__":
    main()
