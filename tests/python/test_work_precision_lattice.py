"""bench/work_precision_lattice.py, the lattice chain's work-precision study: its initial state (the same at site i
whatever n, zero total momentum), its jobs run by the built nonsep with short ladders at n = 10, and its table
(the fastest run at each target, recomputed here from the study's own files)."""
import csv
import importlib.util
import json
import math
import os
import subprocess
import sys
import unittest

from support import SOURCE_DIR, FolderTestCase

SCRIPT = SOURCE_DIR / "bench" / "work_precision_lattice.py"
specification = importlib.util.spec_from_file_location("work_precision_lattice", SCRIPT)
lattice = importlib.util.module_from_spec(specification)
specification.loader.exec_module(lattice)


class LatticeStudyTest(FolderTestCase):
    def test_the_initial_state(self):
        q10, p10 = lattice.initial_state(10)
        q1000, p1000 = lattice.initial_state(1000)
        self.assertEqual(q10, q1000[:10])
        self.assertEqual((len(q1000), len(p1000)), (1000, 1000))
        for p in (p10, p1000):
            self.assertLess(abs(sum(p)), 1e-14)
        self.assertLess(max(abs(a - b) for a, b in zip(p10, p1000)), 0.01)
        with self.assertRaises(ValueError):
            lattice.initial_state(15)

    def test_the_study_at_ten_sites_and_its_table(self):
        done = subprocess.run([sys.executable, str(SCRIPT), "run", os.environ["NONSEP_EXECUTABLE"], "out", "--sites",
                               "10", "--quick"], capture_output=True, text=True)
        self.assertEqual(done.returncode, 0, done.stderr)
        with open(self.folder / "out" / "lattice_10.json") as f:
            job = json.load(f)
        self.assertEqual(job["model"], {"plugin": "lattice_chain", "parameters": {"sites": 10}})
        self.assertEqual(len(job["study"]["integrators"]), len(lattice.INTEGRATORS))
        with open(self.folder / "out" / "wp-10" / "summary.json") as f:
            reference = json.load(f)["study"]["reference"]
        length = math.sqrt(sum(x * x for x in reference["q"] + reference["p"]))
        with open(self.folder / "out" / "wp-10" / "work_precision.csv", newline="") as f:
            rows = [r for r in csv.DictReader(f) if r["status"] == "completed"]
        rows_of = {target: [r for r in rows if float(r["phase_error"]) / length <= target] for target in lattice.TARGETS}
        lines = [line for line in done.stdout.splitlines() if line.startswith("|")]
        self.assertEqual(len(lines), 2 + len(lattice.TARGETS))
        for line, target in zip(lines[2:], lattice.TARGETS):
            cells = [c.strip() for c in line.strip("|").split("|")]
            self.assertEqual(cells[1], f"{target:.0e}")
            if rows_of[target]:
                best = min(rows_of[target], key=lambda r: float(r["wall_seconds"]))
                steps = best["steps"] + (" step:" if best["steps"] == "1" else " steps:")
                self.assertTrue(cells[6].startswith(f"**{best['integrator']}, {steps}"), line)
            else:
                self.assertEqual(cells[6], "**not reached**")
        checks = [line for line in done.stdout.splitlines() if line.startswith("n = 10: reference")]
        self.assertEqual(len(checks), 2)
        for line in checks:
            self.assertLess(float(line.rsplit(" ", 1)[1]), 1e-9, line)


if __name__ == "__main__":
    unittest.main()
