//! The validation report as data (what `markdown.rs` and `html.rs` print, and what
//! `validation.json` holds): the rows, the scenes' runs, the figures and what the profile leaves
//! out. Imports `judge.rs` and `suite.rs` of the validate folder.

use super::judge::{Row, Status};
use super::suite::{Group, Profile};

/// One scene as run (or read back from the cache), or why it stopped.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SceneRun {
    pub id: String,
    pub group: Group,
    pub title: String,
    /// The command that prints its case, for `crush run`.
    pub case_command: String,
    pub cached: bool,
    /// What the run gave; none where it stopped.
    #[serde(flatten)]
    pub figures: Option<Figures>,
    /// Why it has no result, where it stopped.
    pub stopped: Option<String>,
}

/// What a scene's run gave.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Figures {
    pub particles: u64,
    pub steps: u64,
    /// Wall time of the crush itself, s.
    pub run_s: f64,
    /// Wall time of the crush and its error bar (rungs another scene ran are not counted), s.
    pub wall_s: f64,
    pub mean_load_n: f64,
    pub first_peak_load_n: Option<f64>,
    pub mode: String,
    pub folds: u32,
    pub energy_balance_error: f64,
    pub error_bar: String,
    pub verdict: String,
}

/// A drawn figure: SVG text, or PNG bytes for a final shape.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Drawn {
    pub id: String,
    pub group: Group,
    pub title: String,
    /// The file's name under the report's image folder.
    pub file: String,
    #[serde(skip)]
    pub svg: Option<String>,
    #[serde(skip)]
    pub png: Option<Vec<u8>>,
}

/// Everything a report says.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Report {
    pub profile: Profile,
    /// The command that writes it.
    pub command: String,
    /// The machine it ran on, in words.
    pub machine: String,
    pub threads: usize,
    pub rows: Vec<Row>,
    pub scenes: Vec<SceneRun>,
    pub figures: Vec<Drawn>,
    pub leaves_out: Vec<String>,
    /// Papers named for measured rows not yet transcribed.
    pub candidates: Vec<String>,
    /// Wall time of this invocation, s (cached scenes cost nothing).
    pub wall_s: f64,
    /// Wall time of every scene's own run, s, cached or not.
    pub runs_wall_s: f64,
}

impl Report {
    /// Rows judged and in band, judged and out, and scenes that did not run.
    pub fn counts(&self) -> (usize, usize, usize) {
        let count = |s| self.rows.iter().filter(|r| r.status == s).count();
        let stopped = self.scenes.iter().filter(|s| s.stopped.is_some()).count();
        (count(Status::InBand), count(Status::OutOfBand), stopped)
    }

    /// Whether every judged row is in its band and every scene ran.
    pub fn passed(&self) -> bool {
        let (_, out, stopped) = self.counts();
        out == 0 && stopped == 0
    }

    pub fn rows_of(&self, group: Group) -> impl Iterator<Item = &Row> {
        self.rows.iter().filter(move |r| r.group == group)
    }
}

/// A ratio as printed.
pub fn ratio_text(r: Option<f64>) -> String {
    r.map_or("–".into(), |r| format!("{r:.3}"))
}

/// A block of the report's text, which `markdown.rs` and `html.rs` each print.
#[derive(Debug, Clone)]
pub enum Block {
    Heading(u8, String),
    /// A paragraph; `code` in backticks.
    Para(String),
    List(Vec<String>),
    Table(Vec<String>, Vec<Vec<String>>),
    /// A figure by its index in `Report::figures`.
    Figure(usize),
}

fn checks_table(rows: &[&Row], notes: &mut Vec<String>) -> Block {
    let head = [
        "scene",
        "figure",
        "ours",
        "verdict",
        "reference",
        "kind",
        "source",
        "ratio",
        "band",
        "",
    ];
    let body = rows
        .iter()
        .map(|r| {
            let note = match notes.iter().position(|n| *n == r.reason) {
                Some(i) => i,
                None => {
                    notes.push(r.reason.clone());
                    notes.len() - 1
                }
            };
            vec![
                format!("`{}`", r.scene),
                r.figure.clone(),
                r.ours_text.clone(),
                r.verdict.clone(),
                r.reference_text.clone(),
                r.kind.name().to_string(),
                r.source.clone(),
                ratio_text(r.ratio),
                format!("{} [{}]", r.band, note + 1),
                r.status.mark().to_string(),
            ]
        })
        .collect();
    Block::Table(head.iter().map(|s| s.to_string()).collect(), body)
}

