//! The report as one self-contained HTML page: the same blocks as the Markdown, its figures
//! inside it (SVG inline, PNG as data URIs). Imports `report.rs` of the validate folder.

use super::report::{blocks, Block, Report};
use base64::Engine as _;
use std::fmt::Write as _;

/// `text` escaped for HTML, with `code` in backticks set as code.
fn text(s: &str) -> String {
    let escaped = s
        .replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;");
    let mut out = String::new();
    for (i, part) in escaped.split('`').enumerate() {
        if i % 2 == 1 {
            let _ = write!(out, "<code>{part}</code>");
        } else {
            out.push_str(part);
        }
    }
    out
}

const STYLE: &str = "body{font-family:sans-serif;max-width:1400px;margin:1em auto;padding:0 1em;\
line-height:1.4}table{border-collapse:collapse;font-size:0.85em;margin:1em 0}\
td,th{border:1px solid #ccc;padding:2px 6px;vertical-align:top}th{background:#f0f0f0}\
figure{margin:1em 0}figure svg,figure img{max-width:100%;height:auto}";

/// The report's HTML page.
pub fn html(r: &Report) -> String {
    let mut s = String::new();
    let _ = write!(
        s,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
         <title>crush validation</title><style>{STYLE}</style></head><body>\n"
    );
    for b in blocks(r) {
        match b {
            Block::Heading(level, t) => {
                let _ = writeln!(s, "<h{level}>{}</h{level}>", text(&t));
            }
            Block::Para(t) => {
                let _ = writeln!(s, "<p>{}</p>", text(&t));
            }
            Block::List(items) => {
                s.push_str("<ul>");
                for i in items {
                    let _ = write!(s, "<li>{}</li>", text(&i));
                }
                s.push_str("</ul>\n");
            }
            Block::Table(head, rows) => {
                s.push_str("<table><tr>");
                for h in head {
                    let _ = write!(s, "<th>{}</th>", text(&h));
                }
                s.push_str("</tr>\n");
                for row in rows {
                    s.push_str("<tr>");
                    for c in row {
                        let _ = write!(s, "<td>{}</td>", text(&c));
                    }
                    s.push_str("</tr>\n");
                }
                s.push_str("</table>\n");
            }
            Block::Figure(k) => {
                let f = &r.figures[k];
                s.push_str("<figure>");
                if let Some(svg) = &f.svg {
                    let body = svg.find("<svg").map_or(svg.as_str(), |i| &svg[i..]);
                    s.push_str(body);
                } else if let Some(png) = &f.png {
                    let b64 = base64::engine::general_purpose::STANDARD.encode(png);
                    let _ = write!(
                        s,
                        "<img alt=\"{}\" src=\"data:image/png;base64,{b64}\">",
                        text(&f.title)
                    );
                }
                let _ = writeln!(s, "<figcaption>{}</figcaption></figure>", text(&f.title));
            }
        }
    }
    s.push_str("</body></html>\n");
    s
}
