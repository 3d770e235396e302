// crush web page: small helpers — DOM building, the API, number formats, the view's cleanup list, uPlot charts.
// ---------- small helpers ----------

export function el(tag, attrs, ...kids) {
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

// Every request but a GET carries a JSON body (`{}` when it has nothing to say): the server
// takes no other, so that a plain HTML form on another site cannot act on it.
export async function api(method, path, body) {
  const init = { method, headers: { Accept: "application/json" } };
  if (method !== "GET") {
    init.headers["Content-Type"] = "application/json";
    init.body = JSON.stringify(body === undefined ? {} : body);
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
  if (res.status === 401) askForToken();
  return { ok: res.ok, status: res.status, data };
}

// ---------- the token (servers with --token-file) ----------

// Shows the sign-in bar once, however many requests were refused. The token goes to
// POST /v1/session, which keeps it in an HttpOnly cookie: event streams, pictures and download
// links send that cookie, and no script can read it back.
export function askForToken() {
  const form = document.getElementById("signin");
  if (!form.hidden) return;
  form.hidden = false;
  document.getElementById("token-input").focus();
}

export function setUpSession() {
  const form = document.getElementById("signin");
  form.addEventListener("submit", async (e) => {
    e.preventDefault();
    const input = document.getElementById("token-input");
    const r = await api("POST", "/v1/session", { token: input.value.trim() });
    if (r.ok) { location.reload(); return; }
    document.getElementById("signin-error").textContent = (r.data && r.data.detail) || "refused";
  });
  api("GET", "/v1/session").then((r) => {
    if (!r.ok || !r.data.name) return;
    const forget = el("a", { href: "#", id: "forget-token", onclick: async (e) => {
      e.preventDefault();
      await api("DELETE", "/v1/session");
      location.reload();
    } }, "forget token");
    document.getElementById("session").replaceChildren(`${r.data.name} (${r.data.role}) · `, forget);
  });
}

export const kN = (n) => (n === null || n === undefined ? "–" : (n / 1000).toFixed(2) + " kN");
export const fmt = (v, digits = 3) => {
  if (v === null || v === undefined) return "–";
  if (typeof v !== "number") return String(v);
  if (v !== 0 && (Math.abs(v) >= 1e5 || Math.abs(v) < 1e-3)) return v.toExponential(2);
  return Number(v.toPrecision(digits + 1)).toString();
};
export const pct = (v) => (v === null || v === undefined ? "–" : (100 * v).toFixed(1) + " %");
export const seconds = (s) => {
  if (s === null || s === undefined || !isFinite(s)) return "–";
  if (s < 1) return s.toPrecision(2) + " s";
  if (s < 90) return s.toFixed(1) + " s";
  if (s < 5400) return (s / 60).toFixed(1) + " min";
  return (s / 3600).toFixed(1) + " h";
};
export const modeName = (m) => {
  if (!m) return "–";
  if (m.kind === "diamond") return `diamond, ${m.lobes} lobes`;
  return m.kind.replace("_", " ");
};
// A verdict's level in words.
export const verdictName = (level) => ({ trusted: "trusted", caution: "caution", not_trusted: "not trusted" })[level] || level;
// A verdict as a badge and its reasons, each with its rule and level ([] when trusted).
export const verdictBox = (v, id) => {
  if (!v) return null;
  return el("div", { class: "verdict", id },
    el("span", { class: "badge " + v.level, "data-level": v.level }, verdictName(v.level)),
    v.reasons.length
      ? el("ul", { class: "reasons" }, v.reasons.map((r) => el("li", { "data-rule": r.rule },
        el("strong", {}, `${verdictName(r.level)} · ${r.rule.replaceAll("_", " ")}: `), r.detail)))
      : el("span", { class: "small muted" }, " no rule found a reason to doubt this result"));
};
// Short names of the fields most often swept, as the design page writes them.
const SHORT = {
  "discretization.particles_through_thickness": "n", "tube.thickness_mm": "t", "tube.mean_diameter_mm": "d",
  "tube.length_mm": "l", "loading.plate_speed_m_s": "v", "contact.friction": "μ",
};
export const short = (f) => SHORT[f] || f.split(".").pop();
// A case field's unit, read off its name as the case spells units (`tube.thickness_mm`: mm);
// "" for a count or a ratio.
const FIELD_UNITS = [["_m_s", "m/s"], ["_mpa", "MPa"], ["_mm", "mm"], ["_kg_m3", "kg/m³"], ["_per_s", "1/s"]];
export const fieldUnit = (f) => (FIELD_UNITS.find(([suffix]) => f.endsWith(suffix)) || ["", ""])[1];
// A swept field's value as a sweep names its runs: "t = 2 mm", "n = 3".
export const fieldValue = (f, v) => `${short(f)} = ${v}${fieldUnit(f) ? " " + fieldUnit(f) : ""}`;
export const sweepValues = (j) => Object.entries(j.sweep_values || {}).map(([f, v]) => fieldValue(f, v)).join(", ");
export const jobName = (j) => {
  const name = j.label || j.id.slice(0, 8);
  return j.sweep_values ? `${name} (${sweepValues(j)})` : name;
};
export const isLive = (status) => status === "queued" || status === "running";

// A server timestamp (RFC 3339, UTC) in the browser's local time with its offset from UTC,
// "2026-11-29 01:08 UTC+5:30": read against the lab's clock, and unambiguous when pasted into a
// log or sent to another site. Absolute rather than relative ("3 min ago"), which would go
// stale on a page that is not redrawn. The UTC original is the element's tooltip.
export function localTime(iso) {
  const t = new Date(iso);
  if (!iso || Number.isNaN(t.getTime())) return el("time", {}, iso || "–");
  const two = (n) => String(n).padStart(2, "0");
  const east = -t.getTimezoneOffset();
  const zone = east === 0 ? "UTC"
    : `UTC${east > 0 ? "+" : "−"}${Math.floor(Math.abs(east) / 60)}${Math.abs(east) % 60 ? ":" + two(Math.abs(east) % 60) : ""}`;
  const text = `${t.getFullYear()}-${two(t.getMonth() + 1)}-${two(t.getDate())} ${two(t.getHours())}:${two(t.getMinutes())} ${zone}`;
  return el("time", { datetime: iso, title: `${iso} (UTC)` }, text);
}

// A sweep-table column as a header: its name without the unit suffix, and the unit the cell
// shows (loads in kN, energies in J, as the cells are written).
const COLUMN_UNITS = [["_m_s", "m/s"], ["_mpa", "MPa"], ["_mm", "mm"], ["_mj", "J"], ["_j_per_g", "J/g"], ["_g", "g"], ["_n", "kN"], ["_s", ""]];
const COLUMN_NAMES = {
  job_id: "job", mean_vs_reference: "mean / reference − 1", particle_steps_per_s: "particle-steps/s",
  first_peak_load_n: "first peak, kN", crush_force_efficiency: "CFE",
  specific_energy_absorption_j_per_g: "SEA, J/g", mean_load_after_first_peak_n: "mean after first peak, kN",
};
export function columnLabel(c) {
  if (COLUMN_NAMES[c]) return COLUMN_NAMES[c];
  const unit = COLUMN_UNITS.find(([suffix]) => c.endsWith(suffix));
  const bare = c.includes(".") ? short(c)
    : (unit ? c.slice(0, -unit[0].length) : c).replaceAll("_", " ");
  return unit && unit[1] ? `${bare}, ${unit[1]}` : bare;
}

// The jobs picked in the list for an overlay, kept for the browser tab's life.
const PICKED = "crush-picked";
export function picked() {
  try { return JSON.parse(sessionStorage.getItem(PICKED) || "[]"); } catch (_) { return []; }
}
export function setPicked(ids) { sessionStorage.setItem(PICKED, JSON.stringify(ids)); }

// A file made in the page (CSV, SVG), offered as a download link.
export function download(text, type, name, label, id) {
  const url = URL.createObjectURL(new Blob([text], { type }));
  onLeave(() => URL.revokeObjectURL(url));
  return el("a", { href: url, download: name, id }, label);
}

// Things the current view opened (event streams, timers, charts); closed on navigation.
let viewCleanup = [];
export function onLeave(f) { viewCleanup.push(f); }
export function leaveView() {
  for (const f of viewCleanup) { try { f(); } catch (_) { /* already closed */ } }
  viewCleanup = [];
}

// ---------- charts (uPlot) ----------

const PALETTE = ["#1f5fbf", "#d9480f", "#2b8a3e", "#862e9c", "#c92a2a", "#0b7285", "#e67700", "#5c940d", "#364fc7", "#a61e4d"];

export const colour = (i) => PALETTE[i % PALETTE.length];

// The page's own colours (they follow the system's dark mode), for what uPlot draws itself.
function themed() {
  const css = getComputedStyle(document.documentElement);
  const fg = css.getPropertyValue("--fg").trim() || "#1d2430";
  const grid = css.getPropertyValue("--line").trim() || "#d9dee7";
  return { stroke: fg, grid: { stroke: grid, width: 1 }, ticks: { stroke: grid, width: 1 } };
}

/// A dashed horizontal line, as a series of `lineChart` (its data: the level at the first and
/// last x, nulls between).
export const levelSeries = (label) => ({ label, dash: [8, 5], width: 1.5 });
/// One marked point, as a series of `lineChart` (its data: null but at the point).
export const markSeries = (label, fill) => ({ label, paths: () => null, points: { show: true, size: 11, width: 2, fill } });

/// A chart's size in a box `width` px wide: as wide as the box (a phone's too), never wider,
/// for the page must not scroll sideways; half as tall, within 240–420 px.
function chartSize(width) {
  const w = Math.max(200, width || 600);
  return { width: w, height: w < 500 ? 240 : Math.min(420, Math.round(w * 0.5)) };
}

/// A uPlot line chart filling `container`'s width, and following it when the window is resized
/// or a phone turned; `names` are the series' labels, or their uPlot options (see
/// `levelSeries`, `markSeries`). Its legend sits below the plot, where it hides no part of a
/// curve.
export function lineChart(container, { xLabel, yLabel, names, log }) {
  const axis = themed();
  const opts = {
    ...chartSize(container.clientWidth),
    scales: { x: { time: false, distr: log ? 3 : 1 }, y: { distr: log ? 3 : 1 } },
    axes: [{ label: xLabel, ...axis }, { label: yLabel, ...axis }],
    series: [{ label: xLabel }].concat(names.map((n, i) => ({
      stroke: colour(i), width: 2, spanGaps: true, points: { show: log },
      ...(typeof n === "string" ? { label: n } : n),
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
  // The box's width is the layout's, not the chart's: a new height does not call this again.
  // Resized on the next frame, not inside the observer's callback, where a change of layout
  // would be an error of the page ("ResizeObserver loop completed ...").
  let live = true;
  const resized = new ResizeObserver(() => requestAnimationFrame(() => {
    const size = chartSize(container.clientWidth);
    if (live && size.width !== chart.width) chart.setSize(size);
  }));
  resized.observe(container);
  onLeave(() => {
    live = false;
    resized.disconnect();
    chart.destroy();
  });
  return { chart, set };
}

/// Several (x, y) series on one x axis: the union of the x values, nulls elsewhere.
export function align(seriesList) {
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
