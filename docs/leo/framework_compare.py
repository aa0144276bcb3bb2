"""SARSA(lambda) on LEO: the authors' framework (GRL) against pada, at the
paper's 14,666 s of learning.

Reads the framework's per-test-run output (`experiment/online_learning`'s
`output: NAME` file `NAME-0.txt`: learning episodes, learning steps, test
return, test duration, ..., the walking report of `LeoBhWalkSym`: trial
time, footsteps, falls, walked distance, speed, energy, energy per metre)
and pada's per-trial learning curves (`pada run --out DIR`: `trial-NNN.csv`
with test_run, learning_time_s, learning_episodes, return, walked_m, fell,
duration_s). Both count learning time as learning steps / 30 Hz and run a
greedy test every 10 learning episodes.

Writes, into OUT_DIR:
- `framework-14666-runs.csv`: per run the end performance (mean return of
  the last 10 % of test runs, Section VI), the mean walked distance of the
  last 10 % of test runs, whether that is >= 1 m, and the learning time of
  the first test run that walked >= 1 m and >= 3 m;
- `framework-14666-curves.csv`: per run and 500 s of learning time, the
  mean learning-episode length [steps], the mean test return and the mean
  walked distance of the test runs in the bin;
- `framework-14666.png`: those curves, the framework's runs in black and
  grey, pada's in colour.

Usage: python3 framework_compare.py OUT_DIR --grl SEED=FILE ... --pada TRIAL=FILE ...
"""
import argparse
import csv
import math
import os
import sys

RATE_HZ = 30.0
BIN_S = 500.0


def grl_runs(path):
    """The framework's test runs: (learning time s, learning episodes, return, walked m)."""
    rows = []
    with open(path) as f:
        for line_no, line in enumerate(f, 1):
            parts = line.split()
            if not parts:
                continue
            if len(parts) != 13:
                sys.exit(f"{path}:{line_no}: expected 13 columns of the framework's LEO test report, found {len(parts)}")
            episodes, steps, ret = int(parts[0]), int(parts[1]), float(parts[2])
            walked = float(parts[9])
            rows.append((steps / RATE_HZ, episodes, ret, walked))
    if not rows:
        sys.exit(f"{path}: no test runs")
    return rows


def pada_runs(path):
    rows = []
    with open(path) as f:
        r = csv.DictReader(f)
        need = {"learning_time_s", "learning_episodes", "return", "walked_m"}
        if not need <= set(r.fieldnames or []):
            sys.exit(f"{path}: expected pada's learning-curve columns {sorted(need)}, found {r.fieldnames}")
        for row in r:
            rows.append((float(row["learning_time_s"]), int(row["learning_episodes"]), float(row["return"]), float(row["walked_m"])))
    if not rows:
        sys.exit(f"{path}: no test runs")
    return rows


def last_tenth(values):
    k = math.ceil(len(values) / 10)
    tail = values[-k:]
    return sum(tail) / len(tail)


def first_time(rows, metres):
    for t, _, _, walked in rows:
        if walked >= metres:
            return t
    return None


def summary(name, rows):
    walked = last_tenth([r[3] for r in rows])
    return {
        "run": name,
        "learning_time_s": round(rows[-1][0], 1),
        "test_runs": len(rows),
        "end_performance": round(last_tenth([r[2] for r in rows]), 1),
        "walked_last_tenth_m": round(walked, 2),
        "walks_1m": int(walked >= 1.0),
        "first_1m_s": "" if first_time(rows, 1.0) is None else round(first_time(rows, 1.0), 1),
        "first_3m_s": "" if first_time(rows, 3.0) is None else round(first_time(rows, 3.0), 1),
    }


def binned(rows):
    """Per BIN_S of learning time: mean learning-episode length (from the
    episode and step counts at the test runs), mean test return and walked."""
    out = []
    edge = BIN_S
    start_t, start_ep = 0.0, 0
    acc = []
    for t, ep, ret, walked in rows:
        while t >= edge:
            if acc:
                last_t, last_ep = acc[-1][0], acc[-1][1]
                episodes = last_ep - start_ep
                length = (last_t - start_t) * RATE_HZ / episodes if episodes else float("nan")
                out.append((edge - BIN_S / 2, length, sum(a[2] for a in acc) / len(acc), sum(a[3] for a in acc) / len(acc)))
                start_t, start_ep = last_t, last_ep
            acc = []
            edge += BIN_S
        acc.append((t, ep, ret, walked))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out_dir")
    ap.add_argument("--grl", action="append", default=[], metavar="SEED=FILE")
    ap.add_argument("--pada", action="append", default=[], metavar="TRIAL=FILE")
    a = ap.parse_args()
    runs = []
    for spec in a.grl:
        seed, _, path = spec.partition("=")
        runs.append((f"framework seed {seed}", "framework", grl_runs(path)))
    for spec in a.pada:
        trial, _, path = spec.partition("=")
        runs.append((f"pada trial {trial}", "pada", pada_runs(path)))
    if not runs:
        sys.exit("give at least one --grl or --pada run")
    os.makedirs(a.out_dir, exist_ok=True)
    sums = [summary(name, rows) for name, _, rows in runs]
    with open(os.path.join(a.out_dir, "framework-14666-runs.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(sums[0].keys()))
        w.writeheader()
        w.writerows(sums)
    with open(os.path.join(a.out_dir, "framework-14666-curves.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["run", "simulator", "bin_mid_s", "mean_episode_steps", "mean_test_return", "mean_walked_m"])
        for name, sim, rows in runs:
            for mid, length, ret, walked in binned(rows):
                w.writerow([name, sim, mid, f"{length:.1f}", f"{ret:.1f}", f"{walked:.3f}"])
    for s in sums:
        print(",".join(str(v) for v in s.values()))

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(3, 1, figsize=(10, 10.5), sharex=True)
    colours = ["tab:blue", "tab:green", "tab:orange", "tab:red", "tab:purple", "tab:brown"]
    greys = [("black", "-"), ("dimgray", "--"), ("darkgray", ":")]
    k_grl = k_pada = 0
    for name, sim, rows in runs:
        if sim == "framework":
            c, ls = greys[k_grl % len(greys)]
            k_grl += 1
        else:
            c, ls = colours[k_pada % len(colours)], "-"
            k_pada += 1
        b = binned(rows)
        x = [p[0] for p in b]
        for ax, col in zip(axes, (1, 2, 3)):
            ax.plot(x, [p[col] for p in b], color=c, linestyle=ls, linewidth=1.6 if sim == "framework" else 1.1, label=name)
    axes[0].set_ylabel("learning episode\n[control steps]")
    axes[1].set_ylabel("test return\n(mean per 500 s)")
    axes[2].set_ylabel("walked per test run [m]\n(mean per 500 s)")
    axes[2].axhline(1.0, color="gray", linewidth=0.8, linestyle="--")
    axes[2].set_xlabel("learning time [s] (30 learning steps per second)")
    axes[0].set_title("SARSA(λ) on LEO for 14,666 s: the authors' framework on its model (black, grey) and pada on pada's (colour)")
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.set_xlim(0, 14666)
    # The key in a strip under the plot, never over the data.
    axes[2].legend(loc="upper center", bbox_to_anchor=(0.5, -0.22), ncol=3, fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(a.out_dir, "framework-14666.png"), dpi=110)


if __name__ == "__main__":
    main()
