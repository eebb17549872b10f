"""Jobs and helpers shared by the Python tests. The tests run with NONSEP_EXECUTABLE (the built host),
NONSEP_PLUGIN_PATH (tests/host's test plugins) and PYTHONPATH (the source tree's package) set by ctest."""
import csv
import os
import tempfile
import unittest
from pathlib import Path

SOURCE_DIR = Path(__file__).resolve().parents[2]
EXAMPLES = SOURCE_DIR / "examples"


def state(q, p):
    return {"q": [q], "p": [p]}


def paper1d_job(initial, steps=200, every=1, **extra):
    """The paper's 1D test with the basic step, t2 = -2, dt = 0.005 (its Figure 1 settings)."""
    return {"model": {"plugin": "paper1d"}, "integrator": {"scheme": "basic", "t2": -2.0}, "initial": initial,
            "time": {"dt": 0.005, "steps": steps}, "output": {"every": every}, **extra}


def blowup_job(initial, steps=20, **parameters):
    """tests/host/plugins/blowup.cpp: T = p^2/2, V = q^4/4 (H_TTV = 3 q^2 p^2); grad V overflows for |q| above
    ~5.6e102, so such a state diverges in its first step."""
    return {"model": {"plugin": "blowup", "parameters": parameters}, "integrator": {"scheme": "basic"},
            "initial": initial, "time": {"dt": 0.01, "steps": steps}}


def read_csv(path):
    """(header, rows) with every cell as text: the independent reading the loader is compared with."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], rows[1:]


def number(cell):
    """A CSV cell as the host means it: empty is unknown (None), otherwise float(), which round-trips the
    shortest decimals the host writes."""
    return None if cell == "" else float(cell)


class FolderTestCase(unittest.TestCase):
    """Each test in a fresh temporary folder, which is also the current directory."""

    def setUp(self):
        self._folder = tempfile.TemporaryDirectory(prefix="nonsep-python-test-")
        self.folder = Path(self._folder.name)
        self._previous = os.getcwd()
        os.chdir(self.folder)

    def tearDown(self):
        os.chdir(self._previous)
        self._folder.cleanup()

    def assertSameNumber(self, loaded, cell, what=""):
        expected = number(cell)
        if expected is None:
            self.assertNotEqual(loaded, loaded, f"{what}: an empty cell must load as NaN, found {loaded}")
        else:
            self.assertEqual(float(loaded).hex(), expected.hex(), what)

    def assertSameTable(self, first, second):
        """Same fields, same types and the same bits in every cell (NaN included)."""
        self.assertEqual(first.dtype, second.dtype)
        self.assertEqual(len(first), len(second))
        for name in first.dtype.names:
            self.assertEqual(first[name].tobytes(), second[name].tobytes(), f"column {name}")
