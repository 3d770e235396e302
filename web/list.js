// crush web page: the side lists — jobs newest first, with their counts per state, a live
// progress bar per running job (SSE) and boxes to pick jobs for an overlay; sweeps newest first
// with their jobs' states; one label search for both.
import { api, el, isLive, jobName, kN, localTime, picked, setPicked, short, sweepValues } from "./util.js";

const STATES = ["queued", "running", "succeeded", "failed", "cancelled"];
/// Most jobs one overlay draws (the palette's colours).
export const MAX_PICKED = 10;

// ---------- job list (live, SSE) ----------

const listStreams = new Map(); // job id → EventSource, for at most MAX_LIST_STREAMS running jobs
const MAX_LIST_STREAMS = 3;

/// A job's state, and while it waits or runs how far it has got (the list stays narrow enough
/// beside the page that labels keep their room).
function statusCell(job) {
  const badge = el("span", { class: "badge " + job.status }, job.status);
  if (!isLive(job.status)) return el("td", {}, badge);
  const f = (job.progress && job.progress.fraction) || 0;
  const bar = el("progress", { max: "1", value: String(f), "data-job": job.id });
  const label = el("span", { class: "small muted", "data-job-pct": job.id }, " " + Math.round(100 * f) + " %");
  return el("td", { class: "progress-cell" }, badge, el("div", {}, bar, label));
}

function setListProgress(id, fraction) {
  const bar = document.querySelector(`#job-list progress[data-job="${id}"]`);
  const label = document.querySelector(`#job-list [data-job-pct="${id}"]`);
  if (bar) bar.value = fraction;
  if (label) label.textContent = " " + Math.round(100 * fraction) + " %";
}

const search = () => encodeURIComponent(document.getElementById("search").value.trim());

/// Jobs by state, each a link that filters the list to that state.
function countsLine(counts) {
  const filter = document.getElementById("job-filter");
  const parts = STATES.filter((s) => counts && counts[s]).map((s) =>
    el("a", { href: "#", class: "count " + s, "data-state": s, onclick: (e) => {
      e.preventDefault();
      filter.value = [...filter.options].some((o) => o.value === s) ? s : "";
      if (filter.value !== s) {
        filter.append(el("option", { value: s }, s));
        filter.value = s;
      }
      refreshJobList();
    } }, `${counts[s]} ${s}`));
  return parts.flatMap((p, i) => (i ? [" · ", p] : [p]));
}

function updatePicked() {
  const ids = picked();
  const button = document.getElementById("compare");
  button.disabled = ids.length < 1;
  button.textContent = ids.length ? `Overlay ${ids.length} picked` : "Overlay picked jobs";
  document.getElementById("clear-picked").hidden = !ids.length;
}

function pickBox(job) {
  const ids = picked();
  return el("input", {
    type: "checkbox", class: "pick", "data-pick": job.id, "aria-label": "pick " + jobName(job),
    checked: ids.includes(job.id), disabled: job.status !== "succeeded",
    title: job.status === "succeeded" ? "pick for the overlay" : "only a succeeded job has a curve",
    onchange: (e) => {
      let now = picked().filter((x) => x !== job.id);
      if (e.target.checked) now.push(job.id);
      if (now.length > MAX_PICKED) { now = now.slice(-MAX_PICKED); refreshJobList(); }
      setPicked(now);
      updatePicked();
    },
  });
}

