#!/usr/bin/python3
"""CSV I/O benchmark (issue #2): a 10-million-row x,y,z,r,g,b CSV, whole process, median of N runs.

  dpoint parse:  `dpoint bench io data.csv`                       (MB/s = CSV bytes / wall time)
  dpoint write:  `dpoint convert data.ply -o out.csv --decimals 15` (MB/s = CSV bytes / wall time;
                 reading the binary PLY is part of the time)
  pandas parse:  python3 -c 'pandas.read_csv(data.csv)'            (interpreter start included)
  pandas write:  python3 -c 'DataFrame from data.npz; to_csv(float_format="%.15f")'
Peak memory is the child's max RSS (wait4). Usage: bench/scripts/csv_io.py build/dpoint [rows] [runs] [dir]
"""
import json
import os
import platform
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from timing import median_of, remover  # noqa: E402

exe = os.path.abspath(sys.argv[1])
rows = int(sys.argv[2]) if len(sys.argv) > 2 else 10_000_000
runs = int(sys.argv[3]) if len(sys.argv) > 3 else 5
work = sys.argv[4] if len(sys.argv) > 4 else "/tmp/dpoint-bench-csv"
os.makedirs(work, exist_ok=True)
npz, csv, ply, out = (os.path.join(work, n) for n in ("data.npz", "data.csv", "data.ply", "out.csv"))
python = "/usr/bin/python3"


rng = np.random.default_rng(2)
np.savez(npz, xyz=rng.uniform(-1000.0, 1000.0, size=(rows, 3)),
         rgb=rng.uniform(0.0, 1.0, size=(rows, 3)).astype(np.float32))
pandas_write = [python, "-c", f"""
import numpy as np, pandas as pd
d = np.load({npz!r})
f = pd.DataFrame({{'x': d['xyz'][:, 0], 'y': d['xyz'][:, 1], 'z': d['xyz'][:, 2],
                  'r': d['rgb'][:, 0].astype(np.float64), 'g': d['rgb'][:, 1].astype(np.float64),
                  'b': d['rgb'][:, 2].astype(np.float64)}})
f.to_csv({csv!r}, index=False, float_format='%.15f')
"""]
pandas_read = [python, "-c", f"import pandas as pd; pd.read_csv({csv!r})"]

# pandas' to_csv takes ~70 s a run here: median of 3 of those, of `runs` for everything else.
pw_s, pw_rss, _ = median_of(pandas_write, min(runs, 3), remover(csv))  # also makes data.csv
csv_bytes = os.path.getsize(csv)
subprocess.run([exe, "convert", csv, "-o", ply, "--ply-colors", "float", "--quiet"], check=True)
dr_s, dr_rss, inner = median_of([exe, "bench", "io", csv], runs)
dw_s, dw_rss, _ = median_of([exe, "convert", ply, "-o", out, "--decimals", "15", "--quiet"], runs, remover(out))
out_bytes = os.path.getsize(out)
same = subprocess.run(["cmp", "-s", csv, out]).returncode == 0
ds_s, _, _ = median_of([exe, "convert", ply, "-o", out, "--quiet"], runs, remover(out))
short_bytes = os.path.getsize(out)
pr_s, pr_rss, _ = median_of(pandas_read, runs)

pointset_bytes = rows * (24 + 12)
mb = 1e6
result = {
    "machine": f"{platform.node()} ({os.cpu_count()} cores)",
    "rows": rows, "runs": runs, "pandas_write_runs": min(runs, 3), "csv_bytes": csv_bytes,
    "dpoint_parse": {"s": dr_s, "MBps": csv_bytes / mb / dr_s, "peak_rss_MB": dr_rss / mb,
                     "in_process": json.loads(inner)},
    "dpoint_write_decimals15": {"s": dw_s, "MBps": out_bytes / mb / dw_s, "identical_to_pandas_file": same},
    "dpoint_write_shortest": {"s": ds_s, "MBps": short_bytes / mb / ds_s, "bytes": short_bytes},
    "pandas_read_csv": {"s": pr_s, "MBps": csv_bytes / mb / pr_s, "peak_rss_MB": pr_rss / mb},
    "pandas_to_csv_15f": {"s": pw_s, "MBps": csv_bytes / mb / pw_s},
    "parse_speedup_vs_pandas": pr_s / dr_s,
    "write_speedup_vs_pandas": pw_s / dw_s,
    "parse_peak_limit_MB": (1.3 * pointset_bytes + 64 * 2**20) / mb,
    "pointset_MB": pointset_bytes / mb,
}
print(json.dumps(result, indent=1))
