//! OBJ import: counts, welding, spring kinds, and every bad-input error variant.

use std::path::Path;

use clothsim::mesh::{self, GridOrientation, GridSpec, ObjError, SpringKind, obj_from_str};

/// The 16×16-quad grid as OBJ text, two triangles per quad, shared vertices.
fn grid_triangles_obj(n: usize) -> String {
    let mut s = String::new();
    for j in 0..=n {
        for i in 0..=n {
            s += &format!("v {} 0 {}\n", i as f32 / n as f32, j as f32 / n as f32);
        }
    }
    let row = n + 1;
    for j in 0..n {
        for i in 0..n {
            let a = j * row + i + 1;
            let (b, c, d) = (a + 1, a + row, a + row + 1);
            s += &format!("f {a} {c} {d}\nf {a} {d} {b}\n");
        }
    }
    s
}

/// The same grid as a triangle soup: every triangle has its own three `v` lines.
fn grid_soup_obj(n: usize) -> String {
    let p = |i: usize, j: usize| format!("v {} 0 {}\n", i as f32 / n as f32, j as f32 / n as f32);
    let mut s = String::new();
    let mut k = 0;
    for j in 0..n {
        for i in 0..n {
            s += &(p(i, j) + &p(i, j + 1) + &p(i + 1, j + 1));
            s += &format!("f {} {} {}\n", k + 1, k + 2, k + 3);
            s += &(p(i, j) + &p(i + 1, j + 1) + &p(i + 1, j));
            s += &format!("f {} {} {}\n", k + 4, k + 5, k + 6);
            k += 6;
        }
    }
    s
}

#[test]
fn grid_16x16_triangles_gives_289_particles_512_triangles_800_springs() {
    let m = obj_from_str(&grid_triangles_obj(16), "grid.obj")
        .unwrap()
        .mesh;
    assert_eq!(m.positions.len(), 289);
    assert_eq!(m.triangles.len(), 512);
    assert_eq!(m.edges.len(), 800);
    // Interior edges: 800 − boundary 64 = 736, each with one bend pair.
    assert_eq!(m.bend_pairs.len(), 736);
}

#[test]
fn triangle_soup_welds_to_the_same_counts() {
    let build = obj_from_str(&grid_soup_obj(16), "soup.obj").unwrap();
    let m = build.mesh;
    assert_eq!(
        (m.positions.len(), m.triangles.len(), m.edges.len()),
        (289, 512, 800)
    );
    assert_eq!(m.bend_pairs.len(), 736);
    assert!(build.warnings.is_empty(), "{:?}", build.warnings);
}

#[test]
fn edges_are_unique_and_sorted() {
    let m = obj_from_str(&grid_soup_obj(8), "soup.obj").unwrap().mesh;
    assert!(m.edges.iter().all(|e| e[0] < e[1]));
    assert!(
        m.edges.windows(2).all(|w| w[0] < w[1]),
        "edges sorted, hence unique"
    );
}

#[test]
fn quads_give_shear_diagonals_and_generator_matches_its_obj() {
    let spec = GridSpec::square(16, 1.0, GridOrientation::Horizontal, glam::Vec3::ZERO);
    let generated = spec.build().unwrap();
    assert_eq!(generated.edge_count(SpringKind::Structural), 544);
    assert_eq!(generated.edge_count(SpringKind::Shear), 256);
    assert_eq!(
        generated.spring_count(SpringKind::Shear),
        512,
        "both diagonals"
    );
    assert_eq!(generated.spring_count(SpringKind::Bend), 480);
    let imported = obj_from_str(&spec.to_obj(), "grid.obj").unwrap().mesh;
    assert_eq!(
        generated, imported,
        "grid generator and its OBJ must give the same model"
    );
}

/// Particles come in the order of the file's `v` statements, not in the order faces first
/// use them (tobj's): here the faces start from the last vertex, and a second object shares
/// two vertices with the first, which weld into the particles the first object made.
#[test]
fn particles_keep_the_files_vertex_order() {
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 2 0 0\nv 2 1 0\n\
                o first\nf 4 3 1\nf 4 1 2\n\
                o second\nf 6 4 2\nf 2 5 6\n";
    let mesh = obj_from_str(text, "order.obj").unwrap().mesh;
    let x = |i: usize| mesh.positions[i].to_array();
    let want = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
        [2.0, 0.0, 0.0],
        [2.0, 1.0, 0.0],
    ];
    assert_eq!((0..6).map(x).collect::<Vec<_>>(), want);
    assert_eq!(mesh.triangles[0], [3, 2, 0]);
    assert_eq!(mesh.triangles[2], [5, 3, 1]);
}

