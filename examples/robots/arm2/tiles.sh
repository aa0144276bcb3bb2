#!/usr/bin/env bash
# Measures how tile widths and the number of observed signals trade off on
# arm2, for docs/your-robot.md ("Tile widths and observed signals"), from
# the repository's root:
#   bash examples/robots/arm2/tiles.sh [OUT]       (about two minutes on two cores)
# Nine variants of arm2: its two joint angles, with the joint rates (four
# signals), and with the tip's x and z (six); each at narrow tiles (0.2 rad,
# 2 rad/s, 2 cm), medium (0.5 rad, 3 rad/s, 5 cm) and wide (1 rad, 4 rad/s,
# 10 cm). SARSA(lambda), 10 trials of 1200 s each, seed 1; the rest of
# arm2's robot.toml as it is.
set -euo pipefail
cd "$(dirname "$0")/../../.."
out=${1:-pada-out/arm2-tiles}
cargo build --release -q -p pada
pada=target/release/pada
arm=examples/robots/arm2
mkdir -p "$out"

# One [[observe]] table: signal, range, tile.
observe() { printf '[[observe]]\nsignal = "%s"\nrange = %s\ntile = %s\n\n' "$1" "$2" "$3"; }

for n in 2 4 6; do
    for width in narrow medium wide; do
        case $width in
            narrow) a=0.2; r=2.0; p=0.02 ;;
            medium) a=0.5; r=3.0; p=0.05 ;;
            wide) a=1.0; r=4.0; p=0.1 ;;
        esac
        dir="$out/$n-$width"
        mkdir -p "$dir"
        cp "$arm/arm2.urdf" "$dir/"
        {
            observe shoulder.angle "[-1.6, 1.6]" $a
            observe elbow.angle "[-2.4, 2.4]" $a
            if [ $n -ge 4 ]; then
                observe shoulder.rate "[-6.0, 6.0]" $r
                observe elbow.rate "[-6.0, 6.0]" $r
            fi
            if [ $n -ge 6 ]; then
                observe tip.x "[-0.25, 0.25]" $p
                observe tip.z "[-0.2, 0.3]" $p
            fi
        } > "$dir/observe.toml"
        # arm2's robot.toml with its [[observe]] tables replaced.
        awk -v obs="$dir/observe.toml" '
            /^\[\[observe\]\]/ && !done { while ((getline line < obs) > 0) print line; done = 1; skip = 1 }
            /^# Each joint:/ { skip = 0 }
            !skip { print }' "$arm/robot.toml" > "$dir/robot.toml"
        "$pada" run --robot "$dir/robot.toml" --algo sarsa --trials 10 --seconds 1200 --out "$dir/run" > "$dir/run.txt"
        echo "$n signals, $width: $(grep -E 'end performance|rise time|slots claimed' "$dir/run.txt" | tr -s ' ' | tr '\n' ';')"
    done
done
