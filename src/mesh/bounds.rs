//! Axis-aligned bounds of point sets.

use glam::{Vec3, Vec4};

/// Axis-aligned bounds `(min, max)` of a point set; `(0, 0)` when empty. A NaN coordinate
/// is passed over, as `f32::min` and `f32::max` pass it.
///
/// Read as floats, four points (twelve floats, three SSE lanes) at a time: a `Vec3`'s own
/// arithmetic is scalar, and the sphere takes the box of the cloth's motion every substep.
pub fn bounds(points: &[Vec3]) -> (Vec3, Vec3) {
    if points.is_empty() {
        return (Vec3::ZERO, Vec3::ZERO);
    }
    let x: &[f32] = bytemuck::cast_slice(points);
    let (mut lo, mut hi) = ([Vec4::splat(f32::MAX); 3], [Vec4::splat(f32::MIN); 3]);
    let (steps, rest) = x.as_chunks::<12>();
    for step in steps {
        let [a, b, c] = bytemuck::cast::<_, [[f32; 4]; 3]>(*step).map(Vec4::from);
        // `a.min(lo)` is `a < lo ? a : lo`: a NaN in `a` leaves `lo` (never NaN).
        lo = [a.min(lo[0]), b.min(lo[1]), c.min(lo[2])];
        hi = [a.max(hi[0]), b.max(hi[1]), c.max(hi[2])];
    }
    let lane = |v: &[Vec4; 3], k: usize| v[k / 4][k % 4];
    let (mut least, mut most) = (Vec3::MAX, Vec3::MIN);
    for k in 0..12 {
        least[k % 3] = least[k % 3].min(lane(&lo, k));
        most[k % 3] = most[k % 3].max(lane(&hi, k));
    }
    for (k, &x) in rest.iter().enumerate() {
        least[k % 3] = least[k % 3].min(x);
        most[k % 3] = most[k % 3].max(x);
    }
    (least, most)
}

/// Length of the bounding-box diagonal of a point set, metres (0 when empty).
pub fn bbox_diagonal(points: &[Vec3]) -> f32 {
    let (lo, hi) = bounds(points);
    (hi - lo).length()
}

/// Index (0 = x, 1 = y, 2 = z) of the smallest extent of the box `lo..hi`: the normal
/// axis of a flat cloth. Ties go to the lower index.
pub fn thinnest_axis(lo: Vec3, hi: Vec3) -> usize {
    let ext = hi - lo;
    if ext.x <= ext.y && ext.x <= ext.z {
        0
    } else if ext.y <= ext.z {
        1
    } else {
        2
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// As a fold of `f32::min` and `f32::max` gives them, for every count of points the
    /// steps of four leave over, with a NaN passed over, and for no point.
    #[test]
    fn the_bounds_are_the_least_and_greatest_coordinates() {
        assert_eq!(bounds(&[]), (Vec3::ZERO, Vec3::ZERO));
        let each = |a: Vec3, b: Vec3, pick: fn(f32, f32) -> f32| {
            Vec3::from_array(std::array::from_fn(|k| pick(a[k], b[k])))
        };
        let fold = |x: &[Vec3]| {
            (x.iter()).fold((Vec3::MAX, Vec3::MIN), |(lo, hi), &p| {
                (each(lo, p, f32::min), each(hi, p, f32::max))
            })
        };
        let mut rnd = crate::test_rng::uniform(5);
        for n in [1, 2, 4, 5, 13, 4225] {
            let mut x: Vec<Vec3> = (0..n)
                .map(|_| Vec3::new(rnd() - 0.5, rnd() * 3.0, -rnd()) * 4.0)
                .collect();
            assert_eq!(bounds(&x), fold(&x), "{n}");
            x[n / 2].y = f32::NAN;
            assert_eq!(bounds(&x), fold(&x), "{n}, a NaN");
        }
        // The least and greatest first, a NaN after them on the same lane.
        let mut x = vec![Vec3::new(0.5, 1.0, 0.5); 8];
        (x[0], x[1], x[4].y) = (Vec3::splat(-2.0), Vec3::splat(3.0), f32::NAN);
        assert_eq!(bounds(&x), (Vec3::splat(-2.0), Vec3::splat(3.0)));
    }
}
