#!/usr/bin/env python3
"""SciPy's solve_ivp (DOP853, RK45) on autobal's reference problem.

The peer of `autobal-bench --peer-cases`: the same equations, scene, start,
tolerances and horizon, solved the way a Python user would solve them, so that
`run.sh` can report SciPy's time per solve over autobal's.

The model is a line-by-line translation of `RotorSystem::rhs`
(src/model/system.rs) for the reference scene at constant speed: plane rotor
M = 1, k = 1, b = 0.1, e = 0.01, spin ω = 4, n point cargoes
`Cargo::point(0.01, 1.0, 0.01, 1.4)` (src/bench.rs). State
[x, y, ψ_1..ψ_n, ẋ, ẏ, ψ̇_1..ψ̇_n], ψ_j relative to the rotor, φ = ωt.

Fairness: this is a fair, idiomatic implementation. It keeps autobal's O(n)
arrowhead elimination (no dense mass matrix, no np.linalg.solve), precomputes
every constant once, vectorises over the cargoes with numpy, and solves the
2×2 head block in closed form. Because numpy's per-call overhead dominates at
n = 3, a second translation works on Python floats with `math`; `--rhs auto`
(the default) times both and solves with the faster one. Both are checked
against right-hand-side values exported by autobal. solve_ivp is called as
documented (per-component atol vector, no dense output, no t_eval); its own
bookkeeping (it keeps every accepted step) is part of what a user pays.

Subcommands:
  solve   read autobal's peer report (JSON), check start and RHS, time the
          SciPy solves, check the final states, write a JSON result
  report  pool several rounds of autobal and SciPy results, print ratios
"""

import argparse
import glob
import json
import math
import os
import statistics
import sys
import time

import numpy as np
import scipy
from scipy.integrate import solve_ivp

# The reference scene (src/bench.rs: reference_scene, OMEGA, ATOL_PER_RTOL).
ROTOR_MASS = 1.0
STIFFNESS = 1.0
DAMPING = 0.1
ECCENTRICITY = 0.01
OMEGA = 4.0
CARGO_MASS, TRACK_RADIUS, DRAG, KAPPA = 0.01, 1.0, 0.01, 1.4
ATOL_PER_RTOL = 1e-2

# solve_ivp method ↔ the autobal method with the same Runge–Kutta pair.
MATCH = {"DOP853": "dop853", "RK45": "dp5"}
METHODS = ["DOP853", "RK45"]


