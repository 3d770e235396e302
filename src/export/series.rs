//! A run's time series for ParaView (`output.frames`): each frame's particle state as the
//! server's store keeps it (little-endian f32, 56 bytes a particle: position x, y, z in mm,
//! equivalent plastic strain, Cauchy stress xx, yy, zz, yz, xz, xy in MPa, velocity x, y, z in
//! m/s, volume in mm³), each frame as a `.vtu` written as `state.vtu` is (streamed, inline
//! base64), and the `.pvd` collection that ParaView opens as one animated data set, its time
//! the top plate's travel (mm). The frames' files are `frames/{k}.vtu` beside the `.pvd`, the
//! names the server serves them under.

use super::vtu::{array, begin, displacement, end, named_array, scalars};
use crate::solver::Frame;
use std::io::{self, Write};

/// Bytes per particle in a frame's stored form.
pub const FRAME_BYTES_PER_PARTICLE: usize = 56;

/// f32 values per particle in the stored form.
const VALUES: usize = FRAME_BYTES_PER_PARTICLE / 4;

/// One frame's particle state, in f32, in the case's particle order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FrameState {
    pub position_mm: Vec<[f32; 3]>,
    pub plastic_strain: Vec<f32>,
    /// Cauchy stress, Voigt order xx, yy, zz, yz, xz, xy, MPa.
    pub stress_mpa: Vec<[f32; 6]>,
    pub velocity_m_s: Vec<[f32; 3]>,
    pub volume_mm3: Vec<f32>,
}

impl FrameState {
    pub fn len(&self) -> usize {
        self.position_mm.len()
    }

    pub fn is_empty(&self) -> bool {
        self.position_mm.is_empty()
    }
}

/// The stored form of a frame.
pub fn encode(frame: &Frame) -> Vec<u8> {
    let mut out = Vec::with_capacity(frame.position_mm.len() * FRAME_BYTES_PER_PARTICLE);
    for i in 0..frame.position_mm.len() {
        let (x, s, v) = (
            frame.position_mm[i],
            frame.stress_mpa[i],
            frame.velocity_m_s[i],
        );
        let values: [f64; VALUES] = [
            x[0],
            x[1],
            x[2],
            frame.plastic_strain[i],
            s[0],
            s[1],
            s[2],
            s[3],
            s[4],
            s[5],
            v[0],
            v[1],
            v[2],
            frame.volume_mm3[i],
        ];
        for v in values {
            out.extend_from_slice(&(v as f32).to_le_bytes());
        }
    }
    out
}

/// The stored form back; `None` when the bytes do not hold `particles` particles.
pub fn decode(particles: usize, bytes: &[u8]) -> Option<FrameState> {
    if bytes.len() != particles.checked_mul(FRAME_BYTES_PER_PARTICLE)? {
        return None;
    }
    let mut state = FrameState::default();
    state.reserve(particles);
    state.extend_from(bytes);
    Some(state)
}

impl FrameState {
    /// Room for `particles` more particles.
    pub fn reserve(&mut self, particles: usize) {
        self.position_mm.reserve_exact(particles);
        self.plastic_strain.reserve_exact(particles);
        self.stress_mpa.reserve_exact(particles);
        self.velocity_m_s.reserve_exact(particles);
        self.volume_mm3.reserve_exact(particles);
    }

    /// Appends the particles of a piece of the stored form; false (and nothing appended) when
    /// it does not hold whole particles.
    pub fn extend_from(&mut self, bytes: &[u8]) -> bool {
        if !bytes.len().is_multiple_of(FRAME_BYTES_PER_PARTICLE) {
            return false;
        }
        for chunk in bytes.chunks_exact(FRAME_BYTES_PER_PARTICLE) {
            let f = |k: usize| {
                let b = &chunk[4 * k..4 * k + 4];
                f32::from_le_bytes([b[0], b[1], b[2], b[3]])
            };
            self.position_mm.push([f(0), f(1), f(2)]);
            self.plastic_strain.push(f(3));
            self.stress_mpa.push(std::array::from_fn(|j| f(4 + j)));
            self.velocity_m_s.push([f(10), f(11), f(12)]);
            self.volume_mm3.push(f(13));
        }
        true
    }
}

/// The von Mises stress of a Cauchy stress in Voigt order, MPa.
pub fn von_mises(s: &[f32; 6]) -> f32 {
    let s = s.map(f64::from);
    let normal = (s[0] - s[1]).powi(2) + (s[1] - s[2]).powi(2) + (s[2] - s[0]).powi(2);
    let shear = s[3] * s[3] + s[4] * s[4] + s[5] * s[5];
    (0.5 * normal + 3.0 * shear).sqrt() as f32
}

