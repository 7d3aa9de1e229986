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


def load_autobal():
    best, calls, method, settle = {}, {}, {}, {}
    for path in sorted(glob.glob(f"{out}/autobal-*.parquet")):
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


a_time, a_calls, a_method, _ = load_autobal()
rounds = len(glob.glob(f"{out}/autobal-*.parquet"))
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
for label, ids in subsets:
    if not ids:
        continue
    a = stats(a_time, a_calls, ids)
    m = stats(*lean["matched"][:2], ids)
    f = stats(*lean["full"][:2], ids)
    rows.append((label, len(ids), a, m, f))

s = lean["matched"][2][-1]
print(f"{len(runs)} runs of studies/three_balls.toml ({s['same_settling']}/{s['runs']} settling times identical, "
      f"RHS calls identical on {s['same_calls_dp5']} runs autobal kept on dp5), {rounds} interleaved rounds, "
      "fastest round per run, one thread.")
print("autobal: `study run --threads 1`, dev profile (autobal at opt-level 2, debug assertions on);")
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
