"""The client against a live crush server (CRUSH_URL, with the submit token CRUSH_TOKEN and the
read token CRUSH_READ_TOKEN), as .ci/python starts one: submit and follow a job, its history
as a DataFrame, a sweep and its table, the lists, errors, tokens and deletes."""

import os
import subprocess
import sys
import uuid
from pathlib import Path

import pandas as pd
import pytest

from crush_client import Client, CrushError

URL = os.environ.get("CRUSH_URL", "http://127.0.0.1:8080")
TOKEN = os.environ.get("CRUSH_TOKEN")
READ_TOKEN = os.environ.get("CRUSH_READ_TOKEN")

TINY = {
    "tube": {"thickness_mm": 3.2, "mean_diameter_mm": 22.2, "length_mm": 8},
    "discretization": {"particles_through_thickness": 1},
    "loading": {"crush_distance_mm": 1, "plate_speed_m_s": 20},
    "output": {"history_points": 20},
}


@pytest.fixture(scope="module")
def crush():
    return Client(URL, token=TOKEN)


def tiny(label):
    return {**TINY, "label": label}


def test_a_job_is_followed_to_its_end_and_its_history_is_a_dataframe(crush):
    label = f"python {uuid.uuid4().hex[:8]}"
    job = crush.submit(tiny(label))
    assert job["status"] in ("queued", "running")
    progress = []
    done = crush.wait(job["id"], on_progress=progress.append)
    assert done["status"] == "succeeded", done
    assert progress and all(0 <= p["fraction"] <= 1 for p in progress)
    h = crush.history(job["id"])
    assert isinstance(h, pd.DataFrame)
    assert list(h.columns[:4]) == ["time_ms", "displacement_mm", "load_top_n", "load_bottom_n"]
    assert 19 <= len(h) <= 21
    assert h["displacement_mm"].is_monotonic_increasing
    summary = crush.summary(job["id"])
    assert summary["mean_load_n"] > 0
    assert [j["id"] for j in crush.jobs(search=label[-8:].upper())] == [job["id"]]


def test_a_retried_submit_with_the_same_key_is_the_same_job(crush):
    key = uuid.uuid4().hex
    first = crush.submit(tiny("retried"), idempotency_key=key)
    again = crush.submit(tiny("retried"), idempotency_key=key)
    assert first["id"] == again["id"]


def test_a_sweep_table_is_a_dataframe_with_a_row_per_job(crush):
    label = f"python sweep {uuid.uuid4().hex[:8]}"
    sweep = crush.submit_sweep(tiny(None), {"tube.thickness_mm": [2.0, 3.2]}, label=label)
    table = crush.wait_sweep(sweep["id"])
    assert list(table["tube.thickness_mm"]) == [2.0, 3.2]
    assert (table["status"] == "succeeded").all()
    assert (table["mean_load_n"] > 0).all()
    listed = list(crush.sweeps(search=label))
    assert [s["id"] for s in listed] == [sweep["id"]]
    assert listed[0]["counts"]["succeeded"] == 2


def test_an_ensemble_over_seeds_gives_the_distribution_and_the_verdicts(crush):
    base = {**tiny(None), "trigger": {"weak_fraction": 0.05, "seed": 2}}
    sweep = crush.submit_sweep(base, seeds=3, label="seeds")
    table = crush.wait_sweep(sweep["id"])
    assert list(table["trigger.seed"]) == [2, 3, 4]
    assert (table["verdict"] == "not_trusted").all()
    assert (table["ensemble_runs"] == 3).all()
    spread = crush.sweep(sweep["id"])["ensemble"][0]["distribution"]["mean_load_n"]
    assert spread["min"] <= spread["mean"] <= spread["max"]
    assert spread["min"] == table["mean_load_n"].min()


def test_a_refused_case_names_its_fields(crush):
    bad = {**TINY, "tube": {**TINY["tube"], "thickness_mm": 15}}
    with pytest.raises(CrushError) as e:
        crush.submit(bad)
    assert e.value.status == 422
    assert any(err["field"] == "tube.thickness_mm" for err in e.value.errors), e.value.problem
    with pytest.raises(CrushError) as e:
        crush.job(str(uuid.uuid4()))
    assert e.value.status == 404


@pytest.mark.skipif(not TOKEN, reason="the server under test has no tokens")
def test_a_token_is_needed_and_a_reader_may_not_submit_or_delete(crush):
    with pytest.raises(CrushError) as e:
        list(Client(URL).jobs(limit=1))
    assert e.value.status == 401
    reader = Client(URL, token=READ_TOKEN)
    assert list(reader.jobs(limit=1))
    with pytest.raises(CrushError) as e:
        reader.submit(tiny("reader"))
    assert e.value.status == 403


def test_a_finished_job_and_sweep_are_deleted(crush):
    job = crush.submit(tiny("to delete"))
    crush.wait(job["id"])
    crush.delete_job(job["id"])
    with pytest.raises(CrushError) as e:
        crush.job(job["id"])
    assert e.value.status == 404
    sweep = crush.submit_sweep(tiny(None), {"contact.friction": [0.0]}, label="to delete")
    crush.wait_sweep(sweep["id"])
    crush.delete_sweep(sweep["id"])
    with pytest.raises(CrushError) as e:
        crush.sweep(sweep["id"])
    assert e.value.status == 404


def test_the_example_runs_its_sweep_and_draws_the_plot(tmp_path):
    example = Path(__file__).parent.parent / "examples" / "thickness_sweep.py"
    out = tmp_path / "sweep.png"
    run = subprocess.run([sys.executable, str(example), "--url", URL, "--out", str(out)],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert "wrote" in run.stdout
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