/// Writes a frame as a `.vtu` document to `out`; `initial_mm` (same order and length) gives the
/// displacement. Point data: `displacement_mm`, `plastic_strain`, `stress_mpa` (a symmetric
/// tensor in VTK's order XX, YY, ZZ, XY, YZ, XZ, which ParaView reads as such),
/// `von_mises_mpa`, `velocity_m_s`, `volume_mm3`. Memory: a few bytes beyond what `out`
/// buffers.
pub fn write_frame_vtu(
    out: &mut impl Write,
    initial_mm: &[[f64; 3]],
    state: &FrameState,
    note: Option<&str>,
) -> io::Result<()> {
    let n = state.len();
    begin(out, initial_mm.len(), n, note)?;
    displacement(out, initial_mm, &state.position_mm)?;
    scalars(out, "plastic_strain", &state.plastic_strain)?;
    let tensor = ["XX", "YY", "ZZ", "XY", "YZ", "XZ"];
    named_array(
        out,
        "Float32",
        Some("stress_mpa"),
        6,
        &tensor,
        n * 24,
        |w| {
            for s in &state.stress_mpa {
                // Voigt (xx, yy, zz, yz, xz, xy) to VTK's (xx, yy, zz, xy, yz, xz).
                for v in [s[0], s[1], s[2], s[5], s[3], s[4]] {
                    w.write_all(&v.to_le_bytes())?;
                }
            }
            Ok(())
        },
    )?;
    array(out, "Float32", Some("von_mises_mpa"), 1, n * 4, |w| {
        state
            .stress_mpa
            .iter()
            .try_for_each(|s| w.write_all(&von_mises(s).to_le_bytes()))
    })?;
    array(out, "Float32", Some("velocity_m_s"), 3, n * 12, |w| {
        for v in state.velocity_m_s.iter().flatten() {
            w.write_all(&v.to_le_bytes())?;
        }
        Ok(())
    })?;
    scalars(out, "volume_mm3", &state.volume_mm3)?;
    end(out, &state.position_mm)
}

/// Where a series' frame stands: its index, top-plate travel (mm) and simulated time (ms).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameTime {
    pub index: u32,
    pub travel_mm: f64,
    pub time_ms: f64,
}

/// The file name of frame `index`, relative to the `.pvd`.
pub fn frame_file(index: u32) -> String {
    format!("frames/{index}.vtu")
}

/// The index of a frame file's name as [`frame_file`] writes it (`{k}.vtu`, k in plain
/// decimal); none for any other spelling of a number (`+1.vtu`, `01.vtu`), so that each frame
/// has one name.
pub fn frame_index(name: &str) -> Option<u32> {
    let k = name.strip_suffix(".vtu")?;
    let canonical = k.bytes().all(|b| b.is_ascii_digit()) && (k == "0" || !k.starts_with('0'));
    if canonical {
        k.parse().ok()
    } else {
        None
    }
}

/// The note a frame's `.vtu` carries: where it stands, then `symmetry` (what a reduced model's
/// points stand for), if any.
pub fn frame_note(at: &FrameTime, count: u32, symmetry: Option<&str>) -> String {
    let mut note = format!(
        "frame {} of {count}: top-plate travel {} mm, time {} ms",
        at.index, at.travel_mm, at.time_ms
    );
    if let Some(symmetry) = symmetry {
        note.push_str("; ");
        note.push_str(symmetry);
    }
    note
}

/// Writes the `.pvd` collection of `frames` to `out`: one data set per frame, its time the
/// top plate's travel (mm), its file [`frame_file`].
pub fn write_pvd(out: &mut impl Write, frames: &[FrameTime]) -> io::Result<()> {
    write!(
        out,
        "<?xml version=\"1.0\"?>\n\
         <VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n\
         <!-- timestep: the top plate's travel, mm -->\n\
         <Collection>\n"
    )?;
    for f in frames {
        writeln!(
            out,
            "<DataSet timestep=\"{}\" group=\"\" part=\"0\" file=\"{}\"/><!-- time {} ms -->",
            f.travel_mm,
            frame_file(f.index),
            f.time_ms
        )?;
    }
    out.write_all(b"</Collection>\n</VTKFile>\n")
}

#[cfg(test)]
mod tests;
