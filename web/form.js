// crush web page: the case form, built from GET /v1/case/fields; the browser checks each field, the server the whole case (POST /v1/estimate) and how to run it (POST /v1/plan), and refusals show beside their fields.
import { api, el, seconds, verdictName } from "./util.js";
import { refreshJobList } from "./list.js";

// ---------- the case form ----------

let FIELDS = null;
const fieldId = (f) => "f-" + f.replaceAll(".", "-");

export async function loadFields() {
  if (FIELDS) return FIELDS;
  const r = await api("GET", "/v1/case/fields");
  if (!r.ok) throw new Error("could not load the form: " + (r.data && r.data.detail));
  FIELDS = r.data;
  return FIELDS;
}

function inputFor(f) {
  const common = { id: fieldId(f.field), name: f.field, "data-field": f.field, "aria-describedby": "err-" + fieldId(f.field) };
  if (f.kind === "choice") {
    // An optional choice starts on "auto": the server picks (the estimate line says what).
    const auto = f.optional ? [el("option", { value: "", selected: true }, "auto")] : [];
    return el("select", common, auto.concat(f.choices.map((c) => el("option", { value: c, selected: c === f.default }, c))));
  }
  if (f.kind === "boolean") {
    return el("input", { ...common, type: "checkbox", checked: f.default === true });
  }
  if (f.kind === "text") {
    return el("input", { ...common, type: "text", maxlength: "200", value: f.default || "" });
  }
  // A text box with a numeric keyboard, not type="number": a number box empties itself on
  // letters, so a typo would vanish instead of being named beside the field.
  return el("input", {
    ...common, type: "text", inputmode: f.kind === "integer" ? "numeric" : "decimal", autocomplete: "off",
    "data-kind": f.kind, required: !f.optional,
    value: f.default === null || f.default === undefined ? "" : String(f.default),
    placeholder: f.optional ? "auto" : null,
  });
}

/// A decimal number as a case writes it: digits, an optional point and exponent ("2", "-0.5",
/// "1e-3"); not hexadecimal, "Infinity" or a blank, which `Number` would also read.
const DECIMAL = /^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$/;

