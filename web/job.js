// crush web page: one job — live load curve, summary against the closed-form references, the case, the deformed tube, downloads; run it again or delete it.
import { align, api, colour, el, fmt, isLive, jobName, kN, levelSeries, lineChart, localTime, markSeries, modeName, onLeave, pct, seconds, verdictBox } from "./util.js";
import { loadFields } from "./form.js";
import { refreshJobList } from "./list.js";

// ---------- job view ----------

function summaryTable(s) {
  const rows = [
    ["Mean collapse load", kN(s.mean_load_n)],
    ...(s.error_bar ? [["Error bar (mean load)", errorBarText(s.error_bar)]] : []),
    ...(s.error_bar && s.error_bar.first_peak ? [["Error bar (first peak)", peakBarText(s.error_bar.first_peak)]] : []),
    ...(s.expected_error ? [["Expected error (mean load)", el("span", { id: "expected-error", title: s.expected_error.basis },
      s.expected_error.percent == null ? s.expected_error.basis : `±${s.expected_error.percent.toFixed(1)} % (${s.expected_error.basis})`)]] : []),
    ["Peak load (largest, whole crush)", kN(s.peak_load_n)],
    ["First collapse peak", s.first_peak_load_n == null ? "– (the load never drops)" : `${kN(s.first_peak_load_n)} at ${fmt(s.first_peak_displacement_mm)} mm`],
    ["Mean load after it", s.mean_load_after_first_peak_n == null ? "–" : kN(s.mean_load_after_first_peak_n)],
    ["Crush-force efficiency", s.crush_force_efficiency == null ? "–" : fmt(s.crush_force_efficiency)],
    ["Energy absorbed", fmt(s.energy_absorbed_mj / 1000) + " J"],
    ["Dissipated (plastic + friction)", s.energy_dissipated_mj == null ? "–" : fmt(s.energy_dissipated_mj / 1000) + " J"],
    ["Tube mass", s.tube_mass_g == null ? "–" : fmt(s.tube_mass_g) + " g"],
    ["Specific energy absorption", s.specific_energy_absorption_j_per_g == null ? "–" : fmt(s.specific_energy_absorption_j_per_g) + " J/g"],
    ["Crush distance", fmt(s.crush_distance_mm) + " mm"],
    ["Collapse mode", modeName(s.mode)],
    ["Folds (from the shape)", s.folds],
    ["Load drops", s.load_drops ?? "–"],
    ["Energy-balance error", pct(s.energy_balance_error)],
    ["Shape functions", s.shape ? (s.shape.default_reason || s.shape.kind) : "–"],
    ["Particles", s.cost.particles.toLocaleString()],
    ["Steps", s.cost.steps.toLocaleString()],
    ["Δt", `${fmt(s.cost.dt_min_ms * 1000)} – ${fmt(s.cost.dt_max_ms * 1000)} µs`],
    ["Wall time", seconds(s.cost.wall_time_s) + ` (${fmt(s.cost.particle_steps_per_s / 1e6)} M particle-steps/s, ${s.cost.threads} threads)`],
  ];
  return el("table", { id: "summary" }, el("tbody", {}, rows.map(([k, v]) => el("tr", {}, el("th", {}, k), el("td", { class: "num" }, v)))));
}

// The mean load's error bar: where the converged load lies and so how far off this run is.
function errorBarText(b) {
  if (b.basis !== "reduced_ladder" && b.basis !== "three_d_ladder") return el("span", { id: "error-bar", class: "small" }, `none: ${b.why}`);
  const p = (x) => (x === null || x === undefined ? "?" : `${x >= 0 ? "+" : ""}${(100 * x).toFixed(1)} %`);
  const ns = b.rungs.map((r) => r.n).join(", ");
  const from = b.basis === "three_d_ladder" ? `from 3D runs of this case at n = ${ns}` : `from its ${b.model.replace("_", " ")} section at n = ${ns}`;
  return el("span", { id: "error-bar", title: b.covers },
    `converged ${kN(b.low_n)} – ${kN(b.high_n)}; this run ${p(b.error)} (${p(b.error_low)} to ${p(b.error_high)}), ` +
    `${from} (${seconds(b.cost_s)})`);
}

