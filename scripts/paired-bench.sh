#!/usr/bin/env bash
# Paired speed comparison of two `study` binaries on this machine, in one run:
# interleaved (ABBA) single-thread runs of the main job at 100 samples per
# design, then `autobal-bench --quick --json` ABBA; prints medians and the
# after/before ratios. Build each binary from its commit and copy it aside
# with its `autobal-bench` beside it (the bench binary of the same build is
# found in the same folder; a build from before the two binaries were split
# answers `study bench` instead):
#   scripts/paired-bench.sh /tmp/before/study target/debug/study [rounds]
set -euo pipefail
before=$(realpath "$1")
after=$(realpath "$2")
rounds=${3:-3}
repo=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
sed 's/^samples = .*/samples = 100/' "$repo/studies/three_balls.toml" > "$work/study.toml"
cd "$work"
for _ in $(seq "$rounds"); do
  for which in before after after before; do
    bin=$before; [ "$which" = after ] && bin=$after
    rm -rf results
    start=$(date +%s.%N)
    "$bin" run study.toml --threads 1 --quiet > /dev/null
    end=$(date +%s.%N)
    echo "$which $start $end" >> times.txt
  done
done
for which in before after after before; do
  bin=$before; [ "$which" = after ] && bin=$after
  bench_bin=$(dirname "$bin")/autobal-bench
  if [ -x "$bench_bin" ]; then
    "$bench_bin" --quick --json > "bench-$which-$RANDOM.json"
  else
    "$bin" bench --quick --json > "bench-$which-$RANDOM.json"
  fi
done
python3 - <<'EOF'
import glob, json, statistics as st
t = {"before": [], "after": []}
for line in open("times.txt"):
    which, a, b = line.split()
    t[which].append(float(b) - float(a))
m = {k: st.median(v) for k, v in t.items()}
print(f"main job, 100 samples/design, 1 thread: before {m['before']:.3f} s, "
      f"after {m['after']:.3f} s, after/before {m['after'] / m['before']:.3f}")
rhs = {"before": [], "after": []}
solves = {"before": [], "after": []}
for f in glob.glob("bench-*.json"):
    which = f.split("-")[1]
    d = json.load(open(f))
    rhs[which].append([(p["cargoes"], p["ns_per_call"]) for p in d["rhs"]["points"]])
    solves[which].append([(s["method"], s["rtol"], s["median_ms"]) for s in d["solves"]])
for name, data in (("RHS ns/call by cargo count", rhs), ("solve ms by method, rtol", solves)):
    print(name + ", after/before:")
    for col_a, col_b in zip(zip(*data["after"]), zip(*data["before"])):
        label = col_a[0][:-1]
        ratio = st.median(x[-1] for x in col_a) / st.median(x[-1] for x in col_b)
        print(f"  {label}: {ratio:.3f}")
EOF
