#!/usr/bin/env python3
"""Two pieces of the Bristol rig that the scene leaves out, measured at the
paper-protocol fit (docs/validation.md, "The refitted cover's change of
unbalance ..." and "The race-ball clearance never opens"): could the
refitted cover's change of unbalance explain Fig. 12's 0-1 washer ratios
above 1 and the 3 000 rpm onset, and could a race-ball clearance open?

The rig measured each washer case twice, with the balls and without; taking
the balls out means lifting the balancer's cover and refitting it, which
shifts the rotor's static unbalance by some small dU nobody measured. Above
the onset the balls take up whatever static unbalance they find, so dU
moves the ratio through its reference (the run without balls) and not
through the run with them. This script holds the with-balls sweeps of
scripts/bristol-protocol.py (the paper's protocol, at the unknowns given on
the command line) and recomputes the reference per case with dU added to the
case's static unbalance, for dU of each size (in washers, 1.28e-5 kg m)
over directions round the rotor (the same dU for every case: one cover, one
refit). It prints, per (size, direction), the five Fig. 12 ratios and the
2-washer onset, and the misfit sum over the five ratios, (model - paper)/sd
squared. Then, from the same with-balls sweeps, the clearance's margin:
the largest whirl of the balancer plane over the track radius R (the
race's synchronous acceleration over the ball's w^2 R) and gravity over
w^2 R at the slowest step; while their sum stays well under 1 the wall
pushes every ball inward and no radial clearance can open.

Usage: python3 scripts/bristol-cover-and-clearance.py STUDY MU DRAG ANGLE_DEG [SIZES]
(e.g. target/debug/study 7.6e-4 4.2e-2 46 0.1,0.25,0.5; about 15 minutes
on two cores)
"""
import json
import math
import subprocess
import sys
import tempfile
import tomllib
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
STUDY, MU, DRAG, ANGLE = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4])
SIZES = [float(s) for s in (sys.argv[5] if len(sys.argv) > 5 else "0.1,0.25,0.5").split(",")]
DIRECTIONS = [30.0 * k for k in range(12)]
WASHER = 1.28e-5
TRACK_RADIUS = 0.04518 - 0.00238  # race radius less the ball's, scenes/bristol_rig.toml
RIG = tomllib.loads((ROOT / "rigs/bristol_fig12_paper_protocol.toml").read_text())
SCENE = (ROOT / "scenes/bristol_uncertain.toml").read_text().split("[uncertain]")[0]
PAPER = {p["case"]: (p["value"], p["sd"]) for p in RIG["point"] if p["quantity"] == "ratio"}
RPM = lambda s: s["omega"] * 30 / math.pi


def scene(values):
    """The rig's scene with `values` (last key segment -> value) put in."""
    lines = []
    for line in SCENE.splitlines():
        short = line.split("=")[0].strip()
        if "=" in line and not line.startswith("#") and short in values:
            line = f"{short} = {values[short]}"
        lines.append(line)
    text = "\n".join(lines)
    return text.replace("[effects.race_eccentricity]", f"[effects.race_eccentricity]\nangle_deg = {ANGLE}")


def case_values(case, extra=(0.0, 0.0)):
    """The case's keys with the unknowns, and `extra` (size in kg m,
    direction in degrees) added to its static unbalance as vectors."""
    s = case["set"]
    u, a = s["rotor.static_unbalance"], math.radians(s["rotor.static_angle_deg"])
    x = u * math.cos(a) + extra[0] * math.cos(math.radians(extra[1]))
    y = u * math.sin(a) + extra[0] * math.sin(math.radians(extra[1]))
    return {
        "static_unbalance": math.hypot(x, y),
        "static_angle_deg": math.degrees(math.atan2(y, x)) % 360.0,
        "moment_unbalance": s["rotor.moment_unbalance"],
        "coefficient": MU,
        "drag": DRAG,
    }


def stepped(values, args):
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "scene.toml"
        path.write_text(scene(values))
        out = subprocess.run([STUDY, "stepped", str(path), *args, "--json"], capture_output=True, text=True)
        if out.returncode != 0:
            sys.exit(out.stderr)
        return json.loads(out.stdout)


def with_balls(case):
    """The paper's protocol with the balls: 10 rpm steps from 500 rpm, up and down."""
    return stepped(case_values(case), ["--rpm", "500..5000", "--step-rpm", "10", "--dwell", "0.5", "--window", "0.25"])


def reference(job):
    """Each run-up speed's reference (mean bearing peak without the balls'
    unbalance) with the cover's dU: one revolution per step is enough, the
    reference is the steady linear response."""
    case, extra = job
    steps = stepped(case_values(case, extra), ["--rpm", "500..5000", "--step-rpm", "10", "--dwell", "0.121", "--up-only"])
    return {round(RPM(s)): sum(s["bearing_peak_without"]) / len(s["bearing_peak_without"]) for s in steps}


def readings(steps, ref):
    """The Fig. 12 ratio (4 000-5 000 rpm, up and down) and the run-up onset."""
    ratio = lambda s: (sum(s["bearing_peak"]) / len(s["bearing_peak"])) / ref[round(RPM(s))]
    band = [ratio(s) for s in steps if 4000 - 1e-6 <= RPM(s) <= 5000 + 1e-6]
    up = [s for s in steps if s["direction"] == "up"]
    bad = [i for i, s in enumerate(up) if ratio(s) >= 1.0]
    onset = None if bad and bad[-1] + 1 >= len(up) else RPM(up[bad[-1] + 1] if bad else up[0])
    return sum(band) / len(band), onset


cases = RIG["case"]
extras = [(0.0, 0.0)] + [(size * WASHER, d) for size in SIZES for d in DIRECTIONS]
with ThreadPoolExecutor(max_workers=2) as pool:
    sweeps = list(pool.map(with_balls, cases))
    refs = list(pool.map(reference, [(c, e) for e in extras for c in cases]))
print("dU (washers) | direction (deg) | " + " | ".join(c["name"] for c in cases) + " | 2-washer onset (rpm) | misfit")
rows = []
for k, (size, direction) in enumerate(extras):
    cells = [readings(sweeps[i], refs[k * len(cases) + i]) for i in range(len(cases))]
    misfit = sum(((r - PAPER[c["name"]][0]) / PAPER[c["name"]][1]) ** 2 for (r, _), c in zip(cells, cases))
    onset = cells[[c["name"] for c in cases].index("2 washers")][1]
    rows.append((misfit, size / WASHER, direction, cells, onset))
for misfit, size, direction, cells, onset in rows:
    ratios = " | ".join(f"{r:.2f}" for r, _ in cells)
    print(f"{size:.2f} | {direction:.0f} | {ratios} | {onset if onset is None else round(onset)} | {misfit:.1f}")
best = min(rows, key=lambda r: r[0])
print(f"best: dU {best[1]:.2f} washers at {best[2]:.0f} deg, misfit {best[0]:.1f} (none: {rows[0][0]:.1f})")

print("case | largest whirl (mm) | whirl / R | gravity / (w^2 R) at the slowest step")
for case, steps in zip(cases, sweeps):
    whirl = max(s["whirl_peak"] for s in steps)
    slowest = min(s["omega"] for s in steps)
    print(f"{case['name']} | {1e3 * whirl:.2f} | {whirl / TRACK_RADIUS:.4f} | {9.81 / (slowest ** 2 * TRACK_RADIUS):.3f}")