/// What the browser can tell about one field on its own; "" when nothing is wrong.
function clientCheck(f, input) {
  if (f.kind === "choice" || f.kind === "boolean") return "";
  const raw = input.value.trim();
  if (f.kind === "text") return raw.length > 200 ? "must be at most 200 characters" : "";
  if (raw === "") return f.optional ? "" : "is required";
  const v = Number(raw);
  if (!DECIMAL.test(raw) || !Number.isFinite(v)) return "not a number";
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

/// The fields that belong to some cross-sections only; the others' rows are hidden and not sent.
const SECTION_ONLY = {
  "tube.mean_diameter_mm": ["round"],
  "tube.side_a_mm": ["rectangular"],
  "tube.side_b_mm": ["rectangular"],
  "tube.corner_radius_mm": ["rectangular", "hexagonal"],
  "tube.side_mm": ["hexagonal"],
};

/// Whether field `f` applies to the section the form names.
function applies(f) {
  const only = SECTION_ONLY[f.field];
  if (!only) return true;
  const section = document.getElementById(fieldId("tube.section"));
  return only.includes((section && section.value) || "round");
}

/// Shows the rows of the named section's fields and hides the others'.
function showSection() {
  for (const f of FIELDS) {
    const row = document.querySelector(`.field[data-row="${f.field}"]`);
    if (row) row.hidden = !applies(f);
  }
}

/// The case the form says: only the fields the user set (typed, picked, or filled from a job),
/// so that what is left out takes the server's default, or the chosen material preset's value
/// rather than the default shown before the preset was picked.
function readCase() {
  const c = {};
  for (const f of FIELDS) {
    if (!applies(f)) continue;
    const input = document.getElementById(fieldId(f.field));
    if (input.dataset.set !== "yes") continue;
    let v;
    if (f.kind === "boolean") v = input.checked;
    else if (f.kind === "choice") { v = input.value; if (!v) continue; }
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
    const message = applies(f) ? clientCheck(f, input) : "";
    const err = document.querySelector(`.field[data-row="${f.field}"] .err`);
    if (message) showFieldError(f.field, message, "client");
    else if (err.dataset.source === "client") showFieldError(f.field, "", "");
    if (message && !first) first = input;
  }
  return first;
}

/// The sweep the form asks for: the field and its values (null when there is none; no values
/// when they do not read as numbers).
function sweepPlan() {
  const field = document.getElementById("sweep-field").value;
  if (!field) return null;
  const raw = document.getElementById("sweep-values").value.split(",").map((x) => x.trim()).filter(Boolean);
  const values = raw.map(Number);
  return { field, values: values.some((v) => !Number.isFinite(v)) ? [] : values };
}

/// The case with one field set (a dotted path).
function withField(c, field, value) {
  const copy = JSON.parse(JSON.stringify(c));
  const parts = field.split(".");
  let at = copy;
  for (const p of parts.slice(0, -1)) at = at[p] = at[p] || {};
  at[parts[parts.length - 1]] = value;
  return copy;
}

/// Most runs of a sweep estimated one by one; a longer sweep is estimated from this many values
/// spread over its list, and the total scaled to all of them.
const MAX_ESTIMATED = 20;

/// The cost of the whole sweep: every run's estimate added up (the cases differ in the swept
/// field), written under the case's own estimate.
async function estimateSweep(base, seq) {
  const out = document.getElementById("sweep-estimate");
  const plan = sweepPlan();
  if (!plan || !plan.values.length) { out.textContent = ""; return; }
  const n = plan.values.length;
  const picks = n <= MAX_ESTIMATED ? plan.values
    : Array.from({ length: MAX_ESTIMATED }, (_, i) => plan.values[Math.round((i * (n - 1)) / (MAX_ESTIMATED - 1))]);
  const answers = await Promise.all(picks.map((v) => api("POST", "/v1/estimate", withField(base, plan.field, v))));
  if (seq !== estimateSeq || !document.getElementById("sweep-estimate")) return;
  const ok = answers.filter((r) => r.ok).map((r) => r.data);
  const refused = answers.length - ok.length;
  if (!ok.length) { out.textContent = `The sweep: no value of ${plan.field} gives a case the server accepts.`; return; }
  const sum = ok.reduce((t, e) => t + e.wall_time_s, 0);
  const total = (sum / ok.length) * n;
  const longest = Math.max(...ok.map((e) => e.wall_time_s));
  const particles = ok.reduce((t, e) => t + e.particles, 0) / ok.length;
  out.textContent = `The sweep: ${n} jobs, about ${seconds(total)} of run time in all ` +
    `(the longest about ${seconds(longest)}; ${Math.round(particles).toLocaleString()} particles on average)` +
    (n > picks.length ? `, from ${picks.length} of its ${n} values` : "") +
    (refused ? `; ${refused} of the values estimated give a case the server refuses` : "") + ".";
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
    const base = readCase();
    estimateSweep(base, seq);
    const r = await api("POST", "/v1/estimate", base);
    if (seq !== estimateSeq || !document.getElementById("estimate")) return;
    if (r.ok) {
      showProblem(null);
      const e = r.data;
      showForeseen(e.verdict);
      showPlan(base, seq);
      out.textContent = `${e.particles.toLocaleString()} particles, ${e.steps.toLocaleString()} steps, ` +
        `about ${seconds(e.wall_time_s)} on ${e.threads} thread${e.threads === 1 ? "" : "s"}, ` +
        `${(e.memory_bytes / 2 ** 20).toFixed(0)} MiB` +
        (e.shape.default_reason ? `; shape functions ${e.shape.default_reason}` : "") +
        (e.reduced ? `. The ${e.reduced.model.replace("_", " ")} model (discretization.model) would take ` +
          `about ${seconds(e.reduced.wall_time_s)}, ${e.reduced.speedup.toFixed(0)}× less; ` +
          `it cannot show ${e.reduced.cannot_show}.` : "");
    } else {
      out.textContent = "";
      document.getElementById("plan").textContent = "";
      showForeseen(null);
      showProblem(r.data);
    }
  }, 350);
}

