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
out=${1:-pada-out/so101}
robot=examples/robots/so101
cargo build --release -q -p pada
pada=target/release/pada
mkdir -p "$out"

for algo in sarsa pada; do
    "$pada" run --robot "$robot" --algo "$algo" --trials 20 --seconds 1200 --threads 1 --out "$out/run-$algo"
done

for algo in pada sarsa; do
    for secs in 600 1200; do
        held=0
        for seed in 1 2 3 4 5 6 7 8 9 10; do
            dir="$out/hold-$algo-$secs/seed-$seed"
            mkdir -p "$dir"
            "$pada" run --robot "$robot" --algo "$algo" --trials 1 --seed "$seed" --seconds "$secs" --threads 1 \
                --out "$dir/run" --save-weights "$dir/weights.wts" > /dev/null
            line=$("$pada" render --robot "$robot" --policy "$dir/weights.wts" --out "$dir/render" | grep '^grip:')
            echo "$algo, $secs s, seed $seed: $line"
            [[ $line == *"not held"* ]] || held=$((held + 1))
        done
        echo "$algo, $secs s of learning: the grip point held within 2 cm in $held of 10 trials"
    done
done

"$pada" run --robot "$robot" --board f405 --algo pada --trials 1 --seconds 1200 --threads 1 --out "$out/board-f405"
