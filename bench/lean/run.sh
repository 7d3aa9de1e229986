#!/usr/bin/env bash
# The lean reference against autobal's default path on the same runs, same
# machine, same invocation: runs/s per core, RHS calls per run, ns per RHS
# call, and whether both give the same settling times.
#
# Usage: bench/lean/run.sh [ROUNDS] [SAMPLES]   (default 3 rounds, 20 samples per design = 400 runs)
# Environment: OUT (folder for the files; default a fresh temp folder), CARGO_TARGET_DIR as cargo.
#
# autobal runs as `study run --threads 1` in the main crate's dev profile
# (autobal at opt-level 2, debug assertions on); the lean program is built
# with the same settings (its `--release` profile, see Cargo.toml) and, for
# reference, at opt-level 3 (`--profile full`). Each round runs autobal,
# then both lean builds, alternating which side goes first. Not part of the tests or CI.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
rounds=${1:-3}
samples=${2:-20}

# shellcheck source=../venv.sh
source "$here/../venv.sh"

# Its own target folder: CARGO_TARGET_DIR is the main crate's.
(cd "$here" && export CARGO_TARGET_DIR="$here/target" &&
    cargo build --quiet --release && cargo build --quiet --profile full)
lean_matched=$here/target/release/autobal-lean
lean_full=$here/target/full/autobal-lean
(cd "$root" && cargo build --quiet --bin study --bin autobal-bench)
study=${CARGO_TARGET_DIR:-$root/target}/debug/study
bench=${CARGO_TARGET_DIR:-$root/target}/debug/autobal-bench

out=${OUT:-$(mktemp -d "${TMPDIR:-/tmp}/autobal-lean.XXXXXX")}
mkdir -p "$out"
rm -f "$out"/autobal-*.parquet "$out"/lean-*.txt "$out"/walls.txt
echo "results: $out   (load average: $(cut -d' ' -f1-3 /proc/loadavg 2>/dev/null || echo unknown))" >&2

"$bench" --lean-inputs "$out/runs.csv" --samples "$samples"
# The same plan for `study run`: the main job with its samples cut down and
# its output in $out (the draws depend on the seed, design and sample only).
# Twice: by default (certified hold) and holding every window to its end,
# the lean program's rule (`metrics.certified_hold = false`).
sed -e "s/^samples = [0-9]*/samples = $samples/" \
    -e "s|^seed = \(.*\)\$|seed = \1\noutput = \"$out/study\"|" \
    "$root/studies/three_balls.toml" >"$out/three_balls.toml"
sed -e "s/^hold_revs = \(.*\)/hold_revs = \1\ncertified_hold = false/" \
    "$out/three_balls.toml" >"$out/full_hold.toml"

run_autobal() {
    local t0 t1
    t0=$(date +%s.%N)
    "$study" run "$out/three_balls.toml" --threads 1 --quiet --overwrite >/dev/null
    t1=$(date +%s.%N)
    echo "$t1 - $t0" | bc >>"$out/walls.txt"
    cp "$out/study/three_balls/runs.parquet" "$out/autobal-certified-$1.parquet"
    "$study" run "$out/full_hold.toml" --threads 1 --quiet --overwrite >/dev/null
    cp "$out/study/full_hold/runs.parquet" "$out/autobal-full-$1.parquet"
}
run_lean() {
    "$lean_matched" "$out/runs.csv" >"$out/lean-matched-$1.txt"
    "$lean_full" "$out/runs.csv" >"$out/lean-full-$1.txt"
}

for r in $(seq 1 "$rounds"); do
    if [ $((r % 2)) -eq 1 ]; then run_autobal "$r"; run_lean "$r"; else run_lean "$r"; run_autobal "$r"; fi
done
grep -v '^LEAN' "$out/lean-matched-1.txt"
echo
"$venv/bin/python" "$here/summarize.py" "$out"
echo "(load average after: $(cut -d' ' -f1-3 /proc/loadavg 2>/dev/null || echo unknown); $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'))"
