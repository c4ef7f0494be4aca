//! A leaf's triangles side by side: each of their boxes' bounds in a lane of its own, so
//! that one triangle is told apart from a whole leaf's at once (four lanes: one SSE
//! register an axis), where two leaves are tested triangle by triangle.

use glam::{BVec4A, Vec3A, Vec4};

// A leaf's triangles fill one vector of four lanes.
const _: () = assert!(super::LEAF == 4);

/// One triangle's boxes: by boxes its box `[lo, hi]`; by motion also the box of its ends
/// (`lo` and `hi` then bound its starts).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct One {
    pub(super) lo: Vec3A,
    pub(super) hi: Vec3A,
    pub(super) end_lo: Vec3A,
    pub(super) end_hi: Vec3A,
}

impl One {
    /// The boxes by motion of a triangle with `corners`, moving from `from` to `to`.
    pub(super) fn of(corners: [u32; 3], [from, to]: [&[Vec3A]; 2]) -> One {
        let [a, b, c] = corners.map(|k| from[k as usize]);
        let [d, e, f] = corners.map(|k| to[k as usize]);
        One {
            lo: a.min(b).min(c),
            hi: a.max(b).max(c),
            end_lo: d.min(e).min(f),
            end_hi: d.max(e).max(f),
        }
    }

    /// The widest its particles span along an axis over the motion.
    pub(super) fn widest(&self) -> f32 {
        (self.hi.max(self.end_hi) - self.lo.min(self.end_lo)).max_element()
    }
}

/// A leaf's triangles' boxes (as [`One`]), one lane each in the tree's order, a vector an
/// axis; lanes past the leaf's triangles are never read.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Lanes {
    lo: [Vec4; 3],
    hi: [Vec4; 3],
    end_lo: [Vec4; 3],
    end_hi: [Vec4; 3],
}

impl Lanes {
    /// Sets lane `lane` to a triangle's box.
    #[inline(always)]
    pub(super) fn set_box(&mut self, lane: usize, [lo, hi]: [Vec3A; 2]) {
        for x in 0..3 {
            (self.lo[x][lane], self.hi[x][lane]) = (lo[x], hi[x]);
        }
    }

    /// Sets lane `lane` to a triangle's boxes by motion.
    #[inline(always)]
    pub(super) fn set(&mut self, lane: usize, one: One) {
        self.set_box(lane, [one.lo, one.hi]);
        for x in 0..3 {
            self.end_lo[x][lane] = one.end_lo[x];
            self.end_hi[x][lane] = one.end_hi[x];
        }
    }

    /// Sets the lanes to the boxes by motion of the first `count` triangles whose
    /// corners are `corners` (the lanes past them to the first's), their particles moving
    /// from `from` to `to`, a whole leaf at once: each corner's four particles taken into
    /// a vector an axis. The same boxes, to the bit, as [`One::of`] and [`Lanes::set`]
    /// give a lane at a time. Returns the widest a triangle's particles span along an
    /// axis over the motion (0 for no triangle: the lanes are left as they are).
    #[inline(always)]
    pub(super) fn set_leaf(
        &mut self,
        corners: &Corners,
        count: usize,
        [from, to]: [&[Vec3A]; 2],
    ) -> f32 {
        if count == 0 {
            return 0.0;
        }
        // Each corner's particle in each lane (the first triangle's past `count`). Spelled
        // out rather than by arrays' `map`, which the compiler did not always inline here
        // (its closures index, and may panic): the fit took 66 → 116 million instructions
        // in `crumple`'s first second at 64² in a build that left them calls.
        let lane = |l: usize| if l < count { l } else { 0 };
        let (l1, l2, l3) = (lane(1), lane(2), lane(3));
        let ids = |k: usize| {
            let c = &corners[k];
            [c[0], c[l1], c[l2], c[l3]]
        };
        let ids = [ids(0), ids(1), ids(2)];
        // Corner `k`'s four particles at `x`, an axis a vector.
        let axes = |x: &[Vec3A], k: usize| {
            let [a, b, c, d] = ids[k];
            by_axis([x[a as usize], x[b as usize], x[c as usize], x[d as usize]])
        };
        let (s, e) = (
            [axes(from, 0), axes(from, 1), axes(from, 2)],
            [axes(to, 0), axes(to, 1), axes(to, 2)],
        );
        let mut widest = Vec4::ZERO;
        for d in 0..3 {
            self.lo[d] = s[0][d].min(s[1][d]).min(s[2][d]);
            self.hi[d] = s[0][d].max(s[1][d]).max(s[2][d]);
            self.end_lo[d] = e[0][d].min(e[1][d]).min(e[2][d]);
            self.end_hi[d] = e[0][d].max(e[1][d]).max(e[2][d]);
            let span = self.hi[d].max(self.end_hi[d]) - self.lo[d].min(self.end_lo[d]);
            widest = widest.max(span);
        }
        widest.max_element()
    }

