"""output.format "hdf5": one ensemble run twice, csv and hdf5, and every number of results.h5 checked with h5py against
the CSV run's files, read as text (support.read_csv): /samples row by row (NaN exactly where trajectory.csv has no
row), /trajectories, /poincare, /lyapunov; the root attributes; chunked, shuffled and deflated datasets. Then a run
interrupted at a checkpoint and resumed ends with the numbers of an uninterrupted one (h5py and h5diff), and a
results.h5 that cannot be reopened is refused by name."""
import json
import math
import shutil
import signal
import subprocess
import time
import unittest
from pathlib import Path

import h5py
import numpy as np

import nonsep
from support import FolderTestCase, blowup_job, read_csv, state

EVERY = 400


def ensemble_job(output_format):
    """paper2d on the shell H = 7 (12 grid points, some left out), MPE 4, with a Poincare section that stops
    trajectories after 3 crossings (so some stop between samples and NaN follows) and a Lyapunov time series."""
    return {"model": {"plugin": "paper2d", "parameters": {"coupling": 0.2}},
            "integrator": {"scheme": "mpe", "order": 4},
            "initial": {"grid": {"q": [{"from": -1.2, "to": 1.2, "count": 4}, 0.0],
                                 "p": [{"from": -1.5, "to": 1.5, "count": 3}, 0.0]},
                        "energy": 7.0, "solve_for": "p1"},
            "time": {"dt": 0.005, "t_end": 12.0}, "output": {"every": EVERY, "format": output_format},
            "analysis": {"lyapunov": {"vectors": 2, "renormalize_every": 10, "every": 150}, "megno": True,
                         "sali": True, "gali": 3,
                         "poincare": {"component": "q1", "value": 0.0, "direction": "+", "max_crossings": 3}}}


