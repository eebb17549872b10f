"""The work-precision study on the lattice chain at n = 10, 10^3 and 10^5 sites (docs/work-precision.md, "The
lattice chain at n = 10, 10^3, 10^5"): writes the study jobs, runs them with a nonsep executable and prints, for
each n and accuracy, the fastest run of each family and the fastest overall.

Usage (python3, standard library only):
  python3 bench/work_precision_lattice.py jobs DIR [--sites N ...] [--quick]
  python3 bench/work_precision_lattice.py run NONSEP DIR [--sites N ...] [--quick] [--no-check]
  python3 bench/work_precision_lattice.py check NONSEP DIR [--sites N ...] [--quick]
  python3 bench/work_precision_lattice.py table DIR [--sites N ...]

`jobs` writes DIR/lattice_N.json (the study) and DIR/lattice_N_check.json (the reference's check) for each N;
`run` writes them, runs `NONSEP run --output DIR/wp-N DIR/lattice_N.json` and the check into DIR/check-N, and
prints the table; `check` runs only the checks (their timings do not enter the table, so they can run apart from
the timed studies); `table` prints the table from the outputs. --quick: short step ladders and repeats 1 (for the test,
seconds at n = 10). Exit status 0; 1 when a nonsep run fails (its output is printed) or a study's output is
missing; 2 on bad arguments.

The model: plugins/lattice_chain with its default parameters (a = 1, k = 0.5, b = 1), TTV form, t_end = 1.
The initial state, the same at site i whatever n (n a multiple of 10, so the wave is periodic on the ring):
  q_i = 0.3 sin(2 pi i / 10) + 0.02 sin(2 pi g i),   p_i = 0.3 cos(2 pi i / 10) + 0.02 cos(2 pi g^2 i) - mean,
g = (sqrt 5 - 1)/2: a wave of 10 sites' wavelength (the one of docs/scaling.md, with p's amplitude raised to 0.3)
and a deterministic quasi-periodic perturbation, so that no two sites follow the same trajectory; the mean of the
perturbation of p is removed, so that the total momentum sum_i p_i, which the flow conserves (H depends on q only
through the bonds q_{i+1} - q_i), is zero. The chain has no restoring force (H = f'(p)^T V''(q) f'(p) has no
potential part), so its strain grows with time; up to t = 1 the largest bond strain goes from 0.21 to 0.94
(0.86 at n = 10), where the quartic bond stiffness 3 b r^2 is up to 5x the harmonic k: the quartic terms matter,
and the lattice stays moderate (by t = 4 the strain would be 5.6).

The accuracy is the relative phase-space error |(q, p) - (q, p)_ref| / |(q, p)_ref| at t_end, so that a target
means the same accuracy per site at every n. The reference is a `study.reference_run` of Gauss 6 at 256 steps;
the check job runs Gauss 6 at 512 steps and Tao 6 at 1024 steps against the same reference.
"""
import argparse
import csv
import json
import math
import os
import subprocess
import sys

T_END = 1.0
TARGETS = (1e-3, 1e-5, 1e-7, 1e-9, 1e-11)
FAMILIES = (("chin", "Chin basic/triplet"), ("mpe", "Chin MPE (not symplectic)"), ("tao", "Tao"),
            ("gauss", "implicit midpoint / Gauss"))
REFERENCE = {"scheme": "gauss", "stages": 3, "steps": [256]}
CHECKS = ({"scheme": "gauss", "stages": 3, "steps": [512], "label": "gauss 6, 512 steps"},
          {"scheme": "tao", "order": 6, "steps": [1024], "label": "tao 6, 1024 steps"})
SCHEMES = {"basic": "chin", "triplet": "chin", "mpe": "mpe", "tao": "tao", "implicit_midpoint": "gauss",
           "gauss": "gauss"}


def doubling(first, last):
    return [2 ** k for k in range(first, last + 1)]


