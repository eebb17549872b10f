"""Initial states from a file (/initial/file): the same states given as a .npy file (C and Fortran order, a
header of 40 KB, keys in another order), as a .csv file (also without a final newline, with CRLF line ends) and
written in the job give byte-identical trajectories.csv; a file of the wrong shape, with a number that is not
finite, cut short, with trailing bytes, over the states limit, with a .npy header key twice or unknown, a FIFO, or
of another type is refused with exit status 2 naming /initial/file (and never waited on); a CSV file without line
ends is refused within the bounds of a row, in memory far below its size. The .npy files are written here byte by
byte (the format of numpy.save, version 1.0), so numpy is not needed.

    check_initial_file.py --nonsep NONSEP
"""
import argparse
import json
import math
import os
import struct
import subprocess
import sys
import tempfile
from pathlib import Path


def npy_bytes(rows, fortran=False, dtype="<f8", shape=None, trailing=b"", header=None, padding=0):
    """The .npy file of `rows`; `header` replaces numpy's dictionary (written as it is), `padding` spaces are added
    to the header."""
    count, columns = len(rows), len(rows[0])
    shape = shape if shape is not None else (count, columns)
    header = header or ("{'descr': '%s', 'fortran_order': %s, 'shape': (%s), }" % (
        dtype, "True" if fortran else "False", ", ".join(map(str, shape)) + ("," if len(shape) == 1 else "")))
    header += " " * padding
    header += " " * ((64 - (10 + len(header) + 1) % 64) % 64) + "\n"
    order = [rows[b][c] for c in range(columns) for b in range(count)] if fortran else [x for row in rows for x in row]
    return b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header.encode() + struct.pack(
        f"<{len(order)}d", *order) + trailing


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--nonsep", required=True)
    arguments = parser.parse_args()
    problems = []
    # paper2d (dimension 2): q0, q1, p0, p1 per state.
    states = [[0.1 * i - 0.3, 0.05 * i, 0.2 - 0.03 * i, 0.1] for i in range(7)]
    with tempfile.TemporaryDirectory(prefix="nonsep-initial-file-") as folder:
        folder = Path(folder)

        def job(initial, name):
            path = folder / f"{name}.json"
            path.write_text(json.dumps({
                "model": {"plugin": "paper2d"}, "integrator": {"scheme": "triplet", "order": "4/3"},
                "initial": initial, "time": {"dt": 0.01, "steps": 50}, "output": {"every": 10}}))
            return path

        def run(path, output):
            return subprocess.run([arguments.nonsep, "run", "--quiet", "--output", str(folder / output), str(path)],
                                  capture_output=True, text=True, timeout=60)

        written = run(job([{"q": s[:2], "p": s[2:]} for s in states], "written"), "written")
        if written.returncode != 0:
            problems.append(f"the job with the states written in it: exit {written.returncode}: {written.stderr}")
        (folder / "states.npy").write_bytes(npy_bytes(states))
        (folder / "fortran.npy").write_bytes(npy_bytes(states, fortran=True))
        csv_rows = ["q0,q1,p0,p1"] + [",".join(repr(x) for x in s) for s in states]
        (folder / "states.csv").write_text("".join(row + "\n" for row in csv_rows))
        # Files written by hand: the last row without a final newline, CRLF line ends.
        (folder / "no_final_newline.csv").write_text("\n".join(csv_rows))
        (folder / "crlf.csv").write_bytes("".join(row + "\r\n" for row in csv_rows).encode())
        (folder / "crlf_no_final_newline.csv").write_bytes("\r\n".join(csv_rows).encode())
        # Headers of about 40 KB (a recursive regular expression overflowed the stack on them): numpy's padding at
        # the end, and white space inside the dictionary, which numpy's literal_eval accepts too.
        (folder / "long_header.npy").write_bytes(npy_bytes(states, padding=40000))
        spaced = ("{ 'descr' :  '<f8' ,\n 'fortran_order': False, 'shape': (" + " " * 20000 + "7, 4" + " " * 20000
                  + ") }")
        (folder / "spaced_header.npy").write_bytes(npy_bytes(states, header=spaced))
        (folder / "keys_reordered.npy").write_bytes(
            npy_bytes(states, header="{\"shape\": (7, 4,), 'fortran_order': False, 'descr': \"<f8\"}"))
        for name in ["states.npy", "fortran.npy", "states.csv", "no_final_newline.csv", "crlf.csv",
                     "crlf_no_final_newline.csv", "long_header.npy", "spaced_header.npy", "keys_reordered.npy"]:
            result = run(job({"file": name}, "from-" + name), "out-" + name)
            if result.returncode != 0:
                problems.append(f"{name}: exit {result.returncode}: {result.stderr}")
                continue
            for output in ["trajectories.csv", "trajectory.csv"]:
                if (folder / ("out-" + name) / output).read_bytes() != (folder / "written" / output).read_bytes():
                    problems.append(f"{name}: {output} differs from the run with the states written in the job")

        os.mkfifo(folder / "fifo.npy")
        bad = {
            "odd_columns.npy": (npy_bytes([s[:3] for s in states]), "3 columns"),
            "wrong_dimension.npy": (npy_bytes([s + [0.0, 0.0] for s in states]), "the dimension of the model"),
            "not_finite.npy": (npy_bytes(states[:2] + [[math.nan, 0, 0, 0]]), "not finite at byte offset"),
            "cut_short.npy": (npy_bytes(states)[:-8], "bytes where its header says"),
            "trailing.npy": (npy_bytes(states, trailing=b"\0garbage"), "bytes where its header says"),
            "float32.npy": (npy_bytes(states, dtype="<f4"), "an array of dtype '<f4'"),
            "too_many.npy": (npy_bytes([states[0]], shape=(1000001, 4)), "of shape (1000001, 4)"),
            "three_d.npy": (npy_bytes(states, shape=(7, 2, 2)), "more than two dimensions"),
            # numpy's literal_eval would take the last of two descr; nonsep refuses any key given twice.
            "duplicate_descr.npy": (npy_bytes(states, header="{'descr': '<f4', 'descr': '<f8', 'fortran_order': "
                                                             "False, 'shape': (7, 4), }"),
                                    "the key 'descr' a second time"),
            "unknown_key.npy": (npy_bytes(states, header="{'descr': '<f8', 'fortran_order': False, 'shape': (7, 4), "
                                                         "'extra': 1}"), "the key 'extra', not one of"),
            "shape_not_tuple.npy": (npy_bytes(states, header="{'descr': '<f8', 'fortran_order': False, 'shape': (28)}"),
                                    "a shape that is not a tuple"),
            # Numbers past 2^64 are named as written, not as 18446744073709551615.
            "huge_shape.npy": (npy_bytes([states[0]], shape=(99999999999999999999, 4)),
                               "of shape (99999999999999999999, 4)"),
            "huge_columns.npy": (npy_bytes([states[0]], shape=(18446744073709551616,)),
                                 "of shape (18446744073709551616,)"),
            "header.csv": ("p0,q1,q0,p1\n1,2,3,4\n", "column 1 of the header is \"p0\""),
            "crlf_header.csv": ("q0,q1,p1,p0\r\n1,2,3,4\r\n", "column 3 of the header is \"p1\"; allowed: \"p0\""),
            "cell.csv": ("q0,q1,p0,p1\n1,2,3,4\n1,2,inf,4\n", "\"inf\" in column 3"),
            "short_row.csv": ("q0,q1,p0,p1\n1,2,3\n", "3 cells"),
            "states.txt": ("", "neither .npy nor .csv"),
            "fifo.npy": (None, "not a regular file"),
            "missing.csv": (None, "cannot be opened"),
        }
        for name, (content, expected) in bad.items():
            if isinstance(content, bytes):
                (folder / name).write_bytes(content)
            elif isinstance(content, str):
                (folder / name).write_text(content)
            for command in ("validate", "run"):
                path = job({"file": name}, "bad-" + name)
                result = subprocess.run([arguments.nonsep, command, *(["--quiet"] if command == "run" else []),
                                         str(path)], capture_output=True, text=True, timeout=60)
                if result.returncode != 2 or "/initial/file: found" not in result.stderr or \
                        expected not in result.stderr:
                    problems.append(f"{name}, nonsep {command}: exit {result.returncode}, expected 2 naming "
                                    f"/initial/file and {expected!r}:\n{result.stderr}")

        # A CSV file without line ends, of 96 MB: refused within its first line's bounds (max_initial_csv_cell_bytes,
        # max_initial_csv_columns), whose message names; the process's peak memory stays far below the file's size.
        # Written a MiB at a time: a child's peak memory counts the pages of this process before the exec.
        # Under AddressSanitizer (the sanitized suite sets ASAN_OPTIONS) the peak counts the sanitizer's shadow and
        # quarantine, not the reader's buffers: the exit status and message are checked, the peak only in the release
        # suite.
        megabytes = 96
        sanitized = "ASAN_OPTIONS" in os.environ
        for name, piece in [("one_cell.csv", b"1" * (1 << 20)), ("many_cells.csv", b"0," * (1 << 19))]:
            with open(folder / name, "wb") as out:
                for _ in range(megabytes):
                    out.write(piece)
        for name, expected, peak_limit in [("one_cell.csv", ":1: cell 1, longer than 32 bytes", 64),
                                           ("many_cells.csv", ":1: a row of more than 2097152 cells", 256)]:
            process = subprocess.Popen([arguments.nonsep, "validate", str(job({"file": name}, "big-" + name))],
                                       stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
            stderr = process.stderr.read()
            _, status, usage = os.wait4(process.pid, 0)
            process.returncode = os.waitstatus_to_exitcode(status)
            peak = usage.ru_maxrss / 1024  # MB: ru_maxrss is in KiB on Linux
            print(f"{name}: {megabytes} MB without a line end, exit {process.returncode}, peak {peak:.0f} MB")
            if process.returncode != 2 or expected not in stderr or (peak > peak_limit and not sanitized):
                problems.append(f"{name} ({megabytes} MB without a line end): exit {process.returncode}, peak "
                                f"{peak:.0f} MB; expected 2, {expected!r} and at most {peak_limit} MB:\n"
                                f"{stderr[:2000]}")

    for problem in problems:
        print("FAILED:", problem)
    print(f"{len(problems)} problems")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
