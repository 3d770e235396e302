//! Peaks of a sequence counted with hysteresis, as a person reading a curve counts them: a
//! peak counts once the sequence has fallen a margin below it, and the next can only begin
//! once it has risen the margin above the trough since. The folds along a wall line
//! (`folds.rs`) and the drops of the load curve (`summary.rs`) are both counted so.

use crate::solver::Real;

/// The counter, fed one value at a time ([`Peaks::push`]).
#[derive(Debug, Clone, Copy)]
pub struct Peaks {
    rising: bool,
    peak: Real,
    trough: Real,
    /// A peak must also rise the margin above the trough before it, and a value below that
    /// trough while rising starts the rise again from there.
    from_trough: bool,
    count: u32,
    /// Values pushed so far, and where the trough before the rise was.
    pushed: usize,
    trough_at: usize,
}

impl Peaks {
    /// Peaks standing on a trough: the sequence starts on one at `baseline`.
    pub fn from_trough(baseline: Real) -> Peaks {
        Peaks {
            rising: true,
            peak: Real::MIN,
            trough: baseline,
            from_trough: true,
            count: 0,
            pushed: 0,
            trough_at: 0,
        }
    }

    /// Falls from the highest value since the last trough, however they rose.
    pub fn falls() -> Peaks {
        Peaks {
            rising: true,
            peak: Real::MIN,
            trough: Real::NEG_INFINITY,
            from_trough: false,
            count: 0,
            pushed: 0,
            trough_at: 0,
        }
    }

    /// The next value `v`, with the margin that counts at it; a peak below `reach` does not
    /// count. Where a peak counts, returns where (in values pushed, from 0) the trough before
    /// it was.
    #[inline]
    pub fn push(&mut self, v: Real, margin: Real, reach: Real) -> Option<usize> {
        let at = self.pushed;
        self.pushed += 1;
        let mut counted = None;
        if self.rising {
            let rose = !self.from_trough || self.peak - self.trough >= margin;
            if v > self.peak {
                self.peak = v;
            } else if self.peak - v >= margin && rose && self.peak >= reach {
                self.count += 1;
                counted = Some(self.trough_at);
                (self.rising, self.trough, self.trough_at) = (false, v, at);
            }
            if self.from_trough && v < self.trough {
                (self.trough, self.peak, self.trough_at) = (v, v, at);
            }
        } else if v < self.trough {
            (self.trough, self.trough_at) = (v, at);
        } else if v - self.trough >= margin {
            (self.rising, self.peak) = (true, v);
        }
        counted
    }

    /// Peaks counted so far.
    pub fn count(&self) -> u32 {
        self.count
    }
}
