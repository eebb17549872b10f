"""Scheme "auto" against the best hand-picked scheme and step: the table of docs/accuracy.md.

Usage: /usr/bin/python3 bench/auto_accuracy.py NONSEP_EXECUTABLE WORK_FOLDER [--repeats 5] [--cases N]

Three problems with a known answer: paper1d from (2, 0) to its exact quarter period (end point (0, -1.5723...)),
mathews_lakshmanan (lambda 0.5, alpha 1) from (1.5, 0) to its exact quarter period (end point (0, -1.02899...)), and
paper2d's regular orbit q = (0, 0), p = (0.5, 2) to t = 2 against Gauss 6 at 8192 steps (checked against 16384);
tolerances 1e-4, 1e-6, 1e-8, 1e-10 on the phase error at t_end ("phase") and on the largest |dH/H0| with H at
every step ("energy"): 24 cases. For each case:
  auto   `nonsep run` of the job with "scheme": "auto" (time.dt = t_end: the output grid is the end point); its
         actual error against the answer, its choice, and its wall time: the whole process (median of --repeats
         runs), and inside the process the pilots plus the run (summary.json);
  best   every candidate of a hand-picked ladder (gauss 16, 8, 6 and 4, mpe 4, triplet 8/3 and 2, tao 4 and 6; steps
         doubling, from a study with study.repeats 1) at the fewest steps that meet the tolerance, each timed by
         `nonsep run` like auto; the fastest of them.
Prints the markdown table, and writes WORK_FOLDER/auto_accuracy.json with every number.
"""
import argparse
import csv
import json
import math
import statistics
import subprocess
import sys
import time
from pathlib import Path

QUARTER_1D = 0.3863765573361232
QUARTER_ML = 2.289809454535185
PROBLEMS = {
    "paper1d": {"model": {"plugin": "paper1d"}, "initial": {"q": [2.0], "p": [0.0]}, "t_end": QUARTER_1D,
                "answer": {"q": [0.0], "p": [-1.5723027555148466]}},
    "mathews_lakshmanan": {"model": {"plugin": "mathews_lakshmanan", "parameters": {"lambda": 0.5, "alpha": 1.0}},
                           "initial": {"q": [1.5], "p": [0.0]}, "t_end": QUARTER_ML,
                           "answer": {"q": [0.0], "p": [-1.028991510855053]}},
    "paper2d": {"model": {"plugin": "paper2d"}, "initial": {"q": [0.0, 0.0], "p": [0.5, 2.0]}, "t_end": 2.0,
                "answer": None},
}
LADDER = [("gauss 16", {"scheme": "gauss", "stages": 8}, 1), ("gauss 8", {"scheme": "gauss", "stages": 4}, 1),
          ("gauss 6", {"scheme": "gauss", "stages": 3}, 1), ("gauss 4", {"scheme": "gauss", "stages": 2}, 1),
          ("mpe 4", {"scheme": "mpe", "order": "4"}, 2), ("triplet 8/3", {"scheme": "triplet", "order": "8/3"}, 8),
          ("triplet 2", {"scheme": "triplet", "order": "2"}, 8), ("tao 4", {"scheme": "tao", "order": "4"}, 8),
          ("tao 6", {"scheme": "tao", "order": "6"}, 8)]
MAX_STEPS = 1 << 15
TOLERANCES = [1e-4, 1e-6, 1e-8, 1e-10]


def run(nonsep, job, folder, repeats=1):
    """Runs `job` `repeats` times; returns (median process seconds, summary, trajectories row, max |dH/H0|)."""
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "job.json"
    path.write_text(json.dumps(job))
    seconds = []
    for _ in range(repeats):
        start = time.perf_counter()
        done = subprocess.run([nonsep, "run", "--quiet", "--force", "--output", str(folder / "out"), str(path)],
                              capture_output=True, text=True)
        seconds.append(time.perf_counter() - start)
        if done.returncode != 0:
            sys.exit(f"nonsep failed on {path}: {done.stderr}")
    summary = json.loads((folder / "out" / "summary.json").read_text())
    with open(folder / "out" / "trajectories.csv", newline="") as f:
        row = next(csv.DictReader(f))
    return statistics.median(seconds), summary, row


def phase_error(row, answer):
    n = len(answer["q"])
    return math.sqrt(sum((float(row[f"q{i}"]) - answer["q"][i]) ** 2 + (float(row[f"p{i}"]) - answer["p"][i]) ** 2
                         for i in range(n)))


def single_job(problem, integrator, steps, measure):
    p = PROBLEMS[problem]
    job = {"model": p["model"], "integrator": integrator, "initial": p["initial"],
           "time": {"dt": p["t_end"] / steps, "t_end": p["t_end"]}, "output": {"every": 0}}
    if measure == "energy":
        job["output"]["energy_every"] = 1
    return job


def reference(nonsep, folder):
    """paper2d's end point: Gauss 6 at 8192 steps, and its distance to 16384 steps."""
    ends = []
    for steps in (8192, 16384):
        _, _, row = run(nonsep, single_job("paper2d", {"scheme": "gauss", "stages": 3}, steps, "phase"),
                        folder / f"reference-{steps}")
        ends.append({"q": [float(row["q0"]), float(row["q1"])], "p": [float(row["p0"]), float(row["p1"])]})
    return ends[0], phase_error({"q0": ends[1]["q"][0], "q1": ends[1]["q"][1], "p0": ends[1]["p"][0],
                                 "p1": ends[1]["p"][1]}, ends[0])


