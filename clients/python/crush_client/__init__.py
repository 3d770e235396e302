"""A thin Python client of the crush job server (its HTTP contract is api/openapi.yaml).

    from crush_client import Client
    crush = Client("http://127.0.0.1:8080", token=None)
    job = crush.submit({"tube": {"length_mm": 8}, "loading": {"crush_distance_mm": 1}})
    crush.wait(job["id"])
    crush.history(job["id"])          # pandas DataFrame, one row per history point

Lengths are mm, loads N, energies mJ, times ms (history) or s (wall time), as the server
writes them: every column name carries its unit.
"""

from __future__ import annotations

import json
import time
from typing import Any, Callable, Iterator, Optional

import pandas as pd
import requests

__all__ = ["Client", "CrushError"]

FINAL_EVENTS = ("done", "failed", "cancelled")
FINISHED = ("succeeded", "failed", "cancelled")


class CrushError(Exception):
    """An answer of the server that is not a success: its status and problem document
    (RFC 9457: `detail`, and for a refused case `errors`, one `{field, reason}` each)."""

    def __init__(self, status: int, problem: dict):
        self.status = status
        self.problem = problem
        self.detail = problem.get("detail", "")
        self.errors = problem.get("errors", [])
        super().__init__(f"{status}: {self.detail}")


