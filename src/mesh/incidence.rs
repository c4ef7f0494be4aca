//! Which triangles meet at each particle, in compressed sparse row form.

/// The triangles around each of `particles` particles: particle `i`'s are
/// `list[offsets[i]..offsets[i + 1]]`, in increasing order (a triangle that names a
/// particle twice is listed twice).
pub fn triangles_around(particles: usize, triangles: &[[u32; 3]]) -> (Vec<u32>, Vec<u32>) {
    let mut offsets = vec![0u32; particles + 1];
    for &i in triangles.iter().flatten() {
        offsets[i as usize + 1] += 1;
    }
    for p in 0..particles {
        offsets[p + 1] += offsets[p];
    }
    let mut list = vec![0u32; offsets[particles] as usize];
    let mut next = offsets.clone();
    for (t, corners) in triangles.iter().enumerate() {
        for &i in corners {
            let slot = &mut next[i as usize];
            list[*slot as usize] = t as u32;
            *slot += 1;
        }
    }
    (offsets, list)
}