def ladder(nonsep, problem, folder):
    """Every (label, integrator, steps) of the ladder with its phase error and largest |dH/H0| (a study)."""
    p = PROBLEMS[problem]
    integrators = []
    for label, integrator, start in LADDER:
        steps, counts = start, []
        while steps <= MAX_STEPS:
            counts.append(steps)
            steps *= 2
        integrators.append(dict(integrator, label=label, steps=counts))
    job = {"model": p["model"], "initial": p["initial"], "time": {"t_end": p["t_end"]},
           "study": {"reference": p["answer"], "integrators": integrators}}
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "study.json").write_text(json.dumps(job))
    subprocess.run([nonsep, "run", "--quiet", "--force", "--output", str(folder / "out"), str(folder / "study.json")],
                   capture_output=True, text=True)
    rows = []
    with open(folder / "out" / "work_precision.csv", newline="") as f:
        for row in csv.DictReader(f):
            if row["status"] == "completed":
                rows.append(row)
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("nonsep")
    parser.add_argument("folder")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--cases", type=int, default=24, help="only the first N cases (a quick check)")
    args = parser.parse_args()
    work = Path(args.folder)
    answer_2d, reference_check = reference(args.nonsep, work / "paper2d")
    PROBLEMS["paper2d"]["answer"] = answer_2d
    ladders = {name: ladder(args.nonsep, name, work / name / "ladder") for name in PROBLEMS}
    cases, results = [], []
    for name in PROBLEMS:
        for measure in ("phase", "energy"):
            for tolerance in TOLERANCES:
                cases.append((name, measure, tolerance))
    for name, measure, tolerance in cases[:args.cases]:
        p = PROBLEMS[name]
        tag = f"{name}-{measure}-{tolerance:.0e}"
        job = single_job(name, {"scheme": "auto", "tolerance": tolerance, "measure": measure}, 1, measure)
        seconds, summary, row = run(args.nonsep, job, work / tag / "auto", args.repeats)
        choice = summary["scheme_choice"]
        actual = phase_error(row, p["answer"]) if measure == "phase" else float(row["max_abs_relative_energy_error"])
        auto = {"process_seconds": seconds, "chosen": choice["chosen"], "steps": summary["time"]["steps"],
                "predicted": choice["estimated_error"], "actual": actual, "met": actual <= tolerance,
                "pilot_seconds": choice["pilot_cost"]["wall_seconds"], "run_seconds": summary["wall_seconds"]}
        column = "phase_error" if measure == "phase" else "max_abs_relative_energy_error"
        best = None
        for label, integrator, _ in LADDER:
            meeting = [r for r in ladders[name] if r["integrator"] == label and r[column] and
                       abs(float(r[column])) <= tolerance]
            if not meeting:
                continue
            steps = min(int(r["steps"]) for r in meeting)
            t, s, hand_row = run(args.nonsep, single_job(name, integrator, steps, measure),
                                 work / tag / label.replace(" ", "_").replace("/", "_"), args.repeats)
            hand_actual = (phase_error(hand_row, p["answer"]) if measure == "phase"
                           else float(hand_row["max_abs_relative_energy_error"]))
            if hand_actual > tolerance:
                continue
            entry = {"label": label, "steps": steps, "process_seconds": t, "run_seconds": s["wall_seconds"],
                     "actual": hand_actual}
            if best is None or t < best["process_seconds"]:
                best = entry
        results.append({"problem": name, "measure": measure, "tolerance": tolerance, "auto": auto, "best": best})
        print(f"{tag}: auto {auto['chosen']} {auto['steps']} steps, error {actual:.2g}, "
              f"{seconds * 1e3:.1f} ms; best {best and best['label']} {best and best['steps']}, "
              f"{best and best['process_seconds'] * 1e3:.1f} ms", file=sys.stderr)
    (work / "auto_accuracy.json").write_text(json.dumps({"paper2d_reference_check": reference_check,
                                                         "results": results}, indent=1))
    print("| problem | measure | tolerance | auto: scheme, steps | predicted | actual | met | auto ms (process; "
          "pilots + run) | best hand-picked: scheme, steps | best ms (process; run) | ratio (process) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for r in results:
        a, b = r["auto"], r["best"]
        best_text = f"{b['label']}, {b['steps']}" if b else "not reached"
        best_ms = f"{b['process_seconds'] * 1e3:.1f}; {b['run_seconds'] * 1e3:.3f}" if b else "-"
        ratio = f"{a['process_seconds'] / b['process_seconds']:.2f}" if b else "-"
        print(f"| {r['problem']} | {r['measure']} | {r['tolerance']:.0e} | {a['chosen']}, {a['steps']} | "
              f"{a['predicted']:.2g} | {a['actual']:.2g} | {'yes' if a['met'] else '**no**'} | "
              f"{a['process_seconds'] * 1e3:.1f}; {(a['pilot_seconds'] + a['run_seconds']) * 1e3:.3f} | {best_text} | "
              f"{best_ms} | {ratio} |")


if __name__ == "__main__":
    main()
