//! `crush validate`: runs the validation suite (the seed paper's scenes, the measured tubes)
//! with one progress bar, each scene read back from the cache when its case and the solver are
//! unchanged, and writes the report as `validation.md`, one self-contained `validation.html`
//! and `validation.json`, its figures in `img/validation/`. Exits non-zero when a check leaves
//! its band or a scene stops. `--profile quick --out docs` writes docs/validation.md.

mod cache;
mod html;
mod judge;
mod markdown;
mod measured;
mod report;
mod suite;

use crate::plot::{self, Series};
use crate::solver::analysis::error_bar::Rung;
use crate::solver::{estimate, Case, LadderObserver, Limits, Observer, Progress, Runner, Snapshot};
use anyhow::{bail, Context};
use cache::{Cache, Entry};
use report::{Drawn, Figures, Report, SceneRun};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::time::Instant;
use suite::{Plot, Profile, Scene};

/// Arguments of `crush validate`.
#[derive(Debug, Clone, clap::Args)]
pub struct ValidateArgs {
    /// Which scenes, at which resolutions: ci (under two minutes), quick (under ten minutes on
    /// 2 cores), full (the references' resolutions: hours).
    #[arg(long, value_enum, default_value_t = Profile::Quick)]
    pub profile: Profile,
    /// Where validation.md, validation.html, validation.json and img/validation/ go.
    #[arg(long, default_value = "out/validate")]
    pub out: PathBuf,
    /// Where each scene's run is kept, keyed by its case and the solver's sources.
    #[arg(long, default_value = "out/validate-cache")]
    pub cache: PathBuf,
    /// Run every scene, reading nothing from the cache (and keeping nothing in it).
    #[arg(long)]
    pub no_cache: bool,
    /// Solver threads [default: all cores].
    #[arg(long)]
    pub threads: Option<usize>,
    /// Only the scenes whose id starts with one of these (the checks of the others show as
    /// not run).
    #[arg(long, value_delimiter = ',')]
    pub only: Vec<String>,
    /// List the profile's scenes and exit.
    #[arg(long)]
    pub list: bool,
    /// Print one scene's case (JSON, for `crush run`) and exit.
    #[arg(long, value_name = "SCENE")]
    pub case: Option<String>,
}

/// The progress bar over the whole suite, in estimated seconds of wall time.
struct SuiteBar {
    bar: indicatif::ProgressBar,
    /// Estimated seconds of the scenes before this one.
    base: f64,
    /// This scene's.
    span: f64,
}

impl Observer for SuiteBar {
    fn on_progress(&mut self, p: &Progress) {
        let at = self.base + p.fraction.clamp(0.0, 1.0) * self.span;
        self.bar.set_position((at * 1000.0) as u64);
    }
}

/// The error bars' rungs run so far, by ladder and n: scenes that differ only in their n and
/// model climb the same ladder (the paper's tube at n 2–8, in 3D and in its section), which
/// then runs once.
type Rungs = BTreeMap<(String, u32), Rung>;

/// The ladder a scene's error bar climbs: its case without what the rungs set.
fn ladder_key(case: &serde_json::Value) -> String {
    let mut c = case.clone();
    if let Some(o) = c.as_object_mut() {
        o.remove("label");
        o.remove("output");
    }
    if let Some(d) = c.get_mut("discretization").and_then(|d| d.as_object_mut()) {
        d.remove("particles_through_thickness");
        d.remove("model");
    }
    c.to_string()
}

/// Hands the error bar the rungs another scene ran, and keeps the ones it runs.
struct SharedRungs<'a> {
    key: String,
    rungs: &'a mut Rungs,
}

impl LadderObserver for SharedRungs<'_> {
    fn done(&self, _index: usize, n: u32) -> Option<Rung> {
        self.rungs.get(&(self.key.clone(), n)).cloned()
    }
    fn on_rung(&mut self, _index: usize, rung: &Rung) {
        self.rungs.insert((self.key.clone(), rung.n), rung.clone());
    }
}

/// The machine, in words: its CPU model and cores.
fn machine() -> String {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|s| s.trim().to_string())
        })
        .unwrap_or_else(|| "an unknown CPU".into());
    format!("{cpu} ({} cores)", crate::solver::cores())
}

/// The final shape of a run whose case keeps it, as PNG.
fn shape_png(case: &Case, snapshot: &Snapshot) -> Option<Vec<u8>> {
    if snapshot.position_mm.is_empty() || !case.spec().output.final_state {
        return None;
    }
    let state = crate::export::FinalState::of(snapshot);
    let title = case.spec().label.as_deref().unwrap_or("final shape");
    plot::tube_png(
        case.geometry(),
        case.crush_distance_mm(),
        title,
        &state.position_mm,
        &state.plastic_strain,
    )
    .ok()
}

