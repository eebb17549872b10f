"""nonsep.run and nonsep.validate against the built executable: job files and dicts, where outputs go, runs that
diverge or fail (RunError with the Result), invalid jobs (RunError and validate name the JSON path), a child that
crashes, and the executable's lookup order."""
import contextlib
import io
import os
import shutil
import stat
import tempfile
import unittest
from pathlib import Path

import numpy as np

import nonsep
from nonsep.formula import write_formula_model
from support import EXAMPLES, FolderTestCase, blowup_job, paper1d_job, state


class RunTest(FolderTestCase):
    def test_a_job_file_writes_beside_itself_by_default(self):
        shutil.copy(EXAMPLES / "jobs" / "ensemble.json", "ensemble.json")
        result = nonsep.run("ensemble.json", threads=2)
        self.assertEqual(result.directory, Path("ensemble.out"))
        self.assertTrue((self.folder / "ensemble.out" / "summary.json").exists())
        self.assertEqual(result.status, "completed")
        self.assertEqual(list(result.trajectories["trajectory"]), [0, 1, 2, 3])
        self.assertTrue(np.all(result.trajectories["status"] == "completed"))
        # The job's initial states, as written, are each trajectory's first sample.
        for i, q0 in enumerate([0.5, 1.0, 1.5, 2.0]):
            self.assertEqual(result.orbit(i).q[0, 0], q0)

    def test_output_overrides_the_job_and_threads_do_not_change_the_numbers(self):
        job = paper1d_job([state(0.5, 0.0), state(2.0, 0.0)], steps=50)
        one = nonsep.run(job, output="one", threads=1)
        two = nonsep.run(job, output="two", threads=2)
        self.assertEqual(one.directory, Path("one"))
        self.assertEqual((self.folder / "one" / "trajectory.csv").read_bytes(),
                         (self.folder / "two" / "trajectory.csv").read_bytes())
        self.assertSameTable(one.trajectories, two.trajectories)

    def test_a_model_given_by_h_runs_and_loads_with_its_indicators(self):
        job = {"model": {"plugin": "henon_heiles"}, "integrator": {"scheme": "gauss", "stages": 3},
               "initial": [{"q": [0.0, 0.1], "p": [0.45, 0.0]},
                           {"q": [0.0, -0.2], "p": [0.4, 0.1]}],
               "time": {"dt": 0.02, "steps": 500}, "output": {"every": 50}, "analysis": {"megno": True}}
        result = nonsep.run(job, output="h")
        self.assertEqual(result.status, "completed")
        self.assertEqual(result.summary["hamiltonian"], "general")
        self.assertEqual(result.orbit(1).q.shape, (11, 2))
        self.assertTrue(np.all(np.abs(result.trajectories["max_abs_relative_energy_error"]) < 1e-10))
        self.assertTrue(np.all(np.isfinite(result.trajectories["mean_megno"])))

    def test_a_dict_resolves_relative_paths_against_the_current_directory(self):
        os.mkdir("plugins")
        shutil.copy(os.path.join(os.environ["NONSEP_PLUGIN_PATH"], "blowup.so"), "plugins/blowup.so")
        job = blowup_job(state(1.0, 0.5))
        job["model"]["plugin"] = "plugins/blowup.so"  # a path: relative to the current directory, not the temp file
        job["output"] = {"directory": "out/run"}
        result = nonsep.run(job)
        self.assertEqual(result.directory.resolve(), (self.folder / "out" / "run").resolve())
        self.assertEqual(result.summary["model"]["path"], str((self.folder / "plugins" / "blowup.so").resolve()))
        self.assertEqual(result.status, "completed")

    def test_a_dicts_model_file_and_initial_file_are_relative_to_the_current_directory(self):
        os.mkdir("inputs")
        write_formula_model("inputs/model.json", T="p0 + p0^3/6", V="q0^2/2 + q0^4/12", name="paper1d_twin")
        Path("inputs/states.csv").write_text("q0,p0\n0.5,0.0\n2.0,0.0\n")
        formula_job = paper1d_job({"file": "inputs/states.csv"}, steps=5)
        formula_job["model"] = {"formula": "inputs/model.json"}
        self.assertEqual(nonsep.validate(formula_job), [])  # validate reads both files and compiles nothing
        result = nonsep.run(paper1d_job({"file": "inputs/states.csv"}, steps=5), output="out")
        self.assertEqual([result.orbit(i).q[0, 0] for i in (0, 1)], [0.5, 2.0])

    def test_a_dict_without_output_goes_to_a_new_temporary_folder(self):
        result = nonsep.run(paper1d_job(state(1.0, 0.0), steps=5))
        try:
            self.assertTrue(result.directory.name.startswith("nonsep-run-"))
            self.assertEqual(result.summary["time"]["steps_completed"], 5)
        finally:
            shutil.rmtree(result.directory)
        temporary = set(Path(tempfile.gettempdir()).glob("nonsep-run-*"))
        with self.assertRaises(nonsep.RunError):
            nonsep.run(paper1d_job(state(1.0, 0.0), steps=5) | {"colour": 1})
        self.assertEqual(set(Path(tempfile.gettempdir()).glob("nonsep-run-*")), temporary)  # none left behind

    def test_quiet_false_passes_the_hosts_completion_line_on(self):
        printed = io.StringIO()
        with contextlib.redirect_stdout(printed):
            nonsep.run(paper1d_job(state(1.0, 0.0), steps=5), output="loud", quiet=False)
            nonsep.run(paper1d_job(state(1.0, 0.0), steps=5), output="quiet")
        self.assertEqual(printed.getvalue().count("completed: 1 trajectory"), 1)

    def test_a_diverging_run_raises_with_its_data(self):
        job = blowup_job([state(1.0, 0.5), state(1e103, 1.0), state(-0.5, 0.25)])
        with self.assertRaises(nonsep.RunError) as caught:
            nonsep.run(job, output="out")
        error = caught.exception
        self.assertEqual(error.status, 1)
        self.assertIn("trajectory 1 diverged at step 1", error.stderr)
        self.assertIn("status 1", str(error))
        self.assertEqual(error.problems, [])
        result = error.result
        self.assertEqual(result.status, "diverged")
        self.assertEqual(list(result.trajectories["status"]), ["completed", "diverged", "completed"])
        diverged = result.trajectories[1]
        self.assertEqual(diverged["stop_step"], 1)
        self.assertEqual(diverged["stop_variable"], "q[0]")
        self.assertEqual(diverged["step"], 0)  # the last finite state: the initial one
        # The other two completed all 20 steps; the diverged one has no row after its last finite state.
        self.assertEqual(list(result.trajectories["step"][[0, 2]]), [20, 20])
        self.assertEqual(list(result.orbit(1).step), [0])

    def test_a_failing_plugin_raises_with_the_message(self):
        job = blowup_job([state(1.0, 0.5), state(4.0, 0.1)], fail_above=3.0)
        with self.assertRaises(nonsep.RunError) as caught:
            nonsep.run(job, output="out")
        trajectories = caught.exception.result.trajectories
        self.assertEqual(list(trajectories["status"]), ["completed", "failed"])
        self.assertIn("q = 4.000000 is beyond fail_above", trajectories["message"][1])
        self.assertEqual(trajectories["message"][0], "")

    def test_a_bad_key_in_a_dict_is_named_by_its_json_path(self):
        job = paper1d_job(state(1.0, 0.0))
        job["colour"] = "red"
        job["time"]["dt"] = "0.1"
        with self.assertRaises(nonsep.RunError) as caught:
            nonsep.run(job, output="out")
        self.assertEqual(caught.exception.status, 2)
        self.assertIsNone(caught.exception.result)
        self.assertFalse((self.folder / "out").exists())  # nothing was run
        paths = [problem.path for problem in caught.exception.problems]
        self.assertEqual(sorted(paths), ["/colour", "/time/dt"])
        self.assertEqual(sorted(nonsep.validate(job)), sorted(caught.exception.problems))
        colour = next(p for p in caught.exception.problems if p.path == "/colour")
        self.assertTrue(colour.message.startswith('found the unknown key "colour"; allowed: only the keys'))

    def test_an_old_summary_is_not_taken_for_a_failed_runs(self):
        nonsep.run(paper1d_job(state(1.0, 0.0), steps=3), output="out")
        job = paper1d_job(state(1.0, 0.0), steps=3)
        job["integrator"]["scheme"] = "rk4"
        with self.assertRaises(nonsep.RunError) as caught:
            nonsep.run(job, output="out")
        self.assertEqual(caught.exception.status, 2)
        self.assertIsNone(caught.exception.result)

    def test_non_finite_numbers_in_a_dict_are_refused_before_running(self):
        with self.assertRaises(ValueError):
            nonsep.run(paper1d_job(state(float("nan"), 0.0)), output="out")