/// The checks of `rows` (theories apart), then the bands' reasons, numbered.
fn checks(out: &mut Vec<Block>, rows: Vec<&Row>) {
    use super::suite::Kind;
    let theory = |r: &&Row| matches!(r.kind, Kind::Theory | Kind::Fit);
    let judged: Vec<&Row> = rows.iter().copied().filter(|r| !theory(r)).collect();
    let forms: Vec<&Row> = rows.iter().copied().filter(theory).collect();
    let mut notes = Vec::new();
    if !judged.is_empty() {
        out.push(checks_table(&judged, &mut notes));
    }
    if !forms.is_empty() {
        out.push(Block::Para(
            "Closed forms for the same runs: theories and fits, shown beside ours and never \
             taken for measurements."
                .into(),
        ));
        out.push(checks_table(&forms, &mut notes));
    }
    if !notes.is_empty() {
        out.push(Block::List(
            notes
                .iter()
                .enumerate()
                .map(|(i, n)| format!("[{}] {n}", i + 1))
                .collect(),
        ));
    }
}

/// The report's text, block by block.
pub fn blocks(r: &Report) -> Vec<Block> {
    let mut out = Vec::new();
    out.push(Block::Heading(1, "Validation".into()));
    out.push(Block::Para(format!(
        "What crush's results come to beside the seed paper (Yang, Meguid & Zhang 2013), tubes \
         crushed in testing machines, and the closed forms, figure by figure: ours with its error \
         bar and verdict, the reference, their ratio and the band ours must stay in, with the \
         band's reason. Written by `{}` on {} with {} thread{}; a scene's case is printed by \
         `crush validate --case SCENE`, and `crush run` on it prints the same numbers. The \
         suite and its bands are in src/cli/validate/, the measured tubes in \
         validation/measured_tests.json.",
        r.command,
        r.machine,
        r.threads,
        if r.threads == 1 { "" } else { "s" }
    )));
    let (inside, outside, stopped) = r.counts();
    let cached = r.scenes.iter().filter(|s| s.cached).count();
    out.push(Block::Heading(2, "Summary".into()));
    out.push(Block::Para(format!(
        "{} checks judged: {inside} in their band, {outside} out of it; {} shown beside ours; \
         {stopped} scenes stopped. The {} runs took {:.0} s of wall time ({} read back from the \
         cache; this invocation took {:.0} s).",
        inside + outside,
        r.rows
            .iter()
            .filter(|x| x.status == super::judge::Status::Shown)
            .count(),
        r.scenes.len(),
        r.runs_wall_s,
        cached,
        r.wall_s
    )));
    if !r.leaves_out.is_empty() {
        out.push(Block::Para(format!(
            "What the {} profile leaves out (`crush validate --profile full` runs it):",
            r.profile.name()
        )));
        out.push(Block::List(r.leaves_out.clone()));
    }
    let groups = [
        (Group::Paper, "The seed paper"),
        (Group::Measured, "Measured tests"),
        (
            Group::ThinWalls,
            "A thin wall in 3D: its error bars held to finer runs",
        ),
    ];
    for (i, (group, title)) in groups.into_iter().enumerate() {
        let rows: Vec<&Row> = r.rows_of(group).collect();
        // A part this profile does not run is named among what it leaves out; the measured
        // tests are always shown, with the papers to transcribe while they have no row.
        if rows.is_empty() && group != Group::Measured {
            continue;
        }
        out.push(Block::Heading(2, format!("{}. {title}", i + 1)));
        if group == Group::Measured && rows.is_empty() {
            out.push(Block::Para(
                "No measured tube is transcribed yet. The tables of the papers below give the \
                 geometry, the material's measured properties and the measured mean and peak \
                 loads, but their full text could not be read from where this suite was \
                 written, and no number is entered that was not read in its source. Each row \
                 added to validation/measured_tests.json (its source, table and units, measured \
                 columns apart from theory columns) becomes a scene and a check here."
                    .into(),
            ));
            out.push(Block::List(r.candidates.clone()));
            continue;
        }
        checks(&mut out, rows);
        for (k, f) in r.figures.iter().enumerate() {
            if f.group == group {
                out.push(Block::Figure(k));
            }
        }
    }
    out.push(Block::Heading(2, "Scenes".into()));
    let head = [
        "scene",
        "what",
        "particles",
        "steps",
        "run s",
        "with error bar s",
        "mean kN",
        "first peak kN",
        "mode",
        "folds",
        "books",
        "error bar",
        "verdict",
    ];
    let body = r
        .scenes
        .iter()
        .map(|s| {
            let mut row = vec![format!("`{}`", s.id), s.title.clone()];
            match (&s.figures, &s.stopped) {
                (Some(f), _) => row.extend([
                    f.particles.to_string(),
                    f.steps.to_string(),
                    format!("{:.1}", f.run_s),
                    format!("{:.1}{}", f.wall_s, if s.cached { " (cached)" } else { "" }),
                    format!("{:.3}", f.mean_load_n / 1e3),
                    f.first_peak_load_n
                        .map_or("–".into(), |p| format!("{:.3}", p / 1e3)),
                    f.mode.clone(),
                    f.folds.to_string(),
                    format!("{:.2} %", 100.0 * f.energy_balance_error),
                    f.error_bar.clone(),
                    f.verdict.clone(),
                ]),
                (None, why) => {
                    let why = why.clone().unwrap_or_default();
                    row.push(format!("stopped: {why}"));
                    row.resize(head.len(), "–".into());
                }
            }
            row
        })
        .collect();
    out.push(Block::Table(
        head.iter().map(|s| s.to_string()).collect(),
        body,
    ));
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::validate::judge::Status;
    use crate::cli::validate::suite::{Kind, Quantity};

    fn row(status: Status) -> Row {
        Row {
            scene: "s".into(),
            group: Group::Paper,
            figure: "mean load".into(),
            quantity: Quantity::MeanLoadKn,
            ours: Some(1.0),
            ours_text: "1.000 kN".into(),
            verdict: "trusted".into(),
            reference: Some(1.0),
            reference_text: "1.000 kN".into(),
            kind: Kind::PaperMpm,
            source: "the paper".into(),
            ratio: Some(1.0),
            band: "0.90–1.10".into(),
            reason: "why".into(),
            status,
        }
    }

    fn report(rows: Vec<Row>, stopped: Option<String>) -> Report {
        Report {
            profile: Profile::Ci,
            command: "crush validate".into(),
            machine: "m".into(),
            threads: 1,
            rows,
            scenes: vec![SceneRun {
                id: "s".into(),
                group: Group::Paper,
                title: "t".into(),
                case_command: String::new(),
                cached: false,
                figures: stopped.is_none().then(|| Figures {
                    particles: 1,
                    steps: 1,
                    run_s: 1.0,
                    wall_s: 1.0,
                    mean_load_n: 1e3,
                    first_peak_load_n: None,
                    mode: "ring".into(),
                    folds: 1,
                    energy_balance_error: 0.0,
                    error_bar: String::new(),
                    verdict: "trusted".into(),
                }),
                stopped,
            }],
            figures: Vec::new(),
            leaves_out: Vec::new(),
            candidates: Vec::new(),
            wall_s: 1.0,
            runs_wall_s: 1.0,
        }
    }

    #[test]
    fn a_check_out_of_its_band_or_a_stopped_scene_fails_the_report() {
        assert!(report(vec![row(Status::InBand), row(Status::Shown)], None).passed());
        assert!(!report(vec![row(Status::InBand), row(Status::OutOfBand)], None).passed());
        assert!(!report(vec![row(Status::InBand)], Some("unstable".into())).passed());
    }

    #[test]
    fn each_band_reason_is_printed_once_and_numbered() {
        let mut b = row(Status::InBand);
        b.reason = "another".into();
        let text = crate::cli::validate::markdown::markdown(&report(
            vec![row(Status::InBand), row(Status::InBand), b],
            None,
        ));
        assert_eq!(text.matches("[1] why").count(), 1, "{text}");
        assert_eq!(text.matches("[2] another").count(), 1, "{text}");
        assert_eq!(text.matches("0.90–1.10 [1]").count(), 2, "{text}");
    }
}
