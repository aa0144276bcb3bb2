#!/usr/bin/env bash
# Measures what README.md reports for arm2, from the repository's root:
#   bash examples/robots/arm2/measure.sh [OUT]        (about a minute on one core)
# 1. SARSA(lambda) and PADA (Delta = 0.5, the paper's pendulum value), 20
#    trials of 1200 s each: end performance, rise time, MTBF per gearbox.
# 2. The hold: PADA learns for 300, 600 and 1200 s with seeds 1..10, one
#    trial each; `pada render --robot` judges each greedy run (the tip within
#    2 cm of its target over the episode's last half).
set -euo pipefail
cd "$(dirname "$0")/../../.."
source examples/robots/measure-lib.sh arm2 "$@"

for algo in sarsa pada; do
    learn "$algo" 1200 "$out/run-$algo" --trials 20 --threads 1
done

for secs in 300 600 1200; do
    hold pada "$secs" "$out/hold-$secs" tip tip --threads 1
done
