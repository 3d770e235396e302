//! Checkpoints: a run's whole state at a step boundary as bytes, so that a run stopped there
//! continues on any machine with the same bits as one that never stopped.
//!
//! What a run carries from step to step is the particles (position, velocity, stress, volume,
//! plastic strain and their order in memory), the plates, the clock, the energy books, the
//! next step's signal speed and mass floor, and the run loop's own sums (the history rows so
//! far, the open row's impulses, the cost figures). Everything else is rebuilt from the case:
//! the particles' masses and trigger factors (by particle id) and every grid and scratch
//! buffer, which each step recomputes from the particles. The particles are restored in the
//! order they had in memory, so every sum of the next steps runs in the same order.
//!
//! Layout (little-endian): the magic `CRUSHCKP`, the format version, the case (its physics as
//! JSON: a checkpoint of another case is refused), the loop, the state, the plates, the rows,
//! the particles, and a CRC-32 of everything before it. Size: 116 bytes a particle plus
//! 112 bytes a history row, plus about a kilobyte ([`Checkpoint::size_for`]).

use crate::solver::engine::history::HistoryRow;
use crate::solver::engine::kernel::{Energies, Engine};
use crate::solver::model::case::Case;
use crate::solver::Real;
use nalgebra::Vector3;

const MAGIC: &[u8; 8] = b"CRUSHCKP";
/// Changes whenever the layout or the meaning of a field changes: a checkpoint of another
/// version is refused, never misread.
const VERSION: u32 = 1;
/// Bytes a particle takes: x, v (3 f64 each), stress (6 f64), volume, plastic strain (f64),
/// id (u32).
const PARTICLE_BYTES: usize = 8 * (3 + 3 + 6 + 1 + 1) + 4;
const ROW_BYTES: usize = 8 * HistoryRow::COLUMNS.len();
/// Plates of every scene: the moving one and the fixed one.
const PLATES: u32 = 2;

/// A run's state at a step boundary, encoded.
#[derive(Debug, Clone, PartialEq)]
pub struct Checkpoint {
    /// Steps taken when it was written.
    pub step: u64,
    /// Share of the crush distance done, 0..1 (of the history rows completed).
    pub fraction: f64,
    pub bytes: Vec<u8>,
}

/// Why a checkpoint cannot be used: the run starts over instead.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CheckpointError {
    #[error("not a crush checkpoint")]
    NotACheckpoint,
    #[error("written by checkpoint format {0}, this build reads format {VERSION}")]
    Version(u32),
    #[error("its checksum does not match: the bytes were damaged")]
    Checksum,
    #[error("it ends early: the bytes were cut short")]
    Truncated,
    #[error("it belongs to another case")]
    OtherCase,
    #[error("it does not fit this case: {0}")]
    Mismatch(String),
}

/// Where the run loop stood: what it has summed since the run began (`rows` finished, the open
/// row's sums) and what it has measured of the run so far.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct Tally {
    pub rows: Vec<HistoryRow>,
    /// Simulated time at which the open row began, ms.
    pub row_start_ms: Real,
    /// The plates' impulses over the open row so far (top, bottom), N·ms.
    pub impulse: [Real; 2],
    /// Kinetic energy after the open row's last step, mJ.
    pub kinetic: Real,
    /// Smallest and largest stable time step so far, ms.
    pub dt_min_ms: Real,
    pub dt_max_ms: Real,
    pub active_cells_max: u64,
    /// Sum and count of the plate gaps of the rows with a load, mm.
    pub gap_sum: Real,
    pub gap_rows: u32,
    /// Wall time of the run before this stretch of it, s.
    pub elapsed_s: f64,
}

impl Tally {
    /// At the start of a run.
    pub fn new(points: usize) -> Tally {
        Tally {
            rows: Vec::with_capacity(points),
            dt_min_ms: Real::INFINITY,
            ..Default::default()
        }
    }
}

/// A decoded checkpoint, checked against its case: [`crate::solver::resume`] continues from it.
#[derive(Debug, Clone)]
pub struct Resume {
    tally: Tally,
    time: Real,
    steps: u64,
    energy: Energies,
    signal: Real,
    mass_floor: Real,
    /// Each plate's z (mm) and velocity (mm/ms), top then bottom.
    plates: [(Real, Real); PLATES as usize],
    x: Vec<Vector3<Real>>,
    v: Vec<Vector3<Real>>,
    stress: Vec<[Real; 6]>,
    vol: Vec<Real>,
    plastic_strain: Vec<Real>,
    id: Vec<u32>,
}

impl Checkpoint {
    /// Bytes a checkpoint of `particles` particles and `rows` history rows takes, at most.
    pub fn size_for(case: &Case, particles: u64, rows: u64) -> u64 {
        let fixed = 8 + 4 + 4 + physics(case).len() as u64 + 256;
        fixed + particles * PARTICLE_BYTES as u64 + rows * ROW_BYTES as u64 + 4
    }

