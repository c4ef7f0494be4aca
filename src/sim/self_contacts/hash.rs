//! The broad phase: a hierarchical spatial hash of the triangles' boxes. Each box goes to
//! the first level whose cells (the base cell times 2^level) hold it in at most two cells
//! along each axis, so the table holds at most eight entries a triangle however the cloth
//! is stretched, and two boxes that overlap share a cell at the coarser one's level.

use glam::{Vec3, Vec3A};

use super::error::ContactError;

/// Levels of the hash. A box wider than the base cell times 2^`MAX_LEVEL` (a million times
/// the cloth's own scale) is a state that has blown up, refused rather than binned.
const MAX_LEVEL: u32 = 20;

/// Most cells one triangle is binned in: two along each axis.
pub const CELLS_PER_TRIANGLE: usize = 8;

/// The boxes of a cell a search reads into a local array before it pairs them (the rest,
/// in a fuller cell, are read where they are).
const LOCAL: usize = 48;

/// The key of cell `c` at `level`, in [`KEY_BITS`] bits: three coordinates wrapped into
/// 21 bits each, mixed with the level, then hashed (the top bits of an odd multiple).
/// Distinct cells rarely share a key, and a shared key only adds entries that the level,
/// overlap and cell checks then skip.
fn cell_key(c: [i32; 3], level: u32) -> u64 {
    let w = |x: i32| (x as u64) & 0x1F_FFFF;
    let cell = (w(c[0]) | (w(c[1]) << 21) | (w(c[2]) << 42))
        ^ (level as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    cell.wrapping_mul(0xD6E8_FEB8_6659_FD93) >> (64 - KEY_BITS)
}

/// Bits of a table entry that number its box; the key takes the rest.
const BOX_BITS: u32 = 24;
const KEY_BITS: u32 = 64 - BOX_BITS;

/// An entry of the table: the cell's key above the box's number, so that entries sort by
/// key in eight bytes (a cloth of more than 2^24 triangles is refused: see
/// [`BoxHash::bin`]).
fn entry(key: u64, b: usize) -> u64 {
    debug_assert!(b < 1 << BOX_BITS);
    (key << BOX_BITS) | b as u64
}

fn entry_key(e: u64) -> u64 {
    e >> BOX_BITS
}

fn entry_box(e: u64) -> usize {
    (e & ((1 << BOX_BITS) - 1)) as usize
}

fn cell_of(p: Vec3, size: f32) -> [i32; 3] {
    // Float-to-int casts saturate: a far-away point lands in an edge cell, which only adds
    // candidates. `floor` without a call into libm: truncate, then step down below zero
    // (saturating too: past i32::MIN the truncation already is the edge cell).
    (p / size).to_array().map(|x| {
        let i = x as i32;
        if (i as f32) > x {
            i.saturating_sub(1)
        } else {
            i
        }
    })
}

/// The first level at which the box `lo..hi` lies in at most two cells along each axis,
/// and how many cells it lies in there; `None` past [`MAX_LEVEL`].
fn level_of(lo: Vec3, hi: Vec3, cell: f32) -> Option<(u32, usize)> {
    let extent = (hi - lo).max_element();
    (0..=MAX_LEVEL).find_map(|level| {
        let size = cell * (1u32 << level) as f32;
        let (first, last) = (cell_of(lo, size), cell_of(hi, size));
        let spans = [0, 1, 2].map(|i| i64::from(last[i]) - i64::from(first[i]));
        (extent <= size && spans.iter().all(|&d| d <= 1))
            .then(|| (level, spans.iter().map(|&d| d as usize + 1).product()))
    })
}

/// Calls `visit` with each cell of the box `lo..hi` at cell `size`.
fn each_cell(lo: Vec3, hi: Vec3, size: f32, mut visit: impl FnMut([i32; 3])) {
    let (first, last) = (cell_of(lo, size), cell_of(hi, size));
    for x in first[0]..=last[0] {
        for y in first[1]..=last[1] {
            for z in first[2]..=last[2] {
                visit([x, y, z]);
            }
        }
    }
}

/// The table, kept between substeps (its buffers are reused).
#[derive(Clone, Debug, Default)]
pub struct BoxHash {
    /// Entries ([`entry`]: cell key and box), sorted.
    bins: Vec<u64>,
    /// Where each run of entries with one key starts.
    runs: Vec<u32>,
    /// Each box's level.
    level: Vec<u8>,
    /// The cell of each box's lowest corner at its level: the cell of two boxes' overlap's
    /// lowest corner is theirs taken axis by axis at the larger (a floor keeps order).
    first: Vec<[i32; 3]>,
    /// Bit `l` is set when some box is at level `l`.
    levels: u32,
    cell: f32,
}

impl BoxHash {
    /// Entries in the table now: at most [`CELLS_PER_TRIANGLE`] per box.
    pub fn len(&self) -> usize {
        self.bins.len()
    }

    /// Bins the boxes (`lo[i]..hi[i]`) with a base cell of `cell` metres.
    ///
    /// # Errors
    /// [`ContactError::Extent`] for a box a million base cells wide, [`ContactError::TooMany`]
    /// for more boxes than an entry can number (nothing is binned).
    pub fn bin(&mut self, lo: &[Vec3], hi: &[Vec3], cell: f32) -> Result<(), ContactError> {
        if lo.len() > 1 << BOX_BITS {
            return Err(ContactError::TooMany {
                triangles: lo.len(),
                most: 1 << BOX_BITS,
            });
        }
        self.bins.clear();
        self.level.clear();
        self.first.clear();
        self.levels = 0;
        self.cell = cell;
        // The entries counted first, so the table grows to what it holds, not to the next
        // power of two (where a cloth lands fast that is megabytes).
        let mut entries = 0;
        for (t, (&lo, &hi)) in lo.iter().zip(hi).enumerate() {
            let Some((level, cells)) = level_of(lo, hi, cell) else {
                self.bins.clear();
                return Err(ContactError::Extent {
                    triangle: t,
                    extent: (hi - lo).max_element(),
                    cell,
                });
            };
            self.levels |= 1 << level;
            self.level.push(level as u8);
            self.first.push(cell_of(lo, self.size(level)));
            entries += cells;
        }
        self.bins.reserve_exact(entries);
        for (t, ((&lo, &hi), &level)) in lo.iter().zip(hi).zip(&self.level).enumerate() {
            let level = u32::from(level);
            each_cell(lo, hi, self.size(level), |c| {
                self.bins.push(entry(cell_key(c, level), t))
            });
        }
        self.bins.sort_unstable();
        self.runs.clear();
        for (i, w) in self.bins.iter().enumerate() {
            if i == 0 || entry_key(self.bins[i - 1]) != entry_key(*w) {
                self.runs.push(i as u32);
            }
        }
        Ok(())
    }

    /// Pieces the search for overlapping pairs is cut into, for a team to share: runs of
    /// the table's cells, then (with boxes at more than one level) ranges of boxes looked
    /// up at the coarser levels.
    pub fn pieces(&self) -> usize {
        let cross = if self.levels.count_ones() > 1 {
            self.level.len().div_ceil(BOXES_PER_PIECE)
        } else {
            0
        };
        self.runs.len().div_ceil(RUNS_PER_PIECE) + cross
    }

    /// Calls `pair(a, b)` for the pairs of overlapping boxes that piece `piece` finds: pairs
    /// at one level from a run of cells, each in the one cell that holds the overlap's
    /// lowest corner; or a range of boxes against the coarser levels' cells they touch.
    /// Every overlapping pair is found by exactly one piece, once.
    pub fn piece_pairs(
        &self,
        piece: usize,
        lo: &[Vec3],
        hi: &[Vec3],
        mut pair: impl FnMut(u32, u32),
    ) {
        let mut overlap = |a: usize, b: usize, level: u32, key: u64| {
            let (l, h) = (lo[a].max(lo[b]), hi[a].min(hi[b]));
            let size = self.size(level);
            if l.cmple(h).all() && cell_key(cell_of(l, size), level) == key {
                pair(a as u32, b as u32);
            }
        };
        let run_pieces = self.runs.len().div_ceil(RUNS_PER_PIECE);
        if piece < run_pieces {
            let first = piece * RUNS_PER_PIECE;
            let last = (first + RUNS_PER_PIECE).min(self.runs.len());
            let mut local = [(Vec3A::ZERO, Vec3A::ZERO, [0; 3], 0, 0); LOCAL];
            for r in first..last {
                let start = self.runs[r] as usize;
                let end = self
                    .runs
                    .get(r + 1)
                    .map_or(self.bins.len(), |&e| e as usize);
                let cell = &self.bins[start..end];
                let key = entry_key(cell[0]);
                // The cell's boxes read once into `local` (most cells hold a few dozen),
                // not once per pair, as 16-byte vectors whose tests are one instruction
                // each (with `Vec3`'s 12 bytes, `crumple`'s contact at 64² took 10 % longer).
                let n = cell.len().min(LOCAL);
                let boxed = |e: u64| {
                    let b = entry_box(e);
                    let (l, h) = (Vec3A::from(lo[b]), Vec3A::from(hi[b]));
                    (l, h, self.first[b], self.level[b], b as u32)
                };
                for (slot, &e) in local.iter_mut().zip(&cell[..n]) {
                    *slot = boxed(e);
                }
                let read = |i: usize| if i < n { local[i] } else { boxed(cell[i]) };
                for i in 0..cell.len() {
                    let (alo, ahi, first, level, a) = read(i);
                    for j in i + 1..cell.len() {
                        let (blo, bhi, bfirst, blevel, b) = read(j);
                        // A shared key from another level is not a shared cell; the pair is
                        // taken in the cell of its overlap's lowest corner, which is this
                        // one when the larger of the boxes' first cells has its key.
                        if blevel == level && alo.max(blo).cmple(ahi.min(bhi)).all() {
                            let lowest = std::array::from_fn(|k| first[k].max(bfirst[k]));
                            if cell_key(lowest, u32::from(level)) == key {
                                pair(a, b);
                            }
                        }
                    }
                }
            }
            return;
        }
        let first = (piece - run_pieces) * BOXES_PER_PIECE;
        for a in first..(first + BOXES_PER_PIECE).min(lo.len()) {
            let own = u32::from(self.level[a]);
            let coarser = self.levels >> (own + 1) << (own + 1);
            self.each_cell_at(coarser, lo[a], hi[a], |level, c| {
                for b in self.binned_in(c, level) {
                    overlap(a, b as usize, level, cell_key(c, level));
                }
            });
        }
    }

    /// The base cell the boxes were binned with, m.
    pub fn cell(&self) -> f32 {
        self.cell
    }

    /// The cells' size at `level`, m.
    fn size(&self, level: u32) -> f32 {
        self.cell * (1u32 << level) as f32
    }

    /// The boxes binned at `level` in its cell `c` (looked up by the cell's key; a box of
    /// another level under the same key is not in this cell).
    fn binned_in(&self, c: [i32; 3], level: u32) -> impl Iterator<Item = u32> + '_ {
        let key = cell_key(c, level);
        let start = self.bins.partition_point(|&e| entry_key(e) < key);
        (self.bins[start..].iter())
            .take_while(move |&&e| entry_key(e) == key)
            .map(|&e| entry_box(e) as u32)
            .filter(move |&b| u32::from(self.level[b as usize]) == level)
    }

    /// How many levels finer than box `a`'s the finest binned box is: looking up `a` at
    /// that level visits up to (2^levels + 1)³ cells.
    pub fn levels_below(&self, a: usize) -> u32 {
        u32::from(self.level[a]).saturating_sub(self.levels.trailing_zeros())
    }

    /// Calls `visit(b)` once for each binned box `b` other than `a` (binned too) that
    /// overlaps `a`: at each level, `a`'s cells are looked up, and `b` is taken in the one
    /// that holds the overlap's lowest corner.
    pub fn overlapping(&self, a: usize, lo: &[Vec3], hi: &[Vec3], mut visit: impl FnMut(u32)) {
        self.each_cell_at(self.levels, lo[a], hi[a], |level, c| {
            let size = self.size(level);
            for b in self.binned_in(c, level) {
                let bi = b as usize;
                if bi == a {
                    continue;
                }
                let (l, h) = (lo[a].max(lo[bi]), hi[a].min(hi[bi]));
                if l.cmple(h).all() && cell_of(l, size) == c {
                    visit(b);
                }
            }
        });
    }

    /// Calls `visit(level, c)` for each cell `c` of the box `lo..hi` at each level whose
    /// bit is set in `levels`.
    fn each_cell_at(&self, levels: u32, lo: Vec3, hi: Vec3, mut visit: impl FnMut(u32, [i32; 3])) {
        let mut levels = levels;
        while levels != 0 {
            let level = levels.trailing_zeros();
            levels &= levels - 1;
            each_cell(lo, hi, self.size(level), |c| visit(level, c));
        }
    }
}

/// Cell runs in one piece of the search.
const RUNS_PER_PIECE: usize = 64;

/// Boxes in one piece of the search across levels.
const BOXES_PER_PIECE: usize = 2048;

#[cfg(test)]
mod tests {
    use super::*;

    /// The cell of a point is the floor of its coordinates over the size, and a point past
    /// what an `i32` holds lands in the edge cell (the truncation saturates; stepping down
    /// from it once overflowed).
    #[test]
    fn cells_floor_and_saturate() {
        let c = cell_of(Vec3::new(-0.5, 0.0, 2.5), 1.0);
        assert_eq!(c, [-1, 0, 2]);
        assert_eq!(cell_of(Vec3::new(-1.0, 1.0, -2.0), 1.0), [-1, 1, -2]);
        let far = cell_of(Vec3::new(-1e12, 1e12, -3.5e9), 1.0);
        assert_eq!(far, [i32::MIN, i32::MAX, i32::MIN]);
    }
}
