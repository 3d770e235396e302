// crush web page: a sweep — its runs' load curves overlaid, its table (and the server's CSV of it), for a resolution sweep the convergence view (error against run time), and for a sweep over trigger seeds the ensemble's distribution.
import { align, api, columnLabel, el, fieldValue, fmt, isLive, kN, lineChart, localTime, modeName, onLeave, pct, seconds, verdictName } from "./util.js";
import { refreshSweepList } from "./list.js";

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
  if (column === "verdict" && value) return el("td", {}, el("span", { class: "badge " + value }, verdictName(value)));
  if (column === "verdict_reasons") return el("td", { class: "small" }, value ? value.replaceAll("_", " ") : "–");
  if (value === null || value === undefined) return el("td", { class: "num" }, "–");
  if (column.endsWith("_n")) return el("td", { class: "num" }, kN(value));
  if (column.endsWith("_mj")) return el("td", { class: "num" }, fmt(value / 1000) + " J");
  if (column.includes("error") || column === "mean_vs_reference") return el("td", { class: "num" }, pct(value));
  if (column === "wall_time_s") return el("td", { class: "num" }, seconds(value));
  if (column === "mode") return el("td", {}, value);
  return el("td", { class: "num" }, typeof value === "number" ? fmt(value) : String(value));
}

/// The columns an engineer compares runs by, first after the job and what the sweep varies, so
/// that they show without scrolling; the rest (cost, checks, reasons) follow in the server's order.
const FIRST_COLUMNS = ["status", "mean_load_n", "first_peak_load_n", "crush_force_efficiency",
  "specific_energy_absorption_j_per_g", "peak_load_n", "energy_absorbed_mj", "mode", "verdict"];

function tableOrder(columns, varied) {
  const first = ["job_id", ...varied, ...FIRST_COLUMNS].filter((c) => columns.includes(c));
  return first.concat(columns.filter((c) => !first.includes(c)));
}

export async function renderSweep(main, id) {
  const first = await api("GET", `/v1/sweeps/${id}`);
  if (!first.ok) { main.replaceChildren(el("h1", {}, "Sweep not found"), el("p", {}, first.data && first.data.detail)); return; }
  const fields = first.data.parameters.map((p) => p[0]);
  const curveBox = el("div", { class: "chart", id: "sweep-curves" });
  const tableBox = el("div", { id: "sweep-table" });
  const convBox = el("div", { id: "convergence" });
  const ensBox = el("div", { id: "ensemble" });
  const countsText = el("span", { class: "muted", id: "sweep-counts" });
  const note = el("span", { class: "small", id: "sweep-action-note" });
  // Once every job has finished, the sweep can be deleted with its jobs: first click asks.
  const remove = el("button", { class: "secondary danger", id: "delete-sweep", hidden: true, onclick: async () => {
    if (remove.dataset.armed !== "yes") {
      remove.dataset.armed = "yes";
      remove.textContent = "Delete the sweep and its jobs for good?";
      return;
    }
    const r = await api("DELETE", `/v1/sweeps/${id}`);
    if (r.ok) { location.hash = "#/"; refreshSweepList(); } else note.textContent = r.data.detail;
  } }, "Delete sweep");
  // The table as the server writes it (GET /v1/sweeps/{id}?format=csv), every column.
  const csv = el("a", { href: `/v1/sweeps/${id}?format=csv`, download: `${id}-sweep.csv`, id: "sweep-csv", class: "button secondary" }, "Table as CSV");
  main.replaceChildren(
    el("div", { class: "job-head" }, el("h1", {}, first.data.label || `Sweep ${id.slice(0, 8)}`), countsText, remove, note),
    el("p", { class: "muted small" }, `varies ${fields.join(", ")} · sweep ${id} · made `, localTime(first.data.created_at)),
    el("h2", {}, "Load curves"), curveBox, ensBox,
    el("div", { class: "section-head" }, el("h2", {}, "Runs"), csv), tableBox, convBox);
  const rowName = (row) => fields.map((f) => fieldValue(f, row[f])).join(", ");
  let chart = null;
  let drawn = "";
  let convChart = null;
  let timer = null;
  const update = async () => {
    const r = await api("GET", `/v1/sweeps/${id}`);
    if (!r.ok || !document.body.contains(curveBox)) return;
    const v = r.data;
    if (v.ensemble) renderEnsemble(ensBox, v.ensemble);
    countsText.textContent = Object.entries(v.counts).filter(([, n]) => n).map(([s, n]) => `${n} ${s}`).join(" · ");
    const columns = tableOrder(v.columns, fields);
    tableBox.replaceChildren(el("div", { class: "scroll" }, el("table", {},
      el("thead", {}, el("tr", {}, columns.map((c) => el("th", { title: c, "data-column": c }, columnLabel(c))))),
      el("tbody", {}, v.rows.map((row) => el("tr", {}, columns.map((c) => cell(c, row[c]))))))));
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
    const live = v.rows.some((row) => isLive(row.status));
    remove.hidden = live;
    if (live) timer = setTimeout(update, 2000);
  };
  onLeave(() => clearTimeout(timer));
  await update();
}