// The first collapse peak's error bar, from the same ladder.
function peakBarText(p) {
  const sign = (x) => `${x >= 0 ? "+" : ""}${(100 * x).toFixed(1)} %`;
  return el("span", { id: "peak-error-bar" },
    `converged ${kN(p.low_n)} – ${kN(p.high_n)}; this run ${sign(p.error)}`);
}

// Where the plates' work went (summary.energy, absent in summaries stored before it existed).
function energyTable(s) {
  const e = s.energy;
  if (!e) return el("p", { class: "small muted" }, "This run's summary has no energy books.");
  const work = e.work_top_mj + e.work_bottom_mj;
  const rows = [
    ["Work of the moving plate", e.work_top_mj],
    ["Work of the fixed plate", e.work_bottom_mj],
    ["Kinetic energy", e.kinetic_mj],
    ["Elastic energy", e.elastic_mj],
    ["Plastic work", e.plastic_mj],
    ["Friction", e.friction_mj],
    ["Contact (nodes caught by a plate)", e.contact_mj],
    ["Residual (numerical error)", e.residual_mj],
  ];
  return el("table", { id: "energy" }, el("tbody", {}, rows.map(([k, v]) => el("tr", {}, el("th", {}, k),
    el("td", { class: "num" }, fmt(v / 1000) + " J"),
    el("td", { class: "num" }, work > 0 ? pct(v / work) : "–")))));
}

/// Each cross-section's closed-form rows, by the case's `tube.section`: `row(name, load, primary)`.
const REFERENCE_ROWS = {
  round: (r, lateral, row) => lateral
    // Only the references of this loading: a lateral formula says nothing of an axial run.
    ? [
      row("DeRuntz & Hodge (1963), mean over the crush", r.deruntz_hodge_mean_n || 0, true),
      row("DeRuntz & Hodge (1963), at first contact", r.deruntz_hodge_initial_n, false),
    ]
    : [
      row("Alexander (1960), ring", r.alexander_ring_n, true),
      ...r.diamond.map((d) => row(`Johnson et al. (1977), diamond n = ${d.lobes}`, d.travelling_n, false)),
      row("Euler, clamped ends (global buckling)", r.euler_clamped_n, false),
    ],
  // A rectangular tube's own closed forms (axial only; none covers a lateral crush).
  rectangular: (r, lateral, row) => lateral
    ? [el("tr", {}, el("td", { colspan: "3" }, "no closed form covers a rectangular tube crushed laterally"))]
    : [
      row("Abramowicz & Jones (1984), effective crushing distance" +
        (r.abramowicz_jones_dynamic_n ? `, × ${r.rate_factor.toFixed(2)} for the strain rate` : ""), r.primary_n, true),
      row("Wierzbicki & Abramowicz (1983), superfolding element", r.wierzbicki_abramowicz_n, false),
      row("Euler, clamped ends (global bending)", r.euler_clamped_n, false),
    ],
  // A hexagonal tube has no folding closed form here: Euler's load and the squash load alone.
  hexagonal: (r, lateral, row) => lateral
    ? [el("tr", {}, el("td", { colspan: "3" }, "no closed form covers a hexagonal tube crushed laterally"))]
    : [
      el("tr", {}, el("td", { colspan: "3" }, "no folding closed form is given for a hexagonal tube")),
      row("Squash load σ0·A (the whole wall yielding)", r.squash_n, false),
      row("Euler, clamped ends (global bending)", r.euler_clamped_n, false),
    ],
};

