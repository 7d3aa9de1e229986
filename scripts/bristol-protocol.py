#!/usr/bin/env python3
"""What the sweep protocol changes on the Bristol rig, at the calibrated
unknowns (docs/validation.md, "Calibrated on Fig. 12").

Runs the five washer cases of rigs/bristol_fig12.toml with the unknowns at
the values `study calibrate rigs/bristol_fig12.toml` fitted (given on the
command line), once with the rig file's protocol (50 rpm steps from
1 000 rpm) and once with the paper's own (about 10 rpm steps from 500 rpm;
both hold each speed 0.25 s and read it over the next 0.25 s, up and back
down), and prints per case the Fig. 12 ratio (mean over the 4 000-5 000 rpm
steps of both runs of the bearings' mean peak over the same without the
balls' unbalance) and the onset of balancing on the run-up.

Usage: python3 scripts/bristol-protocol.py STUDY MU DRAG ANGLE_DEG
(e.g. target/debug/study 1.934e-3 8.382e-3 307.9; about 3 minutes on two cores)
"""
import json
import subprocess
import sys
import tempfile
import tomllib
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
STUDY, MU, DRAG, ANGLE = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4])
RIG = tomllib.loads((ROOT / "rigs/bristol_fig12.toml").read_text())
SCENE = (ROOT / "scenes/bristol_uncertain.toml").read_text().split("[uncertain]")[0]
PROTOCOLS = {"rig file (50 rpm from 1000)": ("1000..5000", "50"), "paper (10 rpm from 500)": ("500..5000", "10")}


def scene(case):
    text = SCENE
    values = dict(case["set"])
    values.update({"coefficient": MU, "drag": DRAG, "angle_deg": ANGLE})
    lines = []
    for line in text.splitlines():
        key = line.split("=")[0].strip()
        short = key.split(".")[-1]
        for k, v in values.items():
            if k.split(".")[-1] == short and "=" in line and not line.startswith("#"):
                line = f"{short} = {v}"
        lines.append(line)
    text = "\n".join(lines)
    if "angle_deg" not in text.split("[effects.race_eccentricity]")[1].split("[")[0]:
        text = text.replace("[effects.race_eccentricity]", f"[effects.race_eccentricity]\nangle_deg = {ANGLE}")
    return text


def sweep(args):
    case, (rpm, step) = args
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "scene.toml"
        path.write_text(scene(case))
        out = subprocess.run(
            [STUDY, "stepped", str(path), "--rpm", rpm, "--step-rpm", step, "--dwell", "0.5",
             "--window", "0.25", "--json"],
            capture_output=True, text=True)
        if out.returncode != 0:
            sys.exit(out.stderr)
        steps = json.loads(out.stdout)
    mean = lambda v: sum(v) / len(v)
    ratio = lambda s: mean(s["bearing_peak"]) / mean(s["bearing_peak_without"])
    band = [ratio(s) for s in steps if 4000 - 1e-6 <= s["omega"] * 30 / 3.141592653589793 <= 5000 + 1e-6]
    up = [s for s in steps if s["direction"] == "up"]
    bad = [i for i, s in enumerate(up) if ratio(s) >= 1.0]
    onset = up[bad[-1] + 1]["omega"] * 30 / 3.141592653589793 if bad and bad[-1] + 1 < len(up) else (
        up[0]["omega"] * 30 / 3.141592653589793 if not bad else None)
    return mean(band), onset


jobs = [(case, p) for p in PROTOCOLS.values() for case in RIG["case"]]
with ThreadPoolExecutor(max_workers=2) as pool:
    results = list(pool.map(sweep, jobs))
n = len(RIG["case"])
print("case | " + " | ".join(f"{name}: ratio | onset rpm" for name in PROTOCOLS))
for i, case in enumerate(RIG["case"]):
    cells = []
    for k in range(len(PROTOCOLS)):
        ratio, onset = results[k * n + i]
        cells.append(f"{ratio:.3f} | {onset if onset is None else round(onset)}")
    print(f"{case['name']} | " + " | ".join(cells))
