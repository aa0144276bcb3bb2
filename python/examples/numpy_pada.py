"""A small numpy learner with and without PADA, on pada's pendulum and on
Gymnasium's Pendulum-v1: prints each run's end return and predicted MTBF
(Eqs. 3–7, over the paper's first 1200 actions and over the whole run) and
writes a plot of the learning curves (SVG, no plotting library needed).

    python python/examples/numpy_pada.py [--episodes N] [--out DIR]

The learner is tabular SARSA(0) with ε-greedy on a 21 × 21 grid of
(angle, angular velocity) and three actions (−max, 0, +max torque). PADA
(Eq. 9, ``PadaWrapper``) lets each action move at most Δ of the range from
the previous one; ``MtbfWrapper`` underneath sees the torque applied. Run
by `cargo xtask test` (and so in CI).
"""

import argparse
import math
import os

import gymnasium as gym
import numpy as np

import pada
from pada.wrappers import MtbfWrapper, PadaWrapper

BINS = 21


def discretise(obs):
    """(θ, θ̇) from pada's observation [θ, θ̇] or Pendulum-v1's
    [cos θ, sin θ, θ̇], as grid indices."""
    if len(obs) == 3:
        theta, omega = math.atan2(obs[1], obs[0]), obs[2]
    else:
        theta, omega = obs[0], obs[1]
    i = int((theta + math.pi) / (2 * math.pi) * (BINS - 1) + 0.5) % BINS
    j = min(max(int((omega + 8.0) / 16.0 * (BINS - 1) + 0.5), 0), BINS - 1)
    return i, j


def learn(env, to_action, episodes, seed, alpha=0.2, gamma=0.99, epsilon=0.05):
    rng = np.random.default_rng(seed)
    q = rng.uniform(0.0, 1.0, size=(BINS, BINS, 3))
    returns = []
    obs, _ = env.reset(seed=seed)
    info = {}
    for _ in range(episodes):
        s = discretise(obs)
        a = int(np.argmax(q[s])) if rng.random() > epsilon else int(rng.integers(3))
        total, done = 0.0, False
        while not done:
            obs, r, term, trunc, info = env.step(to_action(a))
            total += r
            s2 = discretise(obs)
            a2 = int(np.argmax(q[s2])) if rng.random() > epsilon else int(rng.integers(3))
            target = r if term else r + gamma * q[s2][a2]
            q[s][a] += alpha * (target - q[s][a])
            s, a = s2, a2
            done = term or trunc
        returns.append(total)
        obs, _ = env.reset()
    return np.array(returns), info


def mtbf_of(env):
    """The MtbfWrapper under any PadaWrapper."""
    while not isinstance(env, MtbfWrapper):
        env = env.env
    return env.report()


def svg_plot(path, curves, title):
    w, h, m = 720, 420, 50
    ys = np.concatenate([c for _, c in curves])
    lo, hi = float(ys.min()), float(ys.max())
    hi = hi if hi > lo else lo + 1
    n = max(len(c) for _, c in curves)
    colors = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd"]
    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" font-family="sans-serif" font-size="12">',
             f'<rect width="{w}" height="{h}" fill="white"/>',
             f'<text x="{w / 2}" y="20" text-anchor="middle" font-size="14">{title}</text>',
             f'<line x1="{m}" y1="{h - m}" x2="{w - m}" y2="{h - m}" stroke="black"/>',
             f'<line x1="{m}" y1="{m}" x2="{m}" y2="{h - m}" stroke="black"/>',
             f'<text x="{w / 2}" y="{h - 12}" text-anchor="middle">episode</text>',
             f'<text x="{m - 5}" y="{m}" text-anchor="end">{hi:.0f}</text>',
             f'<text x="{m - 5}" y="{h - m}" text-anchor="end">{lo:.0f}</text>']
    for k, (label, c) in enumerate(curves):
        k_smooth = max(1, len(c) // 50)
        sm = np.convolve(c, np.ones(k_smooth) / k_smooth, mode="valid")
        pts = " ".join(
            f"{m + (w - 2 * m) * i / max(n - 1, 1):.1f},{h - m - (h - 2 * m) * (v - lo) / (hi - lo):.1f}"
            for i, v in enumerate(sm)
        )
        parts.append(f'<polyline fill="none" stroke="{colors[k % 4]}" stroke-width="1.5" points="{pts}"/>')
        parts.append(f'<text x="{w - m - 5}" y="{m + 16 * k}" text-anchor="end" fill="{colors[k % 4]}">{label}</text>')
    parts.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(parts))


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--episodes", type=int, default=300)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--out", default="pada-out/python-example")
    args = p.parse_args()
    os.makedirs(args.out, exist_ok=True)
    setups = {
        "pada/Pendulum-v0": (lambda: gym.make("pada/Pendulum-v0"), lambda a: a, 0.5),
        "Pendulum-v1": (lambda: gym.make("Pendulum-v1"), lambda a: np.array([(a - 1) * 2.0], dtype=np.float32), 0.25),
    }
    print(f"{'environment':<18} {'learner':<14} {'end return':>11} {'MTBF first 1200 [s]':>20} {'MTBF run [s]':>13}")
    for name, (make, to_action, delta) in setups.items():
        curves = []
        for label, wrap in (("SARSA", lambda e: MtbfWrapper(e)), (f"PADA d={delta}", lambda e: PadaWrapper(MtbfWrapper(e), delta))):
            env = wrap(make())
            returns, _ = learn(env, to_action, args.episodes, args.seed)
            r = mtbf_of(env)
            end = float(np.mean(returns[-max(1, len(returns) // 10):]))
            print(f"{name:<18} {label:<14} {end:>11.1f} {r['robot_window_mtbf_s']:>20.1f} {r['robot_mtbf_s']:>13.1f}")
            curves.append((f"{label}: MTBF {r['robot_window_mtbf_s']:.0f} s", returns))
        path = os.path.join(args.out, name.replace("/", "_") + ".svg")
        svg_plot(path, curves, f"{name}: return per episode (tabular SARSA, numpy)")
        print(f"  plot: {path}")


if __name__ == "__main__":
    main()
