"""Dynamics outputs from Python: poincare.csv and lyapunov.csv as Result.poincare / Result.lyapunov (and per
trajectory), the Lyapunov and MEGNO columns of trajectories.csv, each number bit for bit the CSV text; a run stopped
by max_crossings; nonsep.plot.poincare and nonsep.plot.chaos_map headless (Agg)."""
import tempfile
import unittest

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import nonsep  # noqa: E402
import nonsep.plot  # noqa: E402
from support import FolderTestCase, blowup_job, read_csv  # noqa: E402

MAX_CROSSINGS = 4


def paper2d_job(q_count=4, p_count=3, t_end=12.0, poincare=True, every=0):
    """paper2d on the shell H = 7, a grid over (q0, p0) at q1 = 0 with p1 >= 0 solved for (points off the shell are
    left out), MPE 4 at dt = 0.005 (the settings of examples/dynamics, on a coarse grid for a short time)."""
    analysis = {"lyapunov": {"vectors": 2, "renormalize_every": 10, "every": every}, "megno": True, "sali": True,
                "gali": 3, "fli": True, "ofli": True}
    if poincare:
        analysis["poincare"] = {"component": "q1", "value": 0.0, "direction": "+", "max_crossings": MAX_CROSSINGS}
    return {"model": {"plugin": "paper2d", "parameters": {"coupling": 0.2}},
            "integrator": {"scheme": "mpe", "order": 4},
            "initial": {"grid": {"q": [{"from": -1.2, "to": 1.2, "count": q_count}, 0.0],
                                 "p": [{"from": -1.5, "to": 1.5, "count": p_count}, 0.0]},
                        "energy": 7.0, "solve_for": "p1"},
            "time": {"dt": 0.005, "t_end": t_end}, "output": {"every": 400}, "analysis": analysis}


class SharedRun(FolderTestCase):
    """One run of paper2d_job(every=100) per test class, in a folder of its own."""

    @classmethod
    def setUpClass(cls):
        cls._shared = tempfile.TemporaryDirectory(prefix="nonsep-python-dynamics-")
        cls.result = nonsep.run(paper2d_job(every=100), output=f"{cls._shared.name}/out", threads=2)

    @classmethod
    def tearDownClass(cls):
        cls._shared.cleanup()


