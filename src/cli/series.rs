//! `crush run`'s time series (`output.frames`): each frame written as the run reaches it, to
//! `frames/{k}.vtu` in the output folder, and `series.pvd` beside them once the run ends (or
//! stops: the frames reached so far). The bytes are the server's (`series.pvd`,
//! `frames/{k}.vtu`): each frame goes through the stored form (f32) first.

use super::progress::BarObserver;
use crate::export::series::{self, FrameTime};
use crate::solver::{Case, Frame, HistoryRow, Observer, Progress};
use anyhow::Context;
use std::io::Write;
use std::path::{Path, PathBuf};

/// The run's observer: the progress bar, and the series' files when the case keeps one.
pub struct RunObserver {
    pub bar: BarObserver,
    pub series: Option<SeriesFiles>,
}

impl Observer for RunObserver {
    fn on_progress(&mut self, p: &Progress) {
        self.bar.on_progress(p);
    }
    fn on_history(&mut self, row: &HistoryRow) {
        self.bar.on_history(row);
    }
    fn wants_frames(&self) -> bool {
        self.series.is_some()
    }
    fn on_frame(&mut self, frame: &Frame) {
        if let Some(series) = &mut self.series {
            series.write_frame(frame);
        }
    }
}

/// The series' files under one folder, one frame in memory at a time.
pub struct SeriesFiles {
    dir: PathBuf,
    start: Vec<[f64; 3]>,
    symmetry: Option<&'static str>,
    written: Vec<FrameTime>,
    /// The first frame that could not be written: the rest are skipped, the run goes on.
    failed: Option<anyhow::Error>,
}

impl SeriesFiles {
    /// The series of `case` in `dir`; `None` when the case keeps none.
    pub fn new(dir: &Path, case: &Case) -> anyhow::Result<Option<SeriesFiles>> {
        if case.spec().output.frames == 0 {
            return Ok(None);
        }
        let frames = dir.join("frames");
        std::fs::create_dir_all(&frames)
            .with_context(|| format!("creating {}", frames.display()))?;
        Ok(Some(SeriesFiles {
            dir: dir.to_path_buf(),
            start: case.geometry().positions(),
            symmetry: case.geometry().symmetry_note(),
            written: Vec::new(),
            failed: None,
        }))
    }

    fn write_frame(&mut self, frame: &Frame) {
        if self.failed.is_some() {
            return;
        }
        let at = FrameTime {
            index: frame.index,
            travel_mm: frame.travel_mm,
            time_ms: frame.time_ms,
        };
        let path = self.dir.join(series::frame_file(frame.index));
        let written = (|| -> anyhow::Result<()> {
            let bytes = series::encode(frame);
            let state = series::decode(frame.position_mm.len(), &bytes)
                .context("a frame's stored form does not read back")?;
            drop(bytes);
            let note = series::frame_note(&at, frame.count, self.symmetry);
            let file = std::fs::File::create(&path)?;
            let mut out = std::io::BufWriter::new(file);
            series::write_frame_vtu(&mut out, &self.start, &state, Some(&note))?;
            out.flush()?;
            Ok(())
        })();
        match written {
            Ok(()) => self.written.push(at),
            Err(e) => self.failed = Some(e.context(format!("writing {}", path.display()))),
        }
    }

    /// Writes `series.pvd` of the frames written; returns its path and how many frames it
    /// lists, or the first frame's failure.
    pub fn finish(self) -> anyhow::Result<(PathBuf, usize)> {
        if let Some(e) = self.failed {
            return Err(e);
        }
        let path = self.dir.join("series.pvd");
        let mut pvd = Vec::new();
        series::write_pvd(&mut pvd, &self.written)?;
        std::fs::write(&path, pvd).with_context(|| format!("writing {}", path.display()))?;
        Ok((path, self.written.len()))
    }
}
