// crush web page: a case form built from GET /v1/case/fields, live lists of jobs (SSE) and
// sweeps with a label search, a job view (live load curve, summary against the closed-form
// references, deformed-tube picture, downloads, run again, delete), a sweep view (overlaid
// curves, table, convergence: error against run time) and an overlay of any picked jobs.
// Plain JavaScript; the one library is uPlot, served by this server like everything else.
import { leaveView, el, setUpSession } from "./util.js";
import { startJobList } from "./list.js";
import { renderForm } from "./form.js";
import { renderJob } from "./job.js";
import { renderSweep } from "./sweep.js";
import { renderCompare } from "./compare.js";

// Uncaught errors, kept where a test (or a curious user's console) can read them.
window.__errors = [];
window.addEventListener("error", (e) => window.__errors.push(String(e.message)));
window.addEventListener("unhandledrejection", (e) => window.__errors.push(String(e.reason)));
// Anything the content security policy blocked (the server sends one with every answer).
document.addEventListener("securitypolicyviolation", (e) =>
  window.__errors.push(`CSP blocked ${e.blockedURI || "inline"} (${e.violatedDirective})`));

// ---------- routing ----------

async function renderRoute() {
  leaveView();
  const main = document.getElementById("main");
  const hash = location.hash || "#/";
  let m;
  try {
    if ((m = hash.match(/^#\/jobs\/([0-9a-f-]{36})$/))) await renderJob(main, m[1]);
    else if ((m = hash.match(/^#\/sweeps\/([0-9a-f-]{36})$/))) await renderSweep(main, m[1]);
    else if ((m = hash.match(/^#\/new\/([0-9a-f-]{36})$/))) await renderForm(main, m[1]);
    else if ((m = hash.match(/^#\/compare\/([0-9a-f,-]+)$/))) await renderCompare(main, m[1]);
    else await renderForm(main);
  } catch (e) {
    main.replaceChildren(el("h1", {}, "Something went wrong"), el("p", {}, String(e)));
  }
  document.body.dataset.view = (hash.split("/")[1] || "form");
}

window.addEventListener("hashchange", renderRoute);
setUpSession();
startJobList();
renderRoute();
