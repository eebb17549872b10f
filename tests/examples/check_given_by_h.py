#!/usr/bin/env python3
"""Checks what examples/given_by_h/run_pictures.sh --small wrote into OUT_DIR: each picture a PNG, each run completed,
the Poincare crossings on their planes, the Schwarzschild orbits' cyclic momenta p_t and p_phi kept to the bit and
their mass shell H = -1/2 kept, and no runaway warning in the runs' messages (the time and azimuth around the black
hole grow while the orbits stay bounded).

Usage: check_given_by_h.py OUT_DIR
"""
import csv
import json
import sys
from pathlib import Path

out = Path(sys.argv[1])
failures = []


def check(condition, what):
    print(("ok: " if condition else "FAILED: ") + what)
    if not condition:
        failures.append(what)


def rows(path):
    with open(path, newline="") as file:
        return list(csv.DictReader(file))


for name in ("henon_heiles", "henon_heiles_map", "schwarzschild", "schwarzschild_map", "magnetic_bottle",
             "magnetic_bottle_section"):
    png = out / f"given_by_h_{name}.png"
    check(png.is_file() and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", f"{png.name} is a PNG")
for job in ("henon_heiles_portrait", "schwarzschild_section", "schwarzschild_stability_map", "magnetic_bottle_section",
            "magnetic_bottle_chaos_map"):
    summary = json.loads((out / job / "summary.json").read_text())
    counts = summary["counts"]
    check(counts["completed"] > 0 and counts["completed"] == sum(counts.values()), f"{job}: every run completed {counts}")
    check(summary["hamiltonian"] == "general", f"{job}: a model given by H")
for job, column, value in (("henon_heiles_portrait", "q0", 0.0), ("schwarzschild_section", "q2", 1.5707963267948966),
                           ("magnetic_bottle_section", "q2", 0.0)):
    crossings = rows(out / job / "poincare.csv")
    worst = max(abs(float(row[column]) - value) for row in crossings)
    check(len(crossings) > 0 and worst <= 1e-12, f"{job}: {len(crossings)} crossings on {column} = {value} ({worst:.2g})")
for row in rows(out / "schwarzschild_section" / "trajectories.csv"):
    check(float(row["p0"]) == -0.995 and float(row["p3"]) == 4.6,
          f"Schwarzschild trajectory {row['trajectory']}: p_t and p_phi kept ({row['p0']}, {row['p3']})")
    check(abs(float(row["relative_energy_error"])) <= 1e-9,
          f"Schwarzschild trajectory {row['trajectory']}: H kept ({row['relative_energy_error']})")
log = out / "messages.txt"
check(log.is_file() and "runs off with bounded energy" not in log.read_text(), "no runaway warning")
sys.exit(1 if failures else 0)
