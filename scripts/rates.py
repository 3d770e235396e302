#!/usr/bin/env python3
"""The solver's throughput by material law and shape function, and the wall-time estimate
against the measured run: each case run whole with `crush run` (one thread by default), its
particle-steps per second and wall time read from the run's summary.json, beside
`crush estimate --json` of the same case.

    cargo build --release
    python3 scripts/rates.py --shapes gimp --crush-mm 1 --repeats 1
    python3 scripts/rates.py docs/materials/al6060_dt25.json --presets aa6060_t5,mild_steel \
        --crush-mm 10 --repeats 3

Without a case, the AA6060 tube of t 1.67 mm, d 48.33 mm at l 20 mm in 3D, n 3 (29 448
particles). Each case is run with its material section replaced by each of --presets: a
preset's name, or one of the laws alone that the presets combine (`ludwik`: aa6061_t6 without
its rate law; `swift`: stainless_304 without its rate law; `johnson_cook`: mild_steel with
Johnson-Cook's rate law, C 0.02, reference rate 1/s, in place of Cowper-Symonds'; `elastic`:
PVC's constants, model elastic); with
`discretization.shape` set to each of --shapes, and, with --crush-mm, its crush distance
shortened to that (a short run of a long case). A row gives the median over --repeats runs of
the wall time and of particles x steps / wall time, the particle-steps/s over the first
preset's of the same shape (the law's factor), and the estimate's wall time over the measured
one. Standard library only.
"""
import argparse
import copy
import json
import os
import statistics
import subprocess
import sys
import tempfile

CRUSH = os.path.join(os.path.dirname(__file__), "..", "target", "release", "crush")


SHORT_3D = {
    "label": "AA6060 t 1.67 d 48.33 l 20, 3D n 3",
    "tube": {"thickness_mm": 1.67, "mean_diameter_mm": 48.33, "length_mm": 20},
    "loading": {"mode": "axial", "plate_speed_m_s": 10.0, "crush_distance_mm": 60.0},
    "discretization": {"particles_through_thickness": 3, "model": "3d"},
}

LAWS_ALONE = {
    "ludwik": {"preset": "aa6061_t6", "rate": "none"},
    "swift": {"preset": "stainless_304", "rate": "none"},
    "johnson_cook": {"preset": "mild_steel", "rate": "johnson_cook", "johnson_cook_c": 0.02,
                     "johnson_cook_reference_rate_per_s": 1},
    "elastic": {"preset": "pvc", "model": "elastic"},
}


def variant(case, preset, shape, crush_mm, model):
    case = copy.deepcopy(case)
    case["material"] = LAWS_ALONE.get(preset, {"preset": preset})
    case.setdefault("discretization", {})["shape"] = shape
    if model:
        case["discretization"]["model"] = model
    if crush_mm:
        case.setdefault("loading", {})["crush_distance_mm"] = crush_mm
        case["loading"]["ramp_mm"] = min(0.5, crush_mm / 2)
    return case


def run(path, threads, out):
    subprocess.run(
        [CRUSH, "run", path, "--threads", str(threads), "--out", out, "--no-limits"],
        check=True,
        stdout=subprocess.DEVNULL,
    )
    with open(os.path.join(out, "summary.json")) as f:
        cost = json.load(f)["cost"]
    return cost


def estimate(path, threads):
    text = subprocess.run(
        [CRUSH, "estimate", path, "--threads", str(threads), "--json", "--max-particles",
         "100000000"],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    return json.loads(text)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("cases", nargs="*")
    ap.add_argument("--presets", default="pvc,aa6060_t5,aa6061_t6,mild_steel,stainless_304,"
                    "ludwik,swift,johnson_cook,elastic")
    ap.add_argument("--shapes", default="linear,gimp,bspline")
    ap.add_argument("--model", default=None, help="discretization.model for every run")
    ap.add_argument("--crush-mm", type=float, default=None)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    print("| case | preset | shape | particles | steps (est.) | wall s | particle-steps/s | "
          "over first preset | estimate s | estimate / measured |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for case_path in args.cases or [None]:
            if case_path is None:
                base, name = SHORT_3D, "aa6060_l20_3d"
            else:
                with open(case_path) as f:
                    base = json.load(f)
                name = os.path.splitext(os.path.basename(case_path))[0]
            for shape in args.shapes.split(","):
                first = None
                for preset in args.presets.split(","):
                    case = variant(base, preset, shape, args.crush_mm, args.model)
                    path = os.path.join(tmp, "case.json")
                    with open(path, "w") as f:
                        json.dump(case, f)
                    est = estimate(path, args.threads)
                    costs = [run(path, args.threads, os.path.join(tmp, "out"))
                             for _ in range(args.repeats)]
                    wall = statistics.median(c["wall_time_s"] for c in costs)
                    rate = statistics.median(c["particle_steps_per_s"] for c in costs)
                    first = first or rate
                    print(f"| {name} | {preset} | {shape} | {costs[0]['particles']} | "
                          f"{costs[0]['steps']} ({est['steps']}) | {wall:.2f} | {rate:.3e} | "
                          f"{rate / first:.2f} | {est['wall_time_s']:.2f} | "
                          f"{est['wall_time_s'] / wall:.2f} |", flush=True)


if __name__ == "__main__":
    sys.exit(main())
