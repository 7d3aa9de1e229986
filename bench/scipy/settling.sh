#!/usr/bin/env bash
# SciPy with autobal's settling observer against autobal's default path, per
# solve, on the runs of the main job (issue 17: "≥ 100× SciPy solve_ivp
# (DOP853, same tolerances, same observer) per solve").
#
# Usage: bench/scipy/settling.sh [SAMPLES] [STRIDE] [ROUNDS]
#   SAMPLES  samples per design of the main job's plan (default 20: 400 runs)
#   STRIDE   SciPy solves every STRIDE-th run (default 10: 40 runs, every design twice)
#   ROUNDS   autobal rounds; a run's time is its fastest (default 3)
# Environment: OUT (folder for the files; default a fresh temp folder), CARGO_TARGET_DIR as cargo.
#
# autobal runs as `study run --threads 1` in the dev profile (as the README's
# main job and bench/lean/run.sh), by default (certified hold) and with
# `metrics.certified_hold = false` (the full hold, the observer SciPy runs
# here); each run's own `wall_time_s`. SciPy runs settling_peer.py with RK45
# (the Dormand–Prince pair of autobal's dp5) and DOP853. Not part of the
# tests or CI; takes a few minutes (SciPy crawls through the stiff runs that
# autobal hands to Radau5).
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
samples=${1:-20}
stride=${2:-10}
rounds=${3:-3}

# shellcheck source=../venv.sh
source "$here/../venv.sh"

(cd "$root" && cargo build --quiet --bin study --bin autobal-bench)
study=${CARGO_TARGET_DIR:-$root/target}/debug/study
bench=${CARGO_TARGET_DIR:-$root/target}/debug/autobal-bench

out=${OUT:-$(mktemp -d "${TMPDIR:-/tmp}/autobal-settling.XXXXXX")}
mkdir -p "$out"
echo "results: $out   (load average: $(cut -d' ' -f1-3 /proc/loadavg 2>/dev/null || echo unknown))" >&2

"$bench" --lean-inputs "$out/runs.csv" --samples "$samples" >&2
sed -e "s/^samples = [0-9]*/samples = $samples/" \
    -e "s|^seed = \(.*\)\$|seed = \1\noutput = \"$out/study\"|" \
    "$root/studies/three_balls.toml" >"$out/three_balls.toml"
sed -e "s/^hold_revs = \(.*\)/hold_revs = \1\ncertified_hold = false/" \
    "$out/three_balls.toml" >"$out/full_hold.toml"
for r in $(seq 1 "$rounds"); do
    "$study" run "$out/three_balls.toml" --threads 1 --quiet --overwrite >/dev/null
    cp "$out/study/three_balls/runs.parquet" "$out/autobal-certified-$r.parquet"
    "$study" run "$out/full_hold.toml" --threads 1 --quiet --overwrite >/dev/null
    cp "$out/study/full_hold/runs.parquet" "$out/autobal-full-$r.parquet"
done
for method in RK45 DOP853; do
    "$py" "$here/settling_peer.py" "$out/runs.csv" --method "$method" --stride "$stride" \
        --runs 100000 --out "$out/scipy-$method.csv" 2>/dev/null
done

"$py" - "$out" "$rounds" <<'EOF'
import csv
import statistics
import sys

import pyarrow.parquet as pq

out, rounds = sys.argv[1], int(sys.argv[2])


def autobal(kind):
    """Fastest wall time per run over the rounds, and the runs' answers."""
    best, answer = {}, {}
    for r in range(1, rounds + 1):
        t = pq.read_table(f"{out}/autobal-{kind}-{r}.parquet").to_pydict()
        for i, run in enumerate(t["run_id"]):
            best[run] = min(best.get(run, float("inf")), t["wall_time_s"][i])
            answer[run] = (t["outcome"][i], t["settling_revs"][i], t["method"][i])
    return best, answer


print("| SciPy | autobal | runs | SciPy s per run | autobal ms per run | ratio of totals | median ratio | min ratio | same outcome and settling time | SciPy RHS calls per run |")
print("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
for method in ["RK45", "DOP853"]:
    with open(f"{out}/scipy-{method}.csv", newline="") as f:
        scipy = {int(r["run_id"]): r for r in csv.DictReader(f)}
    for kind, label in [("certified", "default (certified hold)"), ("full", "full hold")]:
        best, answer = autobal(kind)
        ids = sorted(scipy)
        ratios = [float(scipy[i]["seconds"]) / best[i] for i in ids]
        same = 0
        for i in ids:
            outcome, settling, _ = answer[i]
            s = scipy[i]["settling_revs"]
            if scipy[i]["outcome"] == outcome and (
                (settling is None and s == "") or (s != "" and settling is not None and abs(float(s) - settling) < 1e-9)
            ):
                same += 1
        total_scipy = sum(float(scipy[i]["seconds"]) for i in ids)
        total_autobal = sum(best[i] for i in ids)
        rhs = statistics.mean(int(scipy[i]["rhs_calls"]) for i in ids)
        print(
            f"| {method} | {label} | {len(ids)} | {total_scipy / len(ids):.3f} | {1e3 * total_autobal / len(ids):.3f} "
            f"| **{total_scipy / total_autobal:.0f}** | {statistics.median(ratios):.0f} | {min(ratios):.0f} "
            f"| {same}/{len(ids)} | {rhs:,.0f} |".replace(",", " ")
        )
stiff = sum(1 for m in autobal("certified")[1].values() if m[2] != "dp5")
print(f"\n(autobal: {rounds} rounds, fastest per run, one thread, dev profile; of the plan's runs {stiff} hand over to Radau5)")
EOF
echo "(load average after: $(cut -d' ' -f1-3 /proc/loadavg 2>/dev/null || echo unknown); $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'))"