class ReferenceRotor:
    """The reference scene with n cargoes: constants, start, scales, right-hand sides."""

    def __init__(self, n):
        self.n = n
        m = np.full(n, CARGO_MASS)
        l = np.full(n, TRACK_RADIUS)
        self.ml = m * l
        self.drag_l2 = DRAG * l * l
        self.inv_inertia = 1.0 / (KAPPA * m * l * l)
        self.m_total = ROTOR_MASS + m.sum()
        self.me = ROTOR_MASS * ECCENTRICITY
        # Plain-float copies for the scalar translation.
        self.ml_f = self.ml.tolist()
        self.drag_l2_f = self.drag_l2.tolist()
        self.inv_inertia_f = self.inv_inertia.tolist()

    def rhs_numpy(self, t, y):
        """dy/dt, vectorised over the cargoes (RotorSystem::rhs at constant speed)."""
        n = self.n
        psi = y[2 : 2 + n]
        xd, yd = y[2 + n], y[3 + n]
        psid = y[4 + n :]
        phi = OMEGA * t
        ang = phi + psi
        s, c = np.sin(ang), np.cos(ang)
        # Generalised forces on the rotor: supports, rotor unbalance, and the
        # cargoes' centrifugal pull (ml·φ̇_j²·(cos, sin)).
        pull = self.ml * (OMEGA + psid) ** 2
        w2me = self.me * OMEGA * OMEGA
        gx = -STIFFNESS * y[0] - DAMPING * xd + w2me * math.cos(phi) + np.dot(pull, c)
        gy = -STIFFNESS * y[1] - DAMPING * yd + w2me * math.sin(phi) + np.dot(pull, s)
        q = -self.drag_l2 * psid  # cargo forces: drag relative to the race
        # Eliminate the cargo rows onto the 2×2 head block: w_j = ml(−s, c).
        wx, wy = -self.ml * s, self.ml * c
        ux, uy = wx * self.inv_inertia, wy * self.inv_inertia
        a11 = self.m_total - np.dot(ux, wx)
        a12 = -np.dot(ux, wy)
        a22 = self.m_total - np.dot(uy, wy)
        gx -= np.dot(ux, q)
        gy -= np.dot(uy, q)
        det = a11 * a22 - a12 * a12
        xdd = (a22 * gx - a12 * gy) / det
        ydd = (a11 * gy - a12 * gx) / det
        psidd = (q - wx * xdd - wy * ydd) * self.inv_inertia
        return np.concatenate(((xd, yd), psid, (xdd, ydd), psidd))

    def rhs_scalar(self, t, y):
        """dy/dt on Python floats (faster than numpy for a handful of cargoes)."""
        n = self.n
        v = y.tolist()
        x, yy = v[0], v[1]
        psi = v[2 : 2 + n]
        xd, yd = v[2 + n], v[3 + n]
        psid = v[4 + n :]
        phi = OMEGA * t
        w2me = self.me * OMEGA * OMEGA
        gx = -STIFFNESS * x - DAMPING * xd + w2me * math.cos(phi)
        gy = -STIFFNESS * yy - DAMPING * yd + w2me * math.sin(phi)
        a11 = a22 = self.m_total
        a12 = 0.0
        wxs, wys, qs = [], [], []
        for j in range(n):
            s, c = math.sin(phi + psi[j]), math.cos(phi + psi[j])
            ml, inv = self.ml_f[j], self.inv_inertia_f[j]
            rate = OMEGA + psid[j]
            pull = ml * rate * rate
            gx += pull * c
            gy += pull * s
            wx, wy = -ml * s, ml * c
            q = -self.drag_l2_f[j] * psid[j]
            a11 -= wx * wx * inv
            a12 -= wx * wy * inv
            a22 -= wy * wy * inv
            gx -= wx * inv * q
            gy -= wy * inv * q
            wxs.append(wx)
            wys.append(wy)
            qs.append(q)
        det = a11 * a22 - a12 * a12
        xdd = (a22 * gx - a12 * gy) / det
        ydd = (a11 * gy - a12 * gx) / det
        psidd = [
            (qs[j] - wxs[j] * xdd - wys[j] * ydd) * self.inv_inertia_f[j] for j in range(n)
        ]
        return [xd, yd, *psid, xdd, ydd, *psidd]

    def initial_state(self, psi0):
        """The `locked_steady` start (src/model/start.rs: locked_response)."""
        n = self.n
        psi0 = np.asarray(psi0, dtype=float)
        # Total unbalance at φ = 0 (rotor's at ψ₀ = 0, plus the cargoes').
        ux = self.me + np.sum(self.ml * np.cos(psi0))
        uy = np.sum(self.ml * np.sin(psi0))
        w2 = OMEGA * OMEGA

        def response(ure, uim):
            # x = Re[ω² U e^{iωt} / D], D = k − M_Σ ω² + i b ω; ẋ = Re[iω(...)].
            dre, dim = STIFFNESS - self.m_total * w2, DAMPING * OMEGA
            den = dre * dre + dim * dim
            re = w2 * (ure * dre + uim * dim) / den
            im = w2 * (uim * dre - ure * dim) / den
            return re, -OMEGA * im

        x, xd = response(ux, uy)
        y, yd = response(uy, -ux)  # y is driven by sin: −i U
        return np.concatenate(([x, y], psi0, [xd, yd], np.zeros(n)))

    def a_ref(self):
        """A_ref = U ω² / |k − M_Σ ω² + i b ω| with U = M e (src/metrics/reference.rs)."""
        w2 = OMEGA * OMEGA
        return self.me * w2 / math.hypot(STIFFNESS - self.m_total * w2, DAMPING * OMEGA)

    def scale(self):
        """Units of the state components: A_ref, rad, A_ref·ω, rad·ω (simulation::scaled_atol)."""
        n, a = self.n, self.a_ref()
        return np.concatenate(([a, a], np.ones(n), [a * OMEGA] * 2, np.full(n, OMEGA)))

    def atol(self, rtol):
        """Per-component absolute tolerances, as autobal's bench uses them."""
        return rtol * ATOL_PER_RTOL * self.scale()


def reference_angles(n):
    """90°, 100°, 110°, … (src/bench.rs: reference_angles)."""
    return np.radians(90.0 + 10.0 * np.arange(n))


