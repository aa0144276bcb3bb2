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
out=${1:-pada-out/arm2}
robot=examples/robots/arm2/robot.toml
cargo build --release -q -p pada
pada=target/release/pada
mkdir -p "$out"

for algo in sarsa pada; do
    "$pada" run --robot "$robot" --algo "$algo" --trials 20 --seconds 1200 --threads 1 --out "$out/run-$algo"
done

for secs in 300 600 1200; do
    held=0
    for seed in 1 2 3 4 5 6 7 8 9 10; do
        dir="$out/hold-$secs/seed-$seed"
        mkdir -p "$dir"
        "$pada" run --robot "$robot" --algo pada --trials 1 --seed "$seed" --seconds "$secs" --threads 1 \
            --out "$dir/run" --save-weights "$dir/weights.wts" > /dev/null
        line=$("$pada" render --robot "$robot" --policy "$dir/weights.wts" --out "$dir/render" | grep '^tip:')
        echo "pada, $secs s, seed $seed: $line"
        [[ $line == *"not held"* ]] || held=$((held + 1))
    done
    echo "pada, $secs s of learning: the tip held within 2 cm in $held of 10 trials"
done
