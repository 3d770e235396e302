"""A small sweep over the wall thickness, run on a crush server and plotted: the load curves
overlaid, and the mean collapse load against the thickness beside Alexander's closed form.

    python examples/thickness_sweep.py [--url http://127.0.0.1:8080] [--out sweep.png]

The token, if the server asks for one, comes from CRUSH_TOKEN. The cases are axisymmetric
sections with a short crush, so the whole sweep runs in seconds.
"""

import argparse
import os

import matplotlib

matplotlib.use("Agg")  # draws to a file; no display needed
import matplotlib.pyplot as plt  # noqa: E402

from crush_client import Client  # noqa: E402

BASE = {
    "label": "thickness sweep (python example)",
    "tube": {"mean_diameter_mm": 22.2, "length_mm": 40},
    "loading": {"mode": "axial", "plate_speed_m_s": 10, "crush_distance_mm": 8},
    "discretization": {"model": "axisymmetric", "particles_through_thickness": 3},
    "trigger": {"weak_fraction": 0},
    "output": {"history_points": 200},
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--url", default=os.environ.get("CRUSH_URL", "http://127.0.0.1:8080"))
    parser.add_argument("--out", default="thickness_sweep.png")
    args = parser.parse_args()
    crush = Client(args.url, token=os.environ.get("CRUSH_TOKEN"))

    sweep = crush.submit_sweep(BASE, {"tube.thickness_mm": [1.5, 2.0, 2.5, 3.2]})
    print(f"sweep {sweep['id']}: {len(sweep['rows'])} jobs")
    table = crush.wait_sweep(sweep["id"], on_job=lambda j: print(f"  {j['id'][:8]} {j['status']}"))
    print(table[["tube.thickness_mm", "status", "mean_load_n", "energy_absorbed_mj"]].to_string(index=False))

    fig, (curves, means) = plt.subplots(1, 2, figsize=(11, 4.2))
    alexander = []
    for _, row in table.iterrows():
        h = crush.history(row["job_id"])
        label = f"t = {row['tube.thickness_mm']} mm"
        curves.plot(h["displacement_mm"], h["load_top_n"] / 1000, label=label)
        summary = crush.summary(row["job_id"])
        alexander.append(summary["references"]["alexander_ring_n"] / 1000)
    curves.set(xlabel="plate travel, mm", ylabel="load, kN", title="load curves")
    curves.legend()
    t = table["tube.thickness_mm"]
    means.plot(t, table["mean_load_n"] / 1000, "o-", label="crush, mean load")
    means.plot(t, alexander, "s--", label="Alexander (1960)")
    means.set(xlabel="wall thickness, mm", ylabel="mean collapse load, kN", title="mean load")
    means.legend()
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
