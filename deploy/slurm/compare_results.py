"""Exit 0 when two autobal results folders hold the same runs and summary.

Usage: compare_results.py WHOLE MERGED. Every column is compared except the
per-run wall time, which is a measurement, not a result.
"""
import sys

import pyarrow.parquet as pq

whole, merged = sys.argv[1], sys.argv[2]
for name in ("runs.parquet", "summary.parquet"):
    a = pq.read_table(f"{whole}/{name}")
    b = pq.read_table(f"{merged}/{name}")
    keep = [c for c in a.column_names if c != "wall_time_s"]
    if a.select(keep) != b.select(keep):
        sys.exit(f"{name}: the merged shards differ from the single run")
    print(f"{name}: {a.num_rows} rows identical (wall time aside)")