/// Runs one scene: the crush, then its error bar where the case asks for one or it is cheap
/// (as `crush run` does).
fn run_scene(
    scene: &Scene,
    runner: &Runner,
    bar: &mut SuiteBar,
    rungs: &mut Rungs,
) -> Result<Entry, String> {
    let case = Case::from_json(&scene.case.to_string(), &Limits::unbounded())
        .map_err(|e| e.to_string())?;
    let cancel = AtomicBool::new(false);
    let start = Instant::now();
    let mut out = runner.run(&case, bar, &cancel).map_err(|e| e.to_string())?;
    let mut shared = SharedRungs {
        key: ladder_key(&scene.case),
        rungs,
    };
    runner
        .add_error_bar_if_asked(&case, &mut out, &mut shared, &cancel)
        .map_err(|e| e.to_string())?;
    let png = shape_png(&case, &out.snapshot);
    Ok(Entry {
        summary: out.summary,
        history: out.history,
        shape_png: None,
        wall_s: start.elapsed().as_secs_f64(),
    }
    .with_png(png))
}

/// The figures of the suite, drawn from the runs.
fn draw(figures: &[suite::Figure], runs: &BTreeMap<String, Entry>) -> Vec<Drawn> {
    let mut out = Vec::new();
    for f in figures {
        let present: Vec<(&String, &Entry)> = f
            .scenes
            .iter()
            .filter_map(|id| runs.get(id).map(|e| (id, e)))
            .collect();
        if present.is_empty() {
            continue;
        }
        let (series, titles, log): (Vec<Series>, _, bool) = match f.what {
            Plot::LoadCurves => (
                present
                    .iter()
                    .map(|(id, e)| Series {
                        name: id.to_string(),
                        points: e
                            .history
                            .iter()
                            .map(|r| (r.displacement_mm, r.load_top_n / 1e3))
                            .collect(),
                    })
                    .collect(),
                ("plate travel, mm", "load, kN"),
                false,
            ),
            Plot::Energies => {
                let (_, e) = present[0];
                let line = |name: &str, pick: fn(&crate::solver::HistoryRow) -> f64| Series {
                    name: name.into(),
                    points: e
                        .history
                        .iter()
                        .map(|r| (r.displacement_mm, pick(r) / 1e3))
                        .collect(),
                };
                (
                    vec![
                        line("internal energy", |r| r.internal_mj),
                        line("kinetic energy", |r| r.kinetic_mj),
                    ],
                    ("plate travel, mm", "energy, J"),
                    false,
                )
            }
            Plot::WallTime => {
                let mut points: Vec<(f64, f64)> = present
                    .iter()
                    .map(|(_, e)| {
                        let c = &e.summary.cost;
                        (c.particles as f64, c.wall_time_s.max(1e-3))
                    })
                    .collect();
                points.sort_by(|a, b| a.0.total_cmp(&b.0));
                (
                    vec![Series {
                        name: "runs of this report".into(),
                        points,
                    }],
                    ("tube particles", "wall time, s"),
                    true,
                )
            }
        };
        match plot::lines_svg((&f.title, titles.0, titles.1), &series, &[], log) {
            Ok(svg) => out.push(Drawn {
                id: f.id.clone(),
                group: f.group,
                title: f.title.clone(),
                file: format!("{}.svg", f.id),
                svg: Some(svg),
                png: None,
            }),
            Err(e) => eprintln!("figure {} not drawn: {e:#}", f.id),
        }
    }
    out
}

/// What a scene's run gave, as the report prints it.
fn figures(e: &Entry) -> Figures {
    let s = &e.summary;
    Figures {
        particles: s.cost.particles,
        steps: s.cost.steps,
        run_s: s.cost.wall_time_s,
        wall_s: e.wall_s,
        mean_load_n: s.mean_load_n,
        first_peak_load_n: s.measures.first_peak_load_n,
        mode: judge::mode_text(&s.mode),
        folds: s.folds,
        energy_balance_error: s.energy_balance_error,
        error_bar: judge::error_bar_text(e),
        verdict: judge::verdict_text(e),
    }
}

