"""stable-baselines3 PPO on Gymnasium's Pendulum-v1 with MtbfWrapper: how
long would the gearbox last under the actions PPO explores with?

NOT RUN IN CI: stable-baselines3 pulls in PyTorch (hundreds of MB), which
`cargo xtask test` does not install. Run it by hand:

    pip install ./python stable-baselines3
    python python/examples/sb3_ppo_mtbf.py [--steps 50000] [--delta 0.1]

With ``--delta`` the actions go through PadaWrapper (Eq. 9) as well, so the
two predicted MTBFs (Eqs. 3–7) can be compared at equal training steps.
"""

import argparse

import gymnasium as gym

import pada  # noqa: F401  (registers pada's environments)
from pada.wrappers import MtbfWrapper, PadaWrapper


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--steps", type=int, default=50_000)
    p.add_argument("--delta", type=float, default=None, help="PADA's delta (0 < delta <= 1); none: plain PPO")
    args = p.parse_args()
    from stable_baselines3 import PPO
    from stable_baselines3.common.monitor import Monitor

    env = MtbfWrapper(gym.make("Pendulum-v1"))
    if args.delta is not None:
        env = PadaWrapper(env, args.delta)
    env = Monitor(env)
    model = PPO("MlpPolicy", env, verbose=0, seed=0)
    model.learn(total_timesteps=args.steps)
    inner = env
    while not isinstance(inner, MtbfWrapper):
        inner = inner.env
    r = inner.report()
    returns = env.get_episode_rewards()
    tail = returns[-10:] if returns else [float("nan")]
    print(f"PPO{'' if args.delta is None else f' + PADA delta={args.delta}'} on Pendulum-v1, {args.steps} steps")
    print(f"  mean return of the last 10 episodes: {sum(tail) / len(tail):.1f}")
    print(f"  re-engagements: {r['reengagements'][0]}, damage J: {r['damage'][0]:.4e}")
    print(f"  predicted MTBF: {r['robot_window_mtbf_s']:.1f} s over the first 1200 actions, {r['robot_mtbf_s']:.1f} s over training")


if __name__ == "__main__":
    main()
