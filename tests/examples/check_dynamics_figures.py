#!/usr/bin/env python3
"""Checks what examples/dynamics/run_dynamics.sh produced in OUT_DIR (the examples test runs it with --small):

  - every picture (PICTURES) exists as a PNG file of at least 150 dpi (its pHYs chunk) and 800 pixels wide, and as a
    PDF file;
  - no run printed anything on stderr (JOB.stderr is empty: no warning, false or true);
  - the portrait's crossings lie on the section q1 = 0 (to 1e-12 relative) with H on the shell H = 7;
  - every starting point was put on the shell (H0 = 7), some were left out, and the chaos map has both regular
    (<Y> within 10% of 2) and chaotic (<Y> > 4) orbits, as the picture claims;
  - the stability map swept every coupling of its job, put each coupling's starting points on H = 7 with that
    coupling, and has regular and chaotic orbits; lyapunov.csv ends at each orbit's <Y> of trajectories.csv;
  - on the shell H = 8 (stability_map_shell8, chaotic_fraction), every coupling up to 0.3 was swept and every orbit
    completed with |dH/H0| below 1e-6 (Gauss-Legendre at dt = 0.02), and the chaotic fraction (<Y> > 2.5) that
    the picture shows is that of trajectories.csv counted here, with some chaotic and some regular orbits;
  - the frequency map analysed every orbit, its diffusion index tells tori (< -5) from chaotic orbits (> -3), and
    every frequency lies within the sampling band.

    /usr/bin/python3 tests/examples/check_dynamics_figures.py OUT_DIR
"""
import csv
import json
import math
import sys
from pathlib import Path

failures = []


def check(condition, message):
    if not condition:
        failures.append(message)


def rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def png_chunks(data):
    at = 8
    while at + 8 <= len(data):
        length = int.from_bytes(data[at:at + 4], "big")
        yield data[at + 4:at + 8], data[at + 8:at + 8 + length]
        at += 12 + length


JOBS = ("poincare_portrait", "chaos_map", "stability_map", "stability_map_shell8", "chaotic_fraction",
        "frequency_map")
PICTURES = ("dynamics_poincare", "dynamics_chaos_map", "dynamics_stability_map", "dynamics_stability_map_shell8",
            "dynamics_chaotic_fraction", "dynamics_frequency_map")


def check_pictures(out):
    for name in PICTURES:
        path = out / f"{name}.png"
        check(path.exists(), f"{path} was not produced")
        if path.exists():
            data = path.read_bytes()
            check(data[:8] == b"\x89PNG\r\n\x1a\n", f"{path} is not a PNG file")
            chunks = dict(png_chunks(data))
            width = int.from_bytes(chunks.get(b"IHDR", bytes(4))[:4], "big")
            check(width >= 800, f"{path} is {width} pixels wide")
            phys = chunks.get(b"pHYs")
            dpi = int.from_bytes(phys[:4], "big") * 0.0254 if phys and phys[8] == 1 else None
            check(dpi is not None and dpi >= 149.5, f"{path}: {dpi} dpi, expected at least 150")
        pdf = out / f"{name}.pdf"
        check(pdf.exists() and pdf.read_bytes()[:5] == b"%PDF-", f"{pdf} is not a PDF file")


