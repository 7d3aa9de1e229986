"""Pool the rounds of bench/lean/run.sh into one table (called by run.sh).

Per run, the fastest of the rounds is taken on each side (autobal: the
wall_time_s column of runs.parquet, which times Simulation::run; lean: the
program's own per-run clock), so that a round disturbed by other processes
does not count; runs/s per core = runs / Σ per-run times (one thread).
"""

import glob
import math
import sys

import pyarrow.parquet as pq

out = sys.argv[1]


def load_autobal(variant):
    best, calls, method, settle = {}, {}, {}, {}
    for path in sorted(glob.glob(f"{out}/autobal-{variant}-*.parquet")):
        d = pq.read_table(path, columns=["run_id", "wall_time_s", "rhs_calls", "method", "settling_revs"]).to_pydict()
        for i, rid in enumerate(d["run_id"]):
            best[rid] = min(best.get(rid, math.inf), d["wall_time_s"][i])
            calls[rid], method[rid], settle[rid] = d["rhs_calls"][i], d["method"][i], d["settling_revs"][i]
    return best, calls, method, settle


def load_lean(profile):
    best, calls, summary = {}, {}, []
    for path in sorted(glob.glob(f"{out}/lean-{profile}-*.txt")):
        for line in open(path):
            f = line.split()
            if f and f[0] == "LEANRUN":
                rid, secs, c = int(f[1]), float(f[2]), int(f[3])
                best[rid] = min(best.get(rid, math.inf), secs)
                calls[rid] = c
            elif f and f[0] == "LEAN":
                summary.append(dict(kv.split("=", 1) for kv in f[1:]))
    return best, calls, summary


# "certified": the default (certified hold on); "full": metrics.certified_hold = false,
# the lean program's own rule (it holds every window to its end).
autobal = {v: load_autobal(v) for v in ("certified", "full")}
a_time, a_calls, a_method, _ = autobal["full"]
rounds = len(glob.glob(f"{out}/autobal-full-*.parquet"))
lean = {p: load_lean(p) for p in ("matched", "full")}
runs = sorted(a_time)
subsets = [
    ("all runs", runs),
    ("runs autobal kept on dp5", [r for r in runs if a_method[r] == "dp5"]),
    ("runs autobal switched to radau5", [r for r in runs if a_method[r] != "dp5"]),
]


def stats(times, calls, ids):
    secs = sum(times[r] for r in ids)
    c = sum(calls[r] for r in ids)
    return len(ids) / secs, c / len(ids), 1e9 * secs / c


rows = []
for variant, label_hold in (("full", "full hold"), ("certified", "certified hold (default)")):
    v_time, v_calls = autobal[variant][0], autobal[variant][1]
    if not v_time:
        continue
    for label, ids in subsets:
        if not ids:
            continue
        a = stats(v_time, v_calls, ids)
        m = stats(*lean["matched"][:2], ids)
        f = stats(*lean["full"][:2], ids)
        rows.append((f"{label}, {label_hold}", len(ids), a, m, f))

s = lean["matched"][2][-1]
certified = autobal["certified"]
same = sum(1 for r in runs if certified[3].get(r) == autobal["full"][3].get(r))
print(f"{len(runs)} runs of studies/three_balls.toml ({s['same_settling']}/{s['runs']} settling times identical, "
      f"RHS calls identical on {s['same_calls_dp5']} runs autobal kept on dp5; with the certified hold "
      f"{same}/{len(runs)} settling times as with the full hold), {rounds} interleaved rounds, "
      "fastest round per run, one thread.")
print("autobal: `study run --threads 1`, dev profile (autobal at opt-level 2, debug assertions on), "
      "with `metrics.certified_hold = false` (full hold, the lean program's rule) and by default;")
print("lean: bench/lean built with the same settings (`--release`, see its Cargo.toml) and, last column, at opt-level 3.\n")
hdr = ["runs", "n", "autobal runs/s", "lean runs/s", "autobal/lean", "lean O3 runs/s",
       "RHS/run autobal", "RHS/run lean", "ns/RHS autobal", "ns/RHS lean", "ns/RHS lean O3"]
print("| " + " | ".join(hdr) + " |")
print("|" + " --- |" * len(hdr))
for label, n, a, m, f in rows:
    cells = [label, str(n), f"{a[0]:.0f}", f"{m[0]:.0f}", f"{a[0] / m[0]:.2f}", f"{f[0]:.0f}",
             f"{a[1]:.0f}", f"{m[1]:.0f}", f"{a[2]:.0f}", f"{m[2]:.0f}", f"{f[2]:.0f}"]
    print("| " + " | ".join(cells) + " |")
walls = [float(x) for x in open(f"{out}/walls.txt").read().split()]
print(f"\nwhole `study run` wall time (incl. files, summary, verdict): median {sorted(walls)[len(walls) // 2]:.3f} s over {len(walls)} rounds")
