"""Fixture for stats::sobol_indices: SALib's first-order and total Sobol
indices of the Ishigami function, with the model outputs they came from.

Produced with SALib 1.6.0 (numpy 2.4.6, scipy 1.17.1, Python 3.11), the pins
in requirements.txt. To rerun from the repository's root:

    python3 -m venv /tmp/salib
    /tmp/salib/bin/pip install -r bench/sobol/requirements.txt
    /tmp/salib/bin/python bench/sobol/salib_ishigami.py

It writes tests/fixtures/salib_ishigami.csv, read by the Rust test
`stats::sobol_indices::tests::agrees_with_salib`. The file has one
`kind,index,value` row per number: `Y` rows hold SALib's model outputs in
its own row order (for calc_second_order=False, per base sample j:
A_j, AB_1j, ..., AB_Dj, B_j, as SALib's `separate_output_values` reads
them), `S1` and `ST` rows SALib's indices. Floats are written with repr,
which round-trips float64 exactly.
"""

from importlib.metadata import version
from pathlib import Path

import numpy as np
from SALib.analyze import sobol as analyze
from SALib.sample import sobol as sample
from SALib.test_functions import Ishigami

# N = 2^10 keeps the fixture small (N (D + 2) = 5120 outputs).
N = 1024
SEED = 20100
PROBLEM = {
    "num_vars": 3,
    "names": ["x1", "x2", "x3"],
    "bounds": [[-np.pi, np.pi]] * 3,
}

OUT = Path(__file__).resolve().parents[2] / "tests" / "fixtures" / "salib_ishigami.csv"


def main():
    x = sample.sample(PROBLEM, N, calc_second_order=False, seed=SEED)
    y = Ishigami.evaluate(x)  # A = 7, B = 0.1
    si = analyze.analyze(PROBLEM, y, calc_second_order=False, seed=SEED)
    rows = ["kind,index,value"]
    rows += [f"S1,{i},{float(v)!r}" for i, v in enumerate(si["S1"])]
    rows += [f"ST,{i},{float(v)!r}" for i, v in enumerate(si["ST"])]
    rows += [f"Y,{j},{float(v)!r}" for j, v in enumerate(y)]
    OUT.write_text("\n".join(rows) + "\n")
    print(f"SALib {version('SALib')}, numpy {np.__version__}: {OUT}")
    for i in range(PROBLEM["num_vars"]):
        print(
            f"x{i + 1}: S1 {si['S1'][i]:.4f} ± {si['S1_conf'][i]:.4f}, "
            f"ST {si['ST'][i]:.4f} ± {si['ST_conf'][i]:.4f}"
        )


if __name__ == "__main__":
    main()