function referenceTable(s, lateral, section) {
  const r = s.references;
  const mean = s.mean_load_n;
  const row = (name, value, primary) => {
    const ratio = value > 0 ? mean / value : null;
    const cls = ratio === null ? "" : Math.abs(ratio - 1) <= 0.25 ? "good" : "off";
    return el("tr", {}, el("td", {}, name, primary ? el("strong", {}, " (primary)") : ""),
      el("td", { class: "num" }, value > 0 ? kN(value) : "–"),
      el("td", { class: "num ratio " + cls }, ratio === null ? "–" : ratio.toFixed(2)));
  };
  const rows = (REFERENCE_ROWS[section] || REFERENCE_ROWS.round)(r, lateral, row);
  return el("table", { id: "references" },
    el("thead", {}, el("tr", {}, el("th", {}, "closed-form reference"), el("th", { class: "num" }, "load"), el("th", { class: "num" }, "run mean / reference"))),
    el("tbody", {}, rows));
}

/// The form's field list, for the defaults of what a case leaves out.
let fields = [];

/// The shape functions a case names, or what the code chose (or will choose: `estimated`, from
/// POST /v1/estimate while the job waits or runs) when it left them out.
function shapeText(named, summary, estimated) {
  if (named !== null && named !== undefined) return named;
  const chosen = (summary && summary.shape && summary.shape.kind) || estimated;
  return chosen ? `${chosen}, chosen by the code` : "chosen by the code";
}

/// How far the plates travel when a case leaves `loading.crush_distance_mm` out, mm (the
/// field's help says the same).
const DEFAULT_CRUSH_MM = { axial: 50, lateral: 12.5 };

/// Material presets by name, as an engineer writes them.
const PRESET_NAMES = { pvc: "PVC", aa6060_t5: "AA6060-T5", aa6061_t6: "AA6061-T6", mild_steel: "mild steel", stainless_304: "stainless steel 304" };
const presetName = (p) => PRESET_NAMES[p] || p.replaceAll("_", " ");

/// The material in words: the preset the case names, else the preset whose values it has
/// (the default material is the paper's PVC), else "custom".
function materialName(c, value) {
  const named = c.material && c.material.preset;
  if (named) return `${presetName(named)} (preset)`;
  const material = fields.filter((f) => f.field.startsWith("material.") && f.presets);
  const names = [...new Set(material.flatMap((f) => Object.keys(f.presets)))];
  const same = names.find((p) => material.every((f) => !(p in f.presets) || f.presets[p] === value(f.field)));
  return same ? presetName(same) : "custom";
}

/// The case's main numbers, each as the case gives it or, where it leaves one out, the value
/// the server uses, said to be the default; `summary` (once the job succeeded) or `estimated`
/// says which shape functions the code chose for a case that left them out.
/// Each cross-section's row of the case table, from the case's values.
const TUBE_ROW = {
  round: (value) => ["Tube t × d × l",
    `${value("tube.thickness_mm")} × ${value("tube.mean_diameter_mm")} × ${value("tube.length_mm")} mm`],
  rectangular: (value) => ["Tube t × a × b × l, corner r",
    `${value("tube.thickness_mm")} × ${value("tube.side_a_mm")} × ` +
    `${value("tube.side_b_mm") ?? value("tube.side_a_mm")} × ${value("tube.length_mm")} mm, ` +
    `r ${value("tube.corner_radius_mm") ?? value("tube.thickness_mm")} mm`],
  hexagonal: (value) => ["Tube t × hexagon side s × l, corner r",
    `${value("tube.thickness_mm")} × ${value("tube.side_mm")} × ${value("tube.length_mm")} mm, ` +
    `r ${value("tube.corner_radius_mm") ?? value("tube.thickness_mm")} mm`],
};

