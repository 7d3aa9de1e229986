#!/usr/bin/env python3
"""The Bristol rig's Fig. 12 ratios and onset speed as bands over what was
not measured (docs/validation.md, "Fig. 12 as a band").

Each of the five washer cases of Table 2 (as scripts/bristol-rig-cases.py
writes them) is swept with `study stepped --draws N` over
scenes/bristol_uncertain.toml's uncertain keys: the balls' rolling
resistance (log-uniform 3e-4..3e-3) and the direction of the race's 5 um
eccentricity (uniform). Per draw: the mean over the 4000-5000 rpm steps of
the bearings' mean peak over the same without the balls' unbalance (the
paper's Fig. 12 measure), and the onset of balancing on the run-up. Prints
the 5 %, 50 % and 95 % quantiles over the draws beside the paper.

Usage: python3 scripts/bristol-uncertain-bands.py [STUDY_BINARY] [DRAWS]
(after `cargo build`; about 1 minute per 32 draws on two cores).
"""

import importlib.util
import json
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
STUDY = sys.argv[1] if len(sys.argv) > 1 else str(ROOT / "target/debug/study")
DRAWS = sys.argv[2] if len(sys.argv) > 2 else "32"
SCENE = (ROOT / "scenes/bristol_uncertain.toml").read_text()
# Table 2 and the paper's Fig. 12 ratios, from the rig-cases script (one copy).
_CASES = importlib.util.spec_from_file_location("cases", ROOT / "scripts/bristol-rig-cases.py")
cases = importlib.util.module_from_spec(_CASES)
_CASES.loader.exec_module(cases)
M, JT_MINUS_JP, TABLE2, PAPER_FIG12 = cases.M, cases.JT_MINUS_JP, cases.TABLE2, cases.PAPER_FIG12
PAPER_ONSET = 3000


def scene(washers):
    ecc, chi, beta = TABLE2[washers]
    return (
        SCENE.replace("static_unbalance = 3.712e-5", f"static_unbalance = {M * ecc * 1e-3:.6e}")
        .replace("static_angle_deg = 224.0", f"static_angle_deg = {beta}")
        .replace("moment_unbalance = 8.54e-7", f"moment_unbalance = {chi * JT_MINUS_JP:.6e}")
    )


def draws(text):
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "scene.toml"
        path.write_text(text)
        args = [STUDY, "stepped", str(path), "--rpm", "1000..5000", "--step-rpm", "50",
                "--dwell", "0.25", "--up-only", "--draws", DRAWS, "--json"]
        out = subprocess.run(args, capture_output=True, text=True)
        if out.returncode != 0:
            sys.exit(out.stderr)
        return json.loads(out.stdout)


def ratio(step):
    peaks, without = step["bearing_peak"], step["bearing_peak_without"]
    return (sum(peaks) / len(peaks)) / (sum(without) / len(without))


def rpm(step):
    return step["omega"] * 30 / 3.141592653589793


def quantiles(values):
    """5 %, 50 % and 95 % with linear interpolation (the tool's own)."""
    v = sorted(values)
    def at(q):
        h = (len(v) - 1) * q
        lo = int(h)
        return v[lo] + (h - lo) * (v[min(lo + 1, len(v) - 1)] - v[lo])
    return at(0.05), at(0.5), at(0.95)


def main():
    print(f"washers | paper | ratio 4-5k rpm: median [5 %, 95 %] | onset rpm: median [5 %, 95 %], never ({DRAWS} draws)")
    for w in TABLE2:
        ratios, onsets, never = [], [], 0
        for d in draws(scene(w)):
            steps = [s for s in d["steps"] if 4000 <= rpm(s) <= 5000]
            if steps:
                ratios.append(sum(map(ratio, steps)) / len(steps))
            if d["onset_rpm"] is None:
                never += 1
            else:
                onsets.append(d["onset_rpm"])
        r = quantiles(ratios)
        o = quantiles(onsets) if onsets else (float("nan"),) * 3
        print(f"{w} | {PAPER_FIG12[w]} | {r[1]:.2f} [{r[0]:.2f}, {r[2]:.2f}] | "
              f"{o[1]:.0f} [{o[0]:.0f}, {o[2]:.0f}], {never}")


if __name__ == "__main__":
    main()
