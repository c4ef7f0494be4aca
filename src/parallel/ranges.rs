//! Ranges cut into members' shares.

/// `range` cut short at `len` (empty where it starts past it).
pub fn clamped(range: std::ops::Range<usize>, len: usize) -> std::ops::Range<usize> {
    let end = range.end.min(len);
    range.start.min(end)..end
}

/// `0..len` cut into `parts` nearly equal ranges; the `i`-th.
pub fn share(len: usize, parts: usize, i: usize) -> std::ops::Range<usize> {
    let parts = parts.max(1);
    (len * i / parts)..(len * (i + 1) / parts)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shares_cover_the_range_in_order() {
        for (len, parts) in [(10, 3), (0, 2), (7, 7), (5, 8)] {
            let covered: Vec<usize> = (0..parts).flat_map(|i| share(len, parts, i)).collect();
            assert_eq!(covered, (0..len).collect::<Vec<_>>());
        }
    }
}