    /// Lane `lane`'s triangle.
    #[inline(always)]
    pub(super) fn one(&self, lane: usize) -> One {
        let at = |v: &[Vec4; 3]| Vec3A::new(v[0][lane], v[1][lane], v[2][lane]);
        One {
            lo: at(&self.lo),
            hi: at(&self.hi),
            end_lo: at(&self.end_lo),
            end_hi: at(&self.end_hi),
        }
    }

    /// The lanes (as bits) whose box overlaps that of lane `k` of `one`.
    #[inline(always)]
    pub(super) fn boxes_meet(&self, (one, k): (&Lanes, usize)) -> u32 {
        let mut meet = BVec4A::splat(true);
        for x in 0..3 {
            let (lo, hi) = (Vec4::splat(one.lo[x][k]), Vec4::splat(one.hi[x][k]));
            meet &= lo.cmple(self.hi[x]) & self.lo[x].cmple(hi);
        }
        meet.bitmask()
    }

    /// Each lane's box of its starts and its ends less `m`, an axis each: in the frame
    /// that moves by `m` along the motion, its triangle stays in it (each particle's path
    /// runs between its start and its end less `m`).
    #[inline(always)]
    fn hulls(&self, m: Vec3A) -> [[Vec4; 2]; 3] {
        // Spelled out rather than by `array::from_fn`, which the compiler did not always
        // inline into the walk (55 million instructions in `crumple`'s first second).
        let axis = |x: usize| {
            let mx = Vec4::splat(m[x]);
            [
                self.lo[x].min(self.end_lo[x] - mx),
                self.hi[x].max(self.end_hi[x] - mx),
            ]
        };
        [axis(0), axis(1), axis(2)]
    }

    /// The lanes (as bits) whose triangle the triangle of lane `k` of `one` is not told
    /// `reach` apart from along their motion, in the frame that moves by `m` (any frame
    /// keeps the test; the two leaves' own motion keeps it tight).
    #[inline(always)]
    pub(super) fn moving_near(&self, (one, k): (&Lanes, usize), m: Vec3A, reach: f32) -> u32 {
        near_row(&self.hulls(m), &one.hulls(m), k, reach)
    }

    /// [`Lanes::moving_near`] for each lane of `other`, as a row of bits each (each
    /// leaf's boxes carried into the frame once for all four rows).
    #[inline(always)]
    pub(super) fn moving_near_rows(&self, other: &Lanes, m: Vec3A, reach: f32) -> [u32; 4] {
        let (b, a) = (self.hulls(m), other.hulls(m));
        let row = |k: usize| near_row(&b, &a, k, reach);
        [row(0), row(1), row(2), row(3)]
    }

    /// [`Lanes::boxes_meet`] for each lane of `other`, as a row of bits each.
    #[inline(always)]
    pub(super) fn boxes_meet_rows(&self, other: &Lanes) -> [u32; 4] {
        let row = |k: usize| self.boxes_meet((other, k));
        [row(0), row(1), row(2), row(3)]
    }

    /// The box of the first `count` lanes' boxes, and by motion the box of their ends.
    #[inline(always)]
    pub(super) fn bounds(&self, count: usize, moving: bool) -> ([Vec3A; 2], [Vec3A; 2]) {
        // Each bound's lanes back into points, the first `count` of them joined.
        let join = |v: &[Vec4; 3], start: Vec3A, with: fn(Vec3A, Vec3A) -> Vec3A| {
            let points = by_lane(v);
            (0..4).fold(start, |m, l| if l < count { with(m, points[l]) } else { m })
        };
        let least = |v| join(v, Vec3A::INFINITY, Vec3A::min);
        let most = |v| join(v, Vec3A::NEG_INFINITY, Vec3A::max);
        let ends = if moving {
            [least(&self.end_lo), most(&self.end_hi)]
        } else {
            [Vec3A::INFINITY, Vec3A::NEG_INFINITY]
        };
        ([least(&self.lo), most(&self.hi)], ends)
    }
}

