"""Runs examples/jobs/ensemble.json (the four Figure 1 orbits as one batch) and plots their relative energy errors:
python3 examples/python/ensemble.py [OUT_DIR] (PYTHONPATH=python). Writes OUT_DIR/energy_error.png."""
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import nonsep  # noqa: E402
import nonsep.plot  # noqa: E402

out = Path(sys.argv[1] if len(sys.argv) > 1 else "ensemble-python")
result = nonsep.run(Path(__file__).parents[1] / "jobs" / "ensemble.json", output=out / "ensemble")
ax = nonsep.plot.energy_error(result)
ax.set_title("examples/jobs/ensemble.json: basic step, t2 = -2, dt = 0.005", fontsize=10)
ax.figure.tight_layout()
ax.figure.savefig(out / "energy_error.png", dpi=100)
for row in result.trajectories:
    print(f"trajectory {row['trajectory']}: {row['status']}, largest |dE/E| {row['max_abs_relative_energy_error']:.3g}")