def scaled_error(y, ref, scale):
    return float(np.max(np.abs(np.asarray(y) - np.asarray(ref)) / scale))


def time_rhs(fun, t, y, calls):
    start = time.perf_counter()
    for _ in range(calls):
        fun(t, y)
    return (time.perf_counter() - start) / calls


def check_model(rotor, peer):
    """Compare start, scales, atol and RHS with autobal's export; returns the checks."""
    n = rotor.n
    checks = {}
    y0 = rotor.initial_state(reference_angles(n))
    scale = rotor.scale()
    checks["y0_max_rel_diff"] = float(
        np.max(np.abs(y0 - peer["y0"]) / np.maximum(np.abs(peer["y0"]), 1e-300))
    )
    checks["scale_max_rel_diff"] = float(np.max(np.abs(scale - peer["scale"]) / peer["scale"]))
    checks["atol_max_rel_diff"] = max(
        float(np.max(np.abs(rotor.atol(c["rtol"]) - c["atol"]) / np.asarray(c["atol"])))
        for c in peer["cases"]
    )
    rhs_diff = {"numpy": 0.0, "scalar": 0.0}
    # dy/dt_i has the unit scale_i·ω (A_ref·ω, …, rad·ω²): a relative test
    # would be meaningless where the end state is steady and dy/dt ≈ 1e-14.
    rate_scale = OMEGA * scale
    for smp in peer["rhs_samples"]:
        ref = np.asarray(smp["dydt"])
        y = np.asarray(smp["y"])
        for name, fun in (("numpy", rotor.rhs_numpy), ("scalar", rotor.rhs_scalar)):
            got = np.asarray(fun(smp["t"], y))
            rhs_diff[name] = max(rhs_diff[name], float(np.max(np.abs(got - ref) / rate_scale)))
    checks["rhs_max_scaled_diff"] = rhs_diff
    checks["passed"] = bool(
        checks["y0_max_rel_diff"] < 1e-12
        and checks["scale_max_rel_diff"] < 1e-14
        and checks["atol_max_rel_diff"] < 1e-14
        and max(rhs_diff.values()) < 1e-12
    )
    return y0, checks


def cmd_solve(args):
    with open(args.autobal) as f:
        peer = json.load(f)
    n = peer["config"]["cargoes"]
    rotor = ReferenceRotor(n)
    if peer["omega"] != OMEGA:
        sys.exit(f"autobal's omega {peer['omega']} is not this script's {OMEGA}")
    y0, checks = check_model(rotor, peer)
    if not checks["passed"]:
        print(json.dumps(checks, indent=2), file=sys.stderr)
        sys.exit("the Python model does not reproduce autobal's start or right-hand side")
    t_end = peer["t_end"]
    scale = np.asarray(peer["scale"])
    y_ref = np.asarray(peer["reference"]["y"])

    # Per-call cost of both translations (10k calls at the start state).
    calls = args.rhs_calls
    rhs_us = {
        name: 1e6 * min(time_rhs(fun, 1.234, y0, calls) for _ in range(3))
        for name, fun in (("numpy", rotor.rhs_numpy), ("scalar", rotor.rhs_scalar))
    }
    variant = args.rhs if args.rhs != "auto" else min(rhs_us, key=rhs_us.get)
    fun = rotor.rhs_numpy if variant == "numpy" else rotor.rhs_scalar

    rtols = sorted({c["rtol"] for c in peer["cases"]}, reverse=True)
    cases = [(m, r) for m in args.methods for r in rtols]
    times = {c: [] for c in cases}
    sols = {}
    for _ in range(args.repeats):
        for method, rtol in cases:
            atol = rotor.atol(rtol)
            start = time.perf_counter()
            sol = solve_ivp(fun, (0.0, t_end), y0, method=method, rtol=rtol, atol=atol)
            times[(method, rtol)].append(1e3 * (time.perf_counter() - start))
            sols[(method, rtol)] = sol

    auto = {(c["method"], c["rtol"]): c for c in peer["cases"]}
    results = []
    for method, rtol in cases:
        sol = sols[(method, rtol)]
        y_final = sol.y[:, -1]
        mine = auto.get((MATCH[method], rtol))
        err = scaled_error(y_final, y_ref, scale)
        results.append(
            {
                "method": method,
                "rtol": rtol,
                "times_ms": times[(method, rtol)],
                "median_ms": statistics.median(times[(method, rtol)]),
                "status": int(sol.status),
                "message": sol.message,
                "t_final": float(sol.t[-1]),
                "nfev": int(sol.nfev),
                "accepted_steps": len(sol.t) - 1,
                "y_final": y_final.tolist(),
                "error_vs_reference": err,
                "diff_to_autobal": (
                    scaled_error(y_final, mine["y_final"], scale) if mine else None
                ),
                "autobal_error": mine["error_vs_reference"] if mine else None,
                # Same criterion as autobal's own test (tests/it/bench.rs).
                "within_tolerance": bool(sol.status == 0 and err < 100 * rtol),
            }
        )

    out = {
        "python": sys.version.split()[0],
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "cargoes": n,
        "revolutions": peer["config"]["revolutions"],
        "t_end": t_end,
        "rhs_variant": variant,
        "rhs_us_per_call": rhs_us,
        "checks": checks,
        "reference": {k: peer["reference"][k] for k in ("method", "rtol", "cross_check")},
        "cases": results,
    }
    if args.out:
        with open(args.out, "w") as f:
            json.dump(out, f, indent=1)
    if not args.quiet:
        print_solve(out)
    return 0 if all(r["within_tolerance"] for r in results) else 1