/// Targets the plan line offers, % error of the mean load.
const PLAN_TARGETS = [5, 10];
/// The reduced model's option the plan line offers: its most accurate within this, s.
const PLAN_REDUCED_S = 60;

/// The planner's answer beside Run (POST /v1/plan): the cheapest run of the case's own model
/// for each target, and the most accurate of its reduced model within a minute, with what it
/// cannot show; e.g. "±5 %: n = 8, about 26.8 min; ±10 %: n = 6, about 8.5 min;
/// axisymmetric n = 16 (±0.4 %), about 1.9 min, rings only".
async function showPlan(base, seq) {
  const out = document.getElementById("plan");
  if (!out) return;
  const r = await api("POST", "/v1/plan", { case: base, target_error_percent: PLAN_TARGETS[0] });
  if (seq !== estimateSeq || !document.getElementById("plan")) return;
  if (!r.ok) { out.textContent = ""; return; }
  const options = r.data.options;
  const own = (base.discretization && base.discretization.model) || "3d";
  const known = options.filter((o) => o.expected_error_percent !== null);
  const parts = [];
  let last = null;
  for (const t of PLAN_TARGETS) {
    const fits = known.filter((o) => o.model === own && o.expected_error_percent <= t);
    const o = fits.sort((a, b) => a.wall_time_s - b.wall_time_s)[0];
    if (!o) { parts.push(`±${t} %: no ${own} run within this server's limits`); continue; }
    if (o === last) continue;
    last = o;
    parts.push(`±${t} %: n = ${o.n}, about ${seconds(o.wall_time_s)}`);
  }
  const reduced = known.filter((o) => o.model !== own && o.wall_time_s <= PLAN_REDUCED_S)
    .sort((a, b) => a.expected_error_percent - b.expected_error_percent)[0];
  if (reduced) {
    parts.push(`${reduced.model.replace("_", " ")} n = ${reduced.n} (±${reduced.expected_error_percent} %), ` +
      `about ${seconds(reduced.wall_time_s)}, ${reduced.shows.split(":")[0]}`);
  }
  const basis = options.some((o) => o.wall_time_basis.source === "measured") ? "times from this server's runs" : "times at assumed rates";
  out.textContent = `Plan (uGIMP, errors of the mean load; ${basis}): ${parts.join("; ")}.`;
  out.title = r.data.error_basis;
}

/// The level the case alone foretells (the estimate's verdict), for the Run button.
let foreseenLevel = "trusted";

/// Warns under the Run button of what will make the result less than trusted, rule by rule.
function showForeseen(v) {
  const box = document.getElementById("foreseen");
  if (!box) return;
  foreseenLevel = v ? v.level : "trusted";
  const button = document.getElementById("submit");
  delete button.dataset.armed;
  button.textContent = "Run";
  box.replaceChildren(...(v && v.reasons.length ? [
    el("span", {}, `Before it runs, this case will come out ${verdictName(v.level)}:`),
    el("ul", {}, v.reasons.map((r) => el("li", { "data-rule": r.rule }, r.detail)))] : []));
}

