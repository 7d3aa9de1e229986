#!/usr/bin/env bash
# Issue 31's peer design (bench/lean/peer.toml) against the lean reference:
# runs/s per core and RHS calls per run of `study run --threads 1` with
# contact on as the penalty model, on as rigid contact (the default), and
# off, and of the lean program (a careful DP5
# of this one design, full hold, contact off like the issue's peer) on the
# same runs. Rounds alternate which side goes first; per run the fastest
# round counts on each side (runs/s per core = runs / Σ per-run times).
#
# Usage: bench/lean/peer.sh [ROUNDS] [SAMPLES]   (default 3 rounds, 1000 samples)
#        PROFILE=release bench/lean/peer.sh ...  (autobal's release build; default
#        the dev build the README's commands use)
# Not part of the tests or CI.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
rounds=${1:-3}
samples=${2:-1000}
# shellcheck source=../venv.sh
source "$here/../venv.sh"

(cd "$here" && export CARGO_TARGET_DIR="$here/target" && cargo build --quiet --release)
lean=$here/target/release/autobal-lean
profile=${PROFILE:-debug}
case "$profile" in
    debug) (cd "$root" && cargo build --quiet --bin study --bin autobal-bench) ;;
    release) (cd "$root" && cargo build --quiet --release --bin study --bin autobal-bench) ;;
    *) echo "PROFILE must be debug or release, not '$profile'" >&2; exit 2 ;;
esac
study=${CARGO_TARGET_DIR:-$root/target}/$profile/study
bench=${CARGO_TARGET_DIR:-$root/target}/$profile/autobal-bench

out=${OUT:-$(mktemp -d "${TMPDIR:-/tmp}/autobal-peer.XXXXXX")}
mkdir -p "$out"
echo "results: $out   (autobal $profile build; load average: $(cut -d' ' -f1-3 /proc/loadavg 2>/dev/null || echo unknown))" >&2
for contact in on rigid off; do
    enabled=true
    [ "$contact" = off ] && enabled=false
    model=penalty
    [ "$contact" = rigid ] && model=rigid
    sed -e "s/^samples = [0-9]*/samples = $samples/" \
        -e "s/^enabled = .*/enabled = $enabled\nmodel = \"$model\"/" \
        -e "s|^seed = \(.*\)\$|seed = \1\noutput = \"$out/study\"|" \
        "$here/peer.toml" >"$out/peer_$contact.toml"
done
"$bench" --lean-inputs "$out/runs.csv" --lean-study "$out/peer_off.toml" --samples "$samples"

run_autobal() {
    for contact in on rigid off; do
        "$study" run "$out/peer_$contact.toml" --threads 1 --quiet --overwrite >/dev/null
        cp "$out/study/peer_$contact/runs.parquet" "$out/autobal-$contact-$1.parquet"
    done
}
for r in $(seq 1 "$rounds"); do
    if [ $((r % 2)) -eq 1 ]; then
        run_autobal "$r"; "$lean" "$out/runs.csv" >"$out/lean-$r.txt"
    else
        "$lean" "$out/runs.csv" >"$out/lean-$r.txt"; run_autobal "$r"
    fi
done

"$venv/bin/python" - "$out" <<'PY'
import glob, math, sys
import pyarrow.parquet as pq
out = sys.argv[1]
def autobal(contact):
    best, calls = {}, {}
    for path in sorted(glob.glob(f"{out}/autobal-{contact}-*.parquet")):
        d = pq.read_table(path, columns=["run_id", "wall_time_s", "rhs_calls"]).to_pydict()
        for rid, w, c in zip(d["run_id"], d["wall_time_s"], d["rhs_calls"]):
            best[rid] = min(best.get(rid, math.inf), w)
            calls[rid] = c
    return best, calls
def lean():
    best, calls = {}, {}
    for path in sorted(glob.glob(f"{out}/lean-*.txt")):
        for line in open(path):
            f = line.split()
            if f and f[0] == "LEANRUN":
                rid = int(f[1])
                best[rid] = min(best.get(rid, math.inf), float(f[2]))
                calls[rid] = int(f[3])
    return best, calls
lt, lc = lean()
lean_rate = len(lt) / sum(lt.values())
print(f"{'path':<40} {'runs':>5} {'runs/s per core':>16} {'vs lean':>8} {'RHS calls per run':>18}")
print(f"{'lean DP5, contact off, full hold':<40} {len(lt):>5} {lean_rate:>16.0f} {1.0:>8.2f} {sum(lc.values()) / len(lc):>18.0f}")
for contact, label in (("on", "on (penalty)"), ("rigid", "on (rigid)"), ("off", "off")):
    t, c = autobal(contact)
    rate = len(t) / sum(t.values())
    print(f"{'study run --threads 1, contact ' + label:<40} {len(t):>5} {rate:>16.0f} {rate / lean_rate:>8.2f} {sum(c.values()) / len(c):>18.0f}")
PY
echo "(load average after: $(cut -d' ' -f1-3 /proc/loadavg 2>/dev/null || echo unknown))"