def check_numbers(out):
    crossings = rows(out / "poincare_portrait/poincare.csv")
    check(len(crossings) > 100, f"the portrait has only {len(crossings)} crossings")
    for r in crossings:
        v = [float(r[k]) for k in ("q0", "q1", "p0", "p1")]
        check(abs(v[1]) <= 1e-12 * math.hypot(*v), f"crossing {r['trajectory']}/{r['crossing']} is off q1 = 0: {v[1]}")
        check(abs(float(r["H"]) / 7.0 - 1.0) < 1e-3, f"crossing {r['trajectory']}/{r['crossing']} has H = {r['H']}")
    for folder in JOBS:
        stderr = (out / f"{folder}.stderr").read_text()
        check(stderr == "", f"{folder}: the run printed on stderr: {stderr[:300]}")
        summary = json.loads((out / folder / "summary.json").read_text())
        check(summary["status"] == "completed", f"{folder}: status {summary['status']}")
        check(summary["energy_shell"]["left_out"] > 0, f"{folder}: no starting point was left out")
        energy = summary["energy_shell"]["energy"]
        for r in rows(out / folder / "trajectories.csv"):
            check(abs(float(r["H0"]) - energy) <= 1e-13,
                  f"{folder}: trajectory {r['trajectory']} starts at H = {r['H0']}, not {energy}")
    megno = [float(r["mean_megno"]) for r in rows(out / "chaos_map/trajectories.csv")]
    check(any(abs(y - 2.0) < 0.2 for y in megno), "the chaos map has no regular orbit (<Y> near 2)")
    check(any(y > 4.0 for y in megno), "the chaos map has no chaotic orbit (<Y> > 4)")
    summary = json.loads((out / "stability_map/summary.json").read_text())
    table = rows(out / "stability_map/trajectories.csv")
    couplings = sorted({float(r["coupling"]) for r in table})
    swept = summary["model"]["parameters"]["coupling"]
    check(couplings == sorted(swept) and summary["sweep"]["parameter_sets"] == len(swept) > 1,
          f"the stability map has trajectories of every swept coupling ({len(couplings)} of {len(swept)})")
    megno = [float(r["mean_megno"]) for r in table]
    check(any(abs(y - 2.0) < 0.2 for y in megno) and any(y > 4.0 for y in megno),
          "the stability map has regular (<Y> near 2) and chaotic (<Y> > 4) orbits")
    last = {}
    for r in rows(out / "stability_map/lyapunov.csv"):
        last[int(r["trajectory"])] = r["mean_megno"]
    check(len(last) == len(table) and all(last[int(r["trajectory"])] == r["mean_megno"] for r in table),
          "lyapunov.csv's last <Y> of every orbit is its <Y> in trajectories.csv")


def check_shell8(out):
    for folder in ("stability_map_shell8", "chaotic_fraction"):
        summary = json.loads((out / folder / "summary.json").read_text())
        swept = summary["model"]["parameters"]["coupling"]
        check(summary["energy_shell"]["energy"] == 8.0 and min(swept) == 0.0 and max(swept) == 0.3,
              f"{folder}: not the shell H = 8 over the couplings 0 to 0.3")
        largest = summary["energy"]["largest_relative_error"]["value"]
        check(summary["counts"]["completed"] == summary["trajectories"] and largest < 1e-6,
              f"{folder}: {summary['counts']}, largest |dH/H0| {largest}")
    table = rows(out / "chaotic_fraction/trajectories.csv")
    printed = (out / "plot_dynamics.txt").read_text()
    couplings = sorted({float(r["coupling"]) for r in table})
    for coupling in couplings:
        mine = [float(r["mean_megno"]) for r in table if float(r["coupling"]) == coupling]
        chaotic = sum(1 for y in mine if y > 2.5)
        check(f"coupling {coupling:g}: {chaotic} of {len(mine)} orbits with mean_megno > 2.5 " in printed,
              f"the chaotic fraction at coupling {coupling:g} is not {chaotic} of {len(mine)}: {printed}")
    megno = [float(r["mean_megno"]) for r in table]
    check(any(y > 4.0 for y in megno) and any(abs(y - 2.0) < 0.2 for y in megno),
          "the chaotic fraction's grids have no chaotic (<Y> > 4) or no regular (<Y> near 2) orbit")


def check_frequency_map(out):
    """Every orbit analysed, the torus and the chaotic sea told apart by the diffusion index, and each frequency
    within the sampling band |nu| < pi / tau; the printed range is trajectories.csv's."""
    summary = json.loads((out / "frequency_map/summary.json").read_text())
    facts = summary["analysis"]["frequencies"]
    check(facts["analysed"] == summary["trajectories"], f"frequency map: {facts['analysed']} orbits analysed of "
          f"{summary['trajectories']}")
    table = rows(out / "frequency_map/trajectories.csv")
    index = [float(r["diffusion"]) for r in table]
    check(min(index) < -5.0 and max(index) > -3.0,
          f"the frequency map has no torus (index < -5) or no chaotic orbit (index > -3): {min(index)}, {max(index)}")
    band = math.pi / facts["tau"]
    for r in table:
        for k in ("frequency0", "frequency1"):
            check(abs(float(r[k])) < band, f"frequency map: {k} of trajectory {r['trajectory']} is {r[k]}")
    printed = (out / "plot_dynamics.txt").read_text()
    check(f"diffusion index from {min(index):.2f} to {max(index):.2f}" in printed,
          f"plot_dynamics.py printed another range of the diffusion index: {printed}")


def main():
    out = Path(sys.argv[1])
    check_pictures(out)
    check_numbers(out)
    check_shell8(out)
    check_frequency_map(out)
    for failure in failures[:20]:
        print(f"FAIL {failure}", file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