/// Four points' coordinates, an axis a vector (the lanes in the points' order).
#[inline(always)]
fn by_axis(p: [Vec3A; 4]) -> [Vec4; 3] {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{
            __m128, _mm_movehl_ps, _mm_movelh_ps, _mm_unpackhi_ps, _mm_unpacklo_ps,
        };
        let [a, b, c, d] = p.map(__m128::from);
        // SAFETY: SSE is part of every x86-64 CPU; these only move lanes.
        unsafe {
            let (ab_xy, cd_xy) = (_mm_unpacklo_ps(a, b), _mm_unpacklo_ps(c, d));
            let (ab_zw, cd_zw) = (_mm_unpackhi_ps(a, b), _mm_unpackhi_ps(c, d));
            [
                _mm_movelh_ps(ab_xy, cd_xy),
                _mm_movehl_ps(cd_xy, ab_xy),
                _mm_movelh_ps(ab_zw, cd_zw),
            ]
            .map(Vec4::from)
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    [0, 1, 2].map(|d| Vec4::new(p[0][d], p[1][d], p[2][d], p[3][d]))
}

/// The four lanes of three axes' vectors as points (the inverse of [`by_axis`]).
#[inline(always)]
fn by_lane(v: &[Vec4; 3]) -> [Vec3A; 4] {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{
            __m128, _mm_movehl_ps, _mm_movelh_ps, _mm_setzero_ps, _mm_unpackhi_ps, _mm_unpacklo_ps,
        };
        let [x, y, z] = v.map(__m128::from);
        // SAFETY: SSE is part of every x86-64 CPU; these only move lanes.
        unsafe {
            let w = _mm_setzero_ps();
            let (xy_01, zw_01) = (_mm_unpacklo_ps(x, y), _mm_unpacklo_ps(z, w));
            let (xy_23, zw_23) = (_mm_unpackhi_ps(x, y), _mm_unpackhi_ps(z, w));
            [
                _mm_movelh_ps(xy_01, zw_01),
                _mm_movehl_ps(zw_01, xy_01),
                _mm_movelh_ps(xy_23, zw_23),
                _mm_movehl_ps(zw_23, xy_23),
            ]
            .map(Vec3A::from)
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    std::array::from_fn(|l| Vec3A::new(v[0][l], v[1][l], v[2][l]))
}

/// The lanes (as bits) of hulls `b` ([`Lanes::hulls`]) not told `reach` apart from lane
/// `k` of hulls `a` along any axis.
#[inline(always)]
fn near_row(b: &[[Vec4; 2]; 3], a: &[[Vec4; 2]; 3], k: usize, reach: f32) -> u32 {
    let mut gap = Vec4::NEG_INFINITY;
    for ([blo, bhi], [alo, ahi]) in b.iter().zip(a) {
        let (alo, ahi) = (Vec4::splat(alo[k]), Vec4::splat(ahi[k]));
        gap = gap.max((*blo - ahi).max(alo - *bhi));
    }
    (!gap.cmpge(Vec4::splat(reach))).bitmask()
}

/// A leaf's triangles' corners, one lane each, an array a corner.
pub(super) type Corners = [[u32; 4]; 3];

/// The lanes (as bits) whose triangle shares no corner with one with `corners`.
#[inline(always)]
pub(super) fn share_none(corners: [u32; 3], lanes: &Corners) -> u32 {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{
            __m128i, _mm_castsi128_ps, _mm_cmpeq_epi32, _mm_loadu_si128, _mm_movemask_ps,
            _mm_or_si128, _mm_set1_epi32, _mm_setzero_si128,
        };
        // SAFETY: SSE2 is part of every x86-64 CPU; the loads read whole `[u32; 4]`s.
        unsafe {
            let mut any = _mm_setzero_si128();
            for lane in lanes {
                let lane = _mm_loadu_si128(lane.as_ptr().cast::<__m128i>());
                for c in corners {
                    any = _mm_or_si128(any, _mm_cmpeq_epi32(lane, _mm_set1_epi32(c as i32)));
                }
            }
            !(_mm_movemask_ps(_mm_castsi128_ps(any)) as u32) & 0xf
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    share_none_plainly(corners, lanes)
}

/// [`share_none`] without SIMD.
#[cfg(any(test, not(target_arch = "x86_64")))]
fn share_none_plainly(corners: [u32; 3], lanes: &Corners) -> u32 {
    let mut none = 0;
    for l in 0..4 {
        let shared = corners
            .iter()
            .any(|&c| lanes.iter().any(|lane| lane[l] == c));
        none |= u32::from(!shared) << l;
    }
    none
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::self_contacts::search::in_lanes;
    use glam::Vec3;

    /// Two leaves of four triangles each, moving 2–20 cm toward, past or along each other
    /// (each triangle a few cm wide and 1–10 cm from the other leaf): the pairs their rows
    /// tell apart in the frame of the leaves' mean motion, of none, or of any motion, keep
    /// the reach apart all along it (at each of 33 points their boxes lie that far apart
    /// along an axis), and a row is what one lane's test tells.
    #[test]
    fn triangles_told_apart_by_their_motion_keep_apart_along_it() {
        let mut rnd = crate::test_rng::uniform(17);
        let mut vector = |scale: f32| Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5) * scale;
        let reach = 0.01;
        let (mut apart, mut near) = (0, 0);
        for trial in 0..600 {
            let (ca, cb) = (vector(0.1), vector(0.1));
            let (ma, mb) = (vector(0.2), vector(0.2));
            let mut leaf = |centre: Vec3, motion: Vec3| {
                let from: Vec<Vec3> = (0..12).map(|_| centre + vector(0.04)).collect();
                let to: Vec<Vec3> = from.iter().map(|&p| p + motion + vector(0.01)).collect();
                let mut lanes = Lanes::default();
                for lane in 0..4 {
                    let corners = [0, 1, 2].map(|c| (3 * lane + c) as u32);
                    lanes.set(lane, One::of(corners, [&in_lanes(&from), &in_lanes(&to)]));
                }
                (lanes, from, to)
            };
            let ((a, a_from, a_to), (b, b_from, b_to)) = (leaf(ca, ma), leaf(cb, mb));
            let m = match trial % 3 {
                0 => Vec3A::from(0.5 * (ma + mb)),
                1 => Vec3A::ZERO,
                _ => Vec3A::from(vector(0.4)),
            };
            let rows = b.moving_near_rows(&a, m, reach);
            for (k, &row) in rows.iter().enumerate() {
                assert_eq!(row, b.moving_near((&a, k), m, reach));
                for j in 0..4 {
                    if row & (1 << j) != 0 {
                        near += 1;
                        continue;
                    }
                    apart += 1;
                    for step in 0..=32 {
                        let t = step as f32 / 32.0;
                        let at = |from: &[Vec3], to: &[Vec3], lane: usize| {
                            (3 * lane..3 * lane + 3).fold(
                                (Vec3::INFINITY, Vec3::NEG_INFINITY),
                                |(lo, hi), i| {
                                    let p = from[i] + (to[i] - from[i]) * t;
                                    (lo.min(p), hi.max(p))
                                },
                            )
                        };
                        let ((alo, ahi), (blo, bhi)) =
                            (at(&a_from, &a_to, k), at(&b_from, &b_to, j));
                        let gap = (blo - ahi).max(alo - bhi).max_element();
                        assert!(
                            gap >= reach * (1.0 - 1e-4),
                            "trial {trial}: {k} and {j} {gap} m apart at {t}"
                        );
                    }
                }
            }
        }
        assert!(apart > 1000 && near > 1000, "{apart} apart, {near} near");
    }

    /// A leaf's lanes set at once hold, to the bit, the boxes each lane's triangle gets on
    /// its own ([`One::of`]), for full leaves and for leaves of one to three; the widest
    /// is the widest triangle's span; a leaf's bounds are its triangles' boxes together,
    /// whatever the lanes past them hold; a leaf of none reads no particle.
    #[test]
    fn a_leaf_set_at_once_holds_each_triangles_own_boxes() {
        let mut rnd = crate::test_rng::uniform(29);
        let mut point = || Vec3A::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5) * 3.0;
        let from: Vec<Vec3A> = (0..40).map(|_| point()).collect();
        let to: Vec<Vec3A> = (0..40).map(|_| point()).collect();
        let bits = |v: Vec3A| v.to_array().map(f32::to_bits);
        for trial in 0..400 {
            let count = 1 + trial % 4;
            // Lanes past the count hold no particle's number, as in the tree.
            let corners: Corners = [0, 11, 23].map(|offset| {
                std::array::from_fn(|lane| {
                    let first = (trial * 7 + lane * 13) as u32;
                    if lane < count {
                        (first + offset) % 40
                    } else {
                        u32::MAX
                    }
                })
            });
            let mut leaf = Lanes::default();
            let widest = leaf.set_leaf(&corners, count, [&from, &to]);
            let mut most = 0.0f32;
            let (mut lo, mut hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
            let (mut end_lo, mut end_hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
            for lane in 0..count {
                let own = One::of(corners.map(|c| c[lane]), [&from, &to]);
                let set = leaf.one(lane);
                assert_eq!(
                    [set.lo, set.hi, set.end_lo, set.end_hi].map(bits),
                    [own.lo, own.hi, own.end_lo, own.end_hi].map(bits),
                    "trial {trial}, lane {lane}"
                );
                most = most.max(own.widest());
                (lo, hi) = (lo.min(own.lo), hi.max(own.hi));
                (end_lo, end_hi) = (end_lo.min(own.end_lo), end_hi.max(own.end_hi));
            }
            assert_eq!(widest.to_bits(), most.to_bits(), "trial {trial}");
            // Lanes past the count may hold anything (a refit leaves them stale): the bounds
            // pass them by.
            let far = Vec3A::splat(100.0);
            for lane in count..4 {
                leaf.set(
                    lane,
                    One {
                        lo: -far,
                        hi: far,
                        end_lo: -far,
                        end_hi: far,
                    },
                );
            }
            let ([l, h], [el, eh]) = leaf.bounds(count, true);
            assert_eq!([l, h, el, eh].map(bits), [lo, hi, end_lo, end_hi].map(bits));
        }
        // No triangle: no particle is read (every lane holds none's number).
        let none = Lanes::default().set_leaf(&[[u32::MAX; 4]; 3], 0, [&from, &to]);
        assert_eq!(none, 0.0);
    }

    /// Two triangles moving along an axis, one by 5 cm and the other by 15 cm after it,
    /// closing from 12 cm to 2 cm: in the frame of their mean motion each keeps to a box
    /// 5 cm long, and they are told apart at a reach of 1.9 cm (not at 2.1); in the
    /// cloth's frame the second's box runs into the first's.
    #[test]
    fn in_their_own_frame_two_triangles_that_close_and_stop_short_are_told_apart() {
        let flat = [
            Vec3::ZERO,
            Vec3::new(0.0, 0.01, 0.0),
            Vec3::new(0.0, 0.0, 0.01),
        ];
        let along = |x: f32| flat.map(|p| p + Vec3::new(x, 0.0, 0.0));
        let lanes = |from: [Vec3; 3], to: [Vec3; 3]| {
            let mut lanes = Lanes::default();
            let ends: Vec<Vec3> = from.into_iter().chain(to).collect();
            let ends = in_lanes(&ends);
            lanes.set(0, One::of([0, 1, 2], [&ends[..3], &ends[3..]]));
            lanes
        };
        let (a, b) = (
            lanes(along(0.0), along(0.05)),
            lanes(along(-0.12), along(0.03)),
        );
        let own = Vec3A::new(0.1, 0.0, 0.0);
        assert_eq!(a.moving_near((&b, 0), own, 0.019) & 1, 0);
        assert_eq!(a.moving_near((&b, 0), own, 0.021) & 1, 1);
        assert_eq!(a.moving_near((&b, 0), Vec3A::ZERO, 0.019) & 1, 1);
    }

    /// The SIMD compare and the plain one flag the same lanes, for corners drawn from a
    /// few particles (so that many share one, in every lane and every corner's place), and
    /// from numbers past `i32::MAX` (compared as signed lanes).
    #[test]
    fn the_corner_compare_flags_what_the_plain_one_flags() {
        let mut rnd = crate::test_rng::uniform(5);
        let mut pick = |few: bool| {
            let r = (rnd() * 6.0) as u32;
            if few { r } else { u32::MAX - r }
        };
        let (mut apart, mut shared) = (0, 0);
        for k in 0..2000 {
            let few = k % 2 == 0;
            let corners = [pick(few), pick(few), pick(few)];
            let lanes: Corners = std::array::from_fn(|_| std::array::from_fn(|_| pick(few)));
            let flags = share_none(corners, &lanes);
            assert_eq!(
                flags,
                share_none_plainly(corners, &lanes),
                "{corners:?} {lanes:?}"
            );
            apart += u32::from(flags != 0);
            shared += u32::from(flags != 0xf);
        }
        assert!(
            apart > 100 && shared > 100,
            "{apart} with a lane apart, {shared} shared"
        );
    }
}
