"""nonsep.load: every number equal, bit for bit, to the CSV and JSON text the host wrote (read independently here
with the csv module and float()); trajectories.csv read by header whatever the column order, and the same array
built from summary.json without it; empty cells as NaN; a study's table and exponents; dynamics files."""
import csv
import json
import math
import unittest

import numpy as np

import nonsep
from nonsep import tables
from support import FolderTestCase, blowup_job, number, paper1d_job, read_csv, state

# The header of trajectories.csv (docs/outputs.md).
TRAJECTORIES_HEADER = ["trajectory", "status", "step", "t", "q0", "p0", "H0", "H", "relative_energy_error",
                       "max_abs_relative_energy_error", "stop_step", "stop_t", "stop_variable", "message"]


class SamplesTest(FolderTestCase):
    def test_every_sample_equals_its_csv_text(self):
        result = nonsep.run(paper1d_job([state(0.5, 0.0), state(1.0, 0.0), state(2.0, 0.0)], steps=300, every=7),
                            output="out")
        header, rows = read_csv(self.folder / "out" / "trajectory.csv")
        samples = result.samples()
        self.assertEqual(list(samples.dtype.names), header)
        self.assertEqual(len(samples), len(rows))
        for row, loaded in zip(rows, samples):
            for name, cell in zip(header, row):
                if name in ("trajectory", "step"):
                    self.assertEqual(loaded[name], int(cell))
                else:
                    self.assertSameNumber(loaded[name], cell, name)
        # orbit(i): the rows of trajectory i in step order, q and p as [samples, 1].
        orbit = result.orbit(1)
        mine = [row for row in rows if row[0] == "1"]
        self.assertEqual(orbit.q.shape, (len(mine), 1))
        self.assertEqual(list(orbit.step), [int(row[1]) for row in mine])
        self.assertEqual([x.hex() for x in orbit.p[:, 0]], [float(row[4]).hex() for row in mine])
        self.assertEqual([x.hex() for x in orbit.H], [float(row[5]).hex() for row in mine])
        with self.assertRaises(KeyError):
            result.orbit(3)

    def test_unknown_energies_are_nan_and_both_readers_agree(self):
        # blowup_gradients_only has no Hessians: H and relative_energy_error are empty cells.
        job = blowup_job([state(1.0, 0.5), state(-0.5, 0.25)])
        job["model"]["plugin"] = "blowup_gradients_only"
        result = nonsep.run(job, output="out")
        samples = result.samples()
        self.assertTrue(np.all(np.isnan(samples["H"])))
        self.assertTrue(np.all(np.isnan(samples["relative_energy_error"])))
        self.assertTrue(np.all(np.isfinite(samples["q0"])))
        path = self.folder / "out" / "trajectory.csv"
        header, _ = read_csv(path)
        body = path.read_text().partition("\n")[2]
        self.assertSameTable(samples, tables._read_cells(header, body))
        self.assertTrue(np.all(np.isnan(result.trajectories["H0"])))

    def test_a_two_dimensional_orbit(self):
        job = {"model": {"plugin": "radial"}, "integrator": {"scheme": "triplet", "order": "4/3"},
               "initial": {"q": [0.8, 0.0], "p": [0.0, 0.439]}, "time": {"dt": 0.01, "steps": 40}}
        result = nonsep.run(job, output="out")
        orbit = result.orbit(0)
        self.assertEqual(orbit.q.shape, (41, 2))
        self.assertEqual(list(orbit.q[0]), [0.8, 0.0])
        self.assertEqual(list(orbit.p[0]), [0.0, 0.439])
        self.assertEqual(list(result.trajectories.dtype.names[4:8]), ["q0", "q1", "p0", "p1"])


