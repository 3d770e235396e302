use super::*;
use vtkio::model::{Attribute, DataSet, Vtk};

fn frame() -> Frame {
    Frame {
        index: 1,
        count: 3,
        time_ms: 0.25,
        travel_mm: 2.5,
        position_mm: vec![[1.5, 2.0, 2.0], [4.0, 5.25, 5.0]],
        velocity_m_s: vec![[0.0, 0.0, -1.5], [0.5, 0.0, 0.0]],
        stress_mpa: vec![
            [-10.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            [1.0, 2.0, 3.0, 4.0, 5.0, 6.0],
        ],
        volume_mm3: vec![0.125, 0.25],
        plastic_strain: vec![0.0, 0.5],
    }
}

const START: [[f64; 3]; 2] = [[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]];

fn point_array(piece: &vtkio::model::UnstructuredGridPiece, name: &str) -> (u32, Vec<f32>) {
    let found = piece.data.point.iter().find(|a| a.name() == name);
    let Some(Attribute::DataArray(array)) = found else {
        panic!("no point data array {name}")
    };
    let values: Vec<f32> = array.data.clone().cast_into().unwrap();
    (array.elem.num_comp(), values)
}

#[test]
fn the_stored_frame_round_trips_and_refuses_a_wrong_length() {
    let bytes = encode(&frame());
    assert_eq!(bytes.len(), 2 * FRAME_BYTES_PER_PARTICLE);
    let back = decode(2, &bytes).unwrap();
    assert_eq!(back.position_mm[1], [4.0, 5.25, 5.0]);
    assert_eq!(back.stress_mpa[1], [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
    assert_eq!(back.velocity_m_s[0], [0.0, 0.0, -1.5]);
    assert_eq!(back.volume_mm3, vec![0.125, 0.25]);
    assert_eq!(back.plastic_strain, vec![0.0, 0.5]);
    assert!(decode(3, &bytes).is_none());
    assert!(decode(usize::MAX, &bytes).is_none());
}

#[test]
fn von_mises_is_the_uniaxial_stress_of_a_bar_and_counts_each_shear_three_times() {
    assert_eq!(von_mises(&[-10.0, 0.0, 0.0, 0.0, 0.0, 0.0]), 10.0);
    assert_eq!(von_mises(&[7.0, 7.0, 7.0, 0.0, 0.0, 0.0]), 0.0);
    let shear = von_mises(&[0.0, 0.0, 0.0, 0.0, 0.0, 2.0]);
    assert!((shear - 2.0 * 3f32.sqrt()).abs() < 1e-6);
}

#[test]
fn a_frame_vtu_parses_with_every_field_at_its_size() {
    let state = decode(2, &encode(&frame())).unwrap();
    let mut bytes = Vec::new();
    write_frame_vtu(&mut bytes, &START, &state, Some("frame -- 1")).unwrap();
    let vtk = Vtk::parse_xml(&bytes[..]).unwrap();
    let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else {
        panic!("not an unstructured grid")
    };
    let piece = pieces[0].load_piece_data(None).unwrap();
    assert_eq!(piece.num_points(), 2);
    assert_eq!(piece.cells.types.len(), 2);
    let points: Vec<f32> = piece.points.clone().cast_into().unwrap();
    assert_eq!(points, vec![1.5, 2.0, 2.0, 4.0, 5.25, 5.0]);
    for (name, components) in [
        ("displacement_mm", 3),
        ("plastic_strain", 1),
        ("stress_mpa", 6),
        ("von_mises_mpa", 1),
        ("velocity_m_s", 3),
        ("volume_mm3", 1),
    ] {
        let (comp, values) = point_array(&piece, name);
        assert_eq!(comp, components, "{name}");
        assert_eq!(values.len(), 2 * components as usize, "{name}");
    }
    let (_, d) = point_array(&piece, "displacement_mm");
    assert_eq!(d, vec![0.5, 0.0, -1.0, 0.0, 0.25, -1.0]);
    // VTK's tensor order: XX, YY, ZZ, XY, YZ, XZ.
    let (_, s) = point_array(&piece, "stress_mpa");
    assert_eq!(&s[6..], &[1.0, 2.0, 3.0, 6.0, 4.0, 5.0]);
    let (_, vm) = point_array(&piece, "von_mises_mpa");
    assert_eq!(vm[0], 10.0);
    let (_, v) = point_array(&piece, "velocity_m_s");
    assert_eq!(v, vec![0.0, 0.0, -1.5, 0.5, 0.0, 0.0]);
    let (_, vol) = point_array(&piece, "volume_mm3");
    assert_eq!(vol, vec![0.125, 0.25]);
    let text = String::from_utf8(bytes).unwrap();
    assert!(text.contains("ComponentName3=\"XY\""));
    assert!(text.contains("<!-- frame - - 1 -->"));
    assert!(write_frame_vtu(&mut Vec::new(), &START[..1], &state, None).is_err());
}

#[test]
fn the_pvd_lists_each_frame_by_its_relative_file_and_travel() {
    let frames = [
        FrameTime {
            index: 0,
            travel_mm: 0.0,
            time_ms: 0.0,
        },
        FrameTime {
            index: 1,
            travel_mm: 2.5,
            time_ms: 0.25,
        },
    ];
    let mut out = Vec::new();
    write_pvd(&mut out, &frames).unwrap();
    let text = String::from_utf8(out).unwrap();
    assert!(text.contains("type=\"Collection\""));
    assert!(text.contains("<DataSet timestep=\"0\" group=\"\" part=\"0\" file=\"frames/0.vtu\"/>"));
    assert!(
        text.contains("<DataSet timestep=\"2.5\" group=\"\" part=\"0\" file=\"frames/1.vtu\"/>")
    );
    assert_eq!(text.matches("<DataSet").count(), 2);
}

#[test]
fn a_frame_is_named_only_as_frame_file_writes_it() {
    for k in [0, 1, 10, 4_294_967_295] {
        let file = frame_file(k);
        assert_eq!(frame_index(file.strip_prefix("frames/").unwrap()), Some(k));
    }
    for name in [
        "+1.vtu",
        "01.vtu",
        "00.vtu",
        "-0.vtu",
        ".vtu",
        "1.vtk",
        " 1.vtu",
        "1 .vtu",
        "4294967296.vtu",
    ] {
        assert_eq!(frame_index(name), None, "{name}");
    }
}
