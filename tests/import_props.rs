//! Property test: random and mutated OBJ text never panics or hangs the importer; it gives a
//! cloth or a typed error. (`fuzz/` holds the coverage-guided version of the same target.)

use proptest::prelude::*;

use clothsim::mesh::{GridOrientation, GridSpec, obj_from_str};

/// A number as OBJ files write them, and as they should not.
fn number() -> impl Strategy<Value = String> {
    prop_oneof![
        4 => (-10.0f32..10.0).prop_map(|x| x.to_string()),
        1 => prop_oneof![
            Just("nan".to_string()),
            Just("inf".to_string()),
            Just("-inf".to_string()),
            Just("1e999".to_string()),
            Just("1e30".to_string()),
            Just("0x1p3".to_string()),
            Just("".to_string()),
            Just("-".to_string()),
            "[a-z]{1,3}",
        ],
    ]
}

/// A face corner: an index (some out of range, negative or zero), maybe with `/t/n`.
fn corner() -> impl Strategy<Value = String> {
    (
        -8i64..16,
        prop::option::of(0i64..8),
        prop::option::of(0i64..8),
    )
        .prop_map(|(v, t, n)| match (t, n) {
            (None, None) => v.to_string(),
            (Some(t), None) => format!("{v}/{t}"),
            (t, Some(n)) => format!("{v}/{}/{n}", t.map(|t| t.to_string()).unwrap_or_default()),
        })
}

/// One line of OBJ-like text.
fn line() -> impl Strategy<Value = String> {
    prop_oneof![
        6 => prop::collection::vec(number(), 0..5).prop_map(|n| format!("v {}", n.join(" "))),
        1 => prop::collection::vec(number(), 0..4).prop_map(|n| format!("vt {}", n.join(" "))),
        1 => prop::collection::vec(number(), 0..4).prop_map(|n| format!("vn {}", n.join(" "))),
        5 => prop::collection::vec(corner(), 0..7).prop_map(|c| format!("f {}", c.join(" "))),
        // Points and polylines (an empty `l` once crashed triangulation; the fuzzer found it).
        1 => (prop_oneof![Just("l"), Just("p")], prop::collection::vec(corner(), 0..4))
            .prop_map(|(e, c)| std::iter::once(e.to_string()).chain(c).collect::<Vec<_>>().join(" ")),
        1 => Just("mtllib /no/such.mtl".to_string()),
        1 => Just("usemtl red".to_string()),
        1 => "[og] [a-z]{0,5}",
        1 => Just("s 1".to_string()),
        1 => "# [ -~]{0,20}",
        1 => "[ -~]{0,30}",
        1 => Just("\\".to_string()),
    ]
}

/// A small valid quad grid, for mutations.
fn valid_obj() -> String {
    GridSpec::square(3, 1.0, GridOrientation::Horizontal, glam::Vec3::ZERO).to_obj()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

    #[test]
    fn random_obj_text_gives_a_cloth_or_a_typed_error(lines in prop::collection::vec(line(), 0..40)) {
        let text = lines.join("\n");
        match obj_from_str(&text, "random.obj") {
            Ok(build) => {
                let m = &build.mesh;
                prop_assert!(!m.triangles.is_empty());
                prop_assert!(m.positions.iter().all(|p| p.is_finite()));
                let n = m.positions.len() as u32;
                prop_assert!(m.triangles.iter().flatten().all(|&i| i < n));
                prop_assert!(m.springs().all(|([a, b], _)| a < n && b < n && a != b));
            }
            Err(e) => prop_assert!(e.to_string().starts_with("random.obj"), "{}", e),
        }
    }

    #[test]
    fn mutated_valid_obj_gives_a_cloth_or_a_typed_error(
        edits in prop::collection::vec((any::<usize>(), any::<u8>(), 0u8..3), 1..12)
    ) {
        let mut bytes = valid_obj().into_bytes();
        for (at, byte, how) in edits {
            let at = at % (bytes.len() + 1);
            match how {
                0 if at < bytes.len() => bytes[at] = byte,
                1 => bytes.insert(at, byte),
                _ if at < bytes.len() => { bytes.remove(at); }
                _ => {}
            }
        }
        let text = String::from_utf8_lossy(&bytes);
        if let Err(e) = obj_from_str(&text, "mutated.obj") {
            prop_assert!(e.to_string().starts_with("mutated.obj"), "{}", e);
        }
    }
}
