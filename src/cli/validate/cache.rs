//! What one scene's run left (its summary, history, final shape and wall time), kept in a cache
//! folder under a key made of the case and the solver that ran it: a re-run of `crush validate`
//! after a change that leaves `src/solver` and `Cargo.lock` as they were reads every scene back
//! and runs none. Imports nothing of the validate folder.

use crate::solver::{HistoryRow, Summary};
use anyhow::Context;
use base64::Engine as _;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// The solver's sources, hashed at build time (`build.rs`).
const SOLVER_SOURCE: &str = env!("CRUSH_SOLVER_SOURCE");

/// What a scene's run left.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Entry {
    pub summary: Summary,
    pub history: Vec<HistoryRow>,
    /// The final shape as PNG, base64 (3D runs that keep their final state).
    #[serde(default)]
    pub shape_png: Option<String>,
    /// Wall time of the run and of its error bar's rungs, s.
    pub wall_s: f64,
}

impl Entry {
    pub fn shape_png_bytes(&self) -> Option<Vec<u8>> {
        self.shape_png
            .as_ref()
            .and_then(|b| base64::engine::general_purpose::STANDARD.decode(b).ok())
    }

    pub fn with_png(mut self, png: Option<Vec<u8>>) -> Entry {
        self.shape_png = png.map(|b| base64::engine::general_purpose::STANDARD.encode(b));
        self
    }
}

/// The key of a case as JSON: the solver's source hash and the case's canonical text.
pub fn key(case: &serde_json::Value) -> String {
    let mut h = Sha256::new();
    h.update(SOLVER_SOURCE.as_bytes());
    h.update(b"\n");
    h.update(case.to_string().as_bytes());
    let digest = h.finalize();
    digest[..12].iter().map(|b| format!("{b:02x}")).collect()
}

/// The cache folder.
pub struct Cache {
    dir: Option<PathBuf>,
}

impl Cache {
    /// A cache in `dir`, or none (every scene runs).
    pub fn new(dir: Option<&Path>) -> anyhow::Result<Cache> {
        if let Some(d) = dir {
            std::fs::create_dir_all(d).with_context(|| format!("creating {}", d.display()))?;
        }
        Ok(Cache {
            dir: dir.map(Path::to_path_buf),
        })
    }

    fn path(&self, key: &str) -> Option<PathBuf> {
        self.dir.as_ref().map(|d| d.join(format!("{key}.json")))
    }

    /// The entry under `key`, if one was kept and reads back.
    pub fn get(&self, key: &str) -> Option<Entry> {
        let text = std::fs::read_to_string(self.path(key)?).ok()?;
        serde_json::from_str(&text).ok()
    }

    /// Keeps `entry` under `key` (written whole, then renamed into place).
    pub fn put(&self, key: &str, entry: &Entry) -> anyhow::Result<()> {
        let Some(path) = self.path(key) else {
            return Ok(());
        };
        let tmp = path.with_extension("tmp");
        std::fs::write(&tmp, serde_json::to_string(entry)?)
            .with_context(|| format!("writing {}", tmp.display()))?;
        std::fs::rename(&tmp, &path).with_context(|| format!("writing {}", path.display()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn the_key_follows_the_case_and_nothing_else() {
        let a = json!({"tube": {"thickness_mm": 3.2}});
        let b = json!({"tube": {"thickness_mm": 3.3}});
        assert_eq!(key(&a), key(&a.clone()));
        assert_ne!(key(&a), key(&b));
    }

    #[test]
    fn an_entry_reads_back_as_written_and_a_missing_one_is_none() {
        let dir = tempfile::tempdir().unwrap();
        let cache = Cache::new(Some(dir.path())).unwrap();
        assert!(cache.get("nothing").is_none());
        let case = crate::solver::Case::from_json(
            r#"{"discretization": {"model": "axisymmetric", "particles_through_thickness": 1},
                "loading": {"crush_distance_mm": 0.5}}"#,
            &crate::solver::Limits::default(),
        )
        .unwrap();
        let out =
            crate::solver::run(&case, &mut (), &std::sync::atomic::AtomicBool::new(false)).unwrap();
        let entry = Entry {
            summary: out.summary.clone(),
            history: out.history.clone(),
            shape_png: None,
            wall_s: 1.0,
        }
        .with_png(Some(vec![1, 2, 3]));
        cache.put("k", &entry).unwrap();
        let back = cache.get("k").unwrap();
        assert_eq!(back.summary, out.summary);
        assert_eq!(back.history, out.history);
        assert_eq!(back.shape_png_bytes(), Some(vec![1, 2, 3]));
        assert!(Cache::new(None).unwrap().get("k").is_none());
    }
}