class ValidateTest(FolderTestCase):
    def test_a_valid_job_has_no_problems(self):
        self.assertEqual(nonsep.validate(EXAMPLES / "jobs" / "ensemble.json"), [])
        self.assertEqual(nonsep.validate(paper1d_job(state(1.0, 0.0))), [])

    def test_every_problem_of_a_file_with_its_path(self):
        bad = EXAMPLES.parent / "tests" / "host" / "jobs" / "bad" / "many_errors_at_once.json"
        problems = nonsep.validate(bad)
        self.assertEqual([p.path for p in problems],
                         ["/colour", "/initial/q/0", "/integrator/order", "/time/dt", "/output/every"])
        self.assertTrue(all(p.message.startswith("found ") and "; allowed: " in p.message for p in problems))

    def test_a_message_over_several_lines_stays_one_problem(self):
        problems = nonsep.validate(paper1d_job(state(1.0, 0.0)) | {"model": {"plugin": "no_such_model"}})
        self.assertEqual(len(problems), 1)
        self.assertEqual(problems[0].path, "/model/plugin")
        self.assertIn("no_such_model.so (no such file)", problems[0].message)

    def test_a_document_that_is_not_json(self):
        Path("broken.json").write_text('{"model": ')
        problems = nonsep.validate("broken.json")
        self.assertEqual([p.path for p in problems], ["(document)"])
        self.assertIn("not JSON", problems[0].message)


