"""Running the `nonsep` executable from Python: run(), validate(), and the errors they raise.

The executable always runs as a child process, so a model plugin that crashes takes down that process, never the
caller's Python session (the crash is a RunError with a negative status, the signal's number). The child runs in
its own session: Ctrl-C reaches it only through run() (as one SIGINT), and a Python process killed outright leaves
it running to its end.

Which executable: the first of
  1. $NONSEP_EXECUTABLE, when set and not empty (an error if it names no executable file);
  2. <prefix>/bin/nonsep, when this package is installed as <prefix>/lib/python3/dist-packages/nonsep
     (`cmake --install` puts both there, so an installed package runs the host it was installed with);
  3. `nonsep` on PATH.

A job is a path to a job file or a dict. A dict is written to a temporary job file, so relative paths inside it
(model.plugin given as a path, model.formula given as a model file, initial.file, output.directory) are
made absolute first, against the current working directory.
A dict without output.directory, run without `output`, writes into a new folder made by tempfile.mkdtemp()
(Result.directory says where).
"""
import copy
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
from collections.abc import Mapping
from pathlib import Path
from typing import NamedTuple

from .results import load

# docs/user-guide.md, "Exit status".
EXIT_STATUS_MEANINGS = {
    1: "the run started but did not complete: a trajectory diverged or failed, or an output could not be written",
    2: "invalid input, nothing was run",
    130: "interrupted by SIGINT",
    143: "terminated by SIGTERM",
}


class ExecutableNotFound(FileNotFoundError):
    """No `nonsep` executable where this module looks (see the module's documentation)."""


class Problem(NamedTuple):
    """One problem of a job file: `path` is a JSON Pointer into the job ("/time/dt") or "(document)"; `message`
    says what was found there and what is allowed."""
    path: str
    message: str


class RunError(RuntimeError):
    """`nonsep` exited with a non-zero status.

    status    the exit status (docs/user-guide.md, "Exit status"); negative: the process was killed by that signal
    stderr    everything the process wrote on stderr; stdout likewise
    result    the Result of the outputs, when the run started and wrote summary.json (a diverged, failed or
              interrupted run), else None
    problems  the job file's problems (a list of Problem) for status 2, else []
    """

    def __init__(self, command, status, stdout, stderr, result=None):
        self.command, self.status, self.stdout, self.stderr, self.result = command, status, stdout, stderr, result
        self.problems = parse_problems(stderr) if status == 2 else []
        if status < 0:
            meaning = f"killed by {signal.Signals(-status).name}"
        elif status == 0:
            meaning = "but wrote no summary.json where this module looked"
        else:
            meaning = EXIT_STATUS_MEANINGS.get(status, "unknown status")
        super().__init__(f"nonsep {command} exited with status {status} ({meaning})\n{stderr.rstrip()}")


class RunInterrupted(RunError, KeyboardInterrupt):
    """A KeyboardInterrupt (Ctrl-C) during run(): the run was told to stop (SIGINT), finished its current step, saved
    a checkpoint and wrote its outputs; `result` holds them and run(..., resume=True) continues. Caught by
    `except KeyboardInterrupt` as well as by `except RunError`."""


def executable():
    """The path of the `nonsep` executable run() and validate() use. Raises ExecutableNotFound."""
    configured = os.environ.get("NONSEP_EXECUTABLE")
    if configured:
        if os.path.isfile(configured) and os.access(configured, os.X_OK):
            return configured
        raise ExecutableNotFound(f"NONSEP_EXECUTABLE is {configured!r}, which is not an executable file")
    package = Path(__file__).resolve().parent
    installed = package.parents[3] / "bin" / "nonsep"
    if package.parent.parts[-3:] == ("lib", "python3", "dist-packages") and os.access(installed, os.X_OK):
        return str(installed)
    on_path = shutil.which("nonsep")
    if on_path:
        return on_path
    raise ExecutableNotFound("no nonsep executable: NONSEP_EXECUTABLE is not set, this package is not installed "
                             "beside one (<prefix>/lib/python3/dist-packages/nonsep), and PATH has none")


def run(job, output=None, threads=None, resume=False, quiet=True):
    """Runs `job` (a job file's path or a dict) with `nonsep run` and returns its Result.

    output   the output folder (`--output`), relative to the current directory; default: the job's
             output.directory, else <job name>.out beside a job file, else a new temporary folder for a dict
    threads  `--threads N` (default: all cores)
    resume   `--resume`: continue an interrupted run from its checkpoint.json (give the same output)
    quiet    `--quiet`; when False, what the host printed (the completion line) is copied to sys.stdout and
             sys.stderr once it ends

    Raises RunError for a non-zero exit status (with the Result when the run wrote summary.json), RunInterrupted
    when interrupted by Ctrl-C, ValueError for a dict with non-finite numbers, ExecutableNotFound.
    """
    with tempfile.TemporaryDirectory(prefix="nonsep-job-") as workspace:
        job_path, content = _job_file(job, workspace)
        made = output is None and isinstance(job, Mapping) and not _output_directory_of(content)
        if made:
            output = tempfile.mkdtemp(prefix="nonsep-run-")
        arguments = ["run", str(job_path)]
        if output is not None:
            arguments += ["--output", str(output)]
        if threads is not None:
            arguments += ["--threads", str(int(threads))]
        if resume:
            arguments.append("--resume")
        if quiet:
            arguments.append("--quiet")
        directory = _output_directory(job_path, content, output)
        summary = directory / "summary.json" if directory is not None else None
        before = _identity(summary)
        status, stdout, stderr, interrupted = _execute(arguments)
    if made and status == 2:
        os.rmdir(output)  # nothing was run: the folder made for it is empty
    if not quiet:
        sys.stdout.write(stdout)
        sys.stderr.write(stderr)
    # A summary.json counts only when this run replaced it (AtomicFile renames a new file into place).
    result = load(directory) if summary is not None and status != 2 and _identity(summary) != before else None
    if status == 0 and interrupted is not None:
        raise interrupted  # the run ended before the SIGINT reached it; the caller still asked to stop
    if status == 0 and result is not None:
        return result
    error = RunInterrupted if interrupted else RunError
    raise error("run", status, stdout, stderr, result) from interrupted


