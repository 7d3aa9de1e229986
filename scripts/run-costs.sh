#!/usr/bin/env bash
# Where users spend their time: per shipped study, the cost of a run (ms of
# the runs' own wall time, RHS calls) and how its runs end (issue 31's
# table; docs/benchmarks.md, "Cost per run of the shipped studies").
#
# Usage: scripts/run-costs.sh [THREADS] [STUDY ...]   (default 2 threads, every studies/*.toml but regression)
#
# Without STUDY arguments it then prints the second table of issue 31, the
# peer design against the lean DP5 (bench/lean/peer.sh, PEER_ROUNDS rounds of
# PEER_SAMPLES runs, default 3 and 1000; PEER_ROUNDS=0 skips it).
#
# Each study runs once as shipped, with `study run --threads THREADS`, into a
# fresh folder; the table is read from its runs.parquet (pyarrow, bench/lean's
# virtual environment). ms per run is the mean of the runs' own `wall_time_s`
# (each run is timed on its thread, so it does not shrink with more
# threads); "censored" counts runs simulated to the horizon without
# settling, "certified" the settled runs a certified hold ended early. Not
# part of the tests or CI (gravity_horizontal alone takes about a minute).
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
threads=${1:-2}
shift || true
# shellcheck source=bench-setup.sh
source "$root/scripts/bench-setup.sh" costs

peer_too=no
if [ "$#" -eq 0 ]; then
    peer_too=yes
    set -- $(cd "$root/studies" && ls ./*.toml | sed 's|^\./||; s|\.toml$||' | grep -v '^regression$')
fi
for name in "$@"; do
    sed -e "s|^seed = \(.*\)\$|seed = \1\noutput = \"$out\"|" \
        "$root/studies/$name.toml" >"$out/$name.toml"
    # A study whose runs fail exits 1 after writing everything: still measured.
    "$study" run "$out/$name.toml" --threads "$threads" --quiet --overwrite >/dev/null 2>&1 || true
done

"$python" - "$out" "$@" <<'EOF'
import sys
import pyarrow.parquet as pq

out, names = sys.argv[1], sys.argv[2:]
print(f"{'study':>20} {'runs':>6} {'ms per run':>11} {'RHS calls per run':>18} {'censored':>9} {'certified':>10}  outcomes")
for name in names:
    t = pq.read_table(f"{out}/{name}/runs.parquet",
                      columns=["outcome", "rhs_calls", "wall_time_s", "hold_certified"]).to_pydict()
    n = len(t["outcome"])
    ms = 1000 * sum(t["wall_time_s"]) / n
    rhs = sum(t["rhs_calls"]) / n
    counts = {}
    for o in t["outcome"]:
        counts[o] = counts.get(o, 0) + 1
    censored = counts.get("censored", 0)
    certified = sum(1 for c in t["hold_certified"] if c)
    mix = ", ".join(f"{k} {v}" for k, v in sorted(counts.items()))
    print(f"{name:>20} {n:>6} {ms:>11.2f} {rhs:>18.0f} {censored:>9} {certified:>10}  {mix}")
EOF

if [ "$peer_too" = yes ] && [ "${PEER_ROUNDS:-3}" -gt 0 ]; then
    echo
    "$root/bench/lean/peer.sh" "${PEER_ROUNDS:-3}" "${PEER_SAMPLES:-1000}"
fi
