//! Coverage-guided fuzzing of OBJ import: any bytes give a cloth or a typed error, never a
//! panic, a hang or an allocation out of proportion to the input.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // The importer takes text; bytes that are not UTF-8 are what `read_obj` refuses first.
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(build) = clothsim::mesh::obj_from_str(text, "fuzz.obj") {
        let m = &build.mesh;
        let n = m.positions.len() as u32;
        assert!(!m.triangles.is_empty());
        assert!(m.positions.iter().all(|p| p.is_finite()));
        assert!(m.triangles.iter().flatten().all(|&i| i < n));
        assert!(m.springs().all(|([a, b], _)| a < n && b < n && a != b));
        // The model built from it is finite too.
        let model = clothsim::cloth::ClothModel::new(m, 0.2, &[]);
        assert!(model.mass.iter().all(|m| m.is_finite() && *m >= 0.0));
    }
});