/// A grid's particles are numbered row by row (`j·(quads + 1) + i`), as its vertices are
/// written and as the peer frameworks number theirs: neighbours along a row are one apart
/// and along a column one row apart, everywhere (the spring runs' vector loops rely on it).
#[test]
fn a_grid_is_numbered_row_by_row() {
    let spec = GridSpec::square(8, 1.0, GridOrientation::Vertical, glam::Vec3::ZERO);
    let mesh = spec.build().unwrap();
    assert_eq!(mesh.positions, spec.polygons().positions);
    let row = 9;
    for &[a, b] in &mesh.edges {
        let step = b - a;
        assert!(
            step == 1 && b % row != 0 || step == row || step == row + 1 || step == row - 1,
            "edge {a}–{b}"
        );
    }
}

/// A quad's two diagonals are both shear springs, so shear stiffness is the same along
/// both diagonal directions; bend pairs never repeat each other, an edge or a diagonal.
#[test]
fn a_10x10_quad_grid_has_both_diagonals_as_shear_and_unique_bends() {
    let m = GridSpec::square(10, 1.0, GridOrientation::Horizontal, glam::Vec3::ZERO)
        .build()
        .unwrap();
    assert_eq!(m.edges.len(), 320, "220 sides + 100 fan diagonals");
    assert_eq!(m.spring_count(SpringKind::Structural), 220);
    assert_eq!(m.spring_count(SpringKind::Shear), 200);
    // Across each of the 90 interior rows and 90 interior columns of sides, one bend pair;
    // across the 100 fan diagonals the pair would be the other diagonal, already a spring.
    assert_eq!(m.spring_count(SpringKind::Bend), 180);
    // As many shear springs along (1, 1) as along (1, −1).
    let direction = |[a, b]: [u32; 2]| {
        let d = m.positions[b as usize] - m.positions[a as usize];
        (d.x * d.z).signum()
    };
    let shear: Vec<f32> = m
        .springs()
        .filter(|(_, k)| *k == SpringKind::Shear)
        .map(|(s, _)| direction(s))
        .collect();
    assert_eq!(shear.iter().filter(|&&s| s > 0.0).count(), 100);
    assert_eq!(shear.iter().filter(|&&s| s < 0.0).count(), 100);
    // No particle pair carries two springs.
    let mut pairs: Vec<[u32; 2]> = m.springs().map(|(p, _)| p).collect();
    let total = pairs.len();
    pairs.sort_unstable();
    pairs.dedup();
    assert_eq!(pairs.len(), total, "a pair with two springs");
}

#[test]
fn pentagon_fan_has_two_shear_diagonals() {
    let obj = "v 0 0 0\nv 1 0 0\nv 1.5 1 0\nv 0.5 1.8 0\nv -0.5 1 0\nf 1 2 3 4 5\n";
    let m = obj_from_str(obj, "penta.obj").unwrap().mesh;
    assert_eq!(m.triangles.len(), 3);
    assert_eq!(m.edge_count(SpringKind::Structural), 5);
    assert_eq!(m.edge_count(SpringKind::Shear), 2);
}

#[test]
fn texture_coordinates_come_from_vt_or_a_planar_projection() {
    let with_vt = "v 0 0 0\nv 2 0 0\nv 0 0 2\nvt 0.1 0.2\nvt 0.3 0.4\nvt 0.5 0.6\nf 1/1 2/2 3/3\n";
    let m = obj_from_str(with_vt, "a.obj").unwrap().mesh;
    assert_eq!(m.uvs[1], glam::Vec2::new(0.3, 0.4));
    let without = "v 0 0 0\nv 2 0 0\nv 0 0 2\nf 1 2 3\n";
    let m = obj_from_str(without, "b.obj").unwrap().mesh;
    assert_eq!(
        m.uvs,
        vec![
            glam::Vec2::ZERO,
            glam::Vec2::new(1.0, 0.0),
            glam::Vec2::new(0.0, 1.0)
        ]
    );
}

#[test]
fn mtllib_is_never_followed() {
    // The named library does not exist; import must neither read nor fail on it.
    let obj = "mtllib /definitely/not/here.mtl\nusemtl red\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    assert!(obj_from_str(obj, "m.obj").is_ok());
}

#[test]
fn zero_area_and_duplicate_faces_are_dropped_with_a_warning() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 3 2 1\nf 1 2 4\n";
    let build = obj_from_str(obj, "d.obj").unwrap();
    assert_eq!(build.mesh.triangles.len(), 1);
    assert_eq!(
        build.mesh.positions.len(),
        3,
        "vertex 4 only served the dropped face"
    );
    let text = build.warnings.join("; ");
    assert!(
        text.contains("zero-area") && text.contains("duplicate"),
        "{text}"
    );
}