class DynamicsResultTest(SharedRun):
    def assertTableIsTheFile(self, table, path):
        header, rows = read_csv(path)
        self.assertEqual(list(table.dtype.names), header)
        self.assertEqual(len(table), len(rows))
        self.assertGreater(len(rows), 0, path)
        for name_index, name in enumerate(header):
            column = table[name]
            for row, cells in enumerate(rows):
                if np.issubdtype(column.dtype, np.integer):
                    self.assertEqual(int(column[row]), int(cells[name_index]), f"{path}:{row + 2} {name}")
                elif np.issubdtype(column.dtype, np.floating):
                    self.assertSameNumber(column[row], cells[name_index], f"{path}:{row + 2} {name}")
                else:
                    self.assertEqual(str(column[row]), cells[name_index], f"{path}:{row + 2} {name}")

    def test_poincare_csv_loads_bit_for_bit(self):
        poincare = self.result.poincare
        self.assertIs(poincare, self.result.dynamics["poincare"])
        self.assertEqual(poincare.dtype["crossing"], np.int64)
        self.assertTableIsTheFile(poincare, self.result.directory / "poincare.csv")
        self.assertEqual(self.result.section["normal"], [0.0, 1.0, 0.0, 0.0])
        self.assertEqual(self.result.section["crossings"], len(poincare))

    def test_lyapunov_csv_and_the_trajectories_columns_load_bit_for_bit(self):
        lyapunov = self.result.lyapunov
        self.assertEqual(list(lyapunov.dtype.names),
                         ["trajectory", "step", "t", "lyapunov0", "lyapunov1", "megno", "mean_megno", "sali", "gali2",
                          "gali3", "fli", "ofli"])
        self.assertTableIsTheFile(lyapunov, self.result.directory / "lyapunov.csv")
        trajectories = self.result.trajectories
        for name in ("lyapunov0", "lyapunov1", "megno", "mean_megno", "sali", "gali2", "gali3", "fli", "ofli",
                     "poincare_crossings"):
            self.assertIn(name, trajectories.dtype.names)
        self.assertTableIsTheFile(trajectories, self.result.directory / "trajectories.csv")

    def test_each_trajectorys_crossings_and_series(self):
        poincare, lyapunov = self.result.poincare, self.result.lyapunov
        trajectories = self.result.trajectories
        self.assertGreater(len(trajectories), 4)
        for i in range(len(trajectories)):
            rows = poincare[poincare["trajectory"] == i]
            crossings = self.result.crossings(i)
            np.testing.assert_array_equal(crossings.crossing, np.arange(len(rows)))
            self.assertEqual(len(rows), trajectories["poincare_crossings"][i])
            np.testing.assert_array_equal(crossings.step, rows["step"])
            np.testing.assert_array_equal(crossings.t, rows["t"])
            self.assertEqual(crossings.q.shape, (len(rows), 2))
            np.testing.assert_array_equal(crossings.q[:, 0], rows["q0"])
            np.testing.assert_array_equal(crossings.p[:, 1], rows["p1"])
            np.testing.assert_array_equal(crossings.H, rows["H"])
            np.testing.assert_allclose(crossings.q[:, 1], 0.0, atol=1e-12)  # on the plane q1 = 0
            series = self.result.lyapunov_series(i)
            mine = lyapunov[lyapunov["trajectory"] == i]
            self.assertEqual(series.exponents.shape, (len(mine), 2))
            np.testing.assert_array_equal(series.exponents[:, 1], mine["lyapunov1"])
            np.testing.assert_array_equal(series.mean_megno, mine["mean_megno"])
            np.testing.assert_array_equal(series.sali, mine["sali"])
            self.assertEqual(series.gali.shape, (len(mine), 2))
            np.testing.assert_array_equal(series.gali[:, 1], mine["gali3"])
            np.testing.assert_array_equal(series.fli, mine["fli"])
            np.testing.assert_array_equal(series.ofli, mine["ofli"])
            np.testing.assert_array_equal(series.step, np.sort(series.step))
        with self.assertRaises(KeyError):
            self.result.crossings(len(trajectories))

    def test_a_trajectory_stopped_by_max_crossings_is_completed_with_a_message(self):
        trajectories = self.result.trajectories
        stopped = trajectories["poincare_crossings"] == MAX_CROSSINGS
        self.assertTrue(stopped.any() and (~stopped).any(), trajectories["poincare_crossings"])
        self.assertEqual(self.result.status, "completed")  # run() returned: exit status 0, no RunError
        self.assertTrue((trajectories["status"] == "completed").all())
        for row in trajectories[stopped]:
            self.assertEqual(row["message"], f"stopped at its {MAX_CROSSINGS}th Poincare crossing (max_crossings)")
            self.assertEqual(row["step"], self.result.crossings(int(row["trajectory"])).step[-1])
            self.assertLess(row["t"], self.result.summary["time"]["t_end"])
        for row in trajectories[~stopped]:
            self.assertEqual(row["message"], "")
            self.assertEqual(row["t"], self.result.summary["time"]["t_end"])
        reloaded = nonsep.load(self.result.directory)
        self.assertSameTable(reloaded.trajectories, trajectories)
        self.assertEqual(reloaded.orbit(int(np.argmax(stopped))).step[-1], trajectories[stopped]["step"][0])

    def test_initial_states_are_the_step_zero_rows(self):
        q, p = self.result.initial_states()
        samples = self.result.samples()
        first = samples[samples["step"] == 0]
        np.testing.assert_array_equal(q[:, 0], first["q0"])
        np.testing.assert_array_equal(p[:, 1], first["p1"])
        np.testing.assert_array_equal(q[:, 1], 0.0)