function caseTable(c, summary, estimated) {
  const given = (field) => {
    let v = c;
    for (const p of field.split(".")) v = v === undefined || v === null ? undefined : v[p];
    return v === null ? undefined : v;
  };
  // A material field a case leaves out comes from its preset, else from the default material.
  const preset = given("material.preset");
  const value = (field) => {
    const v = given(field);
    if (v !== undefined) return v;
    const f = fields.find((x) => x.field === field);
    if (f && preset && f.presets && preset in f.presets) return f.presets[preset];
    return f ? f.default : undefined;
  };
  const orDefault = (field, unit) => given(field) !== undefined ? `${given(field)}${unit}` : `${value(field)}${unit} (default)`;
  const mode = value("loading.mode");
  const distance = given("loading.crush_distance_mm") !== undefined
    ? `${given("loading.crush_distance_mm")} mm`
    : (DEFAULT_CRUSH_MM[mode] === undefined ? "the default distance" : `${DEFAULT_CRUSH_MM[mode]} mm (default)`);
  const density = value("material.density_kg_m3");
  const rows = [
    (TUBE_ROW[value("tube.section")] || TUBE_ROW.round)(value),
    ["Material", el("span", { id: "material-name" }, materialName(c, value)),
      `: ${value("material.model")}, E ${value("material.youngs_modulus_mpa")} MPa, ν ${value("material.poisson_ratio")}, ` +
      `σy ${value("material.yield_stress_mpa")} MPa` + (density === undefined ? "" : `, ρ ${density} kg/m³`)],
    ["Loading", `${mode}, ${value("loading.plate_speed_m_s")} m/s`],
    ["Crush distance", el("span", { id: "crush-distance" }, distance)],
    ["Particles through the wall n", el("span", { id: "case-n" }, orDefault("discretization.particles_through_thickness", ""))],
    ["Shape functions", shapeText(given("discretization.shape"), summary, estimated)],
    ["Model", orDefault("discretization.model", "")],
    ["Trigger", `${value("trigger.weak_fraction")} weak`],
  ];
  return el("table", { id: "case-table" }, el("tbody", {}, rows.map(([k, ...v]) => el("tr", {}, el("th", {}, k), el("td", {}, ...v)))));
}

