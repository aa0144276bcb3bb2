#!/usr/bin/env bash
# Measures what README.md reports for arm3, from the repository's root:
#   bash examples/robots/arm3/measure.sh [OUT]        (about 10 minutes on two cores)
# 1. On the host: SARSA(lambda) and PADA (Delta = 0.5), 10 trials of 1200 s.
# 2. The table's demand against the F405's (`pada claims`).
# 3. On the F405's learner (`pada run --board f405`), PADA on the same seeds,
#    with each behaviour of a full table: refuse, replace, collide.
set -euo pipefail
cd "$(dirname "$0")/../../.."
source examples/robots/measure-lib.sh arm3 "$@"

for algo in sarsa pada; do
    learn "$algo" 1200 "$out/host-$algo" --trials 10
done
"$pada" claims --robot "$robot" --board f405 --seconds 1200
for full in refuse replace collide; do
    learn pada 1200 "$out/f405-$full" --board f405 --table-full "$full" --trials 10
done
