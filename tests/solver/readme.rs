//! The README's examples say what they cost. An example is a fenced `sh` block that runs cases
//! (`crush run FILE`, a case posted to `/v1/jobs`, a sweep posted to `/v1/sweeps`), followed by
//! a line "Costs about 6 s on 2 threads." (or "Costs under a second on 2 threads."), or a row
//! of a table that links a file of `examples/` and says "about 5 min on 2 threads". Each stated
//! cost must lie within 2× of the wall time the library's estimate gives those cases at its
//! assumed rates (`crush estimate`), so a changed example, or a changed estimate, fails here
//! until the text follows. docs/api.md, which holds the rest of the API's examples, is held to
//! the same.

use crush::service::sweep;
use crush::solver::{estimate, Case, Limits};
use std::path::Path;

/// How far a stated cost may stray from the estimate, either way.
const TOLERANCE: f64 = 2.0;

/// The smallest cost a text states: a run of under a second still takes about one (the
/// process starts, writes its files), and "under a second" is the phrase for it.
const FLOOR_S: f64 = 1.0;

/// Stated costs above this come after every stated cost at or below it: the costly examples
/// come last.
const CHEAP_S: f64 = 60.0;

/// A cost as a text states it.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Stated {
    /// Seconds; [`FLOOR_S`] for "under a second".
    seconds: f64,
    threads: u32,
}

/// One example: where it is, the cases it runs, and the cost stated beside it.
#[derive(Debug)]
struct Example {
    line: usize,
    cases: Vec<Case>,
    stated: Option<Stated>,
}

fn read(path: &str) -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(path)).unwrap()
}

/// "about 6 s on 2 threads", "about 1.5 h on 1 thread" or "under a second on 2 threads",
/// anywhere in `text`.
fn stated_cost(text: &str) -> Option<Stated> {
    let threads_after = |rest: &str| -> Option<u32> {
        let rest = rest.trim_start().strip_prefix("on ")?;
        let (n, rest) = rest.split_once(' ')?;
        rest.starts_with("thread").then(|| n.parse().ok())?
    };
    if let Some(i) = text.find("under a second") {
        let threads = threads_after(&text[i + "under a second".len()..])?;
        return Some(Stated {
            seconds: FLOOR_S,
            threads,
        });
    }
    // The first "about" that a figure, a unit and a thread count follow.
    text.match_indices("about ").find_map(|(i, _)| {
        let mut words = text[i + "about ".len()..].splitn(3, ' ');
        let value: f64 = words.next()?.parse().ok()?;
        let unit = match words.next()? {
            "s" => 1.0,
            "min" => 60.0,
            "h" => 3600.0,
            _ => return None,
        };
        Some(Stated {
            seconds: value * unit,
            threads: threads_after(words.next()?)?,
        })
    })
}

/// The case at `path` (from the repository root), as `crush run` reads it.
fn case_file(path: &str) -> Result<Case, String> {
    Case::from_json(&read(path), &Limits::default()).map_err(|e| format!("{path}: {e}"))
}

/// The JSON body of the first `-d '…'` in `text`.
fn body_after(text: &str) -> Option<&str> {
    let start = text.find("-d '")? + "-d '".len();
    let len = text[start..].find('\'')?;
    Some(&text[start..start + len])
}

/// Every case a shell block runs: `crush run FILE` (`--error-bar` too), and the cases posted to
/// `/v1/jobs` or, as a sweep's combinations, to `/v1/sweeps`.
fn cases_of_block(block: &str) -> Result<Vec<Case>, String> {
    let mut cases = Vec::new();
    for line in block.lines() {
        let Some(i) = line.find("crush run ").or_else(|| line.find("-- run ")) else {
            continue;
        };
        let words: Vec<&str> = line[i..].split_whitespace().collect();
        let file = words
            .iter()
            .find(|w| w.ends_with(".json"))
            .ok_or_else(|| format!("no case file in `{line}`"))?;
        let mut case = case_file(file)?;
        if words.contains(&"--error-bar") {
            let mut spec = case.spec().clone();
            spec.output.error_bar = true;
            case = Case::parse(spec, &Limits::default()).map_err(|e| e.to_string())?;
        }
        cases.push(case);
    }
    for (route, is_sweep) in [("/v1/jobs\"", false), ("/v1/sweeps\"", true)] {
        let mut rest = block;
        while let Some(i) = rest.find(route) {
            rest = &rest[i + route.len()..];
            // A GET of the list has no body before the next request.
            let next = rest.find("curl ").unwrap_or(rest.len());
            let Some(body) = body_after(&rest[..next]) else {
                continue;
            };
            if is_sweep {
                let plan = sweep::plan(body, &Limits::default(), 100)
                    .map_err(|e| format!("sweep {body}: {e:?}"))?;
                for job in plan.jobs {
                    cases.push(
                        Case::from_json(&job.case.to_string(), &Limits::default())
                            .map_err(|e| e.to_string())?,
                    );
                }
            } else {
                cases.push(Case::from_json(body, &Limits::default()).map_err(|e| e.to_string())?);
            }
        }
    }
    Ok(cases)
}

