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
cargo build --release -q -p pada

# learn ALGO SECONDS DIR [pada run's other flags…]: one `pada run` of the arm.
learn() {
    local algo=$1 secs=$2 dir=$3
    shift 3
    mkdir -p "$dir"
    target/release/pada run --robot examples/robots/so101 --algo "$algo" --seconds "$secs" --threads 1 --out "$dir/run" "$@"
}

learn sarsa 1200 "$out/sarsa" --trials 20
learn pada 1200 "$out/pada" --trials 20

for algo in pada sarsa; do
    for secs in 600 1200; do
        held=0
        for seed in $(seq 1 10); do
            dir="$out/hold-$algo-$secs/seed-$seed"
            learn "$algo" "$secs" "$dir" --trials 1 --seed "$seed" --save-weights "$dir/weights.wts" > /dev/null
            line=$(target/release/pada render --robot examples/robots/so101 --policy "$dir/weights.wts" --out "$dir/render" | grep '^grip:')
            echo "$algo, $secs s, seed $seed: $line"
            [[ $line == *"not held"* ]] || held=$((held + 1))
        done
        echo "$algo, $secs s of learning: the grip point held within 2 cm in $held of 10 trials"
    done
done

learn pada 1200 "$out/board-f405" --trials 1 --board f405
