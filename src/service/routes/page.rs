//! The web page: `/` and its assets, compiled into the binary (`web/`), so that the page works
//! with no network: nothing is fetched from anywhere but this server.

use super::answers::file_response;
use crate::service::error::ApiError;
use crate::service::form;
use axum::extract::Path;
use axum::response::Response;
use axum::Json;

const JS: &str = "text/javascript; charset=utf-8";

/// (name, content type, bytes) of every asset: the page's modules (`app.js` imports the rest),
/// its stylesheet, its icon, and uPlot.
const ASSETS: &[(&str, &str, &str)] = &[
    ("app.js", JS, include_str!("../../../web/app.js")),
    ("util.js", JS, include_str!("../../../web/util.js")),
    ("list.js", JS, include_str!("../../../web/list.js")),
    ("form.js", JS, include_str!("../../../web/form.js")),
    ("job.js", JS, include_str!("../../../web/job.js")),
    ("sweep.js", JS, include_str!("../../../web/sweep.js")),
    ("compare.js", JS, include_str!("../../../web/compare.js")),
    (
        "app.css",
        "text/css; charset=utf-8",
        include_str!("../../../web/app.css"),
    ),
    (
        "favicon.svg",
        "image/svg+xml",
        include_str!("../../../web/favicon.svg"),
    ),
    (
        "uplot.min.js",
        JS,
        include_str!("../../../web/vendor/uplot-1.6.32.min.js"),
    ),
    (
        "uplot.min.css",
        "text/css; charset=utf-8",
        include_str!("../../../web/vendor/uplot-1.6.32.min.css"),
    ),
];

const INDEX: &str = include_str!("../../../web/index.html");

pub async fn index() -> Response {
    file_response("text/html; charset=utf-8", None, Some("no-cache"), INDEX)
}

pub async fn asset(Path(name): Path<String>) -> Result<Response, ApiError> {
    let (_, kind, body) =
        ASSETS
            .iter()
            .find(|(n, _, _)| *n == name)
            .ok_or_else(|| ApiError::NotFound {
                what: format!("asset {}", crate::solver::model::input::clip(&name)),
            })?;
    Ok(file_response(kind, None, Some("no-cache"), *body))
}

/// The case form as data (see [`form`]).
pub async fn case_fields() -> Json<Vec<form::Field>> {
    Json(form::fields())
}
