#!/usr/bin/env bash
# Every table of docs/validation.md, in the page's order: the washer cases
# (Table 2 and Fig. 12, the run-up, the ball angles), the bands over the
# unknowns, the calibration on Fig. 12 and the protocol's effect at the
# fitted values, the ball angles as a fitted point, and the refitted cover
# and the race-ball clearance at the paper-protocol fit. About 40 minutes
# on two cores, after `cargo build`; with PAPER_PROTOCOL=1 also the
# calibration on the paper's protocol first (about 90 minutes more), whose
# fit the last step then uses.
# Python with numpy, scipy and polars.
# Usage: [PAPER_PROTOCOL=1] scripts/bristol-validation.sh [path/to/study] [output folder]
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
fitted() {
  python3 - "$1/calibration.parquet" <<'PY'
import sys
import polars as pl
rows = {r["key"]: r["fit"] for r in pl.read_parquet(sys.argv[1]).iter_rows(named=True)}
print(rows["effects.rolling_resistance.coefficient"], rows["balancer.drag"],
      rows["effects.race_eccentricity.angle_deg"])
PY
}
fit=$(fitted "$out")
# shellcheck disable=SC2086
python3 "$root/scripts/bristol-protocol.py" "$study" $fit
# The ball angles as a fitted point (about 16 minutes more).
"$study" calibrate "$root/rigs/bristol_fig12_angles.toml" --draws 32 --restarts 2 --budget 30 \
  --out "$out-angles" --overwrite
# The paper's protocol: its calibration (PAPER_PROTOCOL=1), else the fit
# docs/validation.md records for it ("Calibrated on the paper's protocol").
paper_fit="7.6e-4 4.2e-2 46"
if [ "${PAPER_PROTOCOL:-0}" = 1 ]; then
  "$study" calibrate "$root/rigs/bristol_fig12_paper_protocol.toml" --draws 20 --restarts 2 \
    --budget 24 --out "$out-paper-protocol" --overwrite
  paper_fit=$(fitted "$out-paper-protocol")
fi
# The refitted cover's change of unbalance and the race-ball clearance.
# shellcheck disable=SC2086
python3 "$root/scripts/bristol-cover-and-clearance.py" "$study" $paper_fit 0.1,0.25,0.5
# The hardened-bearing build has its own commands in docs/validation.md.
