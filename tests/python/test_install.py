"""The installed package runs the installed executable: `cmake --install` of the build ($NONSEP_BUILD_DIR, with
$CMAKE_COMMAND) into a temporary prefix, then a fresh Python whose only nonsep is that prefix's: PYTHONPATH is
<prefix>/lib/python3/dist-packages, NONSEP_EXECUTABLE and NONSEP_PLUGIN_PATH are unset, and PATH has no nonsep.
The installed host finds the installed paper1d plugin by itself; the installed package plots work-precision studies
(nonsep.work_precision) and the dynamics examples are installed."""
import json
import os
import shutil
import subprocess
import tempfile
import unittest
from pathlib import Path

CHILD = """
import json, sys
import nonsep
print(json.dumps({"package": nonsep.__file__, "executable": nonsep.executable()}))
result = nonsep.run({"model": {"plugin": "paper1d"}, "integrator": {"scheme": "basic", "t2": -2.0},
                     "initial": {"q": [2.0], "p": [0.0]}, "time": {"dt": 0.005, "steps": 20}}, output=sys.argv[1])
print(json.dumps({"status": result.status, "plugin": result.summary["model"]["path"],
                  "steps": int(result.orbit(0).step[-1])}))
"""


class InstallTest(unittest.TestCase):
    def test_the_installed_package_runs_the_installed_executable(self):
        with tempfile.TemporaryDirectory(prefix="nonsep-python-install-") as folder:
            prefix = Path(folder) / "prefix"
            subprocess.run([os.environ["CMAKE_COMMAND"], "--install", os.environ["NONSEP_BUILD_DIR"],
                            "--prefix", str(prefix)], check=True, stdout=subprocess.DEVNULL)
            package = prefix / "lib" / "python3" / "dist-packages"
            self.assertTrue((package / "nonsep" / "__init__.py").exists())
            path = os.pathsep.join(p for p in os.environ["PATH"].split(os.pathsep)
                                   if p and not (Path(p) / "nonsep").exists())
            environment = {k: v for k, v in os.environ.items()
                           if k not in ("NONSEP_EXECUTABLE", "NONSEP_PLUGIN_PATH", "PYTHONPATH")}
            environment.update(PATH=path, PYTHONPATH=str(package))
            self.assertIsNone(shutil.which("nonsep", path=path))
            child = subprocess.run(["/usr/bin/python3", "-c", CHILD, str(Path(folder) / "out")], env=environment,
                                   cwd=folder, capture_output=True, text=True)
            self.assertEqual(child.returncode, 0, child.stderr)
            found, ran = (json.loads(line) for line in child.stdout.splitlines())
            self.assertEqual(found["package"], str(package / "nonsep" / "__init__.py"))
            self.assertEqual(found["executable"], str(prefix / "bin" / "nonsep"))
            self.assertEqual(ran, {"status": "completed", "steps": 20,
                                   "plugin": str(prefix / "lib" / "nonsep" / "plugins" / "paper1d.so")})
            plotter = subprocess.run(["/usr/bin/python3", "-m", "nonsep.work_precision", "--help"], env=environment,
                                     cwd=folder, capture_output=True, text=True)
            self.assertEqual(plotter.returncode, 0, plotter.stderr)
            self.assertIn("work_precision.csv", plotter.stdout)
            self.assertTrue((prefix / "share" / "nonsep" / "examples" / "dynamics" / "chaos_map.json").exists())


if __name__ == "__main__":
    unittest.main()
