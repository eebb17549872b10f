"""The paper's Figure 1 through the Python layer: python3 examples/python/figure1.py [OUT_DIR] (PYTHONPATH=python)."""
import sys
from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")
import nonsep  # noqa: E402
import nonsep.plot  # noqa: E402

out = Path(sys.argv[1] if len(sys.argv) > 1 else "figure1-python")
result = nonsep.run(Path(__file__).parents[1] / "paper" / "figure1.json", output=out / "figure1")
ax = nonsep.plot.orbit(result)  # the four orbits of the basic step, t2 = -2, dt = 0.005
for energy in result.trajectories["H0"]:  # exact level curves: (1 + p^2/2)^2 (1 + q^2) = E
    q = np.linspace(-1, 1, 801) * np.sqrt(energy - 1)
    p = np.sqrt(np.maximum(2 * (np.sqrt(energy / (1 + q**2)) - 1), 0))
    ax.plot(np.r_[q, q[::-1]], np.r_[p, -p[::-1]], "-", color="0.3", lw=0.8, zorder=0)
ax.set_title("Figure 1: basic step, t2 = -2, dt = 0.005; exact H = E in grey", fontsize=10)
ax.figure.savefig(out / "figure1.png", dpi=100)
print(f"{out / 'figure1.png'}: largest |dE/E|", *np.round(result.trajectories["max_abs_relative_energy_error"], 4))
