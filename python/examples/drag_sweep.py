# %% [markdown]
# # The main job's design against its drag, from Python
#
# The main job (`studies/three_balls.toml`) recommends design 2: three
# steel balls at the optimal radius ratio in a 50 mm race, drag 10 N·s/m,
# on a 10 kg rotor at 300 rad/s. Here the same design is simulated from
# Python over a range of drags and unbalances, its settling time plotted
# against the drag, and scipy finds the drag that settles fastest.
#
# Run it as a script (`python python/examples/drag_sweep.py [OUT.png]`) or
# cell by cell in an editor that reads `# %%` cells.

# %%
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from scipy.optimize import minimize_scalar

import autobal

out = sys.argv[1] if len(sys.argv) > 1 else "drag_sweep.png"


HORIZON_REVS = 2000.0


def design2(drag, eccentricity=2.0e-4, angles=(60, 140, 220)):
    """The main job's design 2 as a scene, with the drag and unbalance given."""
    return {
        "rotor": {"mass": 10.0, "kx": 1.0e5, "ky": 1.0e5, "bx": 100.0, "by": 100.0, "eccentricity": eccentricity},
        "balancer": {"kind": "ball", "n": 3, "rho": "optimal", "race_radius": 0.05, "density": 7850.0, "drag": drag},
        "speed": {"mode": "constant", "omega": 300.0},
        "start": {"mode": "locked_steady", "angles_deg": list(angles)},
        "metrics": {"t_end_revs": HORIZON_REVS},
    }


def settling_revs(drag, eccentricity=2.0e-4):
    """Settling time in revolutions (the horizon when the run does not settle)."""
    m = autobal.simulate(design2(drag, eccentricity), series=False).metrics
    return m["settling_revs"] if m["settled"] else HORIZON_REVS


# %% One run, as arrays
run = autobal.simulate(design2(10.0))
print(f"settled: {run.metrics['settled']} after {run.metrics['settling_revs']:.1f} rev;"
      f" {run.t.size} samples, angles {np.degrees(run.angles[:, -1]).round(1)} deg")

# %% Settling time against drag, for three unbalances
drags = np.geomspace(1.0, 100.0, 13)
eccentricities = [1.0e-4, 2.0e-4, 3.0e-4]
times = {e: [settling_revs(d, e) for d in drags] for e in eccentricities}
fig, ax = plt.subplots(figsize=(6, 4))
for e, t in times.items():
    ax.plot(drags, t, marker="o", label=f"e = {e * 1e6:.0f} µm")
ax.set_xscale("log")
ax.set_xlabel("ball drag β (N·s/m)")
ax.set_ylabel("settling time (rev)")
ax.set_title("Design 2 of the main job: settling time against drag")
ax.legend()
fig.tight_layout()
fig.savefig(out, dpi=100)
print(f"wrote {out}")

# %% The drag that settles fastest at e = 200 µm (scipy on autobal.simulate)
best = minimize_scalar(lambda log_drag: settling_revs(10.0 ** log_drag), bounds=(0.0, 2.0),
                       method="bounded", options={"xatol": 0.02})
print(f"fastest at drag {10.0 ** best.x:.2f} N·s/m: {best.fun:.1f} rev ({best.nfev} simulations)")