let listLimit = 30;
export async function refreshJobList() {
  const status = document.getElementById("job-filter").value;
  const q = search();
  const r = await api("GET", `/v1/jobs?limit=${listLimit}` + (status ? `&status=${status}` : "") + (q ? `&search=${q}` : ""));
  const body = document.querySelector("#job-list tbody");
  const note = document.getElementById("job-list-note");
  if (!r.ok) { note.textContent = "Could not load jobs: " + (r.data && r.data.detail); return; }
  document.getElementById("job-counts").replaceChildren(...countsLine(r.data.counts));
  note.replaceChildren(r.data.jobs.length ? "Newest first; live while running. " : (q ? "No job's label has that. " : "No jobs here yet. "),
    r.data.next_cursor && listLimit < 500
      ? el("a", { href: "#", id: "job-list-more", onclick: (e) => { e.preventDefault(); listLimit = Math.min(500, listLimit * 2); refreshJobList(); } }, "Show more")
      : "");
  body.replaceChildren(...r.data.jobs.map((j) => el("tr", { "data-job-row": j.id },
    el("td", {}, pickBox(j)),
    el("td", { class: "name" }, el("a", { href: `#/jobs/${j.id}`, title: `${jobName(j)} — ${j.id}` }, j.label || j.id.slice(0, 8)),
      j.sweep_id ? el("div", { class: "small" }, el("a", { href: `#/sweeps/${j.sweep_id}` }, "sweep"),
        " · " + sweepValues(j)) : null),
    statusCell(j),
    el("td", { class: "num" }, j.summary ? kN(j.summary.mean_load_n) : "–"))));
  updatePicked();
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

// ---------- sweep list ----------

let sweepLimit = 30;
export async function refreshSweepList() {
  const q = search();
  const r = await api("GET", `/v1/sweeps?limit=${sweepLimit}` + (q ? `&search=${q}` : ""));
  const body = document.querySelector("#sweep-list tbody");
  const note = document.getElementById("sweep-list-note");
  if (!r.ok) { note.textContent = "Could not load sweeps: " + (r.data && r.data.detail); return; }
  note.replaceChildren(r.data.sweeps.length ? "Newest first. " : (q ? "No sweep's label has that. " : "No sweeps yet. "),
    r.data.next_cursor && sweepLimit < 500
      ? el("a", { href: "#", onclick: (e) => { e.preventDefault(); sweepLimit = Math.min(500, sweepLimit * 2); refreshSweepList(); } }, "Show more")
      : "");
  body.replaceChildren(...r.data.sweeps.map((s) => el("tr", { "data-sweep-row": s.id },
    el("td", { class: "name" }, el("a", { href: `#/sweeps/${s.id}` }, s.label || s.id.slice(0, 8))),
    el("td", {}, s.parameters.map((p) => `${short(p[0])} × ${p[1].length}`).join(", ")),
    el("td", { class: "small" }, STATES.filter((st) => s.counts[st]).map((st) => `${s.counts[st]} ${st}`).join(" · ")),
    el("td", { class: "small muted" }, localTime(s.created_at)))));
}

// ---------- the side: tabs, search, refresh ----------

function showTab(name) {
  for (const t of ["jobs", "sweeps"]) {
    document.getElementById(`tab-${t}`).classList.toggle("active", t === name);
    document.getElementById(`tab-${t}`).setAttribute("aria-selected", String(t === name));
    document.getElementById(`${t}-pane`).hidden = t !== name;
  }
  refresh();
}

const current = () => (document.getElementById("sweeps-pane").hidden ? "jobs" : "sweeps");
const refresh = () => (current() === "jobs" ? refreshJobList() : refreshSweepList());

export function startJobList() {
  document.getElementById("job-filter").addEventListener("change", refreshJobList);
  document.getElementById("tab-jobs").addEventListener("click", () => showTab("jobs"));
  document.getElementById("tab-sweeps").addEventListener("click", () => showTab("sweeps"));
  let typing = null;
  document.getElementById("search").addEventListener("input", () => {
    clearTimeout(typing);
    typing = setTimeout(refresh, 250);
  });
  document.getElementById("compare").addEventListener("click", () => {
    location.hash = `#/compare/${picked().join(",")}`;
  });
  document.getElementById("clear-picked").addEventListener("click", (e) => {
    e.preventDefault();
    setPicked([]);
    refreshJobList();
  });
  refresh();
  setInterval(refresh, 3000);
}