    /// The state of `sim` and of the run loop, for `case`.
    pub(crate) fn write<E: Engine>(case: &Case, sim: &E, tally: &Tally, points: usize) -> Self {
        let state = sim.state();
        let p = &state.scene.particles;
        let rows = tally.rows.len() as u64;
        let mut w = Writer(Vec::with_capacity(
            Checkpoint::size_for(case, p.len() as u64, rows) as usize,
        ));
        w.0.extend_from_slice(MAGIC);
        w.u32(VERSION);
        w.text(&physics(case));
        // The loop.
        w.u64(rows);
        w.f64(tally.row_start_ms);
        w.f64s(&tally.impulse);
        w.f64(tally.kinetic);
        w.f64(tally.dt_min_ms);
        w.f64(tally.dt_max_ms);
        w.u64(tally.active_cells_max);
        w.f64(tally.gap_sum);
        w.u32(tally.gap_rows);
        w.f64(tally.elapsed_s);
        // The state.
        w.f64(state.time);
        w.u64(state.steps);
        let e = &state.energy;
        w.f64s(&[
            e.internal, e.plastic, e.work[0], e.work[1], e.catch, e.friction,
        ]);
        w.f64(state.signal);
        w.f64(state.mass_floor);
        w.u32(state.scene.plates.len() as u32);
        for plate in &state.scene.plates {
            w.f64s(&[plate.z, plate.velocity]);
        }
        for row in &tally.rows {
            w.f64s(&row.values());
        }
        w.u64(p.len() as u64);
        for i in 0..p.len() {
            w.f64s(p.x[i].as_slice());
            w.f64s(p.v[i].as_slice());
            w.f64s(&p.stress[i]);
            w.f64s(&[p.vol[i], p.plastic_strain[i]]);
            w.u32(p.id[i]);
        }
        let crc = crc32fast::hash(&w.0);
        w.u32(crc);
        Checkpoint {
            step: state.steps,
            fraction: rows as f64 / points.max(1) as f64,
            bytes: w.0,
        }
    }
}

impl Resume {
    /// Where the run stood when the checkpoint was written, as the progress report of its last
    /// finished history row (`points` rows in the whole run); `None` before the first row.
    pub fn progress(&self, points: usize) -> Option<crate::solver::engine::status::Progress> {
        let row = self.tally.rows.last()?;
        Some(crate::solver::engine::status::Progress {
            step: self.steps,
            time_ms: row.time_ms,
            displacement_mm: row.displacement_mm,
            load_n: row.load_top_n,
            fraction: self.tally.rows.len() as f64 / points.max(1) as f64,
            elapsed_s: self.tally.elapsed_s,
            eta_s: 0.0,
            error_bar: None,
        })
    }

    /// Decodes `bytes` and checks them against `case`: the same physics, a particle count the
    /// case gives, rows no more than it asks for.
    pub fn read(case: &Case, bytes: &[u8]) -> Result<Resume, CheckpointError> {
        if bytes.len() < MAGIC.len() + 8 || &bytes[..MAGIC.len()] != MAGIC {
            return Err(CheckpointError::NotACheckpoint);
        }
        let mut r = Reader {
            bytes: &bytes[..bytes.len() - 4],
            at: MAGIC.len(),
        };
        let version = r.u32()?;
        if version != VERSION {
            return Err(CheckpointError::Version(version));
        }
        let stored = u32::from_le_bytes(bytes[bytes.len() - 4..].try_into().unwrap_or([0; 4]));
        if crc32fast::hash(&bytes[..bytes.len() - 4]) != stored {
            return Err(CheckpointError::Checksum);
        }
        if r.text()? != physics(case) {
            return Err(CheckpointError::OtherCase);
        }
        let rows = r.u64()?;
        let points = case.spec().output.history_points as u64;
        if rows > points {
            return Err(CheckpointError::Mismatch(format!(
                "{rows} history rows where the case has {points}"
            )));
        }
        let mut tally = Tally {
            row_start_ms: r.f64()?,
            impulse: [r.f64()?, r.f64()?],
            kinetic: r.f64()?,
            dt_min_ms: r.f64()?,
            dt_max_ms: r.f64()?,
            active_cells_max: r.u64()?,
            gap_sum: r.f64()?,
            gap_rows: r.u32()?,
            elapsed_s: r.f64()?,
            rows: Vec::new(),
        };
        let time = r.f64()?;
        let steps = r.u64()?;
        let e = r.f64s::<6>()?;
        let energy = Energies {
            internal: e[0],
            plastic: e[1],
            work: [e[2], e[3]],
            catch: e[4],
            friction: e[5],
        };
        let signal = r.f64()?;
        let mass_floor = r.f64()?;
        let plates = r.u32()?;
        if plates != PLATES {
            return Err(CheckpointError::Mismatch(format!(
                "{plates} plates where a scene has {PLATES}"
            )));
        }
        let plates = [(r.f64()?, r.f64()?), (r.f64()?, r.f64()?)];
        tally.rows = (0..rows)
            .map(|_| Ok(HistoryRow::from_values(r.f64s()?)))
            .collect::<Result<_, CheckpointError>>()?;
        let n = r.u64()?;
        if n != case.particle_count() {
            return Err(CheckpointError::Mismatch(format!(
                "{n} particles where the case has {}",
                case.particle_count()
            )));
        }
        let n = n as usize;
        if r.left() != n * PARTICLE_BYTES {
            return Err(CheckpointError::Truncated);
        }
        let mut resume = Resume {
            tally,
            time,
            steps,
            energy,
            signal,
            mass_floor,
            plates,
            x: Vec::with_capacity(n),
            v: Vec::with_capacity(n),
            stress: Vec::with_capacity(n),
            vol: Vec::with_capacity(n),
            plastic_strain: Vec::with_capacity(n),
            id: Vec::with_capacity(n),
        };
        let mut seen = vec![false; n];
        for _ in 0..n {
            resume.x.push(Vector3::from(r.f64s::<3>()?));
            resume.v.push(Vector3::from(r.f64s::<3>()?));
            resume.stress.push(r.f64s::<6>()?);
            resume.vol.push(r.f64()?);
            resume.plastic_strain.push(r.f64()?);
            let id = r.u32()?;
            match seen.get_mut(id as usize) {
                Some(s) if !*s => *s = true,
                _ => {
                    return Err(CheckpointError::Mismatch(format!(
                        "particle id {id} is out of range or repeated"
                    )))
                }
            }
            resume.id.push(id);
        }
        Ok(resume)
    }