class DynamicsPlotTest(SharedRun):
    def tearDown(self):
        plt.close("all")
        super().tearDown()

    def test_poincare_points_per_trajectory_on_the_sections_coordinates(self):
        ax = nonsep.plot.poincare(self.result)
        self.assertEqual((ax.get_xlabel(), ax.get_ylabel()), ("$q_0$", "$p_0$"))
        self.assertIn("$q_1$ = 0", ax.get_title())
        (points,) = ax.collections
        poincare = self.result.poincare
        np.testing.assert_array_equal(points.get_offsets(), np.column_stack([poincare["q0"], poincare["p0"]]))
        colours = points.get_facecolors()
        for i in np.unique(poincare["trajectory"]):
            mine = colours[poincare["trajectory"] == i]
            self.assertTrue((mine == mine[0]).all())
        firsts = [tuple(colours[np.argmax(poincare["trajectory"] == i)]) for i in np.unique(poincare["trajectory"])]
        self.assertEqual(len(set(firsts)), len(firsts))  # one colour per trajectory
        ax.figure.savefig(self.folder / "poincare.png", dpi=60)

    def test_poincare_coloured_by_megno_with_a_labelled_colour_bar(self):
        _, given = plt.subplots()
        ax = nonsep.plot.poincare(self.result, ax=given, color_by="mean_megno", x="q0", y="p1", i=[0, 2])
        self.assertIs(ax, given)
        self.assertEqual(ax.get_ylabel(), "$p_1$")
        (points,) = ax.collections
        poincare = self.result.poincare
        mine = poincare[np.isin(poincare["trajectory"], [0, 2])]
        np.testing.assert_array_equal(points.get_array(), self.result.trajectories["mean_megno"][mine["trajectory"]])
        colour_bar = ax.figure.axes[-1]
        self.assertIn("MEGNO", colour_bar.get_ylabel())
        with self.assertRaisesRegex(ValueError, "no column 'x9'"):
            nonsep.plot.poincare(self.result, x="x9")

    def test_chaos_map_over_the_grid_of_initial_conditions(self):
        for value, label in (("mean_megno", "MEGNO"), ("lyapunov0", "Lyapunov")):
            ax = nonsep.plot.chaos_map(self.result, value=value)
            self.assertEqual((ax.get_xlabel(), ax.get_ylabel()), ("$q_0$ (initial)", "$p_0$ (initial)"))
            (image,) = ax.images
            q, p = self.result.initial_states()
            xs, ys = np.linspace(-1.2, 1.2, 4), np.linspace(-1.5, 1.5, 3)
            expected = np.full((3, 4), np.nan)
            for i, (x, y) in enumerate(zip(q[:, 0], p[:, 0])):
                expected[np.argmin(abs(ys - y)), np.argmin(abs(xs - x))] = self.result.trajectories[value][i]
            shown = np.ma.filled(image.get_array().astype(float), np.nan)
            np.testing.assert_array_equal(shown, expected)
            self.assertTrue(np.isnan(expected).any() and not np.isnan(expected).all())  # some states off the shell
            np.testing.assert_allclose(image.get_extent(), [-1.6, 1.6, -2.25, 2.25])
            self.assertIn(label, ax.figure.axes[-1].get_ylabel())
            ax.figure.savefig(self.folder / f"chaos_map_{value}.png", dpi=60)

    def test_a_chaos_map_without_samples_says_to_set_output_every(self):
        job = paper2d_job(q_count=3, p_count=3, t_end=0.5, poincare=False)
        job["output"] = {"every": 0}
        result = nonsep.run(job, output="no_samples")
        with self.assertRaisesRegex(FileNotFoundError, r"output.every = 0.*run the job with output.every > 0"):
            nonsep.plot.chaos_map(result)
        job["output"] = {"every": 100}  # the number of steps: step 0 and the last only
        ax = nonsep.plot.chaos_map(nonsep.run(job, output="first_and_last"))
        self.assertEqual(len(ax.images), 1)

    def test_without_a_section_there_is_no_poincare_plot(self):
        result = nonsep.run(paper2d_job(q_count=3, p_count=3, t_end=0.5, poincare=False), output="plain")
        self.assertIsNone(result.poincare)
        self.assertIsNone(result.lyapunov)  # every = 0: no time series
        with self.assertRaisesRegex(ValueError, "no poincare.csv"):
            nonsep.plot.poincare(result)
        with self.assertRaises(FileNotFoundError):
            result.crossings(0)



