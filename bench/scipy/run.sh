#!/usr/bin/env bash
# SciPy's solve_ivp (DOP853, RK45) against autobal on the same problem, same
# tolerances, same horizon; prints SciPy's time per solve over autobal's.
#
# Usage: bench/scipy/run.sh [ROUNDS]          (default 7 rounds)
# Environment:
#   AUTOBAL_REPEATS  autobal solves per case per round (default 21)
#   SCIPY_REPEATS    SciPy solves per case per round (default 1)
#   REVOLUTIONS      horizon (default 500)
#   SCIPY_RHS        auto (default: the faster translation), numpy or scalar
#   OUT              folder for the per-round JSON files (default: a fresh temp folder)
#   CARGO_TARGET_DIR honoured as by cargo
#
# Each round runs autobal's solves (`autobal-bench --peer-cases --json`) and then
# SciPy's, alternating which goes first, so that load from other processes
# hits both sides alike; the report pools all rounds (medians) and also gives
# the median of the per-round ratios. Not part of the tests or CI.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
rounds=${1:-7}
autobal_repeats=${AUTOBAL_REPEATS:-21}
scipy_repeats=${SCIPY_REPEATS:-1}
revolutions=${REVOLUTIONS:-500}
scipy_rhs=${SCIPY_RHS:-auto}

# shellcheck source=../venv.sh
source "$here/../venv.sh"

(cd "$root" && cargo build --release --quiet --bin autobal-bench)
bench=${CARGO_TARGET_DIR:-$root/target}/release/autobal-bench

out=${OUT:-$(mktemp -d "${TMPDIR:-/tmp}/autobal-scipy.XXXXXX")}
mkdir -p "$out"
rm -f "$out"/autobal-*.json "$out"/scipy-*.json
echo "results: $out   (load average: $(cut -d' ' -f1-3 /proc/loadavg 2>/dev/null || echo unknown))"

# SciPy reads start, tolerances, RHS samples and autobal's final states from
# here (all deterministic; only the times differ between autobal runs).
"$bench" --peer-cases --json --revolutions "$revolutions" --repeats 1 >"$out/input.json"

run_autobal() {
    "$bench" --peer-cases --json --revolutions "$revolutions" \
        --repeats "$autobal_repeats" >"$out/autobal-$1.json"
}
run_scipy() {
    "$py" "$here/scipy_peer.py" solve --autobal "$out/input.json" \
        --repeats "$scipy_repeats" --rhs "$scipy_rhs" --out "$out/scipy-$1.json" --quiet
}

for r in $(seq -w 1 "$rounds"); do
    if (( 10#$r % 2 == 1 )); then
        run_autobal "$r"
        run_scipy "$r"
    else
        run_scipy "$r"
        run_autobal "$r"
    fi
    echo "round $r of $rounds done"
done
echo "load average: $(cut -d' ' -f1-3 /proc/loadavg 2>/dev/null || echo unknown)"
echo

"$py" "$here/scipy_peer.py" report --dir "$out"