def print_solve(out):
    c = out["checks"]
    print(
        f"SciPy {out['scipy']}, numpy {out['numpy']}, Python {out['python']}: "
        f"{out['cargoes']} cargoes, {out['revolutions']:g} revolutions"
    )
    print(
        f"model check vs autobal: y0 {c['y0_max_rel_diff']:.1e}, "
        f"RHS numpy {c['rhs_max_scaled_diff']['numpy']:.1e}, "
        f"scalar {c['rhs_max_scaled_diff']['scalar']:.1e} "
        "(y0: largest relative difference; RHS: in units of scale·ω)"
    )
    us = out["rhs_us_per_call"]
    print(
        f"RHS per call: numpy {us['numpy']:.2f} µs, scalar {us['scalar']:.2f} µs; "
        f"solving with '{out['rhs_variant']}'"
    )
    for r in out["cases"]:
        print(
            f"  {r['method']:6} rtol {r['rtol']:.0e}: {r['median_ms']:9.2f} ms  "
            f"nfev {r['nfev']:6d}  steps {r['accepted_steps']:5d}  "
            f"error {r['error_vs_reference']:.1e}  vs autobal {r['diff_to_autobal']:.1e}  "
            f"{'ok' if r['within_tolerance'] else 'OUT OF TOLERANCE'}"
        )
        print("    y(t_end) = [" + ", ".join(f"{v:.10e}" for v in r["y_final"]) + "]")