class FrequencyMapTest(FolderTestCase):
    def test_frequency_columns_spectra_signals_and_the_map(self):
        # Henon-Heiles (a model given by H) on H = 1/8, four starting points on the section q0 = 0, gauss 3 stages.
        job = {"model": {"plugin": "henon_heiles"}, "integrator": {"scheme": "gauss", "stages": 3},
               "initial": {"grid": {"q": [0.0, {"from": -0.3, "to": 0.3, "count": 2}],
                                    "p": [0.0, {"from": -0.2, "to": 0.2, "count": 2}]},
                           "energy": 0.125, "solve_for": "p0"},
               "time": {"dt": 0.1, "t_end": 200}, "output": {"every": 2000},
               "analysis": {"frequencies": {"every": 2, "spectra": 3}}}
        result = nonsep.run(job, output="out")
        table = result.trajectories
        header, rows = read_csv(result.directory / "trajectories.csv")
        for column in ("frequency0", "frequency1_second", "diffusion"):
            at = header.index(column)
            self.assertEqual(list(table[column]), [float(r[at]) for r in rows])  # bit for bit
        facts = result.frequency_analysis
        self.assertEqual(facts["samples"], 1000)
        self.assertEqual(facts["signals"], [0, 1])
        spectra = result.frequency_spectra
        self.assertEqual(len(spectra), len(table) * 2 * 3)
        self.assertEqual(spectra["signal"].dtype, np.int64)
        self.assertEqual(list(spectra["term"][:3]), [0, 1, 2])
        first = spectra[(spectra["trajectory"] == 1) & (spectra["signal"] == 1) & (spectra["term"] == 0)]
        self.assertEqual(first["frequency"][0], table["frequency1"][1])
        signals = result.frequency_signals()
        self.assertEqual(signals.shape, (len(table), 2, 1000))
        self.assertEqual(signals.dtype, np.complex128)
        # Sample k is the state at step 2 (k + 1): the last one is the final state of trajectory.csv.
        final = result.orbit(2)
        self.assertEqual(signals[2, 0, -1], complex(final.q[-1, 0], final.p[-1, 0]))
        ax = nonsep.plot.frequency_map(result)
        self.assertIn("Frequency map", ax.get_title())
        self.assertEqual(len(ax.collections[0].get_offsets()), len(table))
        ax.figure.savefig(self.folder / "frequency_map.png", dpi=60)
        plt.close(ax.figure)
        ax = nonsep.plot.chaos_map(result, value="diffusion", x="q1", y="p1")
        self.assertIn("diffusion index", ax.figure.axes[-1].get_ylabel())
        plt.close(ax.figure)
        # One signal: the map needs its axes named, and says which.
        job["analysis"]["frequencies"] = {"every": 2, "signals": [1]}
        one = nonsep.run(job, output="one")
        self.assertEqual(list(one.frequency_analysis["signals"]), [1])
        with self.assertRaisesRegex(ValueError, "frequency1_first"):
            nonsep.plot.frequency_map(one)
        ax = nonsep.plot.frequency_map(one, x="frequency1_first", y="frequency1_second")
        self.assertIn("first half", ax.get_xlabel())
        plt.close(ax.figure)


class FailedRunTest(FolderTestCase):
    def test_a_run_error_carries_the_crossings_of_the_trajectories_that_went_on(self):
        # tests/host/plugins/blowup.cpp in 2D: the first state's crossing of q0 = 0.5 cannot be located (grad V
        # refuses one state with |q1| = 0.8 > fail_single_above), the second's can (test_host_dynamics.cpp).
        job = blowup_job([{"q": [0.3, 0.8], "p": [1.0, 0.0]}, {"q": [0.2, 0.1], "p": [0.5, 0.0]}], steps=1600,
                         dimension=2, fail_single_above=0.6)
        job["time"]["dt"] = 0.001
        job["analysis"] = {"poincare": {"component": "q0", "value": 0.5}}
        with self.assertRaises(nonsep.RunError) as caught:
            nonsep.run(job, output="out")
        self.assertEqual(caught.exception.status, 1)
        result = caught.exception.result
        self.assertEqual(result.status, "failed")
        self.assertEqual(list(result.trajectories["status"]), ["failed", "completed"])
        self.assertIn("while locating a Poincare crossing", result.trajectories["message"][0])
        self.assertEqual(len(result.crossings(0).t), 0)
        crossing = result.crossings(1)
        self.assertEqual(list(crossing.crossing), [0])
        self.assertAlmostEqual(crossing.q[0, 0], 0.5, delta=1e-12)  # on the plane
        self.assertEqual(list(result.trajectories["poincare_crossings"]), [0, 1])


if __name__ == "__main__":
    unittest.main()
