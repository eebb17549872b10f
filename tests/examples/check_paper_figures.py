#!/usr/bin/env python3
"""Checks one of the paper's figures on the outputs examples/paper/run_figures.sh wrote into OUT:

    check_paper_figures.py {reference,figure1,figure2,figure3,plots} --out OUT --examples examples/paper

reference  figure3.json's t_end and reference point equal nonsep_paper_reference's quadrature (q0 = 2) to 1e-15
figure1    each orbit's largest |relative energy error| lies in its measured range, and each orbit returns to its
           start (closest_return) within 5e-3, one period after leaving it: within 5% of the exact period (4 x the
           quarter period; the basic step at dt = 0.005 runs 2-4% fast)
figure2    the paper's settings close the circle and the triangle (and, with a 13% energy error, the twisted
           orbit); the accurate runs close the triangle and the corrected circle and q1 = 2.5 orbits, but not the
           paper's circle and twisted states
figure3    every fitted exponent within 0.1 of its order; the basic constant at exponent 2/3 near the paper's -2;
           the plot script's fit (from convergence.csv) equals summary.json's
plots      figure1, figure2 and figure3 exist as PNG files of at least 150 dpi (their pHYs chunk) and 800 pixels
           wide, not tiny and not over 600 kB, and as PDF files
Exits 1 listing every failed check."""
import argparse
import csv
import importlib.util
import json
import math
import sys
from fractions import Fraction
from pathlib import Path

failures = []


def check(condition, message):
    if not condition:
        failures.append(message)


def summary(out, job):
    return json.loads((out / job / "summary.json").read_text())


def trajectories(out, name):
    """The rows of a run's trajectories.csv, numbers as floats (empty cells None)."""
    def value(text):
        try:
            return float(text) if text != "" else None
        except ValueError:
            return text
    with open(out / name / "trajectories.csv", newline="") as f:
        return [{key: value(cell) for key, cell in row.items()} for row in csv.DictReader(f)]


def exact_quarters(out):
    with open(out / "reference" / "exact_quarter_periods.csv", newline="") as f:
        return {float(row["q0"]): row for row in csv.DictReader(f)}


def check_reference(out, examples):
    exact = exact_quarters(out)[2.0]
    job = json.loads((examples / "figure3.json").read_text())
    t_end, p_ref = float(exact["quarter_period"]), float(exact["p_at_quarter"])
    check(abs(job["time"]["t_end"] - t_end) <= 1e-15 * t_end,
          f"figure3.json t_end {job['time']['t_end']!r} differs from the quadrature's {t_end!r}")
    check(job["study"]["reference"]["q"] == [0.0], "figure3.json reference q is not [0]")
    check(abs(job["study"]["reference"]["p"][0] - p_ref) <= 1e-15 * abs(p_ref),
          f"figure3.json reference p {job['study']['reference']['p'][0]!r} differs from the quadrature's {p_ref!r}")
    check(abs(p_ref + math.sqrt(2 * (math.sqrt(5) - 1))) < 1e-14, f"p at the quarter period {p_ref} != -sqrt(2(sqrt5-1))")


def check_figure1(out, examples):
    exact = exact_quarters(out)
    # max |dE/E| over the run, measured with t2 = -2 and dt = 0.005; the ranges allow a few percent either way.
    ranges = {0.5: (0.0145, 0.0160), 1.0: (0.038, 0.041), 1.5: (0.064, 0.069), 2.0: (0.090, 0.096)}
    s = summary(out, "figure1")
    check(s["status"] == "completed", f"figure1 status {s['status']}")
    initial = json.loads((examples / "figure1.json").read_text())["initial"]
    for trajectory in trajectories(out, "figure1"):
        q0 = initial[int(trajectory["trajectory"])]["q"][0]
        check(abs(trajectory["H0"] - float(exact[q0]["energy"])) < 1e-12, f"figure1 q0 = {q0}: energy {trajectory['H0']}")
        low, high = ranges[q0]
        largest = trajectory["max_abs_relative_energy_error"]
        check(low <= largest <= high, f"figure1 q0 = {q0}: max |dE/E| = {largest} outside [{low}, {high}]")
        period = 4 * float(exact[q0]["quarter_period"])
        distance, t = trajectory["closest_return_distance"], trajectory["closest_return_t"]
        check(distance < 5e-3, f"figure1 q0 = {q0}: closest return {distance} >= 5e-3")
        check(abs(t - period) < 0.05 * period, f"figure1 q0 = {q0}: returns at t = {t}, the exact period is {period}")


def check_figure2(out, examples):
    def orbit(job, index=0):
        t = trajectories(out, job)[index]
        return t["closest_return_distance"], t["max_abs_relative_energy_error"]

    # (job, index, closest return bounds, max |dE/E| bounds)
    expectations = [
        ("figure2_paper_circle", 0, (0, 1e-3), (0, 5e-6)),
        ("figure2_paper_triangle", 0, (0, 2e-3), (0.01, 0.03)),
        ("figure2_paper_twisted", 0, (0, 2e-3), (0.10, 0.16)),
        ("figure2_accurate", 0, (1e-2, 3e-2), (0, 1e-9)),   # the paper's circle does not close
        ("figure2_accurate", 1, (0, 1e-3), (0, 1e-7)),      # the triangle does
        ("figure2_accurate", 2, (0.5, math.inf), (0, 1e-3)),  # the twisted state does not return
        ("figure2_corrected", 0, (0, 1e-4), (0, 1e-9)),
        ("figure2_corrected", 1, (0, 5e-4), (0, 1e-5)),
    ]
    for job, index, (d_low, d_high), (e_low, e_high) in expectations:
        distance, energy = orbit(job, index)
        check(d_low <= distance < d_high, f"{job} #{index}: closest return {distance} outside [{d_low}, {d_high})")
        check(e_low <= energy < e_high, f"{job} #{index}: max |dE/E| {energy} outside [{e_low}, {e_high})")