fn err(text: &str) -> ObjError {
    obj_from_str(text, "bad.obj").expect_err("must be rejected")
}

#[test]
fn empty_file_is_empty_error() {
    let e = err("# nothing here\n");
    assert!(matches!(e, ObjError::Empty { .. }), "{e}");
    assert!(e.to_string().contains("bad.obj"));
}

#[test]
fn only_degenerate_faces_is_empty_error() {
    let e = err("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
    assert!(matches!(e, ObjError::Empty { .. }), "{e}");
}

#[test]
fn face_index_out_of_range_names_the_line() {
    let e = err("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n");
    match &e {
        ObjError::IndexOutOfRange {
            line, index, count, ..
        } => assert_eq!((*line, *index, *count), (4, 7, 3)),
        other => panic!("wrong variant: {other}"),
    }
    assert!(e.to_string().starts_with("bad.obj:4:"), "{e}");
    assert!(matches!(
        err("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"),
        ObjError::IndexOutOfRange { .. }
    ));
    assert!(matches!(
        err("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n"),
        ObjError::IndexOutOfRange { .. }
    ));
}

#[test]
fn unparsable_number_is_parse_error_with_line() {
    let e = err("v 0 0 0\nv 1 zero 0\nv 0 1 0\nf 1 2 3\n");
    match &e {
        ObjError::Parse { line, text, .. } => assert_eq!((*line, text.as_str()), (2, "zero")),
        other => panic!("wrong variant: {other}"),
    }
    assert!(matches!(
        err("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n"),
        ObjError::Parse { line: 4, .. }
    ));
    assert!(matches!(
        err("v 0 0\nf 1 1 1\n"),
        ObjError::Parse { line: 1, .. }
    ));
}

#[test]
fn non_finite_number_is_non_finite_error() {
    for bad in ["nan", "inf", "-inf", "1e999"] {
        let e = err(&format!("v 0 0 0\nv 1 {bad} 0\nv 0 1 0\nf 1 2 3\n"));
        assert!(
            matches!(e, ObjError::NonFinite { line: 2, .. }),
            "{bad}: {e}"
        );
    }
}

#[test]
fn missing_file_is_not_found() {
    let e = mesh::load_obj(Path::new("/no/such/dir/cloth.obj")).unwrap_err();
    assert!(matches!(e, ObjError::NotFound { .. }), "{e}");
    assert!(e.to_string().contains("/no/such/dir/cloth.obj"));
}

#[test]
fn binary_file_is_not_text() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cloth.obj");
    std::fs::write(
        &path,
        [
            0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a, 0, 0, 0xff, 0xfe,
        ],
    )
    .unwrap();
    let e = mesh::load_obj(&path).unwrap_err();
    assert!(matches!(e, ObjError::NotText { .. }), "{e}");
    let nul = dir.path().join("nul.obj");
    std::fs::write(&nul, b"v 0 0 0\0\n").unwrap();
    assert!(matches!(
        mesh::load_obj(&nul).unwrap_err(),
        ObjError::NotText { .. }
    ));
}

#[test]
fn a_directory_is_not_a_file() {
    let dir = tempfile::tempdir().unwrap();
    let e = mesh::load_obj(dir.path()).unwrap_err();
    assert!(
        matches!(
            e,
            ObjError::NotAFile {
                what: "a directory",
                ..
            }
        ),
        "{e}"
    );
}

/// Story: `clothsim info /dev/zero` never returned: the importer read without a bound.
/// Devices and pipes are refused before a byte is read.
#[test]
fn devices_and_pipes_are_refused_before_reading() {
    let e = mesh::load_obj(Path::new("/dev/zero")).unwrap_err();
    assert!(
        matches!(
            e,
            ObjError::NotAFile {
                what: "a device",
                ..
            }
        ),
        "{e}"
    );
    assert!(e.to_string().starts_with("/dev/zero: is a device"), "{e}");
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("cloth.obj");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap();
    assert!(made.success());
    // Opening a pipe with no writer would block: it must not be opened at all.
    let e = mesh::load_obj(&fifo).unwrap_err();
    assert!(
        matches!(e, ObjError::NotAFile { what: "a pipe", .. }),
        "{e}"
    );
}

#[test]
fn a_file_above_the_size_limit_is_refused_unread() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("huge.obj");
    // A sparse file: 300 MiB long, nothing on disk, and nothing read.
    std::fs::File::create(&path)
        .unwrap()
        .set_len(mesh::MAX_FILE_BYTES + 1)
        .unwrap();
    let e = mesh::load_obj(&path).unwrap_err();
    assert!(matches!(e, ObjError::TooLarge { .. }), "{e}");
    assert!(e.to_string().contains("huge.obj"), "{e}");
}