# (label, integrator, ladder exponents at n <= 1000, at n = 10^5): step counts 2^first .. 2^last. The ladders start
# where a scheme first stays finite and end where it reaches its round-off floor (n <= 1000) or where one run at
# n = 10^5 takes several seconds.
INTEGRATORS = (
    ("basic 2/3", {"scheme": "basic"}, (7, 17), (7, 13)),
    ("triplet 4/3", {"scheme": "triplet", "order": "4/3"}, (6, 15), (6, 12)),
    ("triplet 2", {"scheme": "triplet", "order": "2"}, (5, 14), (5, 11)),
    ("triplet 8/3", {"scheme": "triplet", "order": "8/3"}, (6, 13), (6, 10)),
    ("mpe 2", {"scheme": "mpe", "order": "2"}, (2, 12), (2, 9)),
    ("mpe 8/3", {"scheme": "mpe", "order": "8/3"}, (3, 11), (3, 8)),
    ("mpe 4", {"scheme": "mpe", "order": "4"}, (3, 11), (3, 7)),
    ("mpe 16/3", {"scheme": "mpe", "order": "16/3"}, (2, 8), (2, 7)),
    ("mpe 6", {"scheme": "mpe", "order": "6"}, (2, 7), (2, 6)),
    ("mpe 20/3", {"scheme": "mpe", "order": "20/3"}, (2, 6), (2, 4)),
    ("mpe 8", {"scheme": "mpe", "order": "8"}, (2, 5), (2, 4)),
    ("tao 2", {"scheme": "tao", "order": 2}, (2, 14), (2, 10)),
    ("tao 4", {"scheme": "tao", "order": 4}, (3, 12), (3, 9)),
    ("tao 6", {"scheme": "tao", "order": 6}, (4, 11), (4, 7)),
    ("implicit midpoint", {"scheme": "implicit_midpoint"}, (2, 15), (2, 8)),
    ("gauss 4", {"scheme": "gauss", "stages": 2}, (1, 10), (1, 6)),
    ("gauss 6", {"scheme": "gauss", "stages": 3}, (0, 6), (0, 5)),
)


def initial_state(n):
    """(q, p) of the study at n sites (module docstring); site i's values do not depend on n but for p's mean."""
    if n < 10 or n % 10:
        raise ValueError(f"the lattice study needs a multiple of 10 sites (found {n})")
    g = (math.sqrt(5.0) - 1.0) / 2.0
    q = [0.3 * math.sin(2 * math.pi * i / 10) + 0.02 * math.sin(2 * math.pi * g * i) for i in range(n)]
    bump = [0.02 * math.cos(2 * math.pi * g * g * i) for i in range(n)]
    mean = sum(bump) / n
    p = [0.3 * math.cos(2 * math.pi * i / 10) + bump[i] - mean for i in range(n)]
    return q, p


def study_job(n, quick=False):
    q, p = initial_state(n)
    integrators = []
    for label, integrator, small, large in INTEGRATORS:
        first, last = large if n > 1000 else small
        steps = doubling(first, first + 1) if quick else doubling(first, last)
        integrators.append(dict(integrator, label=label, steps=steps))
    reference = dict(REFERENCE, steps=[64]) if quick else REFERENCE
    repeats = 1 if quick or n > 1000 else 5
    return {"description": f"work-precision study on the lattice chain, n = {n} (bench/work_precision_lattice.py)",
            "model": {"plugin": "lattice_chain", "parameters": {"sites": n}}, "initial": {"q": q, "p": p},
            "time": {"t_end": T_END},
            "study": {"repeats": repeats, "reference_run": reference, "integrators": integrators}}


