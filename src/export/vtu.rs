//! A run's final particle state as the server's store keeps it (little-endian f32, 16 bytes a
//! particle: position x, y, z in mm, then the equivalent plastic strain) and as it is exported:
//! a VTK XML unstructured grid (`.vtu`, one vertex cell per particle) that ParaView opens, with
//! the plastic strain and the displacement from the start (mm) as point data.
//!
//! The file is written straight to any `Write` (the download streams it in chunks), never
//! built whole: its arrays are inline base64 of (u64 byte count, little-endian values), as
//! vtkio and VTK write them.

use crate::solver::Snapshot;
use base64::engine::general_purpose::STANDARD;
use base64::write::EncoderWriter;
use std::io::{self, Write};

/// Bytes per particle in the stored form.
pub const BYTES_PER_PARTICLE: usize = 16;

/// The final state of every particle, in the case's particle order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FinalState {
    /// Final positions, mm.
    pub position_mm: Vec<[f32; 3]>,
    /// Equivalent plastic strain.
    pub plastic_strain: Vec<f32>,
}

impl FinalState {
    pub fn len(&self) -> usize {
        self.position_mm.len()
    }

    pub fn is_empty(&self) -> bool {
        self.position_mm.is_empty()
    }
}

impl FinalState {
    /// A run's final state, in f32.
    pub fn of(snapshot: &Snapshot) -> FinalState {
        FinalState {
            position_mm: snapshot
                .position_mm
                .iter()
                .map(|x| x.map(|v| v as f32))
                .collect(),
            plastic_strain: snapshot.plastic_strain.iter().map(|&e| e as f32).collect(),
        }
    }
}

/// The stored form of a run's final state.
pub fn encode(snapshot: &Snapshot) -> Vec<u8> {
    let mut out = Vec::with_capacity(snapshot.position_mm.len() * BYTES_PER_PARTICLE);
    for (x, e) in snapshot.position_mm.iter().zip(&snapshot.plastic_strain) {
        for v in [x[0], x[1], x[2], *e] {
            out.extend_from_slice(&(v as f32).to_le_bytes());
        }
    }
    out
}

/// The stored form back; `None` when the bytes do not hold `particles` particles.
pub fn decode(particles: usize, bytes: &[u8]) -> Option<FinalState> {
    if bytes.len() != particles.checked_mul(BYTES_PER_PARTICLE)? {
        return None;
    }
    let mut state = FinalState {
        position_mm: Vec::with_capacity(particles),
        plastic_strain: Vec::with_capacity(particles),
    };
    for chunk in bytes.chunks_exact(BYTES_PER_PARTICLE) {
        let f = |k: usize| f32::from_le_bytes([chunk[k], chunk[k + 1], chunk[k + 2], chunk[k + 3]]);
        state.position_mm.push([f(0), f(4), f(8)]);
        state.plastic_strain.push(f(12));
    }
    Some(state)
}

/// VTK's cell type of a single vertex.
const VTK_VERTEX: u8 = 1;

/// Writes the state as a `.vtu` document to `out`; `initial_mm` (same order and length) gives
/// the displacement. Memory: a few bytes beyond what `out` buffers.
pub fn write_vtu(
    out: &mut impl Write,
    initial_mm: &[[f64; 3]],
    state: &FinalState,
    note: Option<&str>,
) -> io::Result<()> {
    let n = state.len();
    begin(out, initial_mm.len(), n, note)?;
    scalars(out, "plastic_strain", &state.plastic_strain)?;
    displacement(out, initial_mm, &state.position_mm)?;
    end(out, &state.position_mm)
}

/// The document up to its point data: the header, `note` as a comment, one piece of `n`
/// points; an error, before anything is written, when there are not `n` start positions
/// (`starts`) to measure the displacement from.
pub(super) fn begin(
    out: &mut impl Write,
    starts: usize,
    n: usize,
    note: Option<&str>,
) -> io::Result<()> {
    if starts != n {
        return Err(io::Error::other(format!(
            "{starts} start positions for {n} particles"
        )));
    }
    write!(
        out,
        "<?xml version=\"1.0\"?>\n\
         <VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" \
         header_type=\"UInt64\">\n"
    )?;
    if let Some(note) = note {
        // A comment may not hold "--".
        writeln!(out, "<!-- {} -->", note.replace("--", "- -"))?;
    }
    write!(
        out,
        "<UnstructuredGrid>\n<Piece NumberOfPoints=\"{n}\" NumberOfCells=\"{n}\">\n<PointData>\n"
    )
}

/// The displacement from the start, mm, as point data.
pub(super) fn displacement(
    out: &mut impl Write,
    initial_mm: &[[f64; 3]],
    position_mm: &[[f32; 3]],
) -> io::Result<()> {
    array(
        out,
        "Float32",
        Some("displacement_mm"),
        3,
        position_mm.len() * 12,
        |w| {
            for (x, x0) in position_mm.iter().zip(initial_mm) {
                for k in 0..3 {
                    w.write_all(&(x[k] - x0[k] as f32).to_le_bytes())?;
                }
            }
            Ok(())
        },
    )
}

