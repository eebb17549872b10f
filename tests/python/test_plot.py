"""nonsep.plot: each function returns labelled axes whose lines hold exactly the loaded data, with a legend when
there are several series; headless (Agg). `python3 -m nonsep.work_precision` on a study; the package's message when
numpy is missing."""
import json
import math
import os
import subprocess
import sys
import unittest

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import nonsep  # noqa: E402
import nonsep.plot  # noqa: E402
import nonsep.work_precision  # noqa: E402
from support import FolderTestCase, paper1d_job, state  # noqa: E402


class PlotTest(FolderTestCase):
    def tearDown(self):
        plt.close("all")
        super().tearDown()

    def test_orbit_in_the_phase_plane(self):
        result = nonsep.run(paper1d_job([state(0.5, 0.0), state(2.0, 0.0)], steps=60, every=3), output="out")
        ax = nonsep.plot.orbit(result)
        self.assertEqual((ax.get_xlabel(), ax.get_ylabel()), ("$q$", "$p$"))
        self.assertEqual(len(ax.get_lines()), 2)
        for line, i in zip(ax.get_lines(), (0, 1)):
            np.testing.assert_array_equal(line.get_xdata(), result.orbit(i).q[:, 0])
            np.testing.assert_array_equal(line.get_ydata(), result.orbit(i).p[:, 0])
        self.assertEqual([t.get_text() for t in ax.get_legend().get_texts()],
                         ["trajectory 0: (q, p)(0) = (0.5, 0)", "trajectory 1: (q, p)(0) = (2, 0)"])
        _, given = plt.subplots()
        one = nonsep.plot.orbit(result, 1, ax=given)
        self.assertIs(one, given)
        self.assertEqual(len(one.get_lines()), 1)
        self.assertIsNone(one.get_legend())

    def test_orbit_in_the_configuration_plane_in_2d(self):
        job = {"model": {"plugin": "radial"}, "integrator": {"scheme": "triplet", "order": "4/3"},
               "initial": {"q": [0.8, 0.0], "p": [0.0, 0.439]}, "time": {"dt": 0.01, "steps": 40}}
        result = nonsep.run(job, output="out")
        ax = nonsep.plot.orbit(result, 0)
        self.assertEqual((ax.get_xlabel(), ax.get_ylabel()), ("$q_0$", "$q_1$"))
        np.testing.assert_array_equal(ax.get_lines()[0].get_ydata(), result.orbit(0).q[:, 1])

    def test_energy_error_against_time(self):
        result = nonsep.run(paper1d_job([state(0.5, 0.0), state(1.0, 0.0), state(2.0, 0.0)], steps=60),
                            output="out")
        ax = nonsep.plot.energy_error(result)
        self.assertEqual(ax.get_xlabel(), "$t$")
        self.assertIn("relative energy error", ax.get_ylabel())
        series = [line for line in ax.get_lines() if len(line.get_xdata()) > 2]  # not the zero line
        self.assertEqual(len(series), 3)
        for line, i in zip(series, range(3)):
            np.testing.assert_array_equal(line.get_xdata(), result.orbit(i).t)
            np.testing.assert_array_equal(line.get_ydata(), result.orbit(i).relative_energy_error)
        self.assertEqual(len(ax.get_legend().get_texts()), 3)

    def test_convergence_with_the_fitted_lines(self):
        job = {"model": {"plugin": "paper1d"}, "initial": state(2.0, 0.0), "time": {"t_end": 0.3863765573361232},
               "study": {"integrators": [{"scheme": "basic", "t2": -2.0, "steps": [1024, 2048, 4096]},
                                         {"scheme": "mpe", "order": "4/3", "t2": -2.0, "steps": [128, 256, 512]}]}}
        result = nonsep.run(job, output="out")
        ax = nonsep.plot.convergence(result)
        self.assertEqual((ax.get_xscale(), ax.get_yscale()), ("log", "log"))
        self.assertIn("dt", ax.get_xlabel())
        self.assertIn("relative energy error", ax.get_ylabel())
        points, fits = [], []
        for line in ax.get_lines():
            (points if line.get_linestyle() == "None" else fits).append(line)
        self.assertEqual(len(points), 2)
        self.assertEqual(points[1].get_marker(), "s")  # MPE is not symplectic: open squares
        for line, fit in zip(fits, result.fits):
            x, y = line.get_xdata(), line.get_ydata()
            self.assertAlmostEqual(np.log(y[1] / y[0]) / np.log(x[1] / x[0]), fit["exponent"], places=12)
        ax.figure.canvas.draw()  # the labels' mathtext renders
        labels = [t.get_text() for t in ax.get_legend().get_texts()]
        self.assertEqual(len(labels), 2)
        self.assertTrue(labels[0].startswith("basic: $") and f"{result.exponents['basic']:.3f}" in labels[0])
        with self.assertRaises(ValueError):
            nonsep.plot.convergence(nonsep.run(paper1d_job(state(1.0, 0.0), steps=3), output="run"))


