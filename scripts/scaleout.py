#!/usr/bin/env python3
"""Throughput of tiny jobs through the whole path (submit -> claim -> run -> store) for N crush
nodes on one database, and the nodes' claim latency (quantiles of their /metrics histogram).

    cargo build --release
    eval "$(bash .ci/postgres)"          # or any PostgreSQL: CRUSH_TEST_POSTGRES=postgres://...
    python3 scripts/scaleout.py --backend postgres --nodes 3 --jobs 1000 --repeats 3
    python3 scripts/scaleout.py --backend sqlite --nodes 1 --jobs 1000 --repeats 3

Each repeat makes a fresh database, starts the nodes (`crush serve --port 0`, one worker of one
thread each), submits every job (through all nodes, 16 clients) and times from the first
submit until the store says every job succeeded. With --prequeue the jobs are queued first
through a node that runs none, and the worker nodes start on a full queue (the claim latency
"with 1000 queued jobs"); the time then runs from their start. Standard library only.
"""
import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import threading
import time
import urllib.request
import uuid
from concurrent.futures import ThreadPoolExecutor

TINY = {
    "tube": {"thickness_mm": 3.2, "mean_diameter_mm": 22.2, "length_mm": 8},
    "discretization": {"particles_through_thickness": 1},
    "loading": {"crush_distance_mm": 1, "plate_speed_m_s": 20},
    "output": {"history_points": 20, "final_state": False},
}


def request(url, body=None):
    data = None if body is None else json.dumps(body).encode()
    req = urllib.request.Request(url, data=data, method="POST" if body is not None else "GET")
    if body is not None:
        req.add_header("content-type", "application/json")
    with urllib.request.urlopen(req, timeout=60) as r:
        return r.read().decode()


def fresh_database(backend, tmp):
    if backend == "sqlite":
        return f"sqlite://{tmp}/crush-{uuid.uuid4().hex}.db"
    admin = os.environ["CRUSH_TEST_POSTGRES"]
    name = f"crush_bench_{uuid.uuid4().hex}"
    subprocess.run(["psql", admin, "-qc", f"CREATE DATABASE {name}"], check=True)
    return admin.rsplit("/", 1)[0] + "/" + name


def start_node(binary, db, name, queue, workers=1):
    p = subprocess.Popen(
        [binary, "serve", "--port", "0", "--database-url", db, "--node-name", name,
         "--concurrent-jobs", str(workers), "--threads-per-job", "1", "--max-queue", str(queue)],
        stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
        env={**os.environ, "RUST_LOG": "warn"})
    line = p.stdout.readline()
    threading.Thread(target=lambda: [None for _ in p.stdout], daemon=True).start()
    return p, line.rsplit(" ", 1)[1].strip()


def submit(urls, jobs):
    urls = [urls] if isinstance(urls, str) else urls
    with ThreadPoolExecutor(16) as pool:
        list(pool.map(lambda k: request(f"{urls[k % len(urls)]}/v1/jobs", TINY), range(jobs)))


def metric(text, name):
    m = re.search(rf"^{re.escape(name)} (\S+)$", text, re.M)
    return float(m.group(1)) if m else None


def histogram_quantile(text, name, q):
    """The q-quantile of the histogram `name` in an OpenMetrics text, interpolated linearly
    within the bucket it falls in, as Prometheus' histogram_quantile does (so it is known to
    the buckets' resolution: they double)."""
    buckets = sorted(
        (float("inf") if le == "+Inf" else float(le), float(n))
        for le, n in re.findall(rf'^{re.escape(name)}_bucket{{le="([^"]+)"}} (\S+)$', text, re.M))
    if not buckets or buckets[-1][1] == 0:
        return None
    rank = q * buckets[-1][1]
    lower, below = 0.0, 0.0
    for upper, count in buckets:
        if count >= rank:
            if upper == float("inf"):
                return lower
            return lower + (upper - lower) * (rank - below) / max(count - below, 1e-12)
        lower, below = upper, count
    return None


def one_run(args, tmp):
    db = fresh_database(args.backend, tmp)
    nodes = []
    if args.prequeue:
        nodes.append(start_node(args.binary, db, "queue", args.jobs + 10, workers=0))
        submit(nodes[0][1], args.jobs)
    t0 = time.perf_counter()
    nodes += [start_node(args.binary, db, f"n{k + 1}", args.jobs + 10) for k in range(args.nodes)]
    urls = [u for _, u in nodes[1:]] if args.prequeue else [u for _, u in nodes]
    try:
        if not args.prequeue:
            submit(urls, args.jobs)
        queued = time.perf_counter() - t0
        while True:
            done = metric(request(f"{urls[0]}/metrics"), 'crush_jobs{status="succeeded"}')
            if done == args.jobs:
                break
            time.sleep(0.02)
        total = time.perf_counter() - t0
        claims = []
        for u in urls:
            text = request(f"{u}/metrics")
            claims.append((histogram_quantile(text, "crush_claim_seconds", 0.5),
                           histogram_quantile(text, "crush_claim_seconds", 0.99)))
        return total, queued, claims
    finally:
        for p, _ in nodes:
            p.terminate()
            p.wait()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--backend", choices=["sqlite", "postgres"], required=True)
    ap.add_argument("--nodes", type=int, default=1)
    ap.add_argument("--jobs", type=int, default=1000)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--binary", default="target/release/crush")
    ap.add_argument("--prequeue", action="store_true")
    args = ap.parse_args()
    rates = []
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(args.repeats):
            total, queued, claims = one_run(args, tmp)
            rates.append(args.jobs / total)
            p50 = statistics.median(c[0] for c in claims) * 1e3
            p99 = max(c[1] for c in claims) * 1e3
            print(f"run {r + 1}: {args.jobs} jobs in {total:.2f} s ({args.jobs / total:.1f} jobs/s; "
                  f"{'nodes up' if args.prequeue else 'all queued'} after {queued:.2f} s); claim p50 {p50:.2f} ms, p99 {p99:.2f} ms "
                  f"(median and worst of the nodes)", flush=True)
    print(f"{args.backend}, {args.nodes} node(s): median {statistics.median(rates):.1f} jobs/s "
          f"(range {min(rates):.1f}-{max(rates):.1f})")


if __name__ == "__main__":
    sys.exit(main())