    /// Steps the checkpointed run had taken.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// Puts the checkpoint's state into `sim`, a fresh engine built from the case it was read
    /// for (which fixed the particle count and the plates), and returns the run loop's sums.
    pub(crate) fn restore<E: Engine>(self, sim: &mut E) -> Tally {
        let state = sim.state_mut();
        let scene = &mut state.scene;
        debug_assert_eq!(self.x.len(), scene.particles.len());
        debug_assert_eq!(scene.plates.len(), PLATES as usize);
        for (plate, (z, velocity)) in scene.plates.iter_mut().zip(&self.plates) {
            plate.z = *z;
            plate.velocity = *velocity;
        }
        let p = &mut scene.particles;
        // The masses and trigger factors are the case's: taken from the fresh scene by id.
        let mut at = vec![0usize; p.len()];
        for (i, &id) in p.id.iter().enumerate() {
            at[id as usize] = i;
        }
        p.mass = self.id.iter().map(|&id| p.mass[at[id as usize]]).collect();
        if !p.yield_scale.is_empty() {
            p.yield_scale = self
                .id
                .iter()
                .map(|&id| p.yield_scale[at[id as usize]])
                .collect();
        }
        p.x = self.x;
        p.v = self.v;
        p.stress = self.stress;
        p.vol = self.vol;
        p.plastic_strain = self.plastic_strain;
        p.id = self.id;
        state.time = self.time;
        state.steps = self.steps;
        state.energy = self.energy;
        state.signal = self.signal;
        state.mass_floor = self.mass_floor;
        self.tally
    }
}

/// The case's physics as JSON (its label left out): a checkpoint belongs to exactly this.
fn physics(case: &Case) -> String {
    let mut spec = case.spec().clone();
    spec.label = None;
    // A spec is plain data with string keys, which serde_json always writes; were it ever to
    // fail, every case would share the key "" and accept another case's checkpoint, so fail
    // loudly instead.
    serde_json::to_string(&spec).expect("a case spec serialises to JSON")
}

struct Writer(Vec<u8>);

impl Writer {
    fn u32(&mut self, v: u32) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn u64(&mut self, v: u64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn f64(&mut self, v: f64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn f64s(&mut self, v: &[f64]) {
        for x in v {
            self.f64(*x);
        }
    }
    fn text(&mut self, s: &str) {
        self.u32(s.len() as u32);
        self.0.extend_from_slice(s.as_bytes());
    }
}

struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn take(&mut self, n: usize) -> Result<&[u8], CheckpointError> {
        let end = self.at.checked_add(n).ok_or(CheckpointError::Truncated)?;
        let out = self
            .bytes
            .get(self.at..end)
            .ok_or(CheckpointError::Truncated)?;
        self.at = end;
        Ok(out)
    }
    fn left(&self) -> usize {
        self.bytes.len() - self.at
    }
    fn u32(&mut self) -> Result<u32, CheckpointError> {
        Ok(u32::from_le_bytes(
            self.take(4)?.try_into().unwrap_or([0; 4]),
        ))
    }
    fn u64(&mut self) -> Result<u64, CheckpointError> {
        Ok(u64::from_le_bytes(
            self.take(8)?.try_into().unwrap_or([0; 8]),
        ))
    }
    fn f64(&mut self) -> Result<f64, CheckpointError> {
        Ok(f64::from_le_bytes(
            self.take(8)?.try_into().unwrap_or([0; 8]),
        ))
    }
    fn f64s<const N: usize>(&mut self) -> Result<[f64; N], CheckpointError> {
        let mut out = [0.0; N];
        for v in &mut out {
            *v = self.f64()?;
        }
        Ok(out)
    }
    fn text(&mut self) -> Result<String, CheckpointError> {
        let n = self.u32()? as usize;
        String::from_utf8(self.take(n)?.to_vec()).map_err(|_| CheckpointError::NotACheckpoint)
    }
}

#[cfg(test)]
mod tests;
