// crush web page: a case form built from GET /v1/case/fields, a live job list (SSE), a job view
// (live load curve, summary against the closed-form references, deformed-tube picture,
// downloads), and a sweep view (overlaid curves, table, convergence: error against run time).
// Plain JavaScript; the one library is uPlot, served by this server like everything else.
"use strict";

// ---------- small helpers ----------

function el(tag, attrs, ...kids) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs || {})) {
    if (v === null || v === undefined || v === false) continue;
    if (k === "class") e.className = v;
    else if (k.startsWith("on")) e.addEventListener(k.slice(2), v);
    else e.setAttribute(k, v === true ? "" : v);
  }
  for (const kid of kids.flat()) {
    if (kid === null || kid === undefined) continue;
    e.append(kid instanceof Node ? kid : document.createTextNode(String(kid)));
  }
  return e;
}

async function api(method, path, body) {
  const init = { method, headers: { Accept: "application/json" } };
  if (body !== undefined) {
    init.headers["Content-Type"] = "application/json";
    init.body = JSON.stringify(body);
  }
  let res;
  try {
    res = await fetch(path, init);
  } catch (e) {
    return { ok: false, status: 0, data: { detail: "the server does not answer: " + e.message } };
  }
  let data = null;
  const text = await res.text();
  try { data = text ? JSON.parse(text) : null; } catch (_) { data = { detail: text }; }
  return { ok: res.ok, status: res.status, data };
}

const kN = (n) => (n === null || n === undefined ? "–" : (n / 1000).toFixed(2) + " kN");
const fmt = (v, digits = 3) => {
  if (v === null || v === undefined) return "–";
  if (typeof v !== "number") return String(v);
  if (v !== 0 && (Math.abs(v) >= 1e5 || Math.abs(v) < 1e-3)) return v.toExponential(2);
  return Number(v.toPrecision(digits + 1)).toString();
};
const pct = (v) => (v === null || v === undefined ? "–" : (100 * v).toFixed(1) + " %");
const seconds = (s) => {
  if (s === null || s === undefined || !isFinite(s)) return "–";
  if (s < 1) return s.toPrecision(2) + " s";
  if (s < 90) return s.toFixed(1) + " s";
  if (s < 5400) return (s / 60).toFixed(1) + " min";
  return (s / 3600).toFixed(1) + " h";
};
const modeName = (m) => {
  if (!m) return "–";
  if (m.kind === "diamond") return `diamond, ${m.lobes} lobes`;
  return m.kind.replace("_", " ");
};
// Short names of the fields most often swept, as the design page writes them.
const SHORT = {
  "discretization.particles_through_thickness": "n", "tube.thickness_mm": "t", "tube.mean_diameter_mm": "d",
  "tube.length_mm": "l", "loading.plate_speed_m_s": "v", "contact.friction": "μ",
};
const short = (f) => SHORT[f] || f.split(".").pop();
const sweepValues = (j) => Object.entries(j.sweep_values || {}).map(([f, v]) => `${short(f)} = ${v}`).join(", ");
const jobName = (j) => {
  const name = j.label || j.id.slice(0, 8);
  return j.sweep_values ? `${name} (${sweepValues(j)})` : name;
};
const isLive = (status) => status === "queued" || status === "running";

// Things the current view opened (event streams, timers, charts); closed on navigation.
let viewCleanup = [];
function onLeave(f) { viewCleanup.push(f); }
function leaveView() {
  for (const f of viewCleanup) { try { f(); } catch (_) { /* already closed */ } }
  viewCleanup = [];
}

// ---------- charts (uPlot) ----------

const PALETTE = ["#1f5fbf", "#d9480f", "#2b8a3e", "#862e9c", "#c92a2a", "#0b7285", "#e67700", "#5c940d", "#364fc7", "#a61e4d"];

