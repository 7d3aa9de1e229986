"""What two results folders of one study decide, compared: the
recommendation, the Pareto set, the verdict on #1 of every design and every
"better than #1 on another measure" finding (Holm p <= 0.05, lower is better
for every reported measure), read from summary.parquet. Prints the runs of
each and SAME/DIFF per item, then whether the full study's #1 left the race."""
import sys
import pyarrow.parquet as pq

MEASURES = ["median", "mean", "p90", "residual_p95"]


def decide(folder):
    t = pq.read_table(folder + "/summary.parquet").to_pydict()
    n = len(t["design_id"])
    ids = t["design_id"]
    best = next(ids[i] for i in range(n) if t["rank"][i] == 1)
    criterion = t["rank_by"][0]
    findings = sorted(
        (ids[i], m)
        for i in range(n)
        for m in MEASURES
        if m != criterion
        and t[f"vs_best_{m}_p_holm"][i] is not None
        and t[f"vs_best_{m}_diff"][i] is not None
        and t[f"vs_best_{m}_p_holm"][i] <= 0.05
        and t[f"vs_best_{m}_diff"][i] < 0
    )
    decided = {
        "best": best,
        "pareto": sorted(ids[i] for i in range(n) if t["pareto"][i]),
        "verdicts": {ids[i]: t["vs_best_verdict"][i] for i in range(n)},
        "findings": findings,
    }
    left = {ids[i]: t.get("left_race_after", [None] * n)[i] for i in range(n)}
    return decided, sum(t["runs"]), left


raced, raced_runs, left = decide(sys.argv[1])
full, full_runs, _ = decide(sys.argv[2])
print(f"runs raced {raced_runs} full {full_runs} ({full_runs / raced_runs:.2f}x fewer)")
for key in raced:
    same = raced[key] == full[key]
    print(f"  {key}: " + ("SAME" if same else f"DIFF raced={raced[key]} full={full[key]}"))
print(f"  the full study's #1 (design {full['best']}) left the race: {left[full['best']] is not None}")
