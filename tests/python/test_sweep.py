"""Parameter sweeps from Python: the swept columns of trajectories.csv, nonsep.plot.stability_map over a parameter x
initial-condition plane and over two parameters (each cell the trajectory's value, or the reduction of a cell's
values), and nonsep.plot.indicator_series (lyapunov.csv's running estimates), headless (Agg)."""
import tempfile
import unittest

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import nonsep  # noqa: E402
import nonsep.plot  # noqa: E402

COUPLINGS = [0.0, 0.1, 0.2]


def coupling_job():
    """3 couplings of paper2d x 5 starting points on the shell H = 7 (q0 on a grid, p1 >= 0 solved per coupling)."""
    return {"model": {"plugin": "paper2d", "parameters": {"coupling": COUPLINGS}},
            "integrator": {"scheme": "mpe", "order": 4},
            "initial": {"grid": {"q": [{"from": -1.0, "to": 1.0, "count": 5}, 0.0], "p": [0.0, 0.0]},
                        "energy": 7.0, "solve_for": "p1"},
            "time": {"dt": 0.005, "steps": 400}, "output": {"every": 400},
            "analysis": {"lyapunov": {"vectors": 1, "every": 100}, "megno": True}}


class SweepPlotTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls._folder = tempfile.TemporaryDirectory(prefix="nonsep-python-sweep-")
        cls.result = nonsep.run(coupling_job(), output=f"{cls._folder.name}/couplings", threads=2)
        two = {"model": {"plugin": "mathews_lakshmanan", "parameters": {"lambda": [0.0, 0.5], "alpha": [0.5, 1, 2]}},
               "integrator": {"scheme": "triplet"}, "initial": [{"q": [0.5], "p": [0.0]}, {"q": [1.0], "p": [0.2]}],
               "time": {"dt": 0.01, "steps": 50}, "output": {"every": 50}}
        cls.two = nonsep.run(two, output=f"{cls._folder.name}/two")

    @classmethod
    def tearDownClass(cls):
        cls._folder.cleanup()
        plt.close("all")

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
        self.assertEqual(len(ax.lines), 2)
        for line, index in zip(ax.lines, (0, 7)):
            series = self.result.lyapunov_series(index)
            np.testing.assert_array_equal(line.get_xdata(), series.t)
            np.testing.assert_array_equal(line.get_ydata(), series.mean_megno)
            self.assertIn(f"coupling = {self.result.trajectories['coupling'][index]:g}", line.get_label())

    def test_not_a_sweep(self):
        with self.assertRaisesRegex(ValueError, "not a parameter sweep"):
            plain = nonsep.run(dict(coupling_job(), model={"plugin": "paper2d"}),
                               output=f"{self._folder.name}/plain")
            nonsep.plot.stability_map(plain)


if __name__ == "__main__":
    unittest.main()
