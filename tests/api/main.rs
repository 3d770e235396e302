//! The service against a real server on port 0, one module per area: jobs, events, results
//! and downloads, errors and hostile requests, access control and connection limits, the store
//! under a full or lost disk, restarts and checkpoints, several nodes on PostgreSQL, and the web
//! page in a browser. One test binary: the suites share the helpers of `common` and one link.
//!
//! Every server runs on SQLite, or on PostgreSQL with `CRUSH_TEST_BACKEND=postgres` (see
//! `common`); `.ci/run` runs the suite both ways.

#[path = "../common/browser.rs"]
mod browser_kit;
#[path = "../common/mod.rs"]
mod common;

mod browser;
mod cluster;
mod download;
mod errors;
mod events;
mod guard;
mod jobs;
mod manage;
mod plan;
mod requests;
mod restart;
mod results;
mod series;
mod store;
mod time_step;
mod timeouts;
mod views;