class Hdf5AgainstCsvTest(FolderTestCase):
    @classmethod
    def setUpClass(cls):
        import tempfile
        cls._shared = tempfile.TemporaryDirectory(prefix="nonsep-python-hdf5-")
        base = Path(cls._shared.name)
        cls.csv = nonsep.run(ensemble_job("csv"), output=base / "csv", threads=2)
        cls.hdf5 = nonsep.run(ensemble_job("hdf5"), output=base / "hdf5", threads=2)
        cls.file = h5py.File(cls.hdf5.directory / "results.h5", "r")

    @classmethod
    def tearDownClass(cls):
        cls.file.close()
        cls._shared.cleanup()

    def assertSameColumn(self, dataset, cells, what):
        self.assertEqual(len(dataset), len(cells), what)
        values = dataset[()]
        for row, cell in enumerate(cells):
            if dataset.dtype.kind == "i":
                self.assertEqual(int(values[row]), int(cell), f"{what} row {row}")
            elif dataset.dtype.kind == "f":
                self.assertSameNumber(values[row], cell, f"{what} row {row}")
            else:
                self.assertEqual(values[row].decode(), cell, f"{what} row {row}")

    def assertTableIsTheFile(self, group, path):
        header, rows = read_csv(path)
        self.assertGreater(len(rows), 0, path)
        self.assertEqual(sorted(self.file[group].keys()), sorted(header))
        for k, name in enumerate(header):
            cells = [row[k] for row in rows]
            dataset = self.file[group][name]
            expected = "i" if name in ("trajectory", "step") else (
                "f" if all(c == "" or _is_number(c) for c in cells) else "O")
            self.assertEqual(dataset.dtype.kind, expected, f"{group}/{name}")
            self.assertSameColumn(dataset, cells, f"{group}/{name}")

    def test_the_run_writes_results_h5_instead_of_trajectory_csv(self):
        directory = self.hdf5.directory
        self.assertFalse((directory / "trajectory.csv").exists())
        for name in ("trajectories.csv", "poincare.csv", "lyapunov.csv", "summary.json"):
            self.assertTrue((directory / name).exists(), name)
        output = self.hdf5.summary["output"]
        self.assertIsNone(output["trajectory"])
        self.assertEqual(output["results"], "results.h5")
        self.assertEqual(output["format"], "hdf5")
        self.assertNotIn("results", self.csv.summary["output"])

    def test_samples_equal_trajectory_csv_row_by_row_with_nan_exactly_where_it_has_no_row(self):
        header, rows = read_csv(self.csv.directory / "trajectory.csv")
        samples = self.file["samples"]
        step, t, q, p, H = (samples[name][()] for name in ("step", "t", "q", "p", "H"))
        steps = self.csv.summary["time"]["steps"]
        self.assertEqual(list(step), list(range(0, steps + 1, EVERY)) + ([steps] if steps % EVERY else []))
        self.assertEqual(step.dtype, np.uint64)
        count, n = self.csv.summary["trajectories"], 2
        self.assertEqual(q.shape, (len(step), count, n))
        self.assertEqual(H.shape, (len(step), count))
        column = {name: k for k, name in enumerate(header)}
        row_of_step = {int(s): i for i, s in enumerate(step)}
        seen = np.zeros((len(step), count), dtype=bool)
        off_samples = 0
        for row in rows:
            s, j = int(row[column["step"]]), int(row[column["trajectory"]])
            if s not in row_of_step:  # a final state between samples: /trajectories has it
                off_samples += 1
                continue
            i = row_of_step[s]
            seen[i, j] = True
            self.assertSameNumber(t[i], row[column["t"]], f"t of step {s}")
            for k in range(n):
                self.assertSameNumber(q[i, j, k], row[column[f"q{k}"]], f"q{k} of {j} at step {s}")
                self.assertSameNumber(p[i, j, k], row[column[f"p{k}"]], f"p{k} of {j} at step {s}")
            self.assertSameNumber(H[i, j], row[column["H"]], f"H of {j} at step {s}")
        self.assertGreater(off_samples, 0, "the job must stop some trajectories between samples")
        self.assertTrue(np.isnan(q[~seen]).all() and np.isnan(p[~seen]).all() and np.isnan(H[~seen]).all())
        self.assertFalse(np.isnan(q[seen]).any())
        self.assertGreater((~seen).sum(), 0, "some trajectory must have stopped before the last sample")

    def test_the_tables_equal_the_csv_files(self):
        for group, name in (("trajectories", "trajectories.csv"), ("poincare", "poincare.csv"),
                            ("lyapunov", "lyapunov.csv")):
            with self.subTest(group=group):
                self.assertTableIsTheFile(group, self.csv.directory / name)
        self.assertEqual(self.file["trajectories"]["status"].dtype.kind, "O")
        self.assertEqual(h5py.check_string_dtype(self.file["trajectories"]["status"].dtype).encoding, "utf-8")

    def test_root_attributes_describe_the_run(self):
        attributes = self.file.attrs
        summary = json.loads(attributes["summary"])
        self.assertEqual(summary["output"]["results"], "results.h5")
        self.assertEqual(attributes["format_version"], 1)
        self.assertEqual(attributes["model"], "paper2d")
        self.assertEqual(json.loads(attributes["parameters"]), {"coupling": 0.2})
        self.assertEqual(json.loads(attributes["integrator"]), self.hdf5.summary["integrator"])
        self.assertEqual(attributes["hamiltonian"], "TTV")
        self.assertEqual(attributes["dt"], 0.005)
        self.assertEqual(attributes["t_end"], 12.0)
        self.assertEqual(attributes["steps"], 2400)
        self.assertEqual(attributes["every"], EVERY)
        self.assertEqual(attributes["dimension"], 2)
        self.assertEqual(attributes["trajectories"], self.hdf5.summary["trajectories"])
        self.assertEqual(attributes["hdf5_version"], h5py.version.hdf5_version)
        for name in ("nonsep_version", "plugin_version"):
            self.assertTrue(attributes[name], name)

    def test_datasets_are_chunked_shuffled_and_deflated(self):
        for name in ("samples/q", "samples/p", "samples/H", "trajectories/q0", "poincare/t", "lyapunov/lyapunov0"):
            dataset = self.file[name]
            self.assertIsNotNone(dataset.chunks, name)
            self.assertEqual(dataset.compression, "gzip", name)
            self.assertTrue(dataset.shuffle, name)
        self.assertEqual(self.file["samples/q"].chunks[2], 2)

    def test_result_loads_samples_alike_for_both_formats(self):
        first, second = self.csv.sample_arrays(), self.hdf5.sample_arrays()
        for name in first._fields:
            self.assertTrue(np.array_equal(getattr(first, name), getattr(second, name), equal_nan=True), name)
        for j in range(self.csv.summary["trajectories"]):
            a, b = self.csv.orbit(j), self.hdf5.orbit(j)
            at_samples = np.isin(a.step, second.step)
            self.assertEqual(a.q[at_samples].tobytes(), b.q.tobytes(), f"orbit {j}")
            self.assertEqual(a.relative_energy_error[at_samples].tobytes(), b.relative_energy_error.tobytes())
        self.assertEqual(self.hdf5.format, "hdf5")