/// The rest of the document after the point data: the points at `position_mm` and one vertex
/// cell each.
pub(super) fn end(out: &mut impl Write, position_mm: &[[f32; 3]]) -> io::Result<()> {
    let n = position_mm.len();
    out.write_all(b"</PointData>\n<CellData>\n</CellData>\n<Points>\n")?;
    array(out, "Float32", None, 3, n * 12, |w| {
        for x in position_mm {
            for v in x {
                w.write_all(&v.to_le_bytes())?;
            }
        }
        Ok(())
    })?;
    out.write_all(b"</Points>\n<Cells>\n")?;
    array(out, "Int64", Some("connectivity"), 1, n * 8, |w| {
        (0..n as i64).try_for_each(|i| w.write_all(&i.to_le_bytes()))
    })?;
    array(out, "Int64", Some("offsets"), 1, n * 8, |w| {
        (1..=n as i64).try_for_each(|i| w.write_all(&i.to_le_bytes()))
    })?;
    array(out, "UInt8", Some("types"), 1, n, |w| {
        (0..n).try_for_each(|_| w.write_all(&[VTK_VERTEX]))
    })?;
    out.write_all(b"</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n")
}

/// One float per point, named.
pub(super) fn scalars(out: &mut impl Write, name: &str, values: &[f32]) -> io::Result<()> {
    array(out, "Float32", Some(name), 1, values.len() * 4, |w| {
        values
            .iter()
            .try_for_each(|v| w.write_all(&v.to_le_bytes()))
    })
}

/// One inline binary `DataArray`: base64 of the byte count (u64) then `bytes` bytes of values,
/// as `values` writes them.
pub(super) fn array<W: Write>(
    out: &mut W,
    kind: &str,
    name: Option<&str>,
    components: u32,
    bytes: usize,
    values: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> io::Result<()> {
    named_array(out, kind, name, components, &[], bytes, values)
}

/// [`array`] with a name for each component (`ComponentName0`…), as ParaView shows them.
pub(super) fn named_array<W: Write>(
    out: &mut W,
    kind: &str,
    name: Option<&str>,
    components: u32,
    component_names: &[&str],
    bytes: usize,
    values: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> io::Result<()> {
    let name = name.map_or(String::new(), |n| format!(" Name=\"{n}\""));
    let labels: String = component_names
        .iter()
        .enumerate()
        .map(|(i, c)| format!(" ComponentName{i}=\"{c}\""))
        .collect();
    write!(
        out,
        "<DataArray type=\"{kind}\"{name} NumberOfComponents=\"{components}\"{labels} \
         format=\"binary\">"
    )?;
    {
        // Small writes, buffered before the encoder so that it encodes in long runs.
        let mut encoder = EncoderWriter::new(&mut *out, &STANDARD);
        encoder.write_all(&(bytes as u64).to_le_bytes())?;
        let mut buffered = io::BufWriter::with_capacity(48 * 1024, &mut encoder);
        values(&mut buffered)?;
        buffered.flush()?;
        drop(buffered);
        encoder.finish()?;
    }
    out.write_all(b"</DataArray>\n")
}

/// The state as a `.vtu` document in memory (tests, small states).
pub fn vtu(initial_mm: &[[f64; 3]], state: &FinalState) -> io::Result<Vec<u8>> {
    let mut out = Vec::new();
    write_vtu(&mut out, initial_mm, state, None)?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use vtkio::model::{Attribute, DataSet, Vtk};

    fn snapshot() -> Snapshot {
        Snapshot {
            initial_mm: vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0], [7.0, 8.0, 9.0]],
            position_mm: vec![[1.5, 2.0, 2.0], [4.0, 5.25, 5.0], [7.0, 8.0, 8.5]],
            plastic_strain: vec![0.0, 0.125, 0.5],
        }
    }

    #[test]
    fn the_stored_form_round_trips_and_refuses_a_wrong_length() {
        let s = snapshot();
        let bytes = encode(&s);
        assert_eq!(bytes.len(), 3 * BYTES_PER_PARTICLE);
        let back = decode(3, &bytes).unwrap();
        assert_eq!(back.position_mm[1], [4.0, 5.25, 5.0]);
        assert_eq!(back.plastic_strain, vec![0.0, 0.125, 0.5]);
        assert!(decode(4, &bytes).is_none());
        assert!(decode(usize::MAX, &bytes).is_none());
    }

    #[test]
    fn the_vtu_reads_back_with_every_particle_and_its_displacement() {
        let s = snapshot();
        let state = decode(3, &encode(&s)).unwrap();
        let bytes = vtu(&s.initial_mm, &state).unwrap();
        let text = String::from_utf8(bytes.clone()).unwrap();
        assert!(text.contains("UnstructuredGrid") && text.contains("plastic_strain"));
        let vtk = Vtk::parse_xml(&bytes[..]).unwrap();
        let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else {
            panic!("not an unstructured grid")
        };
        let piece = pieces[0].load_piece_data(None).unwrap();
        assert_eq!(piece.num_points(), 3);
        assert_eq!(piece.cells.types.len(), 3);
        let displacement = piece
            .data
            .point
            .iter()
            .find(|a| a.name() == "displacement_mm")
            .unwrap();
        let Attribute::DataArray(array) = displacement else {
            panic!("displacement is not a data array")
        };
        let d: Vec<f32> = array.data.clone().cast_into().unwrap();
        assert_eq!(d, vec![0.5, 0.0, -1.0, 0.0, 0.25, -1.0, 0.0, 0.0, -0.5]);
        assert!(vtu(&s.initial_mm[..2], &state).is_err());
    }
}