def check_job(n, quick=False):
    """The study's reference run against two independent finer runs: their phase errors are the disagreement."""
    job = study_job(n, quick)
    job["description"] = f"check of the reference of the lattice study, n = {n}"
    checks = [dict(c, steps=[c["steps"][0] // 4]) for c in CHECKS] if quick else list(CHECKS)
    job["study"] = {"repeats": 1, "reference_run": job["study"]["reference_run"], "integrators": checks}
    return job


def write_jobs(folder, sites, quick):
    os.makedirs(folder, exist_ok=True)
    for n in sites:
        for name, job in ((f"lattice_{n}.json", study_job(n, quick)), (f"lattice_{n}_check.json", check_job(n, quick))):
            with open(os.path.join(folder, name), "w") as f:
                json.dump(job, f)


def reference_norm(study_dir):
    with open(os.path.join(study_dir, "summary.json")) as f:
        reference = json.load(f)["study"]["reference"]
    return math.sqrt(sum(x * x for x in reference["q"] + reference["p"]))


def runs(study_dir):
    """The completed runs of a study: dicts with integrator, family, steps, wall (s) and relative phase error."""
    norm = reference_norm(study_dir)
    found = []
    with open(os.path.join(study_dir, "work_precision.csv"), newline="") as f:
        for row in csv.DictReader(f):
            if row["status"] != "completed" or not math.isfinite(float(row["phase_error"])):
                continue
            found.append({"integrator": row["integrator"], "family": SCHEMES[row["scheme"]],
                          "steps": int(row["steps"]), "wall": float(row["wall_seconds"]),
                          "error": float(row["phase_error"]) / norm})
    return found


def fastest(candidates, target):
    meeting = [r for r in candidates if r["error"] <= target]
    return min(meeting, key=lambda r: r["wall"]) if meeting else None


def cell(run):
    if run is None:
        return "not reached"
    steps = f"{run['steps']} step" + ("" if run["steps"] == 1 else "s")
    return f"{run['integrator']}, {steps}: {format_seconds(run['wall'])}"


def format_seconds(seconds):
    if seconds >= 1.0:
        return f"{seconds:.2f} s"
    if seconds >= 1e-3:
        return f"{seconds * 1e3:.3g} ms"
    return f"{seconds * 1e6:.3g} µs"


def table(folder, sites):
    """The markdown table: per n and target the fastest run of each family and overall, with the ratio of the
    fastest Chin run (either family) to the fastest overall."""
    lines = ["| n | target | " + " | ".join(name for _, name in FAMILIES) + " | fastest | fastest Chin / fastest |",
             "|---|---|" + "---|" * (len(FAMILIES) + 2)]
    for n in sites:
        study = os.path.join(folder, f"wp-{n}")
        if not os.path.exists(os.path.join(study, "work_precision.csv")):
            sys.exit(f"work_precision_lattice: no study output in {study} (the `run` command makes it)")
        found = runs(study)
        for index, target in enumerate(TARGETS):
            best = {family: fastest([r for r in found if r["family"] == family], target) for family, _ in FAMILIES}
            overall = fastest(found, target)
            chin = fastest([r for r in found if r["family"] in ("chin", "mpe")], target)
            ratio = "-" if chin is None or overall is None else f"{chin['wall'] / overall['wall']:.2g}"
            first = str(n) if index == 0 else ""
            lines.append(f"| {first} | {target:.0e} | " + " | ".join(cell(best[f]) for f, _ in FAMILIES) +
                         f" | **{cell(overall)}** | {ratio} |")
    return "\n".join(lines)


def check_lines(folder, sites):
    lines = []
    for n in sites:
        folder_n = os.path.join(folder, f"check-{n}")
        if not os.path.exists(os.path.join(folder_n, "work_precision.csv")):
            continue
        for r in runs(folder_n):
            lines.append(f"n = {n}: reference (gauss 6, {REFERENCE['steps'][0]} steps) against {r['integrator']}: "
                         f"relative phase difference {r['error']:.1e}")
    return lines


def run_nonsep(nonsep, job, output):
    done = subprocess.run([nonsep, "run", "--output", output, job], capture_output=True, text=True)
    if done.returncode != 0:
        sys.stderr.write(done.stdout + done.stderr)
        sys.exit(f"work_precision_lattice: {nonsep} run {job} ended with status {done.returncode}")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("command", choices=["jobs", "run", "check", "table"])
    parser.add_argument("arguments", nargs="+", help="jobs/table: DIR; run/check: NONSEP DIR")
    parser.add_argument("--sites", type=int, nargs="+", default=[10, 1000, 100000])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--no-check", action="store_true", help="run: skip the reference's check")
    args = parser.parse_args()
    runs_nonsep = args.command in ("run", "check")
    if len(args.arguments) != (2 if runs_nonsep else 1):
        parser.error(f"{args.command} takes " + ("NONSEP DIR" if runs_nonsep else "DIR"))
    folder = args.arguments[-1]
    try:
        if args.command != "table":
            write_jobs(folder, args.sites, args.quick)
    except ValueError as error:
        parser.error(str(error))
    if args.command == "jobs":
        return
    if runs_nonsep:
        nonsep = args.arguments[0]
        for n in args.sites:
            if args.command == "run":
                run_nonsep(nonsep, os.path.join(folder, f"lattice_{n}.json"), os.path.join(folder, f"wp-{n}"))
            if args.command == "check" or not args.no_check:
                run_nonsep(nonsep, os.path.join(folder, f"lattice_{n}_check.json"), os.path.join(folder, f"check-{n}"))
    if args.command != "check":
        print(table(folder, args.sites))
    for line in check_lines(folder, args.sites):
        print(line)


if __name__ == "__main__":
    main()