/// The form, empty (defaults) or filled with the case of job `fromJob`.
export async function renderForm(main, fromJob) {
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
        el("span", { class: "hint" }, "One job per value. Varying discretization.particles_through_thickness gives the convergence view; varying trigger.seed (with a trigger) gives the ensemble: mode counts and the spread of the loads."),
        el("div", { class: "err", "data-source": "" })),
      el("div", { class: "field" },
        el("label", { for: "sweep-values" }, "Values"),
        el("input", { id: "sweep-values", type: "text", placeholder: "e.g. 2, 3, 4" }),
        el("span"), el("span", { class: "hint" }, "Comma-separated numbers."))),
    el("div", { class: "actions" },
      el("button", { type: "submit", id: "submit" }, "Run"),
      el("button", { type: "button", class: "secondary", id: "reset", onclick: () => renderForm(document.getElementById("main")) }, "Defaults"),
      el("span", { id: "estimate" })),
    el("p", { class: "muted", id: "plan", role: "status" }),
    el("p", { class: "muted", id: "sweep-estimate" }),
    el("div", { class: "foreseen", id: "foreseen", role: "status" }),
    el("p", { class: "form-error", id: "form-error" }));
  main.replaceChildren(el("h1", {}, "New crush case"),
    el("p", { class: "muted" }, "Every field shows its unit and default. The browser checks each value as you type; the server checks the whole case and its cost."),
    form);
  form.addEventListener("input", (e) => {
    const name = e.target.dataset.field;
    if (name) e.target.dataset.set = "yes";
    if (name === "material.preset") showPreset(e.target.value);
    const f = name && FIELDS.find((x) => x.field === name);
    if (f) {
      const message = clientCheck(f, e.target);
      showFieldError(f.field, message, message ? "client" : "");
    }
    if (name === "tube.section") showSection();
    scheduleEstimate();
  });
  form.addEventListener("change", (e) => {
    const name = e.target.dataset.field;
    if (name) e.target.dataset.set = "yes";
    if (name === "tube.section") showSection();
    if (name === "material.preset") { showPreset(e.target.value); scheduleEstimate(); }
  });
  form.addEventListener("submit", submitForm);
  if (fromJob) await fillFromJob(fromJob);
  showSection();
  scheduleEstimate();
}

/// Shows in each material field the user has not set the value `preset` fills in (its own
/// default where the preset leaves the field to it); those fields stay unsent.
function showPreset(preset) {
  for (const f of FIELDS) {
    if (!f.field.startsWith("material.") || f.field === "material.preset") continue;
    const input = document.getElementById(fieldId(f.field));
    if (!input || input.dataset.set === "yes" || f.kind === "boolean") continue;
    const v = preset && f.presets && f.presets[preset] !== undefined ? f.presets[preset] : f.default;
    input.value = v === null || v === undefined ? "" : String(v);
  }
}

/// Fills the form with a job's case as submitted; what it left out keeps its default.
async function fillFromJob(id) {
  const r = await api("GET", `/v1/jobs/${id}`);
  const note = document.getElementById("form-error");
  if (!r.ok || !r.data.case) { note.textContent = `Could not read job ${id}: ${r.data && r.data.detail}`; return; }
  for (const f of FIELDS) {
    let v = r.data.case;
    for (const p of f.field.split(".")) v = v === undefined || v === null ? undefined : v[p];
    if (v === undefined) continue;
    const input = document.getElementById(fieldId(f.field));
    if (f.kind === "boolean") input.checked = v === true;
    else input.value = v === null ? "" : String(v);
    input.dataset.set = "yes";
  }
  const preset = document.getElementById(fieldId("material.preset"));
  if (preset) showPreset(preset.value);
  document.querySelector("main h1").textContent = `New crush case, from ${r.data.label || id.slice(0, 8)}`;
}

async function submitForm(e) {
  e.preventDefault();
  const button = document.getElementById("submit");
  const first = checkAll();
  if (first) { first.focus(); return; }
  // A case the verdict will not trust runs on a second click, once the warning has been read.
  if (foreseenLevel === "not_trusted" && button.dataset.armed !== "yes") {
    button.dataset.armed = "yes";
    button.textContent = "Run anyway";
    document.getElementById("foreseen").scrollIntoView({ block: "nearest" });
    return;
  }
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
