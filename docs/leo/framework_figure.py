"""Draws docs/leo/framework-curves.png from docs/leo/framework-curves.csv:
the mean learning-episode length and the best greedy test return per
10,000 learning steps, the framework's SARSA(lambda) against pada's."""
import csv, sys
import matplotlib
matplotlib.use('Agg')
import matplotlib.pyplot as plt
rows = list(csv.DictReader(open(sys.argv[1])))
runs = []
for r in rows:
    if r['run'] not in runs: runs.append(r['run'])
styles = {'framework seed 1': ('black', '-'), 'framework seed 2': ('black', '--'), 'framework seed 3': ('black', ':'),
          'pada, 2^22 table, 4 physics steps (before)': ('tab:blue', '-'), 'pada, 2^22, 8 physics steps': ('tab:blue', '--'),
          'pada, 2^22, 12 physics steps': ('tab:blue', ':'), 'pada, 2^24 table (now)': ('tab:green', '-'),
          'pada, 2^26': ('tab:orange', '-'), 'pada, 2^26, weights U[0,1]': ('tab:red', '--')}
fig, (a, b) = plt.subplots(2, 1, figsize=(10, 8), sharex=True)
for run in runs:
    rs = [r for r in rows if r['run'] == run]
    x = [(int(r['bin_start_steps']) + 5000) / 30 for r in rs]
    c, ls = styles.get(run, ('gray', '-'))
    a.plot(x, [float(r['mean_episode_steps']) for r in rs], color=c, linestyle=ls, label=run)
    xb = [(int(r['bin_start_steps']) + 5000) / 30 for r in rs if r['best_test_return']]
    b.plot(xb, [float(r['best_test_return']) for r in rs if r['best_test_return']], color=c, linestyle=ls, label=run)
a.set_ylabel('mean learning episode [control steps]')
b.set_ylabel('best greedy test return per bin')
b.set_xlabel('learning time [s] (30 learning steps per second)')
a.set_title("SARSA(λ) on LEO: the authors' framework on its model against pada on pada's")
for ax in (a, b): ax.grid(alpha=0.3)
# The key below the axes, not over the data.
b.legend(loc='upper center', bbox_to_anchor=(0.5, -0.18), ncol=3, fontsize=9)
fig.tight_layout()
fig.savefig(sys.argv[2], dpi=110)
