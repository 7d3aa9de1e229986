#!/usr/bin/env bash
# Racing against the full study over seeds: bench/racing/seeds.sh [N] [STUDY]
# runs STUDY (default studies/three_balls.toml) with seed = 1..N, raced
# (the default) and with `racing = false`, and compares what each decides
# (decide.py). Folders go to target/racing-seeds/.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
# shellcheck source=../venv.sh
source "$here/../venv.sh"
n=${1:-10}
study=$(cd "$root" && realpath "${2:-studies/three_balls.toml}")
work=$root/target/racing-seeds
mkdir -p "$work"
# STUDY_BIN: a study binary already built (default: a release build).
bin=${STUDY_BIN:-}
if [ -z "$bin" ]; then
    (cd "$root" && cargo build --release --quiet)
    bin=$root/target/release/study
fi
name=$(basename "$study" .toml)
for seed in $(seq 1 "$n"); do
    for variant in raced full; do
        file=$work/${name}_${variant}_$seed.toml
        {
            echo "name = \"${name}_${variant}_$seed\""
            echo "output = \"$work/results\""
            grep -v '^#:schema' "$study" | sed "s/^seed = .*/seed = $seed/"
        } >"$file"
        if [ "$variant" = full ]; then
            sed -i 's/^\[sampling\]$/[sampling]\nracing = false/' "$file"
        fi
        "$bin" run "$file" --overwrite --quiet >/dev/null 2>"${file%.toml}.log"
    done
    echo "seed $seed:"
    "$py" "$here/decide.py" "$work/results/${name}_raced_$seed" "$work/results/${name}_full_$seed"
done
