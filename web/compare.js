// crush web page: the overlay of any picked jobs' load curves (from any sweeps or none), with
// their key numbers, and the overlay as CSV or SVG to download (both made here, in the page).
import { align, api, colour, download, el, fmt, jobName, kN, lineChart, setPicked } from "./util.js";

/// The load on the moving plate against its travel, kN against mm, from a stored history.
async function curve(id) {
  const h = await api("GET", `/v1/jobs/${id}/history`);
  if (!h.ok) return null;
  const u = h.data.columns.indexOf("displacement_mm");
  const p = h.data.columns.indexOf("load_top_n");
  return h.data.rows.map((r) => [r[u], r[p] / 1000]);
}

/// The overlay as CSV: plate travel, then each job's load in kN (empty where it has no point).
function overlayCsv(names, data) {
  const quote = (s) => `"${String(s).replaceAll('"', '""')}"`;
  const head = ["displacement_mm", ...names.map((n) => quote(`${n} load_top_kn`))].join(",");
  const rows = data[0].map((x, i) => [x, ...data.slice(1).map((ys) => (ys[i] === null ? "" : ys[i]))].join(","));
  return [head, ...rows].join("\n") + "\n";
}

/// Round steps for an axis from `lo` to `hi`: about `n` of them, at 1, 2 or 5 × 10^k.
function ticks(lo, hi, n) {
  const raw = (hi - lo) / n;
  const decade = 10 ** Math.floor(Math.log10(raw));
  const step = [1, 2, 5, 10].map((m) => m * decade).find((s) => s >= raw) || raw;
  const out = [];
  for (let v = Math.ceil(lo / step) * step; v <= hi + step * 1e-9; v += step) out.push(Number(v.toPrecision(12)));
  return out;
}

/// The overlay as an SVG document: axes with round ticks, one line per job, and a legend under
/// the plot (inside it, it would hide some job's curve).
function overlaySvg(names, curves) {
  const [W, L, R, T, B, ROW] = [900, 70, 20, 20, 60, 18];
  const H = 560 + ROW * names.length + 10;
  const bottom = 560; // of the plot and its axis labels
  const pts = curves.flat();
  const xs = pts.map((p) => p[0]);
  const ys = pts.map((p) => p[1]);
  const [x0, x1] = [Math.min(0, ...xs), Math.max(...xs)];
  const [y0, y1] = [Math.min(0, ...ys), Math.max(...ys) * 1.05];
  const sx = (x) => L + ((x - x0) / (x1 - x0 || 1)) * (W - L - R);
  const sy = (y) => bottom - B - ((y - y0) / (y1 - y0 || 1)) * (bottom - T - B);
  const esc = (s) => String(s).replace(/[<>&"]/g, (c) => ({ "<": "&lt;", ">": "&gt;", "&": "&amp;", '"': "&quot;" })[c]);
  const out = [`<svg xmlns="http://www.w3.org/2000/svg" width="${W}" height="${H}" viewBox="0 0 ${W} ${H}" font-family="sans-serif" font-size="13">`,
    `<rect width="${W}" height="${H}" fill="white"/>`];
  for (const x of ticks(x0, x1, 8)) {
    out.push(`<line x1="${sx(x)}" y1="${T}" x2="${sx(x)}" y2="${bottom - B}" stroke="#e3e6eb"/>`,
      `<text x="${sx(x)}" y="${bottom - B + 18}" text-anchor="middle">${fmt(x)}</text>`);
  }
  for (const y of ticks(y0, y1, 6)) {
    out.push(`<line x1="${L}" y1="${sy(y)}" x2="${W - R}" y2="${sy(y)}" stroke="#e3e6eb"/>`,
      `<text x="${L - 8}" y="${sy(y) + 4}" text-anchor="end">${fmt(y)}</text>`);
  }
  out.push(`<rect x="${L}" y="${T}" width="${W - L - R}" height="${bottom - T - B}" fill="none" stroke="#888"/>`,
    `<text x="${(L + W - R) / 2}" y="${bottom - 14}" text-anchor="middle">plate travel, mm</text>`,
    `<text transform="translate(18 ${(T + bottom - B) / 2}) rotate(-90)" text-anchor="middle">load on the moving plate, kN</text>`);
  curves.forEach((c, i) => {
    const line = c.map(([x, y]) => `${sx(x).toFixed(1)},${sy(y).toFixed(1)}`).join(" ");
    out.push(`<polyline fill="none" stroke="${colour(i)}" stroke-width="2" points="${line}"/>`);
    const ly = bottom + ROW * (i + 1);
    out.push(`<line class="legend" x1="${L}" y1="${ly - 4}" x2="${L + 24}" y2="${ly - 4}" stroke="${colour(i)}" stroke-width="3"/>`,
      `<text class="legend" x="${L + 30}" y="${ly}">${esc(names[i])}</text>`);
  });
  out.push("</svg>");
  return out.join("\n") + "\n";
}

export async function renderCompare(main, list) {
  const ids = [...new Set(list.split(","))].filter((id) => /^[0-9a-f-]{36}$/.test(id));
  setPicked(ids);
  const jobs = (await Promise.all(ids.map((id) => api("GET", `/v1/jobs/${id}`)))).filter((r) => r.ok).map((r) => r.data);
  const done = jobs.filter((j) => j.status === "succeeded");
  const chartBox = el("div", { class: "chart", id: "overlay-curves" });
  const links = el("p", { class: "downloads", id: "overlay-downloads" });
  main.replaceChildren(el("h1", {}, `Overlay of ${done.length} job${done.length === 1 ? "" : "s"}`),
    el("p", { class: "muted small" }, "Pick jobs with the boxes in the job list, from any sweep or none."),
    chartBox, links, el("div", { class: "scroll" }, el("table", { id: "overlay-table" },
      el("thead", {}, el("tr", {}, ["job", "mean load", "peak load", "energy absorbed", "mode", "particles"].map((h) => el("th", {}, h)))),
      el("tbody", {}, done.map((j, i) => el("tr", {},
        el("td", {}, el("span", { class: "swatch", "data-colour": i }), el("a", { href: `#/jobs/${j.id}` }, jobName(j))),
        el("td", { class: "num" }, kN(j.summary.mean_load_n)), el("td", { class: "num" }, kN(j.summary.peak_load_n)),
        el("td", { class: "num" }, fmt(j.summary.energy_absorbed_mj / 1000) + " J"),
        el("td", {}, j.summary.mode.kind), el("td", { class: "num" }, j.summary.cost.particles.toLocaleString())))))));
  // Colours by class, not inline style (the content security policy allows no inline style).
  main.querySelectorAll(".swatch").forEach((s) => s.classList.add("c" + (Number(s.dataset.colour) % 10)));
  const skipped = jobs.length - done.length + (ids.length - jobs.length);
  if (skipped) main.insertBefore(el("p", { class: "muted small" }, `${skipped} picked job${skipped === 1 ? " has" : "s have"} no curve (not succeeded, or gone).`), chartBox);
  if (!done.length) return;
  const curves = (await Promise.all(done.map((j) => curve(j.id)))).map((c) => c || []);
  const names = done.map(jobName);
  const chart = lineChart(chartBox, { xLabel: "plate travel, mm", yLabel: "load, kN", names });
  const data = align(curves);
  chart.set(data);
  links.replaceChildren(
    download(overlayCsv(names, data), "text/csv", "overlay.csv", "overlay (CSV)", "overlay-csv"),
    download(overlaySvg(names, curves), "image/svg+xml", "overlay.svg", "overlay (SVG)", "overlay-svg"));
}