/// Every example of a Markdown text, in reading order, or what could not be read.
fn examples(text: &str) -> Result<Vec<Example>, String> {
    let lines: Vec<&str> = text.lines().collect();
    let mut found = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        let line = lines[i];
        if line.starts_with('|') && line.contains("](examples/") {
            let start = line.find("](examples/").unwrap() + 2;
            let end = start
                + line[start..]
                    .find(')')
                    .ok_or_else(|| format!("line {}: a link without its end", i + 1))?;
            found.push(Example {
                line: i + 1,
                cases: vec![case_file(&line[start..end])?],
                stated: stated_cost(line),
            });
        }
        if let Some(info) = line.strip_prefix("```") {
            let open = i;
            let close = (i + 1..lines.len())
                .find(|&j| lines[j].starts_with("```"))
                .ok_or_else(|| format!("line {}: a block that never closes", i + 1))?;
            i = close;
            let after = lines[close + 1..].iter().find(|l| !l.trim().is_empty());
            let costs_line = after.filter(|l| l.starts_with("Costs "));
            if info.trim() == "sh" {
                let cases = cases_of_block(&lines[open + 1..close].join("\n"))
                    .map_err(|e| format!("line {}: {e}", open + 1))?;
                if !cases.is_empty() || costs_line.is_some() {
                    found.push(Example {
                        line: open + 1,
                        cases,
                        stated: costs_line.and_then(|l| stated_cost(l)),
                    });
                }
            }
        }
        i += 1;
    }
    Ok(found)
}

/// What is wrong with the examples of the text `name`: each missing, unreadable or wrong cost,
/// and a costly example before a cheap one.
fn problems(name: &str, text: &str) -> Vec<String> {
    let examples = match examples(text) {
        Ok(e) => e,
        Err(e) => return vec![format!("{name}: {e}")],
    };
    let mut out = Vec::new();
    let mut costly_at = None;
    for ex in &examples {
        let at = format!("{name}:{}", ex.line);
        let Some(stated) = ex.stated else {
            out.push(format!(
                "{at}: an example that runs {} case(s) states no cost (\"Costs about … on N \
                 threads.\" after its block, \"about … on N threads\" in its row)",
                ex.cases.len()
            ));
            continue;
        };
        if ex.cases.is_empty() {
            out.push(format!(
                "{at}: states a cost but runs no case this test can read"
            ));
            continue;
        }
        let estimated: f64 = ex
            .cases
            .iter()
            .map(|c| {
                let e = estimate(c, stated.threads);
                e.wall_time_s + e.error_bar_wall_time_s.unwrap_or(0.0)
            })
            .sum();
        let ratio = stated.seconds / estimated.max(FLOOR_S);
        if !(1.0 / TOLERANCE..=TOLERANCE).contains(&ratio) {
            out.push(format!(
                "{at}: states {:.0} s on {} threads, the estimate of its {} case(s) is {:.1} s",
                stated.seconds,
                stated.threads,
                ex.cases.len(),
                estimated
            ));
        }
        if stated.seconds > CHEAP_S {
            costly_at.get_or_insert(ex.line);
        } else if let Some(c) = costly_at {
            out.push(format!(
                "{at}: a cheap example after the costly one at line {c}: the costly come last"
            ));
        }
    }
    if examples.is_empty() {
        out.push(format!("{name}: no example found"));
    }
    out
}

#[test]
fn every_readme_example_states_its_cost_within_twice_the_estimate() {
    for name in ["README.md", "docs/api.md"] {
        let found = problems(name, &read(name));
        assert!(found.is_empty(), "{}", found.join("\n"));
    }
    // Every example file has its row, with its cost.
    let readme = read("README.md");
    for entry in std::fs::read_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("examples")).unwrap()
    {
        let name = entry.unwrap().file_name().to_string_lossy().into_owned();
        assert!(
            readme.contains(&format!("](examples/{name})")),
            "README's table of examples has no row for examples/{name}"
        );
    }
}

/// The rules catch what they are for: a block with no cost, a cost far from the estimate, a
/// cost beside no case, and a costly example before a cheap one.
#[test]
fn an_example_without_a_cost_or_with_a_wrong_one_is_caught() {
    let run = "```sh\ncrush run examples/axial_t3.2_axisymmetric.json\n```\n\n";
    let posted = "```sh\ncurl \"$URL/v1/jobs\" -d '{\"tube\": {\"length_mm\": 8}, \
                  \"discretization\": {\"particles_through_thickness\": 1}, \
                  \"loading\": {\"crush_distance_mm\": 1, \"plate_speed_m_s\": 20}}'\n```\n\n";
    let row = "| [`a`](examples/axial_t3.2.json) | 3D | about 8 min on 2 threads |\n\n";

    assert!(problems("ok", &format!("{run}Costs about 6 s on 2 threads.\n")).is_empty());
    assert!(problems(
        "ok",
        &format!("{posted}Costs under a second on 2 threads.\n")
    )
    .is_empty());
    assert!(problems("ok", row).is_empty());

    let missing = problems("missing", run);
    assert!(missing[0].contains("states no cost"), "{missing:?}");
    let wrong = problems("wrong", &format!("{run}Costs about 1 h on 2 threads.\n"));
    assert!(wrong[0].contains("the estimate"), "{wrong:?}");
    let posted_wrong = problems(
        "wrong",
        &format!("{posted}Costs about 5 min on 2 threads.\n"),
    );
    assert!(posted_wrong[0].contains("the estimate"), "{posted_wrong:?}");
    let nothing = problems("none", "```sh\nls\n```\n\nCosts about 6 s on 2 threads.\n");
    assert!(nothing[0].contains("runs no case"), "{nothing:?}");
    let late = problems(
        "late",
        &format!("{row}{run}Costs about 6 s on 2 threads.\n"),
    );
    assert!(late[0].contains("the costly come last"), "{late:?}");
    assert_eq!(
        stated_cost("Costs about 1.5 h on 1 thread."),
        Some(Stated {
            seconds: 5400.0,
            threads: 1
        })
    );
}