/// The report's files under `out`.
fn write(out: &Path, r: &Report) -> anyhow::Result<()> {
    let img = out.join("img").join("validation");
    std::fs::create_dir_all(&img).with_context(|| format!("creating {}", img.display()))?;
    for f in &r.figures {
        let path = img.join(&f.file);
        let bytes = match (&f.svg, &f.png) {
            (Some(svg), _) => svg.as_bytes().to_vec(),
            (None, Some(png)) => png.clone(),
            _ => continue,
        };
        std::fs::write(&path, bytes).with_context(|| format!("writing {}", path.display()))?;
    }
    let files = [
        ("validation.md", markdown::markdown(r)),
        ("validation.html", html::html(r)),
        ("validation.json", serde_json::to_string_pretty(r)? + "\n"),
    ];
    for (name, text) in files {
        let path = out.join(name);
        std::fs::write(&path, text).with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(())
}

pub fn validate(args: ValidateArgs) -> anyhow::Result<()> {
    let started = Instant::now();
    let suite = suite::suite(args.profile);
    if let Some(id) = &args.case {
        let Some(scene) = suite.scenes.iter().find(|s| &s.id == id) else {
            bail!(
                "no scene {id} in the {} profile (--list names them)",
                args.profile.name()
            );
        };
        println!("{}", serde_json::to_string_pretty(&scene.case)?);
        return Ok(());
    }
    if args.list {
        for s in &suite.scenes {
            let runs = if s.run { "" } else { " (particle count only)" };
            println!("{:<28} {}{runs}", s.id, s.title);
        }
        return Ok(());
    }
    let threads = super::run::thread_count(args.threads)?;
    let cache = Cache::new((!args.no_cache).then_some(args.cache.as_path()))?;
    let chosen = |s: &&Scene| {
        s.run && (args.only.is_empty() || args.only.iter().any(|p| s.id.starts_with(p.as_str())))
    };
    let scenes: Vec<&Scene> = suite.scenes.iter().filter(chosen).collect();
    let keys: Vec<String> = scenes.iter().map(|s| cache::key(&s.case)).collect();
    let guess =
        |s: &Scene| suite::parse(&s.case).map_or(1.0, |c| estimate(&c, threads as u32).wall_time_s);
    let to_run: f64 = scenes
        .iter()
        .zip(&keys)
        .filter(|(_, k)| cache.get(k).is_none())
        .map(|(s, _)| guess(s))
        .sum();
    let bar = indicatif::ProgressBar::new((to_run * 1000.0) as u64 + 1);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{bar:40} {percent:>3}% [{elapsed_precise}, about {eta} left] {msg}",
        )
        .expect("a valid template"),
    );
    let runner = Runner::new(threads, |i| format!("crush-validate-{i}"))
        .context("starting the solver's thread pool")?;
    let mut sb = SuiteBar {
        bar,
        base: 0.0,
        span: 0.0,
    };
    let mut runs = BTreeMap::new();
    let mut rungs = Rungs::new();
    let mut scene_runs = Vec::new();
    for (scene, key) in scenes.iter().zip(&keys) {
        let (entry, cached) = match cache.get(key) {
            Some(e) => (Ok(e), true),
            None => {
                sb.span = guess(scene);
                sb.bar.set_message(scene.id.clone());
                let result = run_scene(scene, &runner, &mut sb, &mut rungs);
                sb.base += sb.span;
                if let Ok(e) = &result {
                    cache.put(key, e)?;
                }
                (result, false)
            }
        };
        if let Err(why) = &entry {
            sb.bar.println(format!("{}: stopped: {why}", scene.id));
        }
        let run = SceneRun {
            id: scene.id.clone(),
            group: scene.group,
            title: scene.title.clone(),
            case_command: format!("crush validate --case {}", scene.id),
            cached,
            figures: entry.as_ref().ok().map(figures),
            stopped: entry.as_ref().err().cloned(),
        };
        scene_runs.push(run);
        if let Ok(e) = entry {
            runs.insert(scene.id.clone(), e);
        }
    }
    sb.bar.finish_and_clear();
    let mut figures = draw(&suite.figures, &runs);
    for s in &scenes {
        if let Some(png) = runs.get(&s.id).and_then(Entry::shape_png_bytes) {
            figures.push(Drawn {
                id: s.id.clone(),
                group: s.group,
                title: format!("{}: the final shape", s.title),
                file: format!("{}.png", s.id),
                svg: None,
                png: Some(png),
            });
        }
    }
    let rows = judge::judge(&suite.scenes, &suite.checks, &runs);
    let rows = match args.only.is_empty() {
        true => rows,
        false => rows
            .into_iter()
            .filter(|r| scenes.iter().any(|s| s.id == r.scene))
            .collect(),
    };
    let mut command = format!("crush validate --profile {}", args.profile.name());
    if !args.only.is_empty() {
        command += &format!(" --only {}", args.only.join(","));
    }
    let report = Report {
        profile: args.profile,
        command,
        machine: machine(),
        threads,
        rows,
        runs_wall_s: scene_runs
            .iter()
            .filter_map(|s| s.figures.as_ref().map(|f| f.wall_s))
            .sum(),
        scenes: scene_runs,
        figures,
        leaves_out: suite.leaves_out.clone(),
        candidates: measured::candidates(),
        wall_s: started.elapsed().as_secs_f64(),
    };
    write(&args.out, &report)?;
    let (inside, outside, stopped) = report.counts();
    eprintln!(
        "{inside} checks in band, {outside} out of band, {stopped} scenes stopped; wrote {}",
        args.out.join("validation.md").display()
    );
    if !report.passed() {
        bail!("{outside} checks left their band and {stopped} scenes stopped (see the report)");
    }
    Ok(())
}