class ExecutableTest(FolderTestCase):
    def setUp(self):
        super().setUp()
        self._environment = dict(os.environ)

    def tearDown(self):
        os.environ.clear()
        os.environ.update(self._environment)
        super().tearDown()

    def fake_executable(self, name, body):
        path = self.folder / name
        path.write_text("#!/bin/sh\n" + body + "\n")
        path.chmod(path.stat().st_mode | stat.S_IXUSR)
        return path

    def test_nonsep_executable_comes_first(self):
        built = os.environ["NONSEP_EXECUTABLE"]
        self.assertEqual(nonsep.executable(), built)
        os.environ["PATH"] = str(self.fake_executable("nonsep", "exit 3").parent) + os.pathsep + os.environ["PATH"]
        self.assertEqual(nonsep.executable(), built)
        del os.environ["NONSEP_EXECUTABLE"]
        self.assertEqual(nonsep.executable(), str(self.folder / "nonsep"))  # the source tree: no <prefix>/bin

    def test_a_nonsep_executable_that_is_not_a_file_is_an_error(self):
        os.environ["NONSEP_EXECUTABLE"] = str(self.folder / "missing")
        with self.assertRaises(nonsep.ExecutableNotFound):
            nonsep.run(paper1d_job(state(1.0, 0.0)), output="out")

    def test_a_crashing_child_is_an_error_not_a_crash_of_python(self):
        os.environ["NONSEP_EXECUTABLE"] = str(self.fake_executable("crash", "echo dying >&2; kill -SEGV $$"))
        with self.assertRaises(nonsep.RunError) as caught:
            nonsep.run(paper1d_job(state(1.0, 0.0)), output="out")
        self.assertEqual(caught.exception.status, -11)
        self.assertIn("killed by SIGSEGV", str(caught.exception))
        self.assertIn("dying", caught.exception.stderr)


class ReadmeTest(FolderTestCase):
    def test_the_readme_example_runs(self):
        # The example of the package's manual, docs/python.md, run as shown from the repository root.
        readme = (EXAMPLES.parent / "docs" / "python.md").read_text()
        section = readme[readme.index("# The Python package\n"):]
        code = section[section.index("```python\n") + len("```python\n"):section.index("\n```\n")]
        os.makedirs("examples/jobs")
        shutil.copy(EXAMPLES / "jobs" / "ensemble.json", "examples/jobs/ensemble.json")
        printed = io.StringIO()
        with contextlib.redirect_stdout(printed):
            exec(compile(code, "docs/python.md", "exec"), {})
        self.assertTrue((self.folder / "energy_error.png").exists())
        self.assertEqual(nonsep.load("ensemble.out").status, "completed")
        self.assertIn("Problem(path='/colour'", printed.getvalue())


if __name__ == "__main__":
    unittest.main()
