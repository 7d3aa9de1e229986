#!/usr/bin/env bash
# Every table of docs/validation.md, in the page's order: the washer cases
# (Table 2 and Fig. 12, the run-up, the ball angles), the bands over the
# unknowns, the calibration on Fig. 12 and the protocol's effect at the
# fitted values, and the ball angles as a fitted point. About 35 minutes
# on two cores, after `cargo build`;
# Python with numpy, scipy and polars.
# Usage: scripts/bristol-validation.sh [path/to/study] [output folder]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
study="${1:-$root/target/debug/study}"
out="${2:-$root/results/calibrate/bristol_fig12}"
python3 "$root/scripts/calibrate-bristol-rig.py"
python3 "$root/scripts/bristol-rig-cases.py" "$study"
python3 "$root/scripts/bristol-uncertain-bands.py" "$study" 64
"$study" calibrate "$root/rigs/bristol_fig12.toml" --draws 32 --restarts 2 --budget 30 \
  --out "$out" --overwrite
# The fitted values, read back from the calibration's own file.
fit=$(python3 - "$out/calibration.parquet" <<'PY'
import sys
import polars as pl
rows = {r["key"]: r["fit"] for r in pl.read_parquet(sys.argv[1]).iter_rows(named=True)}
print(rows["effects.rolling_resistance.coefficient"], rows["balancer.drag"],
      rows["effects.race_eccentricity.angle_deg"])
PY
)
# shellcheck disable=SC2086
python3 "$root/scripts/bristol-protocol.py" "$study" $fit
# The ball angles as a fitted point (about 16 minutes more).
"$study" calibrate "$root/rigs/bristol_fig12_angles.toml" --draws 32 --restarts 2 --budget 30 \
  --out "$out-angles" --overwrite
# The paper's protocol (about 90 minutes more) and the hardened-bearing
# build are documented with their own commands in docs/validation.md.
