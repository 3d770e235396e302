//! The report as Markdown: docs/validation.md is the quick profile's. Figures are linked from
//! `img/validation/`. Imports `report.rs` of the validate folder.

use super::report::{blocks, Block, Report};
use std::fmt::Write as _;

/// A table cell: pipes escaped, no line breaks.
fn cell(s: &str) -> String {
    s.replace('|', "\\|").replace('\n', " ")
}

/// The report's Markdown.
pub fn markdown(r: &Report) -> String {
    let mut s = String::new();
    for b in blocks(r) {
        match b {
            Block::Heading(level, text) => {
                let _ = writeln!(s, "{} {text}\n", "#".repeat(level as usize));
            }
            Block::Para(text) => {
                let _ = writeln!(s, "{text}\n");
            }
            Block::List(items) => {
                for i in items {
                    let _ = writeln!(s, "- {i}");
                }
                s.push('\n');
            }
            Block::Table(head, rows) => {
                let _ = writeln!(s, "| {} |", head.join(" | "));
                let _ = writeln!(s, "|{}", "---|".repeat(head.len()));
                for row in rows {
                    let cells: Vec<String> = row.iter().map(|c| cell(c)).collect();
                    let _ = writeln!(s, "| {} |", cells.join(" | "));
                }
                s.push('\n');
            }
            Block::Figure(k) => {
                let f = &r.figures[k];
                let _ = writeln!(s, "![{}](img/validation/{})\n", f.title, f.file);
            }
        }
    }
    s
}
