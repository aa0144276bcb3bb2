#!/usr/bin/env bash
# Measures what README.md reports for so101, from the repository's root:
#   bash examples/robots/so101/measure.sh [OUT]        (about two minutes on one core)
# 1. SARSA(lambda) and PADA (Delta = 0.5, the paper's pendulum value), 20
#    trials of 1200 s each: end performance, rise time, MTBF per gearbox.
# 2. The hold: PADA and SARSA(lambda) learn for 600 and 1200 s with seeds
#    1..10, one trial each; `pada render --robot` judges each greedy run
#    (the grip point within 2 cm of its target over the episode's last half).
# 3. The F405's learner on the host: one trial of 1200 s.
set -euo pipefail
cd "$(dirname "$0")/../../.."
source examples/robots/measure-lib.sh so101 "$@"

learn sarsa 1200 "$out/sarsa/run" --trials 20 --threads 1
learn pada 1200 "$out/pada/run" --trials 20 --threads 1

for algo in pada sarsa; do
    for secs in 600 1200; do
        hold "$algo" "$secs" "$out/hold-$algo-$secs" grip "grip point" --threads 1
    done
done

learn pada 1200 "$out/board-f405/run" --trials 1 --board f405 --threads 1