def check_figure3(out, examples):
    s = summary(out, "figure3")
    check(s["status"] == "completed", f"figure3 status {s['status']}")
    fits = {fit["integrator"]: fit for fit in s["fits"]}
    expected = ["basic", "triplet 4/3", "triplet 2", "mpe 4/3", "mpe 2", "triplet 8/3", "triplet 10/3", "triplet 4",
                "mpe 8/3", "mpe 10/3", "mpe 4"]
    check(sorted(fits) == sorted(expected), f"figure3 integrators {sorted(fits)}")
    spec = importlib.util.spec_from_file_location("plot_figures", examples / "plot_figures.py")
    plot = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(plot)
    rows = {}
    with open(out / "figure3" / "convergence.csv", newline="") as f:
        for row in csv.DictReader(f):
            rows.setdefault(row["integrator"], []).append(row)
    for name, fit in fits.items():
        nominal = float(Fraction(fit["order"]))
        check(fit["exponent"] is not None and abs(fit["exponent"] - nominal) < 0.1,
              f"figure3 {name}: exponent {fit['exponent']} not within 0.1 of {fit['order']}")
        check(abs(fit["phase_exponent"] - nominal) < 0.25,
              f"figure3 {name}: phase-error exponent {fit['phase_exponent']} not within 0.25 of {fit['order']}")
        check(not fit["energy_error_changes_sign"], f"figure3 {name}: the energy error changes sign in the fit range")
        mine = plot.fit_power_law([float(r["dt"]) for r in rows[name]],
                                  [math.copysign(float(r[plot.ENERGY]), float(r["relative_energy_error"]))
                                   for r in rows[name]])
        check(mine is not None and abs(mine[0] - fit["exponent"]) < 1e-9 and
              abs(mine[1] - abs(fit["constant"])) < 1e-9 * abs(fit["constant"]),
              f"figure3 {name}: the plot's fit {mine} differs from the summary's ({fit['exponent']}, {fit['constant']})")
    basic = fits["basic"]
    check(-2.2 < basic["constant_at_nominal_exponent"] < -1.8,
          f"figure3 basic: constant at exponent 2/3 is {basic['constant_at_nominal_exponent']}, the paper says -2")
    # Beyond the paper: at equal work, the higher-order MPEs beat the paper's MPE 2 by orders of magnitude.
    def error_at_most_work(name, work):
        best = [float(r[plot.ENERGY]) for r in rows[name] if int(r["grad_T"]) + int(r["grad_V"]) <= work]
        return min(best) if best else math.inf
    check(error_at_most_work("mpe 4", 1e5) < 1e-3 * error_at_most_work("mpe 2", 1e5),
          "figure3: MPE 4 does not beat MPE 2 by 1000x at 1e5 gradient evaluations")


def png_chunks(data):
    """(type, payload) of every chunk of a PNG file's bytes, after the 8-byte signature."""
    at = 8
    while at + 8 <= len(data):
        length = int.from_bytes(data[at:at + 4], "big")
        yield data[at + 4:at + 8], data[at + 8:at + 8 + length]
        at += 12 + length


def check_plots(out, examples):
    for name in ("figure1", "figure2", "figure3"):
        path = out / f"{name}.png"
        check(path.exists(), f"{path} was not produced")
        if path.exists():
            data = path.read_bytes()
            check(data[:8] == b"\x89PNG\r\n\x1a\n", f"{path} is not a PNG file")
            check(10_000 < len(data) <= 600_000, f"{path} has {len(data)} bytes (expected 10 kB to 600 kB)")
            chunks = dict(png_chunks(data))
            width = int.from_bytes(chunks.get(b"IHDR", bytes(4))[:4], "big")
            check(width >= 800, f"{path} is {width} pixels wide")
            phys = chunks.get(b"pHYs")
            # pixels per unit in x and y, and the unit (1: metre); 150 dpi = 5905.5 pixels per metre
            dpi = int.from_bytes(phys[:4], "big") * 0.0254 if phys and phys[8] == 1 else None
            check(dpi is not None and dpi >= 149.5, f"{path}: {dpi} dpi, expected at least 150")
        pdf = out / f"{name}.pdf"
        check(pdf.exists(), f"{pdf} was not produced")
        if pdf.exists():
            data = pdf.read_bytes()
            check(data[:5] == b"%PDF-" and len(data) > 5_000, f"{pdf} is not a PDF file of some size")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("what", choices=["reference", "figure1", "figure2", "figure3", "plots"])
    parser.add_argument("--out", required=True, type=Path)
    parser.add_argument("--examples", required=True, type=Path)
    args = parser.parse_args()
    globals()["check_" + args.what](args.out, args.examples)
    for failure in failures:
        print(f"FAIL {failure}", file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
