//! Which triangles meet at each particle, in compressed sparse row form, and the counting
//! sort that builds such rows.

/// The triangles around each of `particles` particles: particle `i`'s are
/// `list[offsets[i]..offsets[i + 1]]`, in increasing order (a triangle that names a
/// particle twice is listed twice).
pub fn triangles_around(particles: usize, triangles: &[[u32; 3]]) -> (Vec<u32>, Vec<u32>) {
    grouped(particles, |visit| {
        for (t, corners) in triangles.iter().enumerate() {
            for &i in corners {
                visit(i, t as u32);
            }
        }
    })
}

/// The values that `each` hands its visitor, as rows by key (each below `keys`): row `k`
/// is `values[offsets[k]..offsets[k + 1]]`, in the order they were handed. `each` is
/// called twice, to count and then to place, so that no list of keys and values is kept
/// beside the rows.
pub fn grouped<T: Copy + Default>(
    keys: usize,
    each: impl Fn(&mut dyn FnMut(u32, T)),
) -> (Vec<u32>, Vec<T>) {
    let mut offsets = vec![0u32; keys + 1];
    each(&mut |k, _| offsets[k as usize + 1] += 1);
    for k in 0..keys {
        offsets[k + 1] += offsets[k];
    }
    let mut values = vec![T::default(); offsets[keys] as usize];
    let mut next = offsets.clone();
    each(&mut |k, v| {
        let slot = &mut next[k as usize];
        values[*slot as usize] = v;
        *slot += 1;
    });
    (offsets, values)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rows by key, each in the order its values were handed, empty rows kept; and a
    /// triangle's particles each list it.
    #[test]
    fn rows_keep_the_order_values_came_in() {
        let handed = [(2, 'a'), (0, 'b'), (2, 'c'), (3, 'd'), (0, 'e')];
        let (offsets, values) = grouped(5, |visit| handed.iter().for_each(|&(k, v)| visit(k, v)));
        assert_eq!(offsets, [0, 2, 2, 4, 5, 5]);
        assert_eq!(values, ['b', 'e', 'a', 'c', 'd']);
        let (offsets, list) = triangles_around(4, &[[0, 1, 2], [2, 1, 3]]);
        assert_eq!(
            (offsets, list),
            (vec![0, 1, 3, 5, 6], vec![0, 0, 1, 0, 1, 1])
        );
    }
}
