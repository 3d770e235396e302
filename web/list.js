// crush web page: the job list, newest first, with a live progress bar per running job (SSE).
import { api, el, jobName, kN, sweepValues } from "./util.js";

// ---------- job list (live, SSE) ----------

const listStreams = new Map(); // job id → EventSource, for at most MAX_LIST_STREAMS running jobs
const MAX_LIST_STREAMS = 3;
let listTimer = null;

function progressCell(job) {
  const f = job.status === "succeeded" ? 1 : (job.progress && job.progress.fraction) || 0;
  const bar = el("progress", { max: "1", value: String(f), "data-job": job.id });
  const label = el("span", { class: "small muted", "data-job-pct": job.id }, " " + Math.round(100 * f) + " %");
  return el("td", {}, bar, label);
}

function setListProgress(id, fraction) {
  const bar = document.querySelector(`#job-list progress[data-job="${id}"]`);
  const label = document.querySelector(`#job-list [data-job-pct="${id}"]`);
  if (bar) bar.value = fraction;
  if (label) label.textContent = " " + Math.round(100 * fraction) + " %";
}

let listLimit = 30;
export async function refreshJobList() {
  const status = document.getElementById("job-filter").value;
  const r = await api("GET", `/v1/jobs?limit=${listLimit}` + (status ? `&status=${status}` : ""));
  const body = document.querySelector("#job-list tbody");
  const note = document.getElementById("job-list-note");
  if (!r.ok) { note.textContent = "Could not load jobs: " + (r.data && r.data.detail); return; }
  note.replaceChildren(r.data.jobs.length ? "Newest first; live while running. " : "No jobs here yet. ",
    r.data.next_cursor && listLimit < 500
      ? el("a", { href: "#", id: "job-list-more", onclick: (e) => { e.preventDefault(); listLimit = Math.min(500, listLimit * 2); refreshJobList(); } }, "Show more")
      : "");
  body.replaceChildren(...r.data.jobs.map((j) => el("tr", { "data-job-row": j.id },
    el("td", {}, el("a", { href: `#/jobs/${j.id}`, title: `${jobName(j)} — ${j.id}` }, j.label || j.id.slice(0, 8)),
      j.sweep_id ? el("div", { class: "small" }, el("a", { href: `#/sweeps/${j.sweep_id}` }, "sweep"),
        " · " + sweepValues(j)) : null),
    el("td", {}, el("span", { class: "badge " + j.status }, j.status)),
    progressCell(j),
    el("td", { class: "num" }, j.summary ? kN(j.summary.mean_load_n) : "–"))));
  // One stream per running job (a few at most), so the bars move between refreshes.
  const running = new Set(r.data.jobs.filter((j) => j.status === "running").map((j) => j.id));
  for (const [id, es] of listStreams) {
    if (!running.has(id)) { es.close(); listStreams.delete(id); }
  }
  for (const id of running) {
    if (listStreams.has(id) || listStreams.size >= MAX_LIST_STREAMS) continue;
    const es = new EventSource(`/v1/jobs/${id}/events`);
    es.addEventListener("progress", (e) => {
      const p = JSON.parse(e.data);
      if (typeof p.fraction === "number") setListProgress(id, p.fraction);
    });
    for (const end of ["done", "failed", "cancelled"]) {
      es.addEventListener(end, () => { es.close(); listStreams.delete(id); refreshJobList(); });
    }
    listStreams.set(id, es);
  }
}

export function startJobList() {
  document.getElementById("job-filter").addEventListener("change", refreshJobList);
  refreshJobList();
  listTimer = setInterval(refreshJobList, 3000);
}