class Client:
    """The server at `url`; `token` is sent as `Authorization: Bearer` (servers started with
    `--token-file`)."""

    def __init__(self, url: str = "http://127.0.0.1:8080", token: Optional[str] = None,
                 timeout: float = 30.0):
        self.url = url.rstrip("/")
        self.timeout = timeout
        self.session = requests.Session()
        self.session.headers["Accept"] = "application/json"
        if token:
            self.session.headers["Authorization"] = f"Bearer {token}"

    # ---------- plumbing ----------

    def _request(self, method: str, path: str, body: Any = None, **kwargs) -> requests.Response:
        headers = kwargs.pop("headers", {})
        if method != "GET":
            headers["Content-Type"] = "application/json"
            kwargs["data"] = json.dumps({} if body is None else body)
        r = self.session.request(method, self.url + path, headers=headers,
                                 timeout=kwargs.pop("timeout", self.timeout), **kwargs)
        if r.status_code >= 400:
            try:
                problem = r.json()
            except ValueError:
                problem = {"detail": r.text}
            raise CrushError(r.status_code, problem)
        return r

    def _json(self, method: str, path: str, body: Any = None, **kwargs) -> Any:
        r = self._request(method, path, body, **kwargs)
        return r.json() if r.content else None

    # ---------- jobs ----------

    def submit(self, case: dict, idempotency_key: Optional[str] = None) -> dict:
        """Queues one case; returns the job (`id`, `status`, `links`, ...). A retried submit
        with the same `idempotency_key` returns the job of the first."""
        headers = {"Idempotency-Key": idempotency_key} if idempotency_key else {}
        return self._json("POST", "/v1/jobs", case, headers=headers)

    def estimate(self, case: dict) -> dict:
        """What a case would cost (particles, steps, memory, wall time), without running it."""
        return self._json("POST", "/v1/estimate", case)

    def job(self, job_id: str) -> dict:
        return self._json("GET", f"/v1/jobs/{job_id}")

    def jobs(self, status: Optional[str] = None, search: Optional[str] = None,
             label: Optional[str] = None, limit: Optional[int] = None) -> Iterator[dict]:
        """Jobs newest first, page after page: `status` one or several comma-separated, `search`
        a part of the label, `label` the whole label; at most `limit` jobs."""
        params = {"status": status, "search": search, "label": label}
        yield from self._pages("/v1/jobs", "jobs", params, limit)

    def cancel(self, job_id: str) -> dict:
        return self._json("POST", f"/v1/jobs/{job_id}/cancel")

    def delete_job(self, job_id: str) -> None:
        """Deletes a finished job that belongs to no sweep, with everything stored for it."""
        self._request("DELETE", f"/v1/jobs/{job_id}")

    def events(self, job_id: str, last_event_id: Optional[int] = None) -> Iterator[tuple[str, dict]]:
        """The job's server-sent events as (name, data) until the final one (`done`, `failed`
        or `cancelled`); reconnects where it left off if the connection drops."""
        while True:
            headers = {"Accept": "text/event-stream"}
            if last_event_id is not None:
                headers["Last-Event-ID"] = str(last_event_id)
            try:
                with self.session.get(f"{self.url}/v1/jobs/{job_id}/events", headers=headers,
                                      stream=True, timeout=(self.timeout, 120)) as r:
                    if r.status_code == 204:
                        return  # nothing newer than last_event_id: it had ended
                    if r.status_code >= 400:
                        raise CrushError(r.status_code, _problem(r))
                    for event_id, name, data in _parse_sse(r.iter_lines(decode_unicode=True)):
                        if event_id is not None:
                            last_event_id = event_id
                        yield name, data
                        if name in FINAL_EVENTS:
                            return
            except (requests.ConnectionError, requests.Timeout):
                time.sleep(1.0)

    def wait(self, job_id: str, on_progress: Optional[Callable[[dict], None]] = None) -> dict:
        """Follows the job's event stream to its end and returns the finished job;
        `on_progress` gets each progress event (step, displacement_mm, load_n, fraction, ...)."""
        for name, data in self.events(job_id):
            if name == "progress" and on_progress:
                on_progress(data)
        return self.job(job_id)

    def history(self, job_id: str) -> pd.DataFrame:
        """The load-displacement and energy history of a succeeded job, one row per point."""
        h = self._json("GET", f"/v1/jobs/{job_id}/history")
        return pd.DataFrame(h["rows"], columns=h["columns"])

    def summary(self, job_id: str) -> dict:
        return self._json("GET", f"/v1/jobs/{job_id}/summary")

    def download(self, job_id: str, what: str, path: str) -> str:
        """Saves `plot.svg`, `shape.png`, `state.vtu` or (a case with `output.frames`)
        `series.tar`, `series.pvd` or `frames/{k}.vtu` of a succeeded job to `path`."""
        r = self._request("GET", f"/v1/jobs/{job_id}/{what}", stream=True, timeout=(self.timeout, 300))
        with open(path, "wb") as f:
            for chunk in r.iter_content(1 << 16):
                f.write(chunk)
        return path

    # ---------- sweeps ----------

    def submit_sweep(self, base: dict, parameters: Optional[dict] = None,
                     label: Optional[str] = None, seeds: Optional[int] = None) -> dict:
        """One job per combination of `parameters` (dotted field → list of values) on the
        `base` case; all are queued or none. With `seeds`, every combination runs over that
        many trigger seeds from the base's on (an ensemble: the sweep's `ensemble` holds the
        distribution of its runs). Returns the sweep (`id`, `rows`, ...)."""
        body: dict = {"base": base}
        if parameters:
            body["parameters"] = parameters
        if seeds is not None:
            body["ensemble"] = {"seeds": seeds}
        if label is not None:
            body["label"] = label
        return self._json("POST", "/v1/sweeps", body)

    def sweep(self, sweep_id: str) -> dict:
        return self._json("GET", f"/v1/sweeps/{sweep_id}")

    def sweeps(self, search: Optional[str] = None, limit: Optional[int] = None) -> Iterator[dict]:
        """Sweeps newest first, each with its jobs counted by status."""
        yield from self._pages("/v1/sweeps", "sweeps", {"search": search}, limit)

    def sweep_table(self, sweep_id: str) -> pd.DataFrame:
        """The sweep's table: one row per job, the swept values, status and key results (loads
        N, energies mJ, wall time s; NaN until a job succeeds)."""
        s = self.sweep(sweep_id)
        return pd.DataFrame(s["rows"], columns=s["columns"])

    def wait_sweep(self, sweep_id: str, on_job: Optional[Callable[[dict], None]] = None) -> pd.DataFrame:
        """Waits for every job of the sweep to finish; returns its table."""
        for row in self.sweep(sweep_id)["rows"]:
            job = self.wait(row["job_id"])
            if on_job:
                on_job(job)
        return self.sweep_table(sweep_id)

    def delete_sweep(self, sweep_id: str) -> None:
        """Deletes a sweep whose jobs have all finished, with its jobs."""
        self._request("DELETE", f"/v1/sweeps/{sweep_id}")

    # ---------- lists ----------

    def _pages(self, path: str, key: str, params: dict, limit: Optional[int]) -> Iterator[dict]:
        params = {k: v for k, v in params.items() if v is not None}
        params["limit"] = min(limit or 500, 500)
        seen = 0
        while True:
            page = self._json("GET", path, params=params)
            for item in page[key]:
                yield item
                seen += 1
                if limit is not None and seen >= limit:
                    return
            if not page.get("next_cursor"):
                return
            params["cursor"] = page["next_cursor"]


def _problem(r: requests.Response) -> dict:
    try:
        return r.json()
    except ValueError:
        return {"detail": r.text}


def _parse_sse(lines: Iterator[str]) -> Iterator[tuple[Optional[int], str, dict]]:
    """(id, event name, JSON data) of each event of a `text/event-stream`; comments skipped."""
    event_id, name, data = None, "message", []
    for line in lines:
        if line == "":
            if data:
                yield event_id, name, json.loads("\n".join(data))
            event_id, name, data = None, "message", []
        elif line.startswith(":"):
            continue
        else:
            field, _, value = line.partition(":")
            value = value[1:] if value.startswith(" ") else value
            if field == "id":
                event_id = int(value) if value.isdigit() else None
            elif field == "event":
                name = value
            elif field == "data":
                data.append(value)