class WorkPrecisionTest(FolderTestCase):
    def test_the_module_plots_a_studys_work_precision_csv(self):
        job = {"model": {"plugin": "paper1d"}, "initial": state(2.0, 0.0), "time": {"t_end": 0.3863765573361232},
               "study": {"reference": {"q": [0.0], "p": [-1.5723027555148466]},
                         "integrators": [{"scheme": "triplet", "order": 2, "steps": [32, 64]},
                                         {"scheme": "gauss", "stages": 2, "steps": [8, 16]}]}}
        nonsep.run(job, output="study")
        done = subprocess.run([sys.executable, "-m", "nonsep.work_precision", str(self.folder / "study"), "--out",
                               str(self.folder / "wp.png")], capture_output=True, text=True, env=os.environ)
        self.assertEqual(done.returncode, 0, done.stderr)
        self.assertGreater((self.folder / "wp.png").stat().st_size, 1000)
        # --error energy plots the largest |dH/H0| over each run, which is at least its value at t_end.
        table = str(self.folder / "study" / "work_precision.csv")
        self.assertEqual(nonsep.work_precision.energy_column(str(self.folder / "study")),
                         "max_abs_relative_energy_error")
        largest = nonsep.work_precision.study_curves(table, "max_abs_relative_energy_error")
        at_end = nonsep.work_precision.study_curves(table, "relative_energy_error")
        for label in ("triplet 2", "gauss 4"):
            for (_, _, m), (_, _, e) in zip(largest[label][1], at_end[label][1]):
                self.assertGreaterEqual(m, e)

    def test_the_title_names_only_the_families_it_shows(self):
        title = nonsep.work_precision.title
        self.assertEqual(title("paper1d", {"chin", "comparator"}),
                         "paper1d (solid: Chin, dash-dot: comparators)")
        self.assertNotIn("peers", title("paper1d", {"chin"}))
        self.assertEqual(title("x", {"chin", "comparator", "peer"}),
                         "x (solid: Chin, dash-dot: comparators, dashed: peers)")

    def test_the_relative_phase_error_is_the_phase_error_over_the_reference_length(self):
        job = {"model": {"plugin": "paper2d"}, "initial": {"q": [0.5, 0.2], "p": [0.3, -0.4]}, "time": {"t_end": 0.5},
               "study": {"reference_run": {"scheme": "gauss", "stages": 3, "steps": [64]},
                         "integrators": [{"scheme": "mpe", "order": 4, "steps": [8, 16]}]}}
        nonsep.run(job, output="study")
        with open(self.folder / "study" / "summary.json") as f:
            reference = json.load(f)["study"]["reference"]
        length = math.sqrt(sum(x * x for x in reference["q"] + reference["p"]))
        self.assertEqual(nonsep.work_precision.reference_length(str(self.folder / "study")), length)
        table = str(self.folder / "study" / "work_precision.csv")
        absolute = nonsep.work_precision.study_curves(table, "phase_error")["mpe 4"][1]
        relative = nonsep.work_precision.study_curves(table, "phase_error", length)["mpe 4"][1]
        self.assertEqual(len(relative), 2)
        self.assertEqual([e / length for _, _, e in absolute], [e for _, _, e in relative])
        done = subprocess.run([sys.executable, "-m", "nonsep.work_precision", str(self.folder / "study"), "--out",
                               str(self.folder / "wp.png"), "--error", "relative-phase"],
                              capture_output=True, text=True, env=os.environ)
        self.assertEqual(done.returncode, 0, done.stderr)
        self.assertGreater((self.folder / "wp.png").stat().st_size, 1000)
        del job["study"]["reference_run"]
        nonsep.run(job, output="no-reference")
        done = subprocess.run([sys.executable, "-m", "nonsep.work_precision", str(self.folder / "no-reference"),
                               "--out", str(self.folder / "none.png"), "--error", "relative-phase"],
                              capture_output=True, text=True, env=os.environ)
        self.assertNotEqual(done.returncode, 0)
        self.assertIn("no study.reference", done.stderr)

    def test_without_numpy_the_package_names_the_interpreter_to_use(self):
        done = subprocess.run([sys.executable, "-c", "import sys; sys.modules['numpy'] = None; import nonsep"],
                              capture_output=True, text=True, env=os.environ)
        self.assertNotEqual(done.returncode, 0)
        self.assertIn(f"nonsep needs numpy, which this Python ({sys.executable}) cannot import", done.stderr)
        self.assertIn("run /usr/bin/python3", done.stderr)


if __name__ == "__main__":
    unittest.main()
