#!/usr/bin/env python3
"""SciPy with autobal's settling observer, on the runs of a study.

Issue 17 asks for autobal's speed per solve against SciPy's `solve_ivp`
"(DOP853, same tolerances, same observer)". `scipy_peer.py` compares fixed
500-revolution solves without an observer; this script solves the runs of
the main job as a study does: each run from its own start until r = |(u, v)|
has stayed inside the band δ·A_ref for the hold window (or diverges, or
reaches t_end), r read from the dense output on autobal's sample grid.

Inputs: the CSV of `autobal-bench --lean-inputs` (equations' constants, start,
tolerances, sample step, band, window: the lean reference's inputs,
bench/lean). The model is the lean program's rotating-frame right-hand side
(bench/lean/src/main.rs, `Model::rhs`) on Python floats with `math` (at
three weights numpy's per-call overhead is larger than the arithmetic, as
`scipy_peer.py` measured). The solver is SciPy's own stepper class
(`RK45`: the Dormand–Prince pair of autobal's dp5; `DOP853`), stepped with
`.step()` and `.dense_output()`, which is how `solve_ivp` runs it and the
only way to stop a SciPy solve on a rule that is not an event function's
sign change. Same rtol, same per-component atol vector, SciPy's own first
step. The observer is the lean program's, line for line: sample zero cannot
stop the run; a sample with r non-finite or beyond the divergence limit
ends it; settled at the start of the first stretch inside the band that
lasts the window.

Writes one CSV line per run: run id, outcome, settling revolutions, RHS
calls, steps, seconds. `settling.sh` runs it beside autobal and prints the
comparison.
"""

import argparse
import csv
import math
import sys
import time

import numpy as np
from scipy.integrate import DOP853, RK45

METHODS = {"RK45": RK45, "DOP853": DOP853}


def floats(cell):
    return [float(x) for x in cell.split(";")]


class Run:
    """One exported run: constants, start, tolerances and observer settings."""

    def __init__(self, row):
        self.run_id = int(row["run_id"])
        self.n = int(row["n"])
        self.omega = float(row["omega"])
        self.m_total = float(row["rotor_mass"]) + sum(floats(row["mass"]))
        self.k = float(row["k"])
        self.b = float(row["b"])
        self.force = (float(row["unbalance_force_u"]), float(row["unbalance_force_v"]))
        mass, track = floats(row["mass"]), floats(row["track_radius"])
        self.ml = [m * l for m, l in zip(mass, track)]
        self.inertia = floats(row["inertia"])
        drag = floats(row["drag"])
        self.drag = [d * l * l for d, l in zip(drag, track)]
        self.contact = list(
            zip(
                floats(row["contact_half_angle"]),
                floats(row["contact_stiffness"]),
                floats(row["contact_damping"]),
            )
        )
        self.y0 = floats(row["y0"])
        self.rtol = float(row["rtol"])
        self.atol = floats(row["atol"])
        self.t_end = float(row["t_end"])
        self.dt = float(row["dt"])
        self.samples_per_rev = int(row["samples_per_rev"])
        self.band = float(row["band"])
        self.window = float(row["window"])
        self.divergence_limit = float(row["divergence_limit"])
        self.autobal_settling_revs = (
            float(row["autobal_settling_revs"]) if row["autobal_settling_revs"] else None
        )

    def rhs(self, t, y):
        """The lean program's rotating-frame right-hand side (bench/lean)."""
        n, w = self.n, self.omega
        nq = 2 + n
        u, v, ud, vd = y[0], y[1], y[nq], y[nq + 1]
        fr, fi = -2.0 * w * vd - w * w * u, 2.0 * w * ud - w * w * v
        gr = -self.m_total * fr - self.b * (ud - w * v) - self.k * u + self.force[0]
        gi = -self.m_total * fi - self.b * (vd + w * u) - self.k * v + self.force[1]
        psi = y[2:nq]
        rate = y[nq + 2 :]
        cf = [-self.drag[j] * rate[j] for j in range(n)]
        contact = self.contact
        for j in range(n):
            aj, kj, cj = contact[j]
            if aj == 0.0:
                continue
            for k in range(j + 1, n):
                ak, kk, ck = contact[k]
                if ak == 0.0:
                    continue
                d = math.remainder(psi[k] - psi[j], 2.0 * math.pi)
                overlap = (aj + ak) - abs(d)
                if overlap <= 0.0:
                    continue
                direction = 1.0 if d >= 0.0 else -1.0
                overlap_rate = -direction * (rate[k] - rate[j])
                torque = max(min(kj, kk) * overlap + min(cj, ck) * overlap_rate, 0.0)
                cf[k] += direction * torque
                cf[j] -= direction * torque
        a11, a12, a22 = self.m_total, 0.0, self.m_total
        trig = []
        for j in range(n):
            s, co = math.sin(psi[j]), math.cos(psi[j])
            trig.append((s, co))
            ml = self.ml[j]
            rt = w + rate[j]
            gr += ml * rt * rt * co
            gi += ml * rt * rt * s
            qj = cf[j] - ml * (fi * co - fr * s)
            cf[j] = qj
            wr, wi = -ml * s, ml * co
            inv = 1.0 / self.inertia[j]
            a11 -= wr * wr * inv
            a12 -= wr * wi * inv
            a22 -= wi * wi * inv
            gr -= wr * qj * inv
            gi -= wi * qj * inv
        det = a11 * a22 - a12 * a12
        ar = (gr * a22 - gi * a12) / det
        ai = (gi * a11 - gr * a12) / det
        acc = [
            (cf[j] - self.ml[j] * (trig[j][1] * ai - trig[j][0] * ar)) / self.inertia[j]
            for j in range(n)
        ]
        return np.array(list(y[nq:]) + [ar, ai] + acc)


