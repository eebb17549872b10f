"""Parameter sweeps from Python: the swept columns of trajectories.csv, nonsep.plot.stability_map over a parameter x
initial-condition plane and over two parameters (each cell the trajectory's value, or the reduction of a cell's
values), nonsep.plot.indicator_series (lyapunov.csv's running estimates), and over a sweep of (q0, p0) grids on an
energy shell: one parameter set chosen with `where` (Result.select), chaos_map's `reduce`, the indicators' colour
scales (MEGNO from 1.25 to 8 with 2 marked, SALI on a log scale), the titles, and the chaotic fraction against the
coupling with its Wilson intervals against a count by hand; headless (Agg), each picture saved."""
import math
import tempfile
import unittest

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import LogNorm  # noqa: E402

import nonsep  # noqa: E402
import nonsep.plot  # noqa: E402
from support import blowup_job, state  # noqa: E402

COUPLINGS = [0.0, 0.1, 0.2]


def coupling_job():
    """3 couplings of paper2d x 5 starting points on the shell H = 7 (q0 on a grid, p1 >= 0 solved per coupling)."""
    return {"model": {"plugin": "paper2d", "parameters": {"coupling": COUPLINGS}},
            "integrator": {"scheme": "mpe", "order": 4},
            "initial": {"grid": {"q": [{"from": -1.0, "to": 1.0, "count": 5}, 0.0], "p": [0.0, 0.0]},
                        "energy": 7.0, "solve_for": "p1"},
            "time": {"dt": 0.005, "steps": 400}, "output": {"every": 400},
            "analysis": {"lyapunov": {"vectors": 1, "every": 100}, "megno": True}}


GRID_COUPLINGS = [0.0, 0.15, 0.3]


def grid_job():
    """3 couplings of paper2d x a 5 x 4 grid over (q0, p0) on the section q1 = 0 of the shell H = 8 (p1 >= 0 solved
    per coupling; points that cannot reach the shell left out), Gauss-Legendre 3 stages at dt = 0.02 to t = 40:
    MEGNO, SALI and the upward crossings of q1 = 0."""
    return {"model": {"plugin": "paper2d", "parameters": {"coupling": GRID_COUPLINGS}},
            "integrator": {"scheme": "gauss", "stages": 3},
            "initial": {"grid": {"q": [{"from": -2.0, "to": 2.0, "count": 5}, 0.0],
                                 "p": [{"from": -1.5, "to": 1.5, "count": 4}, 0.0]},
                        "energy": 8.0, "solve_for": "p1"},
            "time": {"dt": 0.02, "t_end": 40}, "output": {"every": 2000},
            "analysis": {"lyapunov": {"vectors": 2, "renormalize_every": 10, "every": 500}, "megno": True,
                         "sali": True, "poincare": {"component": "q1", "value": 0.0, "direction": "+"}}}


class SweepPlotTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls._folder = tempfile.TemporaryDirectory(prefix="nonsep-python-sweep-")
        cls.result = nonsep.run(coupling_job(), output=f"{cls._folder.name}/couplings", threads=2)
        two = {"model": {"plugin": "mathews_lakshmanan", "parameters": {"lambda": [0.0, 0.5], "alpha": [0.5, 1, 2]}},
               "integrator": {"scheme": "triplet"}, "initial": [{"q": [0.5], "p": [0.0]}, {"q": [1.0], "p": [0.2]}],
               "time": {"dt": 0.01, "steps": 50}, "output": {"every": 50}}
        cls.two = nonsep.run(two, output=f"{cls._folder.name}/two")
        cls.grid = nonsep.run(grid_job(), output=f"{cls._folder.name}/grid", threads=2)

    @classmethod
    def tearDownClass(cls):
        cls._folder.cleanup()
        plt.close("all")

    def save(self, ax, name):
        """Draws the figure into a PNG: the picture renders, mathtext and all."""
        path = f"{self._folder.name}/{name}.png"
        ax.figure.savefig(path, dpi=50)
        with open(path, "rb") as f:
            self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")
        plt.close(ax.figure)

    def test_swept_columns(self):
        table = self.result.trajectories
        self.assertEqual(sorted(set(table["coupling"])), COUPLINGS)
        self.assertEqual(self.result.summary["sweep"]["parameter_sets"], 3)
        self.assertTrue(np.all(np.diff(table["coupling"]) >= 0), "set after set")

    def test_parameter_by_initial_condition(self):
        ax = nonsep.plot.stability_map(self.result, value="mean_megno")
        self.assertEqual(ax.get_xlabel(), "coupling")
        self.assertIn("q_0", ax.get_ylabel())
        image = ax.images[0].get_array()
        table = self.result.trajectories
        q, _ = self.result.initial_states()
        q0s = np.unique(q[:, 0])
        self.assertEqual(image.shape, (len(q0s), 3))
        for k, row in enumerate(table):
            cell = image[np.searchsorted(q0s, q[k, 0]), COUPLINGS.index(row["coupling"])]
            self.assertEqual(cell, row["mean_megno"])
        self.assertEqual(np.ma.count(image), len(table), "a cell per trajectory, grey where none")

    def test_parameter_by_parameter(self):
        with self.assertRaisesRegex(ValueError, "reduce"):
            nonsep.plot.stability_map(self.two, value="relative_energy_error")
        ax = nonsep.plot.stability_map(self.two, value="H0", reduce="max")
        self.assertEqual((ax.get_xlabel(), ax.get_ylabel()), ("alpha", "lambda"))
        table = self.two.trajectories
        self.assertEqual(len(ax.images), 0, "alpha's values are not evenly spaced: a mesh, not an image")
        image = np.ma.getdata(ax.collections[0].get_array()).reshape(2, 3)
        for i, lam in enumerate((0.0, 0.5)):
            for j, alpha in enumerate((0.5, 1.0, 2.0)):
                cell = (table["lambda"] == lam) & (table["alpha"] == alpha)
                self.assertEqual(image[i, j], table["H0"][cell].max())

    def test_indicator_series(self):
        ax = nonsep.plot.indicator_series(self.result, i=[0, 7], value="mean_megno")
        series = [line for line in ax.lines if line.get_label().startswith("trajectory")]
        self.assertEqual(len(series), 2)
        marks = [line for line in ax.lines if line not in series]
        self.assertEqual([list(line.get_ydata()) for line in marks], [[2.0, 2.0]], "MEGNO's regular value, dashed")
        for line, index in zip(series, (0, 7)):
            series = self.result.lyapunov_series(index)
            np.testing.assert_array_equal(line.get_xdata(), series.t)
            np.testing.assert_array_equal(line.get_ydata(), series.mean_megno)
            self.assertIn(f"coupling = {self.result.trajectories['coupling'][index]:g}", line.get_label())

    def test_megno_colour_scale_title_and_its_override(self):
        ax = nonsep.plot.stability_map(self.result)
        (image,) = ax.images
        self.assertEqual((image.norm.vmin, image.norm.vmax), (1.25, 8.0))
        bar = ax.figure.axes[-1]
        self.assertEqual([list(line.get_ydata()) for line in bar.lines], [[2.0, 2.0]], "2 marked on the colour bar")
        self.assertIn("2: quasi-periodic", bar.get_ylabel())
        self.assertEqual(ax.get_title(), f"MEGNO $\\langle Y \\rangle$ at t = 2 of {len(self.result.trajectories)} "
                         "orbits\npaper2d, H = 7; mpe order 4, dt = 0.005, t = 2")
        self.save(ax, "megno_scale")
        ax = nonsep.plot.stability_map(self.result, vmin=0.0, vmax=3.0)
        self.assertEqual((ax.images[0].norm.vmin, ax.images[0].norm.vmax), (0.0, 3.0))
        ax = nonsep.plot.stability_map(self.two, value="H0", reduce="max")
        mesh = ax.collections[0]
        cells = np.ma.getdata(mesh.get_array())
        self.assertEqual((mesh.norm.vmin, mesh.norm.vmax), (cells.min(), cells.max()),
                         "other columns: the data's range")
        self.assertEqual(cells.max(), self.two.trajectories["H0"].max())
        self.assertEqual(len(ax.figure.axes[-1].lines), 0)

    def test_where_chooses_one_parameter_set_of_a_chaos_map(self):
        table = self.grid.trajectories
        with self.assertRaisesRegex(ValueError, r"where=\{'coupling': value\} or combine them with reduce"):
            nonsep.plot.chaos_map(self.grid)
        ax = nonsep.plot.chaos_map(self.grid, where={"coupling": 0.15})
        self.assertEqual((ax.get_xlabel(), ax.get_ylabel()), ("$q_0$ (initial)", "$p_0$ (initial)"))
        chosen = np.flatnonzero(table["coupling"] == 0.15)
        np.testing.assert_array_equal(self.grid.select({"coupling": 0.15}), chosen)
        self.assertTrue(0 < len(chosen) < 20, "some of the 20 points are off this coupling's shell")
        shown = np.ma.filled(ax.images[0].get_array().astype(float), np.nan)
        q, p = self.grid.initial_states()
        qs, ps = np.unique(q[chosen, 0]), np.unique(p[chosen, 0])  # the grid's values where states reach the shell
        self.assertEqual(shown.shape, (len(ps), len(qs)))
        expected = np.full(shown.shape, np.nan)
        for i in chosen:
            expected[np.argmin(abs(ps - p[i, 0])), np.argmin(abs(qs - q[i, 0]))] = table["mean_megno"][i]
        np.testing.assert_array_equal(shown, expected)
        self.assertEqual(np.count_nonzero(np.isfinite(shown)), len(chosen))
        self.assertIn("paper2d, H = 8, coupling = 0.15; gauss order 6, dt = 0.02, t = 40", ax.get_title())
        self.save(ax, "chaos_map_where")
        self.assertEqual(len(self.grid.select({"coupling": [0.0, 0.3]})), np.isin(table["coupling"], [0.0, 0.3]).sum())
        with self.assertRaisesRegex(ValueError, r"no trajectory has coupling = 0.2 \(its values: 0, 0.15, 0.3\)"):
            self.grid.select({"coupling": 0.2})
        with self.assertRaisesRegex(ValueError, "'alpha' is not a swept parameter .* \\(swept: coupling\\)"):
            nonsep.plot.chaos_map(self.grid, where={"alpha": 1.0})

    def test_chaos_map_reduces_the_parameter_sets_sharing_a_cell(self):
        table = self.grid.trajectories
        ax = nonsep.plot.chaos_map(self.grid, reduce="max")
        shown = np.ma.filled(ax.images[0].get_array().astype(float), np.nan)
        q, p = self.grid.initial_states()
        qs, ps = np.unique(q[:, 0]), np.unique(p[:, 0])
        self.assertEqual(shown.shape, (len(ps), len(qs)))
        for row, p0 in enumerate(ps):
            for column, q0 in enumerate(qs):
                mine = np.isclose(q[:, 0], q0) & np.isclose(p[:, 0], p0)
                expected = table["mean_megno"][mine].max() if mine.any() else np.nan
                np.testing.assert_array_equal(shown[row, column], expected, f"cell ({q0}, {p0})")
        self.assertIn("max per cell", ax.get_title())
        with self.assertRaisesRegex(ValueError, "unknown reduction 'largest'"):
            nonsep.plot.chaos_map(self.grid, reduce="largest")

    def test_sali_on_a_log_scale_with_its_threshold_marked(self):
        ax = nonsep.plot.chaos_map(self.grid, value="sali", where={"coupling": 0.3})
        (image,) = ax.images
        self.assertIsInstance(image.norm, LogNorm)
        self.assertEqual((image.norm.vmin, image.norm.vmax), (1e-16, 1.0))
        self.assertEqual([list(line.get_ydata()) for line in ax.figure.axes[-1].lines], [[1e-8, 1e-8]])
        sali = self.grid.trajectories["sali"][self.grid.select({"coupling": 0.3})]
        shown = np.ma.compressed(image.get_array()).astype(float)
        self.assertEqual(sorted(shown), sorted(np.where(sali > 0, sali, np.nextafter(0.0, 1.0))))
        self.assertTrue(ax.get_title().startswith("SALI at t = 40"))
        self.save(ax, "sali_map")
        ax = nonsep.plot.indicator_series(self.grid, value="sali", where={"coupling": 0.3})
        self.assertEqual(ax.get_yscale(), "log")
        self.assertEqual(len([line for line in ax.lines if len(line.get_xdata()) > 2]), len(sali))
        self.save(ax, "sali_series")

    def test_chaotic_fraction_against_the_coupling_is_the_count_by_hand(self):
        table = self.grid.trajectories
        ax = nonsep.plot.chaotic_fraction(self.grid)
        line = ax.lines[0]
        np.testing.assert_array_equal(line.get_xdata(), GRID_COUPLINGS)
        bars = [segment for collection in ax.collections for segment in collection.get_segments()]
        self.assertEqual(len(bars), 3)
        z = 1.0
        for k, coupling in enumerate(GRID_COUPLINGS):
            mine = table[table["coupling"] == coupling]
            n = sum(1 for row in mine if row["status"] == "completed" and math.isfinite(row["mean_megno"]))
            chaotic = sum(1 for row in mine if row["status"] == "completed" and row["mean_megno"] > 2.5)
            self.assertEqual(line.get_ydata()[k], chaotic / n)
            f = chaotic / n  # Wilson's score interval, z = 1
            centre = (f + z * z / (2 * n)) / (1 + z * z / n)
            half = z / (1 + z * z / n) * math.sqrt(f * (1 - f) / n + z * z / (4 * n * n))
            np.testing.assert_allclose([bars[k][0][1], bars[k][1][1]], [centre - half, centre + half], rtol=1e-12)
        counts = self.grid.chaotic_fraction()
        self.assertEqual(counts.orbits.sum() + counts.left_out.sum(), len(table))
        self.assertTrue(0 < counts.fraction[-1], "some orbits at coupling 0.3 are chaotic")
        self.assertIn("Chaotic fraction: MEGNO", ax.get_title())
        self.assertIn("> 2.5 at t = 40", ax.get_title())
        self.assertEqual(ax.get_xlabel(), "coupling")
        self.save(ax, "chaotic_fraction")
        by_sali = self.grid.chaotic_fraction(value="sali")
        np.testing.assert_array_equal(
            by_sali.chaotic, [np.sum((table["coupling"] == c) & (table["sali"] < 1e-8)) for c in GRID_COUPLINGS])
        self.assertEqual(by_sali.criterion, "sali < 1e-08")
        higher = self.grid.chaotic_fraction(threshold=4.0)
        self.assertTrue(np.all(higher.chaotic <= counts.chaotic))
        with self.assertRaisesRegex(ValueError, "no default threshold for 'lyapunov0'"):
            self.grid.chaotic_fraction(value="lyapunov0")

    def test_chaotic_fraction_needs_the_other_parameters_fixed(self):
        with self.assertRaisesRegex(ValueError, r"lambda varies too: fix it with where=\{'lambda': ...\}"):
            self.two.chaotic_fraction("alpha", value="H0", threshold=0.5)
        with self.assertRaisesRegex(ValueError, r"where: no trajectory has alpha = 3 \(its values: 0.5, 1, 2\)"):
            self.two.select({"lambda": 0.5, "alpha": 3.0})
        counts = self.two.chaotic_fraction("alpha", value="H0", threshold=0.5, where={"lambda": 0.5})
        np.testing.assert_array_equal(counts.values, [0.5, 1.0, 2.0])
        np.testing.assert_array_equal(counts.orbits, [2, 2, 2])
        table = self.two.trajectories
        np.testing.assert_array_equal(
            counts.chaotic, [np.sum((table["lambda"] == 0.5) & (table["alpha"] == a) & (table["H0"] > 0.5))
                             for a in (0.5, 1.0, 2.0)])

    def test_chaotic_fraction_leaves_out_the_orbits_that_did_not_complete(self):
        # tests/host/plugins/blowup.cpp: q = 1e103 overflows grad V in the first step (diverged); H_TTV = 3 q^2 p^2
        # gives H0 = 0.0075 and 0.12 to the other two, so one of two counted orbits per set has H0 > 0.1.
        job = blowup_job([state(1e103, 0.0), state(0.5, 0.1), state(1.0, 0.2)], steps=5, fail_above=[1e299, 1e300])
        with self.assertRaises(nonsep.RunError) as caught:
            nonsep.run(job, output=f"{self._folder.name}/blowup")
        result = caught.exception.result
        self.assertEqual(list(result.trajectories["status"]), ["diverged", "completed", "completed"] * 2)
        counts = result.chaotic_fraction(value="H0", threshold=0.1)
        np.testing.assert_array_equal(counts.values, [1e299, 1e300])
        np.testing.assert_array_equal(counts.orbits, [2, 2])
        np.testing.assert_array_equal(counts.chaotic, [1, 1])
        np.testing.assert_array_equal(counts.left_out, [1, 1])
        self.assertEqual(list(counts.fraction), [0.5, 0.5])
        ax = nonsep.plot.chaotic_fraction(result, value="H0", threshold=0.1)
        self.assertIn("2 left out (not completed, or no value)", ax.get_title())
        self.save(ax, "chaotic_fraction_left_out")

    def test_poincare_of_one_parameter_set(self):
        ax = nonsep.plot.poincare(self.grid, where={"coupling": 0.0}, color_by="mean_megno")
        (points,) = ax.collections
        crossings = self.grid.poincare
        mine = crossings[np.isin(crossings["trajectory"], self.grid.select({"coupling": 0.0}))]
        self.assertGreater(len(mine), 0)
        self.assertEqual(len(points.get_offsets()), len(mine))
        self.assertEqual((points.norm.vmin, points.norm.vmax), (1.25, 8.0))
        self.assertIn("coupling = 0", ax.get_title())
        self.save(ax, "poincare_where")

    def test_not_a_sweep(self):
        with self.assertRaisesRegex(ValueError, "not a parameter sweep"):
            plain = nonsep.run(dict(coupling_job(), model={"plugin": "paper2d"}),
                               output=f"{self._folder.name}/plain")
            nonsep.plot.stability_map(plain)


if __name__ == "__main__":
    unittest.main()