class TrajectoriesTest(FolderTestCase):
    def test_each_number_is_the_one_in_trajectories_csv(self):
        job = blowup_job([state(1.0, 0.5), state(1e103, 1.0), state(-0.5, 0.25)])
        job["analysis"] = {"closest_return_after": 0.05}
        with self.assertRaises(nonsep.RunError) as caught:
            nonsep.run(job, output="out")
        result = caught.exception.result
        with open(self.folder / "out" / "trajectories.csv", newline="") as f:
            entries = list(csv.DictReader(f))
        table = result.trajectories
        self.assertEqual(len(table), 3)
        self.assertEqual(table.dtype.names[-3:], ("closest_return_distance", "closest_return_t", "closest_return_step"))
        for entry, row in zip(entries, table):
            self.assertEqual(row["trajectory"], int(entry["trajectory"]))
            self.assertEqual(row["status"], entry["status"])
            self.assertEqual(row["step"], int(entry["step"]))
            for name in ("t", "q0", "p0", "H0", "H"):
                self.assertEqual(row[name].hex(), float(entry[name]).hex(), name)
        self.assertEqual(table["status"][1], "diverged")
        self.assertEqual((table["stop_step"][1], table["stop_t"][1], table["stop_variable"][1]), (1.0, 0.01, "q[0]"))
        self.assertTrue(math.isnan(table["closest_return_distance"][1]))  # stopped before 0.05: null
        self.assertEqual(table["closest_return_step"][0], float(entries[0]["closest_return_step"]))
        # The final state of a completed trajectory is its last row in trajectory.csv, to the bit.
        last = result.orbit(0)
        self.assertEqual((last.q[-1, 0].hex(), last.p[-1, 0].hex()), (table["q0"][0].hex(), table["p0"][0].hex()))

    def test_trajectories_csv_is_read_by_header_in_any_column_order_with_extra_columns_and_quoted_messages(self):
        result = nonsep.run(paper1d_job([state(0.5, 0.0), state(2.0, 0.0)], steps=40), output="out")
        as_written = result.trajectories
        # The host's file rewritten with its columns in another order, an extra (dynamics) column, and a message
        # holding a comma and quotes; load() must find every column by its header and give the same numbers.
        order = list(reversed(TRAJECTORIES_HEADER)) + ["lyapunov_1"]
        message = 'plugin said "no", then, stopped'
        with open(self.folder / "out" / "trajectories.csv", "w", newline="") as f:
            writer = csv.writer(f, lineterminator="\n")
            writer.writerow(order)
            for row in as_written:
                cells = {name: _cell(row[name]) for name in TRAJECTORIES_HEADER}
                cells["message"] = message if row["trajectory"] == 1 else ""
                writer.writerow([cells.get(name, "0.125") for name in order])
        loaded = nonsep.load(self.folder / "out").trajectories
        self.assertEqual(loaded.dtype.names, tuple(order))
        for name in TRAJECTORIES_HEADER:
            if name == "message":
                self.assertEqual(list(loaded[name]), ["", message])
            else:
                self.assertEqual(as_written[name].tobytes(), loaded[name].astype(as_written[name].dtype).tobytes(),
                                 name)
        self.assertEqual(loaded["lyapunov_1"].dtype, np.float64)
        self.assertEqual(list(loaded["lyapunov_1"]), [0.125, 0.125])


def _cell(value):
    if isinstance(value, (float, np.floating)):
        return "" if math.isnan(value) else repr(float(value))
    return str(value)


class StudyTest(FolderTestCase):
    def test_the_convergence_table_and_the_fits(self):
        job = {"model": {"plugin": "paper1d"}, "initial": state(2.0, 0.0), "time": {"t_end": 0.3863765573361232},
               "study": {"reference": {"q": [0.0], "p": [-1.5723027555148466]},
                         "integrators": [{"scheme": "basic", "t2": -2.0, "steps": [1024, 2048, 4096]},
                                         {"scheme": "triplet", "order": "4/3", "t2": -2.0,
                                          "steps": [256, 512, 1024]}]}}
        result = nonsep.run(job, output="out")
        self.assertIsNone(result.trajectories)
        header, rows = read_csv(self.folder / "out" / "convergence.csv")
        table = result.convergence
        self.assertEqual(list(table.dtype.names), header)
        self.assertEqual(list(table["integrator"]), [row[0] for row in rows])
        self.assertEqual(list(table["symplectic"]), [row[4] == "true" for row in rows])
        self.assertEqual(list(table["steps"]), [int(row[6]) for row in rows])
        for name in ("dt", "relative_energy_error", "phase_error"):
            k = header.index(name)
            self.assertEqual([x.hex() for x in table[name]], [number(row[k]).hex() for row in rows], name)
        # The exponents, from summary.json, are the least-squares slopes of log max |dH/H0| (the largest over each
        # run, at least the value at t_end) on log dt of the table.
        self.assertEqual(list(result.exponents), ["basic", "triplet 4/3"])
        self.assertTrue(np.all(table["max_abs_relative_energy_error"] >= np.abs(table["relative_energy_error"])))
        for name, exponent in result.exponents.items():
            rows_of = table[table["integrator"] == name]
            slope = np.polyfit(np.log(rows_of["dt"]), np.log(rows_of["max_abs_relative_energy_error"]), 1)[0]
            self.assertAlmostEqual(exponent, slope, places=9)
        self.assertAlmostEqual(result.exponents["basic"], 2 / 3, delta=0.03)     # eq. expalg: order 2/3
        self.assertAlmostEqual(result.exponents["triplet 4/3"], 4 / 3, delta=0.03)  # eq. sym43


class DynamicsTest(FolderTestCase):
    def test_other_csv_files_and_results_h5_are_loaded_by_name(self):
        nonsep.run(paper1d_job(state(1.0, 0.0), steps=4), output="out")
        (self.folder / "out" / "poincare.csv").write_text("trajectory,crossing,t,q0,p0\n0,1,0.5,0,-1.25\n0,2,,1e-3,\n")
        (self.folder / "out" / "megno.csv").write_text("trajectory,megno,note\n0,2.0,chaotic?\n")
        import h5py
        with h5py.File(self.folder / "out" / "results.h5", "w") as f:
            f["lyapunov/exponents"] = np.array([[0.5, -0.5]])
        result = nonsep.load(self.folder / "out")
        self.assertEqual(sorted(result.dynamics), ["megno", "poincare", "results.h5/lyapunov/exponents"])
        poincare = result.dynamics["poincare"]
        self.assertEqual(list(poincare["t"][:1]), [0.5])
        self.assertTrue(math.isnan(poincare["t"][1]) and math.isnan(poincare["p0"][1]))
        self.assertEqual(poincare["q0"][1], 1e-3)
        self.assertEqual(result.dynamics["megno"]["note"][0], "chaotic?")  # not a number: text
        np.testing.assert_array_equal(result.dynamics["results.h5/lyapunov/exponents"], [[0.5, -0.5]])
        with self.assertRaises(KeyError):
            result.dynamics["lyapunov"]


