//! A succeeded job's final particle state as the store keeps it (little-endian f32, 16 bytes a
//! particle: position x, y, z in mm, then the equivalent plastic strain) and as clients download
//! it: a VTK XML unstructured grid (`.vtu`, one vertex cell per particle) that ParaView opens,
//! with the plastic strain and the displacement from the start (mm) as point data.

use crate::solver::Snapshot;
use vtkio::model::{
    Attribute, Attributes, ByteOrder, CellType, Cells, DataArray, DataSet, ElementType, IOBuffer,
    UnstructuredGridPiece, Version, VertexNumbers, Vtk,
};

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

/// The state as a `.vtu` document; `initial_mm` (same order and length) gives the displacement.
pub fn vtu(title: &str, initial_mm: &[[f64; 3]], state: &FinalState) -> anyhow::Result<Vec<u8>> {
    anyhow::ensure!(
        initial_mm.len() == state.len(),
        "{} start positions for {} particles",
        initial_mm.len(),
        state.len()
    );
    let n = state.len() as u64;
    let points: Vec<f32> = state.position_mm.iter().flatten().copied().collect();
    let displacement: Vec<f32> = state
        .position_mm
        .iter()
        .zip(initial_mm)
        .flat_map(|(x, x0)| (0..3).map(move |k| x[k] - x0[k] as f32))
        .collect();
    let vtk = Vtk {
        version: Version::new_xml(1, 0),
        title: title.to_string(),
        byte_order: ByteOrder::LittleEndian,
        file_path: None,
        data: DataSet::inline(UnstructuredGridPiece {
            points: IOBuffer::F32(points),
            cells: Cells {
                cell_verts: VertexNumbers::XML {
                    connectivity: (0..n).collect(),
                    offsets: (1..=n).collect(),
                },
                types: vec![CellType::Vertex; n as usize],
            },
            data: Attributes {
                point: vec![
                    Attribute::DataArray(DataArray {
                        name: "plastic_strain".into(),
                        elem: ElementType::Scalars {
                            num_comp: 1,
                            lookup_table: None,
                        },
                        data: IOBuffer::F32(state.plastic_strain.clone()),
                    }),
                    Attribute::DataArray(DataArray {
                        name: "displacement_mm".into(),
                        elem: ElementType::Vectors,
                        data: IOBuffer::F32(displacement),
                    }),
                ],
                cell: vec![],
            },
        }),
    };
    let mut out = Vec::new();
    vtk.write_xml(&mut out)?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

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
        let bytes = vtu("test", &s.initial_mm, &state).unwrap();
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
        assert!(vtu("bad", &s.initial_mm[..2], &state).is_err());
    }
}
