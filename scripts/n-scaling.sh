#!/usr/bin/env bash
# Cost per run against the number of weights: the table "Cost per run against
# the number of weights" in docs/benchmarks.md.
#
# Usage: [RHO=ρ] scripts/n-scaling.sh [SAMPLES] [N...]   (default 5 samples, n = 2 4 8 16 32)
#
# Balls at half-race fill (rho = "half_race": packed weights touch; RHO=0.02
# for balls too light to balance, whose runs all end in the same
# quasi-steady whirl) on the main job's rotor, drag 10 N·s/m, one study per
# n, `study run --threads 1`;
# per run its own `wall_time_s`. Reads runs.parquet with pyarrow from
# bench/lean's virtual environment (made by bench/lean/run.sh). Not part of
# the tests or CI.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
samples=${1:-5}
shift || true
ns=("$@")
[ ${#ns[@]} -gt 0 ] || ns=(2 4 8 16 32)
# shellcheck source=bench-setup.sh
source "$root/scripts/bench-setup.sh" n

for n in "${ns[@]}"; do
    sed -e "s/^samples = [0-9]*/samples = $samples/" \
        -e "s/^n = .*/n = $n/" \
        -e "s/^rho = .*/rho = ${RHO:-\"half_race\"}/" \
        -e "s/^drag = .*/drag = 10.0/" \
        -e "s|^seed = \(.*\)\$|seed = \1\noutput = \"$out\"|" \
        "$root/studies/three_balls.toml" >"$out/n$n.toml"
    "$study" run "$out/n$n.toml" --threads 1 --quiet >/dev/null 2>&1
done

"$python" - "$out" "${ns[@]}" <<'EOF'
import math
import sys
from collections import Counter
import pyarrow.parquet as pq

out, ns = sys.argv[1], sys.argv[2:]
print("| n | ms per run | RHS calls per run | steps per run | µs per step and weight "
      "| revolutions per run | µs per revolution and weight | settled | method |")
print("| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- |")
for n in ns:
    t = pq.read_table(f"{out}/n{n}/runs.parquet").to_pydict()
    k = len(t["wall_time_s"])
    wall = sum(t["wall_time_s"])
    # Simulated revolutions (the speed is constant): settled runs stop early.
    revs = sum(tf * w / (2 * math.pi) for tf, w in zip(t["t_final"], t["final_spin_rate"]))
    methods = ", ".join(f"{m} {c}" for m, c in Counter(t["method"]).most_common())
    print(f"| {n} | {1e3 * wall / k:,.2f} | {sum(t['rhs_calls']) / k:,.0f} "
          f"| {sum(t['steps']) / k:,.0f} | {1e6 * wall / sum(t['steps']) / int(n):.2f} "
          f"| {revs / k:,.0f} | {1e6 * wall / revs / int(n):.2f} "
          f"| {100 * sum(t['settled']) / k:.0f} % | {methods} |".replace(",", " "))
EOF