class ErrorEstimateTest(FolderTestCase):
    def test_the_estimates_of_each_trajectory_and_its_columns(self):
        job = paper1d_job([state(1.0, 0.0), state(2.0, 0.0)], steps=40, every=10,
                          analysis={"error_estimate": True})
        result = nonsep.run(job, output="out")
        rows = read_csv(self.folder / "out" / "error_estimate.csv")[1]
        self.assertEqual(len(result.error_estimate), len(rows))
        for index in (0, 1):
            estimates = result.error_estimates(index)
            self.assertEqual(list(estimates.step), [10, 20, 30, 40])
            self.assertTrue(np.all(estimates.phase_error > 0))
            self.assertEqual(list(estimates.separated), [False] * 4)
            # trajectories.csv holds the last estimate, at t_end.
            self.assertEqual(result.trajectories["estimated_phase_error"][index], estimates.phase_error[-1])
            self.assertEqual(result.trajectories["error_estimate"][index], "within_horizon")
        self.assertIsNone(nonsep.run(paper1d_job(state(1.0, 0.0), steps=4), output="plain").error_estimate)


class TablesTest(FolderTestCase):
    def test_a_row_of_the_wrong_length_is_an_error(self):
        (self.folder / "bad.csv").write_text('a,message\n1,"x, y"\n2\n')
        with self.assertRaisesRegex(ValueError, "line 3: found 1 cells; expected 2"):
            tables.read_table(self.folder / "bad.csv")

    def test_the_three_readers_give_the_same_table(self):
        # np.loadtxt into typed columns (numbers only, no empty cells), np.loadtxt as text cells (the rest), and
        # the csv module (the reference, and the reader that names a row of the wrong length).
        numbers = "trajectory,step,t,q0\n0,0,0,0.1\n0,1,0.30000000000000004,1e-300\n"
        mixed = ("trajectory,status,step,H,stop_variable,note,lyapunov_1\n"
                 "0,completed,5,0.1,,ok,\n1,diverged,2,,p[0],5 steps,2.5e-3\n2,failed,,,,,\n")
        for text, fields in ((numbers, {"q0": [0.1, 1e-300], "t": [0.0, 0.30000000000000004]}),
                             (mixed, {"status": ["completed", "diverged", "failed"], "stop_variable": ["", "p[0]", ""],
                                      "note": ["ok", "5 steps", ""]})):
            if text is mixed:
                text = text.replace("2,failed,,", "2,failed,7,")  # every integer cell filled
            path = self.folder / "table.csv"
            path.write_text(text)
            header, body = text.split("\n", 1)
            table = tables.read_table(path)
            self.assertSameTable(table, tables._read_cells(header.split(","), body))
            self.assertSameTable(table, tables._read_text(header.split(","), body))
            for name, values in fields.items():
                self.assertEqual(list(table[name]), values, name)
        self.assertEqual(table.dtype["note"].kind, "U")
        self.assertEqual(table.dtype["step"], np.int64)
        self.assertEqual([x.hex() for x in table["lyapunov_1"][1:]], [float("2.5e-3").hex(), "nan"])
        self.assertTrue(np.isnan(table["H"][1]) and np.isnan(table["lyapunov_1"][0]))

    def test_a_header_without_rows_is_an_empty_table(self):
        (self.folder / "empty.csv").write_text("trajectory,step,t,q0\n")
        table = tables.read_table(self.folder / "empty.csv")
        self.assertEqual((len(table), table.dtype["step"]), (0, np.int64))

    def test_a_last_line_cut_off_by_a_hard_kill_is_dropped(self):
        # The host writes whole rows only; a last line without its newline is what a SIGKILL or full disk cut.
        for torn in ("0,2,0.2,-4", "0,2,0.", "0"):
            (self.folder / "torn.csv").write_text("trajectory,step,t,q0\n0,0,0,0.1\n0,1,0.1,-4e-05\n" + torn)
            table = tables.read_table(self.folder / "torn.csv")
            self.assertEqual(list(table["step"]), [0, 1], torn)
            self.assertEqual(table["q0"][1].hex(), float("-4e-05").hex())
        (self.folder / "torn.csv").write_text("trajectory,step,t,q0\n0,0,0")
        self.assertEqual(len(tables.read_table(self.folder / "torn.csv")), 0)


if __name__ == "__main__":
    unittest.main()
