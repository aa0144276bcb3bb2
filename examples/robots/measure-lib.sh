# What each robot's measure.sh shares, sourced from the repository's root:
#   source examples/robots/measure-lib.sh NAME [OUT]
# Builds pada for release and sets `pada` (the binary), `robot`
# (examples/robots/NAME/robot.toml) and `out` (OUT, else pada-out/NAME,
# created).

pada=target/release/pada
robot=examples/robots/$1/robot.toml
out=${2:-pada-out/$1}
cargo build --release -q -p pada
mkdir -p "$out"

# learn ALGO SECONDS DIR [pada run's other flags…]: one `pada run` of the
# robot, its results in DIR.
learn() {
    local algo=$1 secs=$2 dir=$3
    shift 3
    "$pada" run --robot "$robot" --algo "$algo" --seconds "$secs" --out "$dir" "$@"
}

# hold ALGO SECONDS DIR POINT NAME [pada run's other flags…]: ALGO learns
# for SECONDS with seeds 1..10, one trial each (in DIR/seed-N), and
# `pada render --robot` judges each greedy run by its line `POINT: …` (the
# point, NAME, within 2 cm of its target over the episode's last half); a
# line a trial and one of how many held.
hold() {
    local algo=$1 secs=$2 dir=$3 point=$4 name=$5 held=0 seed line
    shift 5
    for seed in $(seq 1 10); do
        mkdir -p "$dir/seed-$seed"
        learn "$algo" "$secs" "$dir/seed-$seed/run" --trials 1 --seed "$seed" --save-weights "$dir/seed-$seed/weights.wts" "$@" > /dev/null
        line=$("$pada" render --robot "$robot" --policy "$dir/seed-$seed/weights.wts" --out "$dir/seed-$seed/render" | grep "^$point:")
        echo "$algo, $secs s, seed $seed: $line"
        [[ $line == *"not held"* ]] || held=$((held + 1))
    done
    echo "$algo, $secs s of learning: the $name held within 2 cm in $held of 10 trials"
}
