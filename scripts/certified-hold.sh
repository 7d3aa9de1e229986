#!/usr/bin/env bash
# The certified hold against the full hold on the main job: the table
# "Certified hold: on by default" in docs/benchmarks.md.
#
# Usage: scripts/certified-hold.sh [ROUNDS] [SAMPLES]   (default 3 rounds, 100 samples per design = 2 000 runs)
#
# Each round runs `study run --threads 1` on a copy of studies/three_balls.toml
# with `metrics.certified_hold = false`, then on one as shipped (certified
# hold on), and prints both times: the whole `study run`, and the runs' own
# time (per run the fastest round's `wall_time_s`, summed). The last round's
# two runs.parquet are compared run by run (pyarrow, bench/lean's virtual
# environment). Not part of the tests or CI.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
rounds=${1:-3}
samples=${2:-100}
# shellcheck source=bench-setup.sh
source "$root/scripts/bench-setup.sh" certified

sed -e "s/^samples = [0-9]*/samples = $samples/" \
    -e "s|^seed = \(.*\)\$|seed = \1\noutput = \"$out\"|" \
    "$root/studies/three_balls.toml" >"$out/certified.toml"
sed -e "s/^hold_revs = \(.*\)/hold_revs = \1\ncertified_hold = false/" \
    "$out/certified.toml" >"$out/full.toml"

for round in $(seq "$rounds"); do
    for hold in full certified; do
        t0=$(date +%s.%N)
        "$study" run "$out/$hold.toml" --threads 1 --quiet --overwrite >/dev/null 2>&1
        t1=$(date +%s.%N)
        echo "$round $hold $(echo "$t1 - $t0" | bc)" >>"$out/walls.txt"
        cp "$out/$hold/runs.parquet" "$out/$hold-$round.parquet"
    done
done

"$python" - "$out" <<'EOF'
import glob
import sys
import pyarrow.parquet as pq

out = sys.argv[1]
cols = ["run_id", "settling_revs", "settling_time_eps", "outcome", "residual_rel", "min_gap_rad",
        "peak_r", "rhs_calls", "wall_time_s", "hold_certified"]
full = pq.read_table(f"{out}/full/runs.parquet", columns=cols).to_pydict()
cert = pq.read_table(f"{out}/certified/runs.parquet", columns=cols).to_pydict()
assert full["run_id"] == cert["run_id"]
n = len(full["run_id"])
same = {c: sum(a == b for a, b in zip(full[c], cert[c])) for c in
        ["settling_revs", "settling_time_eps", "outcome", "min_gap_rad", "peak_r"]}
moved = sorted(abs(b / a - 1) for a, b in zip(full["residual_rel"], cert["residual_rel"]) if a > 0)
walls = {}
for line in open(f"{out}/walls.txt"):
    _, hold, secs = line.split()
    walls.setdefault(hold, []).append(float(secs))
print(f"{n} runs; identical: " + ", ".join(f"{c} {k}/{n}" for c, k in same.items()))
print(f"residual change: max {moved[-1]:.2e}, q99 {moved[int(0.99 * (len(moved) - 1))]:.2e}")
print(f"ended early: {sum(cert['hold_certified']) / n:.1%}")
print(f"RHS calls per run: full {sum(full['rhs_calls']) / n:.0f}, certified {sum(cert['rhs_calls']) / n:.0f}")
def fastest(hold):
    best = {}
    for path in glob.glob(f"{out}/{hold}-*.parquet"):
        d = pq.read_table(path, columns=["run_id", "wall_time_s"]).to_pydict()
        for rid, w in zip(d["run_id"], d["wall_time_s"]):
            best[rid] = min(best.get(rid, float("inf")), w)
    return sum(best.values())


f, c = fastest("full"), fastest("certified")
print(f"run time (fastest round per run): full {f:.3f} s, certified {c:.3f} s, ratio {c / f:.3f}")
for hold in ("full", "certified"):
    print(f"whole study run, {hold}: " + " ".join(f"{w:.3f}" for w in walls[hold]) + " s")
EOF