/// An ensemble over seeds: per group, how often each mode came out and how far the loads spread.
function renderEnsemble(box, groups) {
  const spread = (x) => `${kN(x.mean)} ± ${kN(x.sd)} (min ${kN(x.min)}, max ${kN(x.max)})`;
  box.replaceChildren(el("h2", {}, "Ensemble over trigger seeds"), ...groups.map((g) => {
    const d = g.distribution;
    if (!d) return el("p", { class: "muted" }, `${g.group ? g.group + ": " : ""}no run has finished yet (${g.jobs} seeds).`);
    return el("div", { class: "ensemble-group" },
      g.group ? el("h3", {}, g.group) : null,
      el("table", {}, el("tbody", {},
        el("tr", {}, el("th", {}, "Runs finished"), el("td", { class: "num" }, `${d.runs} of ${g.jobs}`)),
        el("tr", {}, el("th", {}, "Collapse modes"), el("td", { class: "modes" },
          d.modes.map((m) => `${modeName(m.mode)}: ${m.runs} (${Math.round(100 * m.share)} %)`).join(" · "))),
        el("tr", {}, el("th", {}, "Mean load"), el("td", { class: "num" }, spread(d.mean_load_n))),
        el("tr", {}, el("th", {}, "Peak load"), el("td", { class: "num" }, spread(d.peak_load_n))),
        el("tr", {}, el("th", {}, "Energy absorbed"), el("td", { class: "num" },
          `${fmt(d.energy_absorbed_mj.mean / 1000)} ± ${fmt(d.energy_absorbed_mj.sd / 1000)} J`)))),
      d.not_trusted_runs ? el("p", { class: "small warn" }, `${d.not_trusted_runs} of these runs are not trusted by their own verdict.`) : null);
  }));
}

/// What the server read off: the cheapest run within 5 % of the best estimate.
function cheapest(g) {
  const c = g.within_5_percent;
  const trusted = g.mean_extrapolation && g.mean_extrapolation.trustworthy;
  const against = trusted ? "the Richardson value" : "the finest run";
  if (!c) return `No run is within 5 % of ${against}: refine further.`;
  return `For 5 % error in the mean load (against ${against}): n = ${c.n}, ${seconds(c.wall_time_s)}.`;
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
          : "No Richardson extrapolation: the three finest runs do not converge monotonically. Errors are against the finest run."),
      el("p", { class: "cheapest" }, cheapest(g)));
  });
  box.replaceChildren(el("h2", {}, "Convergence: error against run time"), chartBox, ...tables);
  if (!series.length) { chartBox.append(el("p", { class: "muted" }, "Needs at least two succeeded resolutions.")); return null; }
  const c = lineChart(chartBox, { xLabel: "wall time, s", yLabel: "mean-load error, %", names, log: true });
  c.set(align(series));
  return c;
}