def cmd_report(args):
    auto_files = sorted(glob.glob(os.path.join(args.dir, "autobal-*.json")))
    scipy_files = sorted(glob.glob(os.path.join(args.dir, "scipy-*.json")))
    if not auto_files or not scipy_files:
        sys.exit(f"no autobal-*.json or scipy-*.json in {args.dir}")
    autos = [json.load(open(f)) for f in auto_files]
    scipys = [json.load(open(f)) for f in scipy_files]

    # Pool the solves of every round: medians over all of them.
    a_times, a_case = {}, {}
    for rep in autos:
        for c in rep["cases"]:
            key = (c["method"], c["rtol"])
            a_times.setdefault(key, []).extend(c["times_ms"])
            a_case[key] = c
    s_times, s_case = {}, {}
    for rep in scipys:
        for c in rep["cases"]:
            key = (c["method"], c["rtol"])
            s_times.setdefault(key, []).extend(c["times_ms"])
            s_case[key] = c
    # Paired ratios: within each round, SciPy's median over autobal's.
    paired = {}
    for rep_a, rep_s in zip(autos, scipys):
        am = {(c["method"], c["rtol"]): statistics.median(c["times_ms"]) for c in rep_a["cases"]}
        for c in rep_s["cases"]:
            key = (MATCH[c["method"]], c["rtol"])
            if key in am:
                paired.setdefault((c["method"], c["rtol"]), []).append(
                    statistics.median(c["times_ms"]) / am[key]
                )

    last = scipys[-1]
    print_solve(last)
    print()
    print(
        f"SciPy {last['scipy']} / numpy {last['numpy']} / Python {last['python']} "
        f"(RHS '{last['rhs_variant']}': numpy {last['rhs_us_per_call']['numpy']:.2f} µs, "
        f"scalar {last['rhs_us_per_call']['scalar']:.2f} µs per call) against autobal, "
        f"{last['cargoes']} cargoes, {last['revolutions']:g} revolutions, {len(autos)} rounds"
    )
    print(
        f"autobal solves per case: {len(next(iter(a_times.values())))}, "
        f"SciPy solves per case: {len(next(iter(s_times.values())))}"
    )
    # Per-call cost of the RHS the solves used, median over the rounds.
    rhs_us = statistics.median(s["rhs_us_per_call"][s["rhs_variant"]] for s in scipys)
    rows = []
    ok = True
    for (method, rtol), st in sorted(s_times.items(), key=lambda kv: (kv[0][0], -kv[0][1])):
        sc = s_case[(method, rtol)]
        same = (MATCH[method], rtol)
        default = ("dp5", rtol)
        s_med = statistics.median(st)
        a_med = statistics.median(a_times[same])
        d_med = statistics.median(a_times[default])
        ok &= sc["within_tolerance"]
        rows.append(
            [
                method,
                f"{rtol:.0e}",
                f"{s_med:.1f}",
                str(sc["nfev"]),
                MATCH[method],
                f"{a_med:.3f}",
                str(a_case[same]["stats"]["rhs_calls"]),
                f"{s_med / a_med:.0f}",
                f"{statistics.median(paired[(method, rtol)]):.0f}",
                f"{min(st) / min(a_times[same]):.0f}",
                f"{s_med / d_med:.0f}",
                f"{1e3 * s_med / sc['nfev']:.1f}",
                f"{100 * rhs_us * sc['nfev'] / (1e3 * s_med):.0f}",
                f"{sc['error_vs_reference']:.1e}",
                f"{a_case[same]['error_vs_reference']:.1e}",
                f"{sc['diff_to_autobal']:.1e}",
                "ok" if sc["within_tolerance"] else "FAIL",
            ]
        )
    head = [
        "scipy",
        "rtol",
        "ms",
        "nfev",
        "autobal",
        "ms",
        "RHS",
        "ratio",
        "paired",
        "min",
        "vs dp5",
        "µs/f",
        "f %",
        "err scipy",
        "err autobal",
        "scipy−autobal",
        "check",
    ]
    widths = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(head)]
    print("  ".join(h.rjust(w) for h, w in zip(head, widths)))
    for r in rows:
        print("  ".join(v.rjust(w) for v, w in zip(r, widths)))
    ref = last["reference"]
    print(
        "ratio: SciPy median / autobal median (same Runge–Kutta pair); paired: median over rounds\n"
        "of the per-round ratio; min: ratio of fastest solves; vs dp5: against autobal's default;\n"
        "µs/f: SciPy's time per RHS call, solver included; f %: the share of it spent in the RHS.\n"
        f"err: final-state difference to autobal {ref['method']} at rtol {ref['rtol']:.0e} "
        f"(trusted to {ref['cross_check']:.1e}), in units of A_ref, rad, A_ref·ω, rad·ω;\n"
        "check: SciPy finished and err < 100·rtol (autobal's own test criterion)."
    )
    return 0 if ok else 1


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = p.add_subparsers(dest="cmd", required=True)
    s = sub.add_parser("solve", help="time SciPy's solves of autobal's peer cases")
    s.add_argument("--autobal", required=True, help="output of `autobal-bench --peer-cases --json`")
    s.add_argument("--out", help="write the results as JSON here")
    s.add_argument("--repeats", type=int, default=3, help="timed solves per case")
    s.add_argument("--methods", nargs="+", default=METHODS, choices=METHODS)
    s.add_argument("--rhs", choices=["auto", "numpy", "scalar"], default="auto")
    s.add_argument("--rhs-calls", type=int, default=10000, help="calls per RHS timing batch")
    s.add_argument("--quiet", action="store_true")
    r = sub.add_parser("report", help="pool rounds and print SciPy/autobal ratios")
    r.add_argument("--dir", required=True, help="folder of autobal-*.json and scipy-*.json")
    args = p.parse_args()
    return cmd_solve(args) if args.cmd == "solve" else cmd_report(args)


if __name__ == "__main__":
    sys.exit(main())