def _is_number(cell):
    try:
        return not math.isnan(float(cell)) or cell == "nan"
    except ValueError:
        return False


STEPS = 60


def slow_job(sleep_ms, output_format="hdf5"):
    """Three blowup states (one diverges at once), a checkpoint every step, a sample every 7 steps; grad V sleeps
    sleep_ms per call."""
    job = blowup_job([state(0.5, 0.5), state(1e103, 0.0), state(0.3, -0.2)], steps=STEPS, sleep_ms=sleep_ms)
    job["checkpoint"] = {"every_steps": 1, "every_seconds": 0}
    job["output"] = {"every": 7, "format": output_format}
    return job


class Hdf5ResumeTest(FolderTestCase):
    def start(self, job, output, *extra):
        path = self.folder / f"{output}.json"
        path.write_text(json.dumps(job))
        return subprocess.Popen([nonsep.executable(), "run", "--quiet", "--output", output, str(path), *extra],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)

    def interrupted_run(self):
        process = self.start(slow_job(5), "out")
        checkpoint = self.folder / "out" / "checkpoint.json"
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:  # polling for a checkpoint past a few samples
            try:
                if json.loads(checkpoint.read_text())["step"] >= 20:
                    break
            except (OSError, ValueError, KeyError):
                pass
            time.sleep(0.01)
        process.send_signal(signal.SIGINT)
        _, stderr = process.communicate(timeout=60)
        self.assertEqual(process.returncode, 130, stderr)
        self.assertTrue(checkpoint.exists())

    def test_interrupted_and_resumed_ends_with_the_numbers_of_an_uninterrupted_run(self):
        with self.assertRaises(nonsep.RunError) as caught:  # exit 1: the state that diverges at once
            nonsep.run(slow_job(0), output="reference")
        self.assertEqual(caught.exception.result.status, "diverged")
        self.interrupted_run()
        with h5py.File("out/results.h5", "r") as f:
            interrupted_q = f["samples/q"][()]
        self.assertTrue(np.isnan(interrupted_q[-1]).all(), "the interrupted run must not have reached the end")
        with self.assertRaises(nonsep.RunError):  # the diverged state, as in the reference
            nonsep.run(slow_job(5), output="out", resume=True)
        self.assertFalse((self.folder / "out" / "checkpoint.json").exists())
        with h5py.File("out/results.h5", "r") as resumed, h5py.File("reference/results.h5", "r") as uninterrupted:
            names = []
            uninterrupted.visititems(lambda name, item: names.append(name) if isinstance(item, h5py.Dataset) else None)
            self.assertIn("samples/q", names)
            for name in names:
                a, b = resumed[name][()], uninterrupted[name][()]
                if a.dtype.kind == "f":
                    self.assertEqual(a.tobytes(), b.tobytes(), name)
                else:
                    self.assertEqual(list(a), list(b), name)
        h5diff = shutil.which("h5diff")
        if h5diff:  # hdf5-tools (scripts/setup.sh); NaN compared equal to NaN with --nan
            for group in ("/samples", "/trajectories"):
                result = subprocess.run([h5diff, "--nan", "out/results.h5", "reference/results.h5", group, group],
                                        capture_output=True, text=True)
                self.assertEqual(result.returncode, 0, result.stdout + result.stderr)

    def test_a_results_h5_that_cannot_be_reopened_is_refused_by_name(self):
        self.interrupted_run()
        Path("out/results.h5").write_bytes(b"not an HDF5 file")
        with self.assertRaises(nonsep.RunError) as caught:
            nonsep.run(slow_job(5), output="out", resume=True)
        self.assertEqual(caught.exception.status, 2)
        self.assertIn("results.h5", caught.exception.stderr)
        self.assertIn("cannot resume", caught.exception.stderr)

    def test_without_samples_results_h5_has_the_tables_only(self):
        job = slow_job(0)
        job["output"]["every"] = 0
        with self.assertRaises(nonsep.RunError) as caught:
            nonsep.run(job, output="out")
        result = caught.exception.result
        self.assertIsNone(result.summary["output"]["trajectory"])
        with h5py.File(result.directory / "results.h5", "r") as f:
            self.assertNotIn("samples", f)
            self.assertEqual(list(f["trajectories/status"].asstr()[()]), list(result.trajectories["status"]))
        with self.assertRaises(FileNotFoundError):
            result.sample_arrays()


if __name__ == "__main__":
    unittest.main()