function lineChart(container, { xLabel, yLabel, names, log }) {
  const width = Math.max(320, container.clientWidth || 600);
  const opts = {
    width, height: 320,
    scales: { x: { time: false, distr: log ? 3 : 1 }, y: { distr: log ? 3 : 1 } },
    axes: [{ label: xLabel }, { label: yLabel }],
    series: [{ label: xLabel }].concat(names.map((n, i) => ({
      label: n, stroke: PALETTE[i % PALETTE.length], width: 2, spanGaps: true,
      points: { show: log },
    }))),
    legend: { live: false },
  };
  const data = [[]].concat(names.map(() => []));
  const chart = new uPlot(opts, data, container);
  const set = (d) => {
    chart.setData(d);
    container.dataset.points = String(d[0].length);
  };
  container.dataset.points = "0";
  container.dataset.series = String(names.length);
  onLeave(() => chart.destroy());
  return { chart, set };
}

/// Several (x, y) series on one x axis: the union of the x values, nulls elsewhere.
function align(seriesList) {
  const xs = [...new Set(seriesList.flatMap((s) => s.map((p) => p[0])))].sort((a, b) => a - b);
  const index = new Map(xs.map((x, i) => [x, i]));
  const data = [xs];
  for (const s of seriesList) {
    const ys = new Array(xs.length).fill(null);
    for (const [x, y] of s) ys[index.get(x)] = y;
    data.push(ys);
  }
  return data;
}

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
async function refreshJobList() {
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

function startJobList() {
  document.getElementById("job-filter").addEventListener("change", refreshJobList);
  refreshJobList();
  listTimer = setInterval(refreshJobList, 3000);
}

// ---------- the case form ----------

let FIELDS = null;
const fieldId = (f) => "f-" + f.replaceAll(".", "-");

async function loadFields() {
  if (FIELDS) return FIELDS;
  const r = await api("GET", "/v1/case/fields");
  if (!r.ok) throw new Error("could not load the form: " + (r.data && r.data.detail));
  FIELDS = r.data;
  return FIELDS;
}

function inputFor(f) {
  const common = { id: fieldId(f.field), name: f.field, "data-field": f.field, "aria-describedby": "err-" + fieldId(f.field) };
  if (f.kind === "choice") {
    return el("select", common, f.choices.map((c) => el("option", { value: c, selected: c === f.default }, c)));
  }
  if (f.kind === "boolean") {
    return el("input", { ...common, type: "checkbox", checked: f.default === true });
  }
  if (f.kind === "text") {
    return el("input", { ...common, type: "text", maxlength: "200", value: f.default || "" });
  }
  return el("input", {
    ...common, type: "number", step: f.kind === "integer" ? "1" : "any",
    min: f.min, max: f.max, required: !f.optional,
    value: f.default === null || f.default === undefined ? "" : String(f.default),
    placeholder: f.optional ? "auto" : null,
  });
}

/// What the browser can tell about one field on its own; "" when nothing is wrong.
function clientCheck(f, input) {
  if (f.kind === "choice" || f.kind === "boolean") return "";
  const raw = input.value.trim();
  if (f.kind === "text") return raw.length > 200 ? "must be at most 200 characters" : "";
  if (raw === "") return f.optional ? "" : "is required";
  const v = Number(raw);
  if (!Number.isFinite(v) || input.validity.badInput) return "must be a number";
  if (f.kind === "integer" && !Number.isInteger(v)) return "must be an integer";
  if (f.min !== undefined && (f.min_exclusive ? v <= f.min : v < f.min)) {
    return `must be ${f.min_exclusive ? ">" : ">="} ${f.min}`;
  }
  if (f.max !== undefined && (f.max_exclusive ? v >= f.max : v > f.max)) {
    return `must be ${f.max_exclusive ? "<" : "<="} ${f.max}`;
  }
  return "";
}

function showFieldError(field, message, source) {
  const row = document.querySelector(`.field[data-row="${field}"]`);
  const target = row ? row.querySelector(".err") : document.getElementById("form-error");
  if (!target) return;
  if (row) {
    row.classList.toggle("invalid", !!message);
    const input = row.querySelector("input, select");
    if (input) input.setAttribute("aria-invalid", message ? "true" : "false");
  }
  target.textContent = message ? `${row ? "" : field + " "}${message}` : "";
  target.dataset.source = message ? source : "";
}

function clearErrors(source) {
  for (const e of document.querySelectorAll(".field .err")) {
    if (!source || e.dataset.source === source) {
      e.textContent = "";
      e.dataset.source = "";
      e.closest(".field").classList.remove("invalid");
    }
  }
  const general = document.getElementById("form-error");
  if (general) general.textContent = "";
}

/// Server problems (RFC 9457) beside their fields; returns how many were shown.
function showProblem(data) {
  clearErrors("server");
  if (!data) return 0;
  let shown = 0;
  const errors = data.errors || (data.field ? [{ field: data.field, reason: data.detail }] : []);
  for (const e of errors) {
    const field = e.field.replace(/^base\./, "").replace(/^parameters(\..*)?$/, "parameters");
    const row = document.querySelector(`.field[data-row="${field}"]`);
    if (row && row.querySelector(".err").dataset.source === "client") continue;
    showFieldError(field, e.reason, "server");
    shown++;
  }
  if (!errors.length) {
    document.getElementById("form-error").textContent = data.detail || "the server refused the case";
    shown++;
  }
  return shown;
}

function readCase() {
  const c = {};
  for (const f of FIELDS) {
    const input = document.getElementById(fieldId(f.field));
    let v;
    if (f.kind === "boolean") v = input.checked;
    else if (f.kind === "choice") v = input.value;
    else if (f.kind === "text") { v = input.value.trim(); if (!v) continue; }
    else { if (input.value.trim() === "") continue; v = Number(input.value); }
    const parts = f.field.split(".");
    let at = c;
    for (const p of parts.slice(0, -1)) at = at[p] = at[p] || {};
    at[parts[parts.length - 1]] = v;
  }
  return c;
}

function checkAll() {
  let first = null;
  for (const f of FIELDS) {
    const input = document.getElementById(fieldId(f.field));
    const message = clientCheck(f, input);
    const err = document.querySelector(`.field[data-row="${f.field}"] .err`);
    if (message) showFieldError(f.field, message, "client");
    else if (err.dataset.source === "client") showFieldError(f.field, "", "");
    if (message && !first) first = input;
  }
  return first;
}

let estimateTimer = null;
let estimateSeq = 0;
function scheduleEstimate() {
  clearTimeout(estimateTimer);
  estimateTimer = setTimeout(async () => {
    const out = document.getElementById("estimate");
    if (!out) return;
    if (checkAll()) { out.textContent = ""; return; }
    const seq = ++estimateSeq;
    const r = await api("POST", "/v1/estimate", readCase());
    if (seq !== estimateSeq || !document.getElementById("estimate")) return;
    if (r.ok) {
      showProblem(null);
      const e = r.data;
      out.textContent = `${e.particles.toLocaleString()} particles, ${e.steps.toLocaleString()} steps, ` +
        `about ${seconds(e.wall_time_s)} on ${e.threads} thread${e.threads === 1 ? "" : "s"}, ` +
        `${(e.memory_bytes / 2 ** 20).toFixed(0)} MiB`;
    } else {
      out.textContent = "";
      showProblem(r.data);
    }
  }, 350);
}

async function renderForm(main) {
  const fields = await loadFields();
  const groups = new Map();
  for (const f of fields) {
    const g = f.field.includes(".") ? f.field.split(".")[0] : "case";
    if (!groups.has(g)) groups.set(g, []);
    groups.get(g).push(f);
  }
  const numeric = fields.filter((f) => f.kind === "number" || f.kind === "integer");
  const form = el("form", { id: "case-form", novalidate: true },
    [...groups].map(([g, fs]) => el("fieldset", {}, el("legend", {}, g),
      fs.map((f) => el("div", { class: "field", "data-row": f.field },
        el("label", { for: fieldId(f.field), title: f.field }, f.label),
        inputFor(f),
        el("span", { class: "unit" }, f.unit),
        el("span", { class: "hint" },
          f.default === null || f.default === undefined ? "" : `default ${f.default}`,
          f.help ? (f.default === null || f.default === undefined ? "" : " · ") + f.help : ""),
        el("div", { class: "err", id: "err-" + fieldId(f.field), role: "alert", "data-source": "" }))))),
    el("fieldset", {}, el("legend", {}, "sweep (optional)"),
      el("div", { class: "field", "data-row": "parameters" },
        el("label", { for: "sweep-field" }, "Vary this field"),
        el("select", { id: "sweep-field" }, el("option", { value: "" }, "(no sweep)"),
          numeric.map((f) => el("option", { value: f.field }, f.field))),
        el("span"),
        el("span", { class: "hint" }, "One job per value. Varying discretization.particles_through_thickness gives the convergence view."),
        el("div", { class: "err", "data-source": "" })),
      el("div", { class: "field" },
        el("label", { for: "sweep-values" }, "Values"),
        el("input", { id: "sweep-values", type: "text", placeholder: "e.g. 2, 3, 4" }),
        el("span"), el("span", { class: "hint" }, "Comma-separated numbers."))),
    el("div", { class: "actions" },
      el("button", { type: "submit", id: "submit" }, "Run"),
      el("button", { type: "button", class: "secondary", id: "reset", onclick: () => renderRoute() }, "Defaults"),
      el("span", { id: "estimate" })),
    el("p", { class: "form-error", id: "form-error" }));
  main.replaceChildren(el("h1", {}, "New crush case"),
    el("p", { class: "muted" }, "Every field shows its unit and default. The browser checks each value as you type; the server checks the whole case and its cost."),
    form);
  form.addEventListener("input", (e) => {
    const name = e.target.dataset.field;
    const f = name && FIELDS.find((x) => x.field === name);
    if (f) {
      const message = clientCheck(f, e.target);
      showFieldError(f.field, message, message ? "client" : "");
    }
    scheduleEstimate();
  });
  form.addEventListener("submit", submitForm);
  scheduleEstimate();
}

async function submitForm(e) {
  e.preventDefault();
  const button = document.getElementById("submit");
  const first = checkAll();
  if (first) { first.focus(); return; }
  const c = readCase();
  const sweepField = document.getElementById("sweep-field").value;
  button.disabled = true;
  try {
    if (sweepField) {
      const raw = document.getElementById("sweep-values").value.split(",").map((s) => s.trim()).filter(Boolean);
      const values = raw.map(Number);
      if (!values.length || values.some((v) => !Number.isFinite(v))) {
        showFieldError("parameters", "give the values as comma-separated numbers", "client");
        return;
      }
      const body = { base: c, parameters: { [sweepField]: values } };
      if (c.label) body.label = c.label;
      const r = await api("POST", "/v1/sweeps", body);
      if (r.ok) { location.hash = `#/sweeps/${r.data.id}`; refreshJobList(); }
      else showProblem(r.data);
    } else {
      const r = await api("POST", "/v1/jobs", c);
      if (r.ok) { location.hash = `#/jobs/${r.data.id}`; refreshJobList(); }
      else showProblem(r.data);
    }
  } finally {
    button.disabled = false;
  }
}

// ---------- job view ----------

function summaryTable(s) {
  const rows = [
    ["Mean collapse load", kN(s.mean_load_n)],
    ["Peak load", kN(s.peak_load_n)],
    ["Energy absorbed", fmt(s.energy_absorbed_mj / 1000) + " J"],
    ["Crush distance", fmt(s.crush_distance_mm) + " mm"],
    ["Collapse mode", modeName(s.mode)],
    ["Folds (load drops)", s.folds],
    ["Energy-balance error", pct(s.energy_balance_error)],
    ["Particles", s.cost.particles.toLocaleString()],
    ["Steps", s.cost.steps.toLocaleString()],
    ["Δt", `${fmt(s.cost.dt_min_ms * 1000)} – ${fmt(s.cost.dt_max_ms * 1000)} µs`],
    ["Wall time", seconds(s.cost.wall_time_s) + ` (${fmt(s.cost.particle_steps_per_s / 1e6)} M particle-steps/s, ${s.cost.threads} threads)`],
  ];
  return el("table", { id: "summary" }, el("tbody", {}, rows.map(([k, v]) => el("tr", {}, el("th", {}, k), el("td", { class: "num" }, v)))));
}

function referenceTable(s, lateral) {
  const r = s.references;
  const mean = s.mean_load_n;
  const row = (name, value, primary) => {
    const ratio = value > 0 ? mean / value : null;
    const cls = ratio === null ? "" : Math.abs(ratio - 1) <= 0.25 ? "good" : "off";
    return el("tr", {}, el("td", {}, name, primary ? el("strong", {}, " (primary)") : ""),
      el("td", { class: "num" }, value > 0 ? kN(value) : "–"),
      el("td", { class: "num ratio " + cls }, ratio === null ? "–" : ratio.toFixed(2)));
  };
  // Only the references of this loading: a lateral formula says nothing of an axial run.
  const rows = lateral
    ? [
      row("DeRuntz & Hodge (1963), mean over the crush", r.deruntz_hodge_mean_n || 0, true),
      row("DeRuntz & Hodge (1963), at first contact", r.deruntz_hodge_initial_n, false),
    ]
    : [
      row("Alexander (1960), ring", r.alexander_ring_n, true),
      ...r.diamond.map((d) => row(`Johnson et al. (1977), diamond n = ${d.lobes}`, d.travelling_n, false)),
      row("Euler, clamped ends (global buckling)", r.euler_clamped_n, false),
    ];
  return el("table", { id: "references" },
    el("thead", {}, el("tr", {}, el("th", {}, "closed-form reference"), el("th", { class: "num" }, "load"), el("th", { class: "num" }, "run mean / reference"))),
    el("tbody", {}, rows));
}

/// The case's main numbers, defaults filled in from the form's field list.
function caseTable(c) {
  const value = (field) => {
    let v = c;
    for (const p of field.split(".")) v = v === undefined || v === null ? undefined : v[p];
    if (v !== undefined) return v;
    const f = (FIELDS || []).find((x) => x.field === field);
    return f ? f.default : undefined;
  };
  const rows = [
    ["Tube t × d × l", `${value("tube.thickness_mm")} × ${value("tube.mean_diameter_mm")} × ${value("tube.length_mm")} mm`],
    ["Material", `E ${value("material.youngs_modulus_mpa")} MPa, ν ${value("material.poisson_ratio")}, σy ${value("material.yield_stress_mpa")} MPa`],
    ["Loading", `${value("loading.mode")}, ${value("loading.plate_speed_m_s")} m/s, ` +
      (value("loading.crush_distance_mm") === null || value("loading.crush_distance_mm") === undefined ? "default distance" : `${value("loading.crush_distance_mm")} mm`)],
    ["Particles through the wall", `${value("discretization.particles_through_thickness")} (${value("discretization.shape")})`],
    ["Trigger", `${value("trigger.weak_fraction")} weak`],
  ];
  return el("table", { id: "case-table" }, el("tbody", {}, rows.map(([k, v]) => el("tr", {}, el("th", {}, k), el("td", {}, v)))));
}

async function renderJob(main, id) {
  await loadFields().catch(() => null);
  const r = await api("GET", `/v1/jobs/${id}`);
  if (!r.ok) { main.replaceChildren(el("h1", {}, "Job not found"), el("p", {}, r.data && r.data.detail)); return; }
  let job = r.data;
  const status = el("span", { class: "badge " + job.status, id: "job-status" }, job.status);
  const bar = el("progress", { id: "job-progress", max: "1", value: String(job.status === "succeeded" ? 1 : (job.progress && job.progress.fraction) || 0) });
  const barText = el("span", { id: "job-progress-text", class: "muted" });
  const cancel = el("button", { class: "secondary", id: "cancel", onclick: async () => {
    const c = await api("POST", `/v1/jobs/${id}/cancel`);
    if (!c.ok) barText.textContent = c.data.detail;
  } }, "Cancel");
  const chartBox = el("div", { class: "chart", id: "curve" });
  const side = el("div", { id: "job-side" });
  const below = el("div", { id: "job-below" });
  main.replaceChildren(
    el("div", { class: "job-head" }, el("h1", {}, jobName(job)), status, bar, barText, isLive(job.status) ? cancel : null),
    el("p", { class: "muted small" }, `job ${job.id} · ${job.particles.toLocaleString()} particles · submitted ${job.created_at}`,
      job.sweep_id ? el("span", {}, " · ", el("a", { href: `#/sweeps/${job.sweep_id}` }, "its sweep")) : null),
    el("div", { class: "grid2" }, el("div", {}, el("h2", {}, "Load against plate travel"), chartBox), side),
    below);
  side.replaceChildren(el("h2", {}, "Case"), caseTable(job.case || {}));
  const { set } = lineChart(chartBox, { xLabel: "plate travel, mm", yLabel: "load, kN", names: ["moving plate, kN", "fixed plate, kN"] });
  const live = [[], [], []]; // the fixed plate's load comes with the stored history only
  let redraw = null;
  onLeave(() => clearTimeout(redraw));
  const showProgress = (p) => {
    bar.value = p.fraction;
    barText.textContent = `${Math.round(100 * p.fraction)} % · step ${p.step.toLocaleString()} · ` +
      `${fmt(p.displacement_mm)} mm · ${kN(p.load_n)} · ${seconds(p.elapsed_s)} elapsed, ${seconds(p.eta_s)} to go`;
  };
  const finish = async () => {
    const j = await api("GET", `/v1/jobs/${id}`);
    if (!j.ok) return;
    job = j.data;
    status.className = "badge " + job.status;
    status.textContent = job.status;
    cancel.remove();
    clearTimeout(redraw);
    redraw = -1; // no more live redraws
    if (job.status === "succeeded") {
      bar.value = 1;
      barText.textContent = "done";
      await showResult(job, set, side, below);
    } else {
      barText.textContent = job.error || job.status;
    }
  };
  if (isLive(job.status)) {
    if (job.progress) showProgress(job.progress);
    const es = new EventSource(`/v1/jobs/${id}/events`);
    onLeave(() => es.close());
    es.addEventListener("status", (e) => {
      const s = JSON.parse(e.data);
      if (s.status) { status.textContent = s.status; status.className = "badge " + s.status; }
    });
    es.addEventListener("progress", (e) => {
      const p = JSON.parse(e.data);
      if (typeof p.fraction !== "number") return;
      showProgress(p);
      const n = live[0].length;
      if (n && p.displacement_mm <= live[0][n - 1]) return; // a restarted attempt
      live[0].push(p.displacement_mm);
      live[1].push(p.load_n / 1000);
      live[2].push(null);
      // Redraw at most four times a second, whatever the history's resolution.
      if (!redraw) redraw = setTimeout(() => { redraw = null; set(live); }, 250);
    });
    for (const end of ["done", "failed", "cancelled"]) {
      es.addEventListener(end, () => { es.close(); finish(); });
    }
    // A stream the server refused (too many open, say) is not retried by the browser: poll.
    es.onerror = () => {
      if (es.readyState !== EventSource.CLOSED) return;
      const poll = setInterval(async () => {
        const j = await api("GET", `/v1/jobs/${id}`);
        if (!j.ok) return;
        if (j.data.progress) showProgress(j.data.progress);
        if (!isLive(j.data.status)) { clearInterval(poll); finish(); }
      }, 2000);
      onLeave(() => clearInterval(poll));
    };
  } else {
    await finish();
  }
}

async function showResult(job, set, side, below) {
  const h = await api("GET", `/v1/jobs/${job.id}/history`);
  if (h.ok) {
    const u = h.data.columns.indexOf("displacement_mm");
    const p = h.data.columns.indexOf("load_top_n");
    const b = h.data.columns.indexOf("load_bottom_n");
    set([h.data.rows.map((r) => r[u]), h.data.rows.map((r) => r[p] / 1000), h.data.rows.map((r) => r[b] / 1000)]);
  }
  const s = job.summary;
  const lateral = !!(job.case && job.case.loading && job.case.loading.mode === "lateral");
  side.replaceChildren(el("h2", {}, "Summary"), summaryTable(s), el("h2", {}, "Against closed-form references"),
    referenceTable(s, lateral),
    el("p", { class: "small muted" }, "Green: within 25 % of the reference.",
      lateral ? "" : " Diamond loads are Johnson's travelling-hinge form."),
    el("h2", {}, "Case"), caseTable(job.case || {}));
  const keepsState = !(job.case && job.case.output && job.case.output.final_state === false);
  below.replaceChildren(
    el("h2", {}, "Deformed tube, coloured by plastic strain"),
    keepsState
      ? el("div", { class: "shape" }, el("img", {
        id: "shape", src: job.links.shape, alt: "final shape of the tube: side, oblique and section views",
        onerror: async (e) => {
          const r = await api("GET", job.links.shape);
          e.target.replaceWith(el("p", { class: "muted" }, (r.data && r.data.detail) || "No picture."));
        },
      }))
      : el("p", { class: "muted" }, "This case did not keep its final state (output.final_state = false)."),
    el("h2", {}, "Downloads"),
    el("p", { class: "downloads" },
      el("a", { href: job.links.history + "?format=csv", download: `${job.id}-history.csv` }, "history (CSV)"),
      el("a", { href: job.links.summary, download: `${job.id}-summary.json` }, "summary (JSON)"),
      keepsState ? el("a", { href: job.links.state, download: `${job.id}.vtu` }, "final particle state (VTU, ParaView)") : null,
      el("a", { href: job.links.plot, download: `${job.id}-load.svg` }, "load curve (SVG)")),
    el("details", {}, el("summary", {}, "Case as submitted"), el("pre", {}, JSON.stringify(job.case, null, 2))));
}

// ---------- sweep view (and convergence) ----------

const historyCache = new Map();
async function historyOf(id) {
  if (historyCache.has(id)) return historyCache.get(id);
  const h = await api("GET", `/v1/jobs/${id}/history`);
  if (!h.ok) return null;
  const u = h.data.columns.indexOf("displacement_mm");
  const p = h.data.columns.indexOf("load_top_n");
  const pts = h.data.rows.map((r) => [r[u], r[p] / 1000]);
  historyCache.set(id, pts);
  return pts;
}

function cell(column, value) {
  if (column === "job_id") return el("td", {}, el("a", { href: `#/jobs/${value}` }, String(value).slice(0, 8)));
  if (column === "status") return el("td", {}, el("span", { class: "badge " + value }, value));
  if (value === null || value === undefined) return el("td", { class: "num" }, "–");
  if (column.endsWith("_n")) return el("td", { class: "num" }, kN(value));
  if (column.endsWith("_mj")) return el("td", { class: "num" }, fmt(value / 1000) + " J");
  if (column.includes("error") || column === "mean_vs_reference") return el("td", { class: "num" }, pct(value));
  if (column === "wall_time_s") return el("td", { class: "num" }, seconds(value));
  if (column === "mode") return el("td", {}, value);
  return el("td", { class: "num" }, typeof value === "number" ? fmt(value) : String(value));
}

async function renderSweep(main, id) {
  const first = await api("GET", `/v1/sweeps/${id}`);
  if (!first.ok) { main.replaceChildren(el("h1", {}, "Sweep not found"), el("p", {}, first.data && first.data.detail)); return; }
  const fields = first.data.parameters.map((p) => p[0]);
  const curveBox = el("div", { class: "chart", id: "sweep-curves" });
  const tableBox = el("div", { id: "sweep-table" });
  const convBox = el("div", { id: "convergence" });
  const countsText = el("span", { class: "muted", id: "sweep-counts" });
  main.replaceChildren(
    el("div", { class: "job-head" }, el("h1", {}, first.data.label || `Sweep ${id.slice(0, 8)}`), countsText),
    el("p", { class: "muted small" }, `varies ${fields.join(", ")} · sweep ${id}`),
    el("h2", {}, "Load curves"), curveBox, el("h2", {}, "Runs"), tableBox, convBox);
  const rowName = (row) => fields.map((f) => `${short(f)} = ${row[f]}`).join(", ");
  let chart = null;
  let drawn = "";
  let convChart = null;
  let timer = null;
  const update = async () => {
    const r = await api("GET", `/v1/sweeps/${id}`);
    if (!r.ok || !document.body.contains(curveBox)) return;
    const v = r.data;
    countsText.textContent = Object.entries(v.counts).filter(([, n]) => n).map(([s, n]) => `${n} ${s}`).join(" · ");
    tableBox.replaceChildren(el("div", { class: "scroll" }, el("table", {},
      el("thead", {}, el("tr", {}, v.columns.map((c) => el("th", {}, c.replaceAll("_", " "))))),
      el("tbody", {}, v.rows.map((row) => el("tr", {}, v.columns.map((c) => cell(c, row[c]))))))));
    const done = v.rows.filter((row) => row.status === "succeeded");
    const key = done.map((row) => row.job_id).join();
    if (key && key !== drawn) {
      drawn = key;
      const curves = await Promise.all(done.map((row) => historyOf(row.job_id)));
      if (chart) chart.chart.destroy();
      curveBox.replaceChildren();
      chart = lineChart(curveBox, { xLabel: "plate travel, mm", yLabel: "load, kN", names: done.map(rowName) });
      chart.set(align(curves.map((c) => c || [])));
      if (v.convergence) convChart = renderConvergence(convBox, v.convergence, convChart);
    }
    if (v.rows.some((row) => isLive(row.status))) timer = setTimeout(update, 2000);
  };
  onLeave(() => clearTimeout(timer));
  await update();
}

function renderConvergence(box, groups, old) {
  if (old) old.chart.destroy();
  const series = [];
  const names = [];
  for (const g of groups) {
    const label = g.group ? ` (${g.group})` : "";
    const finest = g.rows.filter((r) => r.mean_error_vs_finest !== 0).map((r) => [r.wall_time_s, Math.abs(r.mean_error_vs_finest) * 100]);
    const rich = g.rows.filter((r) => r.mean_error_vs_richardson !== null).map((r) => [r.wall_time_s, Math.abs(r.mean_error_vs_richardson) * 100]);
    if (finest.length) { series.push(finest); names.push("vs finest run, %" + label); }
    if (rich.length) { series.push(rich); names.push("vs Richardson extrapolation, %" + label); }
  }
  const chartBox = el("div", { class: "chart", id: "convergence-chart" });
  const tables = groups.map((g) => {
    const ex = g.mean_extrapolation;
    return el("div", {},
      g.group ? el("h3", {}, g.group) : null,
      el("table", {},
        el("thead", {}, el("tr", {}, ["n", "particles", "steps", "wall time", "mean load", "error vs finest", "error vs Richardson", "vs reference"].map((c) => el("th", {}, c)))),
        el("tbody", {}, g.rows.map((r) => el("tr", {},
          el("td", { class: "num" }, r.n), el("td", { class: "num" }, r.particles.toLocaleString()),
          el("td", { class: "num" }, r.steps.toLocaleString()), el("td", { class: "num" }, seconds(r.wall_time_s)),
          el("td", { class: "num" }, kN(r.mean_load_n)), el("td", { class: "num" }, pct(r.mean_error_vs_finest)),
          el("td", { class: "num" }, pct(r.mean_error_vs_richardson)), el("td", { class: "num" }, pct(r.mean_vs_reference)))))),
      el("p", { class: "small muted" }, ex
        ? `Richardson extrapolation of the mean load: ${kN(ex.value)}, observed order p = ${fmt(ex.order)}` + (ex.trustworthy ? "." : " — not trusted (not monotone, or p outside [0.5, 4]); errors are against the finest run.")
        : g.rows.length < 3
          ? "Too few resolutions for a Richardson extrapolation (it needs three)."
          : "No Richardson extrapolation: the three finest runs do not converge monotonically. Errors are against the finest run."));
  });
  box.replaceChildren(el("h2", {}, "Convergence: error against run time"), chartBox, ...tables);
  if (!series.length) { chartBox.append(el("p", { class: "muted" }, "Needs at least two succeeded resolutions.")); return null; }
  const c = lineChart(chartBox, { xLabel: "wall time, s", yLabel: "mean-load error, %", names, log: true });
  c.set(align(series));
  return c;
}

// ---------- routing ----------

async function renderRoute() {
  leaveView();
  const main = document.getElementById("main");
  const hash = location.hash || "#/";
  let m;
  try {
    if ((m = hash.match(/^#\/jobs\/([0-9a-f-]{36})$/))) await renderJob(main, m[1]);
    else if ((m = hash.match(/^#\/sweeps\/([0-9a-f-]{36})$/))) await renderSweep(main, m[1]);
    else await renderForm(main);
  } catch (e) {
    main.replaceChildren(el("h1", {}, "Something went wrong"), el("p", {}, String(e)));
  }
  document.body.dataset.view = (hash.split("/")[1] || "form");
}

window.addEventListener("hashchange", renderRoute);
startJobList();
renderRoute();