#[test]
fn more_vertices_or_triangles_than_the_limits_are_refused_before_parsing() {
    let vertices = "v 0 0 0\n".repeat(mesh::MAX_VERTICES + 1);
    let e = obj_from_str(&vertices, "many.obj").unwrap_err();
    assert!(
        matches!(
            e,
            ObjError::TooMany {
                what: "vertices",
                ..
            }
        ),
        "{e}"
    );
    let mut one_face = String::from("v 0 0 0\nv 1 0 0\nv 0 1 0\nf");
    one_face += &" 1".repeat(mesh::MAX_TRIANGLES + 3);
    let e = obj_from_str(&one_face, "fan.obj").unwrap_err();
    assert!(
        matches!(
            e,
            ObjError::TooMany {
                what: "triangles",
                ..
            }
        ),
        "{e}"
    );
}

/// Story: a coordinate such as 1e30 squared to infinity, every triangle came out with no
/// area, and the user was told the file had "no usable triangles".
#[test]
fn coordinates_too_large_to_square_are_refused_as_such() {
    let e = err("v 0 0 0\nv 1e30 0 0\nv 0 1 0\nf 1 2 3\n");
    match &e {
        ObjError::CoordinateTooLarge { line, text, .. } => {
            assert_eq!((*line, text.as_str()), (2, "1e30"))
        }
        other => panic!("wrong variant: {other}"),
    }
    assert!(e.to_string().contains("too large"), "{e}");
}

/// Two triangles sharing an edge whose copies differ by one rounding unit.
fn nearly_shared_edge() -> String {
    let eps = f32::EPSILON; // one unit in the last place of 1.0
    format!(
        "v 0 0 0\nv 1 0 0\nv 0 0 1\nv {} 0 0\nv 0 0 {}\nv 1 0 1\nf 1 3 2\nf 4 5 6\n",
        1.0 + eps,
        1.0 + eps
    )
}

/// Story: welding was exact to the bit, so two positions one rounding apart split the
/// cloth in two, silently. Now they weld within a tolerance relative to the cloth's size,
/// and a cloth that really is in pieces is reported.
#[test]
fn positions_one_rounding_apart_weld_and_pieces_are_reported() {
    let build = obj_from_str(&nearly_shared_edge(), "edge.obj").unwrap();
    assert_eq!(build.mesh.positions.len(), 4, "the shared edge welds");
    assert_eq!(build.mesh.bend_pairs.len(), 1, "so the two triangles hinge");
    assert!(build.warnings.is_empty(), "{:?}", build.warnings);
    // With welding made exact again, the same file is two pieces, and says so.
    let exact = mesh::ImportOptions {
        weld_tolerance: 0.0,
    };
    let split = mesh::obj_from_str_with(&nearly_shared_edge(), "edge.obj", &exact).unwrap();
    assert_eq!(split.mesh.positions.len(), 6);
    let text = split.warnings.join("; ");
    assert!(text.contains("2 disconnected pieces"), "{text}");
    // A real feature a thousandth of the cloth's size apart never welds.
    let apart = "v 0 0 0\nv 1 0 0\nv 0 0 1\nv 0.001 0 0\nv 1 0 1\nv 0 0.001 1\nf 1 3 2\nf 4 6 5\n";
    assert_eq!(
        obj_from_str(apart, "apart.obj")
            .unwrap()
            .mesh
            .positions
            .len(),
        6
    );
}

#[test]
fn the_default_asset_is_a_24x24_quad_grid() {
    let m = obj_from_str(clothsim::scene::DEFAULT_CLOTH_OBJ, "cloth.obj")
        .unwrap()
        .mesh;
    assert_eq!(m.positions.len(), 625);
    assert_eq!(m.triangles.len(), 1152);
    assert_eq!(m.edge_count(SpringKind::Shear), 576);
}

#[test]
fn an_empty_polyline_is_an_error_not_a_panic() {
    // Found by the fuzzer (`fuzz/`): an `l` element with no points made triangulation
    // subtract one from zero.
    for text in [
        "\u{1} \nl",
        "v 0 0 0\nl",
        "v 0 0 0\nv 1 0 0\nl 1 2\n",
        "v 0 0 0\np 1\n",
    ] {
        let err = clothsim::mesh::obj_from_str(text, "odd.obj").expect_err(text);
        assert!(err.to_string().contains("odd.obj"), "{err}");
    }
}
