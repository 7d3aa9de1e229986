#!/usr/bin/env bash
# What one run of the main job costs with each method, at three tolerances:
# the table "The default path of a study" in docs/benchmarks.md.
#
# Usage: scripts/method-table.sh [ROUNDS] [SAMPLES]   (default 2 rounds, 50 samples per design = 1 000 runs)
#
# For every rtol (1e-6, 1e-8, 1e-9) and method (radau5, dp5, dop853, auto)
# a copy of studies/three_balls.toml runs with `study run --threads 1`;
# rounds alternate the order of the methods. Per run the fastest round's
# `wall_time_s` counts. Reads runs.parquet with pyarrow from bench/lean's
# virtual environment (made by bench/lean/run.sh). Not part of the tests or CI.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
rounds=${1:-2}
samples=${2:-50}
# shellcheck source=bench-setup.sh
source "$root/scripts/bench-setup.sh" methods

cases=()
for rtol in 1e-6 1e-8 1e-9; do
    for method in radau5 dp5 dop853 auto; do
        cases+=("${rtol}_$method")
    done
done
for round in $(seq "$rounds"); do
    order=("${cases[@]}")
    if [ $((round % 2)) -eq 0 ]; then
        mapfile -t order < <(printf '%s\n' "${cases[@]}" | tac)
    fi
    for case in "${order[@]}"; do
        rtol=${case%%_*}
        method=${case#*_}
        sed -e "s/^samples = [0-9]*/samples = $samples/" \
            -e "s/^method = .*/method = \"$method\"/" \
            -e "s/^rtol = .*/rtol = $rtol/" \
            -e "s|^seed = \(.*\)\$|seed = \1\noutput = \"$out/$case-$round\"|" \
            "$root/studies/three_balls.toml" >"$out/$case.toml"
        "$study" run "$out/$case.toml" --threads 1 --quiet >/dev/null
    done
done

"$python" - "$out" "$rounds" "${cases[@]}" <<'EOF'
import sys
import pyarrow.parquet as pq

out, rounds, cases = sys.argv[1], int(sys.argv[2]), sys.argv[3:]
print("| rtol | method | ms per run | RHS calls per run | steps per run | switched | mean t_s (rev) |")
print("| --- | --- | ---: | ---: | ---: | ---: | ---: |")
for case in cases:
    rtol, method = case.split("_", 1)
    tables = [pq.read_table(f"{out}/{case}-{r}/{case}/runs.parquet").to_pydict() for r in range(1, rounds + 1)]
    walls = [min(t["wall_time_s"][i] for t in tables) for i in range(len(tables[0]["wall_time_s"]))]
    t = tables[0]
    n = len(walls)
    switched = sum("→" in m for m in t["method"]) / n
    settled = [s for s in t["settling_revs"] if s is not None]
    shown = t["method"][0].split("→")[0] if method == "auto" else method
    name = f"**auto ({shown})**" if method == "auto" else method
    ms = f"**{1e3 * sum(walls) / n:.2f}**" if method == "auto" else f"{1e3 * sum(walls) / n:.2f}"
    sw = "–" if method == "radau5" else f"{100 * switched:.0f} %"
    print(f"| {rtol} | {name} | {ms} | {sum(t['rhs_calls']) / n:,.0f} | {sum(t['steps']) / n:,.0f} | {sw} | {sum(settled) / len(settled):.4f} |".replace(",", " "))
EOF
