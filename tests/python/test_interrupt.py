"""Ctrl-C during nonsep.run: the KeyboardInterrupt is passed to the child as one SIGINT, the run stops after its
step with a checkpoint and its outputs (RunInterrupted, status 130, with the Result), and run(..., resume=True)
finishes it with the same trajectory.csv and final states, bit for bit, as a run that was never interrupted."""
import signal
import threading
import unittest
from pathlib import Path

import nonsep
from support import FolderTestCase, blowup_job, state

STEPS = 60  # the orbit from (0.5, 0.5) leaves for infinity near t = 0.93 (step 93)


def slow_job(sleep_ms):
    """blowup's grad V sleeps sleep_ms per call (4 calls a basic step: ~20 ms a step at 5 ms), a checkpoint every
    step, a sample every step."""
    job = blowup_job(state(0.5, 0.5), steps=STEPS, sleep_ms=sleep_ms)
    job["checkpoint"] = {"every_steps": 1, "every_seconds": 0}
    job["output"] = {"every": 1}
    return job


class InterruptTest(FolderTestCase):
    def interrupt_when(self, path, finished):
        """Sends SIGINT to this process's main thread once `path` exists, unless `finished` is set first."""
        main = threading.main_thread().ident

        def watch():
            while not finished.is_set():
                if path.exists():
                    signal.pthread_kill(main, signal.SIGINT)
                    return
                finished.wait(0.005)  # polling the condition; `finished` ends the wait at once

        watcher = threading.Thread(target=watch, daemon=True)
        watcher.start()
        return watcher

    def test_ctrl_c_then_resume_gives_the_uninterrupted_run(self):
        reference = nonsep.run(slow_job(0), output="reference")
        finished = threading.Event()
        watcher = self.interrupt_when(self.folder / "out" / "checkpoint.json", finished)
        try:
            with self.assertRaises(nonsep.RunInterrupted) as caught:
                nonsep.run(slow_job(5), output="out")
        finally:
            finished.set()
            watcher.join()
        error = caught.exception
        self.assertIsInstance(error, KeyboardInterrupt)
        self.assertIsInstance(error, nonsep.RunError)
        self.assertEqual(error.status, 130)
        self.assertIn("stopped by SIGINT", error.stderr)
        interrupted = error.result
        self.assertEqual(interrupted.status, "interrupted")
        completed = interrupted.summary["time"]["steps_completed"]
        self.assertTrue(0 < completed < STEPS, completed)
        self.assertEqual(list(interrupted.trajectories["status"]), ["interrupted"])
        self.assertEqual(interrupted.orbit(0).step[-1], completed)
        self.assertTrue((self.folder / "out" / "checkpoint.json").exists())

        resumed = nonsep.run(slow_job(5), output="out", resume=True)
        self.assertEqual(resumed.status, "completed")
        self.assertFalse((self.folder / "out" / "checkpoint.json").exists())
        self.assertEqual(Path("out/trajectory.csv").read_bytes(), Path("reference/trajectory.csv").read_bytes())
        self.assertSameTable(resumed.trajectories, reference.trajectories)
        self.assertSameTable(resumed.samples(), reference.samples())
        # It did resume (a fresh run would give the same numbers): a resumed run evaluates grad V once more than an
        # uninterrupted one, the gradient the basic step would have reused (docs/outputs.md, "--resume").
        self.assertEqual(resumed.summary["evaluations"]["grad_T"], reference.summary["evaluations"]["grad_T"])
        self.assertEqual(resumed.summary["evaluations"]["grad_V"], reference.summary["evaluations"]["grad_V"] + 1)

    def test_resume_without_a_checkpoint_is_refused(self):
        nonsep.run(slow_job(0), output="out")
        with self.assertRaises(nonsep.RunError) as caught:
            nonsep.run(slow_job(0), output="out", resume=True)
        self.assertEqual(caught.exception.status, 2)
        self.assertIn("nothing to resume", caught.exception.stderr)


if __name__ == "__main__":
    unittest.main()