export async function renderJob(main, id) {
  fields = (await loadFields().catch(() => null)) || [];
  const r = await api("GET", `/v1/jobs/${id}`);
  if (!r.ok) { main.replaceChildren(el("h1", {}, r.status === 401 ? "Sign in to see this job" : "Job not found"), el("p", {}, r.data && r.data.detail)); return; }
  let job = r.data;
  const status = el("span", { class: "badge " + job.status, id: "job-status" }, job.status);
  const bar = el("progress", { id: "job-progress", max: "1", value: String(job.status === "succeeded" ? 1 : (job.progress && job.progress.fraction) || 0) });
  const barText = el("span", { id: "job-progress-text", class: "muted" });
  const cancel = el("button", { class: "secondary", id: "cancel", onclick: async () => {
    const c = await api("POST", `/v1/jobs/${id}/cancel`);
    if (!c.ok) barText.textContent = c.data.detail;
  } }, "Cancel");
  const chartBox = el("div", { class: "chart", id: "curve" });
  const side = el("div", { id: "job-side", class: "panels" });
  const below = el("div", { id: "job-below" });
  const note = el("span", { id: "job-action-note", class: "small" });
  // The same case again, as a new job (its label and every field as submitted).
  const rerun = el("button", { class: "secondary", id: "rerun", onclick: async () => {
    const r = await api("POST", "/v1/jobs", job.case);
    if (r.ok) { location.hash = `#/jobs/${r.data.id}`; refreshJobList(); } else note.textContent = r.data.detail;
  } }, "Run again");
  // A finished job outside a sweep can be deleted: the first click asks, the second deletes.
  const remove = el("button", { class: "secondary danger", id: "delete", onclick: async () => {
    if (remove.dataset.armed !== "yes") {
      remove.dataset.armed = "yes";
      remove.textContent = "Delete for good?";
      return;
    }
    const r = await api("DELETE", `/v1/jobs/${id}`);
    if (r.ok) { location.hash = "#/"; refreshJobList(); } else note.textContent = r.data.detail;
  } }, "Delete");
  const deletable = () => !isLive(job.status) && !job.sweep_id;
  main.replaceChildren(
    el("div", { class: "job-head" }, el("h1", {}, jobName(job)), status, bar, barText, isLive(job.status) ? cancel : null,
      job.case ? rerun : null, deletable() ? remove : null,
      el("a", { href: `#/new/${job.id}`, id: "reuse", class: "small" }, "new case from this one"), note),
    el("p", { class: "muted small", id: "job-meta" }, `job ${job.id} · ${job.particles.toLocaleString()} particles · submitted `,
      localTime(job.created_at), job.node ? ` · node ${job.node}` : "",
      job.sweep_id ? el("span", {}, " · ", el("a", { href: `#/sweeps/${job.sweep_id}` }, "its sweep")) : null),
    el("h2", {}, "Load against plate travel"), chartBox, side, below);
  side.replaceChildren(el("div", {}, el("h2", {}, "Case"), caseTable(job.case || {}, job.summary)));
  // While it waits or runs, the estimate says which shape functions the code will choose.
  if (isLive(job.status) && job.case && !(job.case.discretization && job.case.discretization.shape)) {
    api("POST", "/v1/estimate", job.case).then((e) => {
      const table = document.getElementById("case-table");
      if (e.ok && e.data.shape && table && isLive(job.status)) table.replaceWith(caseTable(job.case, null, e.data.shape.kind));
    });
  }
  const live = lineChart(chartBox, { xLabel: "plate travel, mm", yLabel: "load, kN", names: ["moving plate, kN", "fixed plate, kN"] });
  const set = live.set;
  const points = [[], [], []]; // the fixed plate's load comes with the stored history only
  let redraw = null;
  let ended = false;
  onLeave(() => clearTimeout(redraw));
  const showProgress = (p) => {
    const r = p.error_bar;
    if (r) { // the crush is done; its error bar's ladder runs
      bar.value = r.fraction;
      barText.textContent = `crush done · pricing the error bar: rung ${r.rung} of ${r.rungs} (n = ${r.n}), ` +
        `${Math.round(100 * r.fraction)} % of its crush`;
      return;
    }
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
    if (deletable() && !remove.isConnected) rerun.after(remove);
    clearTimeout(redraw);
    ended = true; // the stored history replaces the live curve
    if (job.status === "succeeded") {
      bar.value = 1;
      barText.textContent = "done";
      await showResult(job, live, chartBox, side, below);
    } else {
      barText.textContent = job.error || job.status;
      if (job.verdict) side.prepend(el("div", {}, el("h2", {}, "Verdict"), verdictBox(job.verdict, "verdict")));
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
      if (p.error_bar) return; // a rung of the ladder, not a point of this run's curve
      const n = points[0].length;
      if (n && p.displacement_mm <= points[0][n - 1]) points.forEach((a) => { a.length = 0; }); // a new attempt
      points[0].push(p.displacement_mm);
      points[1].push(p.load_n / 1000);
      points[2].push(null);
      // Redraw at most four times a second, whatever the history's resolution.
      if (!redraw && !ended) redraw = setTimeout(() => { redraw = null; set(points); }, 250);
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

/// The finished run's load curve: both plates, the mean load as a dashed line across it and the
/// first collapse peak marked (each named in the legend, with its value).
function resultChart(chartBox, h, s) {
  const u = h.data.columns.indexOf("displacement_mm");
  const p = h.data.columns.indexOf("load_top_n");
  const b = h.data.columns.indexOf("load_bottom_n");
  const rows = h.data.rows;
  const names = ["moving plate, kN", "fixed plate, kN"];
  const curves = [rows.map((r) => [r[u], r[p] / 1000]), rows.map((r) => [r[u], r[b] / 1000])];
  if (s.mean_load_n != null && rows.length) {
    names.push(levelSeries(`mean load ${kN(s.mean_load_n)}`));
    curves.push([[rows[0][u], s.mean_load_n / 1000], [rows[rows.length - 1][u], s.mean_load_n / 1000]]);
  }
  if (s.first_peak_load_n != null) {
    names.push(markSeries(`first peak ${kN(s.first_peak_load_n)} at ${fmt(s.first_peak_displacement_mm)} mm`, colour(names.length)));
    curves.push([[s.first_peak_displacement_mm, s.first_peak_load_n / 1000]]);
  }
  chartBox.replaceChildren();
  lineChart(chartBox, { xLabel: "plate travel, mm", yLabel: "load, kN", names }).set(align(curves));
}

async function showResult(job, live, chartBox, side, below) {
  const s = job.summary;
  const h = await api("GET", `/v1/jobs/${job.id}/history`);
  if (h.ok) {
    live.chart.destroy();
    resultChart(chartBox, h, s);
  }
  const lateral = !!(job.case && job.case.loading && job.case.loading.mode === "lateral");
  const section = (job.case && job.case.tube && job.case.tube.section) || "round";
  side.replaceChildren(
    el("div", {}, el("h2", {}, "Verdict"), verdictBox(job.verdict || s.verdict, "verdict") ||
      el("p", { class: "small muted", id: "verdict" }, "This result was stored before there were verdicts."),
    el("h2", {}, "Summary"), summaryTable(s)),
    el("div", {}, el("h2", {}, "Case"), caseTable(job.case || {}, s),
      el("h2", {}, "Energy books"), energyTable(s),
      el("h2", {}, "Against closed-form references"),
      referenceTable(s, lateral, section),
      el("p", { class: "small muted" }, "Green: within 25 % of the reference.",
        lateral ? "" : " Diamond loads are Johnson's travelling-hinge form.")));
  const keepsState = !(job.case && job.case.output && job.case.output.final_state === false);
  const keepsSeries = Boolean(job.case && job.case.output && job.case.output.frames > 0);
  const energyBox = el("div", { class: "chart", id: "energy-curve" });
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
    el("h2", {}, "Energy against plate travel"), energyBox,
    el("h2", {}, "Downloads"),
    el("p", { class: "downloads" },
      el("a", { href: job.links.history + "?format=csv", download: `${job.id}-history.csv` }, "history (CSV)"),
      el("a", { href: job.links.summary, download: `${job.id}-summary.json` }, "summary (JSON)"),
      keepsState ? el("a", { href: job.links.shape, download: `${job.id}-shape.png`, id: "shape-png" }, "deformed tube (PNG)") : null,
      keepsState ? el("a", { href: job.links.state, download: `${job.id}.vtu` }, "final particle state (VTU, ParaView)") : null,
      keepsSeries ? el("a", { href: job.links.self + "/series.tar", download: `${job.id}-series.tar` }, "time series (series.pvd and frames, tar, ParaView)") : null,
      el("a", { href: job.links.plot, download: `${job.id}-load.svg` }, "load curve (SVG)")),
    el("details", {}, el("summary", {}, "Case as submitted"), el("pre", {}, JSON.stringify(job.case, null, 2))));
  // The plates' work and what the wall dissipated of it (plastic work + friction), J.
  const at = (n) => (h.ok ? h.data.columns.indexOf(n) : -1);
  const [u, w, pl, fr] = ["displacement_mm", "external_mj", "plastic_mj", "friction_mj"].map(at);
  if ([u, w, pl, fr].every((i) => i >= 0)) {
    const rows = h.data.rows;
    lineChart(energyBox, { xLabel: "plate travel, mm", yLabel: "energy, J", names: ["work of the plates, J", "dissipated: plastic + friction, J"] })
      .set([rows.map((r) => r[u]), rows.map((r) => r[w] / 1000), rows.map((r) => (r[pl] + r[fr]) / 1000)]);
  } else {
    energyBox.replaceChildren(el("p", { class: "muted" }, "No energy history."));
  }
}