def solve(run, method):
    """Step SciPy's solver with the settling observer; (outcome, settling revs, nfev, steps)."""
    solver = METHODS[method](
        run.rhs,
        0.0,
        np.array(run.y0),
        run.t_end,
        rtol=run.rtol,
        atol=np.array(run.atol),
    )
    next_index, stretch_start, steps = 1, None, 0
    revs = lambda t: t / (run.dt * run.samples_per_rev)  # noqa: E731
    while True:
        message = solver.step()
        if solver.status == "failed":
            return "failed: " + str(message), None, solver.nfev, steps
        steps += 1
        t = solver.t
        ts = []
        while next_index * run.dt <= t:
            ts.append(next_index * run.dt)
            next_index += 1
        if ts:
            u, v = solver.dense_output()(np.array(ts))[:2]
            for t_s, u_s, v_s in zip(ts, u, v):
                r = math.hypot(u_s, v_s)
                if not math.isfinite(r) or r > run.divergence_limit:
                    return "diverged", None, solver.nfev, steps
                if r <= run.band:
                    if stretch_start is None:
                        stretch_start = t_s
                    if t_s - stretch_start >= run.window:
                        return "settled", revs(stretch_start), solver.nfev, steps
                else:
                    stretch_start = None
        if solver.status == "finished":
            return "censored", None, solver.nfev, steps


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("runs_csv", help="`autobal-bench --lean-inputs` output")
    parser.add_argument("--method", choices=sorted(METHODS), default="RK45")
    parser.add_argument("--runs", type=int, default=40, help="the first N runs (by id)")
    parser.add_argument("--stride", type=int, default=1, help="every k-th run")
    parser.add_argument("--out", required=True, help="CSV to write")
    args = parser.parse_args()
    with open(args.runs_csv, newline="") as f:
        runs = [Run(row) for row in csv.DictReader(f)]
    runs = runs[:: args.stride][: args.runs]
    with open(args.out, "w", newline="") as f:
        out = csv.writer(f)
        out.writerow(["run_id", "method", "outcome", "settling_revs", "rhs_calls", "steps", "seconds"])
        for run in runs:
            t0 = time.perf_counter()
            outcome, settling, nfev, steps = solve(run, args.method)
            seconds = time.perf_counter() - t0
            out.writerow([run.run_id, args.method, outcome, settling if settling is not None else "", nfev, steps, seconds])
            f.flush()
            print(
                f"run {run.run_id}: {outcome} {settling} (autobal {run.autobal_settling_revs}), "
                f"{nfev} RHS calls, {seconds:.3f} s",
                file=sys.stderr,
            )


if __name__ == "__main__":
    main()