def validate(job):
    """The problems `nonsep validate` finds in `job` (a path or a dict), as a list of Problem; [] when it is valid.
    Raises RunError when the executable fails in another way."""
    with tempfile.TemporaryDirectory(prefix="nonsep-job-") as workspace:
        job_path, _ = _job_file(job, workspace)
        status, stdout, stderr, interrupted = _execute(["validate", str(job_path)])
    if status == 0:
        return []
    problems = parse_problems(stderr) if status == 2 else []
    if problems:
        return problems
    raise RunError("validate", status, stdout, stderr) from interrupted


def parse_problems(stderr):
    """The problems in the host's report of an invalid job file: lines "  /json/pointer: found ...; allowed: ..."
    (or "  (document): ..."), a line that does not start that way continuing the problem before it."""
    problems = []
    for line in stderr.splitlines():
        match = re.match(r"  (\(document\)|/.*?): (found .*)$", line)
        if match:
            problems.append(Problem(match.group(1), match.group(2)))
        elif problems and line.startswith("  "):
            problems[-1] = Problem(problems[-1].path, problems[-1].message + "\n" + line[2:])
    return problems


def _execute(arguments):
    """Runs the executable with `arguments`; returns (status, stdout, stderr, the KeyboardInterrupt or None).

    The child runs in its own session, so a Ctrl-C at the terminal reaches only Python; the KeyboardInterrupt is
    passed on as one SIGINT (the host then finishes its step and saves its outputs) and the child awaited. A second
    KeyboardInterrupt kills it and propagates."""
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        process = subprocess.Popen([executable(), *arguments], stdin=subprocess.DEVNULL, stdout=out, stderr=err,
                                   start_new_session=True)
        interrupted = None
        try:
            try:
                status = process.wait()
            except KeyboardInterrupt as e:
                interrupted = e
                process.send_signal(signal.SIGINT)
                status = process.wait()
        except BaseException:
            process.kill()
            process.wait()
            raise
        out.seek(0)
        err.seek(0)
        return status, out.read().decode(errors="replace"), err.read().decode(errors="replace"), interrupted


def _job_file(job, workspace):
    """(path of the job file, its parsed content or None when it cannot be read as JSON)."""
    if isinstance(job, Mapping):
        content = _absolute_paths(job)
        path = Path(workspace) / "job.json"
        with open(path, "w") as f:
            json.dump(content, f, allow_nan=False)
        return path, content
    if not isinstance(job, (str, os.PathLike)):
        raise TypeError(f"a job is a path or a dict, not {type(job).__name__}")
    path = Path(job)
    try:
        with open(path) as f:
            return path, json.load(f)
    except (OSError, ValueError):
        return path, None  # the host reports it


# The job file's keys that hold paths (docs/job-file.md: each relative to the job file's folder), as (section, key):
# a dict's are made absolute against the current directory, since its job file is written to a temporary folder.
# model.plugin is a path only when it contains '/' or ends in .so (otherwise a plugin's name); model.formula only
# when it is a string (the path of a model file; otherwise the formulas themselves).
_PATH_KEYS = (("model", "plugin"), ("model", "formula"), ("initial", "file"), ("output", "directory"))


def _is_path(section, key, value):
    if not isinstance(value, str) or not value:
        return False
    if (section, key) == ("model", "plugin"):
        return "/" in value or value.endswith(".so")
    return True


def _absolute_paths(job):
    content = copy.deepcopy(dict(job))
    for section, key in _PATH_KEYS:
        part = content.get(section)
        if isinstance(part, dict) and _is_path(section, key, part.get(key)):
            part[key] = os.path.abspath(part[key])
    return content


def _output_directory_of(content):
    output = content.get("output") if isinstance(content, dict) else None
    directory = output.get("directory") if isinstance(output, dict) else None
    return directory if isinstance(directory, str) and directory else None


def _output_directory(job_path, content, output):
    """Where the run writes: `output`, else output.directory relative to the job file's folder, else
    <job file stem>.out beside it (docs/user-guide.md, output.directory). None when the job file is not readable JSON."""
    if output is not None:
        return Path(output)
    if content is None:
        return None
    return job_path.parent / (_output_directory_of(content) or job_path.stem + ".out")


def _identity(path):
    try:
        stat = os.stat(path)
    except (OSError, TypeError):
        return None
    return stat.st_ino, stat.st_mtime_ns, stat.st_size
