use super::*;

/// A unit square in the plane y = 0, two triangles.
fn square() -> Surface {
    Surface::new(
        vec![
            Vec3::new(-0.5, 0.0, -0.5),
            Vec3::new(0.5, 0.0, -0.5),
            Vec3::new(0.5, 0.0, 0.5),
            Vec3::new(-0.5, 0.0, 0.5),
        ],
        vec![[0, 2, 1], [0, 3, 2]],
    )
}

/// A fast move through the square, from either side, ends `thickness` short of it on
/// the side it came from, keeping its sideways part.
#[test]
fn a_move_through_a_thin_square_is_caught_on_its_side() {
    let s = square();
    let d = 0.01;
    for dir in [1.0f32, -1.0] {
        let from = Vec3::new(0.1, 0.3 * dir, 0.0);
        let to = Vec3::new(0.2, -0.3 * dir, 0.05);
        let c = s.catch(from, to, d).expect("caught");
        assert!((c.at.y - d * dir).abs() < 1e-6, "{dir}: {c:?}");
        assert_eq!(c.normal, Vec3::Y * dir);
        assert!((c.at.x - 0.2).abs() < 1e-6 && (c.at.z - 0.05).abs() < 1e-6);
    }
    // Beside the square: nothing.
    assert_eq!(
        s.catch(Vec3::new(0.7, 0.3, 0.0), Vec3::new(0.7, -0.3, 0.0), d),
        None
    );
    // Staying clear above it.
    assert_eq!(
        s.catch(Vec3::new(0.0, 0.3, 0.0), Vec3::new(0.0, 0.1, 0.0), d),
        None
    );
}

/// A move that ends within the thickness (without crossing) is pushed out to it.
#[test]
fn a_move_ending_within_the_thickness_is_pushed_out() {
    let s = square();
    let c = s
        .catch(Vec3::new(0.0, 0.2, 0.0), Vec3::new(0.0, 0.004, 0.0), 0.01)
        .expect("caught");
    assert!((c.at - Vec3::new(0.0, 0.01, 0.0)).length() < 1e-6);
    // Near the square's edge, from beside it: pushed away from the edge.
    let c = s
        .catch(Vec3::new(0.6, 0.0, 0.0), Vec3::new(0.505, 0.0, 0.0), 0.01)
        .expect("caught");
    assert!((c.at - Vec3::new(0.51, 0.0, 0.0)).length() < 1e-6, "{c:?}");
}

/// A surface of `n` × `n` squares (two triangles each) over a metre, gently bumpy.
fn bumpy(n: usize) -> Surface {
    grid(n, |x, z| 0.02 * (9.0 * x).sin() * (7.0 * z).cos())
}

/// A surface of `n` × `n` squares (two triangles each) over a metre, at the height
/// `y(x, z)`.
fn grid(n: usize, y: impl Fn(f32, f32) -> f32) -> Surface {
    let at = |i: usize, j: usize| {
        let (x, z) = (i as f32 / n as f32 - 0.5, j as f32 / n as f32 - 0.5);
        Vec3::new(x, y(x, z), z)
    };
    let vertices: Vec<Vec3> = (0..=n)
        .flat_map(|i| (0..=n).map(move |j| at(i, j)))
        .collect();
    let index = |i: usize, j: usize| (i * (n + 1) + j) as u32;
    let triangles: Vec<[u32; 3]> = (0..n)
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .flat_map(|(i, j)| {
            let (a, b, c, d) = (
                index(i, j),
                index(i + 1, j),
                index(i + 1, j + 1),
                index(i, j + 1),
            );
            [[a, c, b], [a, d, c]]
        })
        .collect();
    Surface::new(vertices, triangles)
}

/// A short move's one-walk catch ends where the general catch (the tree asked question
/// by question) ends, with the same normal, for moves near and into a bumpy surface of
/// small triangles: resting, sliding, sinking within the thickness, and beside it.
#[test]
fn a_short_moves_catch_agrees_with_the_general_catch() {
    let s = bumpy(40);
    let mut rnd = crate::test_rng::uniform(7);
    let thickness = 0.01;
    let (mut short, mut caught, mut crossed) = (0, 0, 0);
    for _ in 0..4000 {
        let from = Vec3::new(rnd() - 0.5, (rnd() - 0.3) * 0.05, rnd() - 0.5);
        let step = Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5) * 0.018;
        let to = from + step;
        let general = s.catch_among(None, from, to, thickness);
        crossed += usize::from(s.first_crossing(from, to).is_some());
        if !matches!(s.catch_short(from, to, thickness, None), Short::Unsure) {
            short += 1;
        }
        let got = s.catch(from, to, thickness);
        caught += usize::from(got.is_some());
        match (got, general) {
            (None, None) => {}
            (Some(a), Some(b)) => {
                assert!(a.at.distance(b.at) < 1e-6, "{from} → {to}: {a:?} vs {b:?}");
                assert!(a.normal.distance(b.normal) < 1e-5, "{a:?} vs {b:?}");
            }
            (a, b) => panic!("{from} → {to}: {a:?} vs {b:?}"),
        }
    }
    // Most moves took the one walk, many were caught, and some crossed the surface.
    assert!(
        short > 2000 && caught > 500 && crossed > 100,
        "{short} short, {caught} caught, {crossed} crossed"
    );
}

/// In a groove whose sides meet at a right angle, an end pushed off one side comes
/// within the thickness of the other, and is pushed off that too: a short move's catch
/// ends where the general catch ends there as well.
#[test]
fn a_short_moves_catch_in_a_groove_agrees_with_the_general_catch() {
    let s = grid(100, |x, _| x.abs());
    let mut rnd = crate::test_rng::uniform(9);
    let thickness = 0.01;
    let (mut short, mut twice) = (0, 0);
    for _ in 0..2000 {
        let x = (rnd() - 0.5) * 0.03;
        let to = Vec3::new(x, x.abs() + (0.9 + 0.6 * rnd()) * thickness, rnd() * 0.2);
        let from = to + Vec3::new(rnd() - 0.5, rnd(), rnd() - 0.5) * 1e-3;
        if !matches!(s.catch_short(from, to, thickness, None), Short::Unsure) {
            short += 1;
        }
        let (got, general) = (
            s.catch(from, to, thickness),
            s.catch_among(None, from, to, thickness),
        );
        match (got, general) {
            (None, None) => {}
            (Some(a), Some(b)) => {
                assert!(a.at.distance(b.at) < 1e-6, "{from} → {to}: {a:?} vs {b:?}");
                // Its distances from the two sides (the surface's, inside the groove):
                // within the thickness of neither; held by both where it touches both.
                let sides = [a.at.y - a.at.x, a.at.y + a.at.x].map(|d| d / 2f32.sqrt());
                assert!(sides.iter().all(|d| *d > thickness * 0.9998), "{a:?}");
                twice += usize::from(sides.iter().all(|d| *d < thickness * 1.001));
            }
            (a, b) => panic!("{from} → {to}: {a:?} vs {b:?}"),
        }
    }
    assert!(
        short > 400 && twice > 100,
        "{short} short, {twice} held by both sides"
    );
}

/// Where a particle remembering what it gathered (`memory`) ends the move `from → to`,
/// checked against a catch that walks the tree; `walks` counts the moves that walked it.
fn moved_remembering(
    s: &Surface,
    [from, to]: [Vec3; 2],
    thickness: f32,
    memory: &mut Gathered,
    walks: &mut usize,
) -> Vec3 {
    let before = *memory;
    let remembered = s.catch_remembering(from, to, thickness, Some(memory));
    assert_eq!(remembered, s.catch(from, to, thickness), "{from} → {to}");
    *walks += usize::from(*memory != before);
    remembered.map_or(to, |c| c.at)
}

/// A particle remembering what it gathered ends every move where one walking the tree
/// each time does, bit for bit, as it drifts, slides and sinks over a bumpy surface; and
/// it walks the tree for fewer than one move in four.
#[test]
fn remembering_what_was_gathered_changes_nothing() {
    let s = bumpy(40);
    let mut rnd = crate::test_rng::uniform(11);
    let thickness = 0.01;
    let (mut walks, mut moves) = (0, 0);
    for _ in 0..40 {
        let mut memory = Gathered::NONE;
        let mut p = Vec3::new(rnd() - 0.5, 0.0, rnd() - 0.5) * 0.8;
        p.y = s.nearest(p + Vec3::Y, 2.0).map_or(0.0, |n| n.point.y) + thickness;
        for _ in 0..100 {
            let to = p + Vec3::new(rnd() - 0.5, rnd() - 0.6, rnd() - 0.5) * 4e-4;
            p = moved_remembering(&s, [p, to], thickness, &mut memory, &mut walks);
            moves += 1;
        }
    }
    assert!(walks * 4 < moves, "{walks} walks in {moves} moves");
}

/// A particle falling onto a bumpy surface from 6 cm at 1 mm a move, remembering what it
/// gathered, ends every move where one walking the tree each time does, bit for bit, and
/// [`Surface::clears`] tells no move clear that meets the surface. Where nothing is within
/// the reach, the ball it remembers reaches as far as the nearest triangle (up to two
/// reaches): the fall to the surface walks the tree for fewer than one move in five (with
/// the ball only as wide as the gathering, every move walks it).
#[test]
fn a_fall_far_from_the_surface_walks_the_tree_seldom() {
    let s = bumpy(40);
    let mut rnd = crate::test_rng::uniform(19);
    let thickness = 0.01;
    let (mut walks, mut falling, mut told) = (0, 0, 0);
    for _ in 0..30 {
        let mut memory = Gathered::NONE;
        let mut p = Vec3::new(rnd() - 0.5, 0.0, rnd() - 0.5) * 0.8;
        let ground = s.nearest(p + Vec3::Y, 2.0).map_or(0.0, |n| n.point.y);
        p.y = ground + 0.06;
        for _ in 0..80 {
            let to = p + Vec3::new(rnd() - 0.5, -2.0, rnd() - 0.5) * 5e-4;
            if Surface::clears(p, to, thickness, &memory) {
                assert_eq!(s.catch(p, to, thickness), None, "{p} → {to} told clear");
                told += 1;
            }
            let high = s.nearest(to, 2.0 * thickness).is_none();
            let mut walked = 0;
            p = moved_remembering(&s, [p, to], thickness, &mut memory, &mut walked);
            if high {
                (falling, walks) = (falling + 1, walks + walked);
            }
        }
    }
    assert!(walks * 5 < falling, "{walks} walks in {falling} moves");
    assert!(told * 5 > falling * 4, "{told} of {falling} told clear");
}

/// The same on a surface that deforms, rising 0.3 mm a step towards a particle that
/// barely moves and each vertex up to 0.1 mm more in a direction of its own, the
/// gathering made less at each step by the vertices' largest move: every move ends
/// where one walking the tree does, bit for bit (made less by half the move, a move
/// ends clear of triangles that have come within reach), and fewer than one in two
/// walks it.
#[test]
fn remembering_what_was_gathered_on_a_deforming_surface_changes_nothing() {
    let mut s = bumpy(40);
    let rest = s.vertices().to_vec();
    let mut rnd = crate::test_rng::uniform(13);
    let thickness = 0.01;
    let (mut walks, mut moves) = (0, 0);
    for _ in 0..20 {
        let mut vertices = rest.clone();
        s.refit(&vertices);
        let mut memory = Gathered::NONE;
        let mut p = Vec3::new(rnd() - 0.5, 0.0, rnd() - 0.5) * 0.8;
        p.y = s.nearest(p + Vec3::Y, 2.0).map_or(0.0, |n| n.point.y) + 2.0 * thickness;
        for _ in 0..100 {
            let shifts: Vec<Vec3> = (vertices.iter())
                .map(|_| Vec3::new(rnd() - 0.5, rnd(), rnd() - 0.5) * 1e-4 + Vec3::Y * 3e-4)
                .collect();
            for (v, m) in vertices.iter_mut().zip(&shifts) {
                *v += *m;
            }
            s.refit(&vertices);
            let by = (shifts.iter()).fold(0.0f32, |m, v| m.max(v.length()));
            memory.surface_moved(by);
            let to = p + Vec3::new(rnd() - 0.5, rnd() - 0.6, rnd() - 0.5) * 4e-5;
            p = moved_remembering(&s, [p, to], thickness, &mut memory, &mut walks);
            moves += 1;
        }
    }
    assert!(walks * 2 < moves, "{walks} walks in {moves} moves");
}

/// `n` random triangles of sides up to 0.3 m in a cube of side `size` (`v`: a random
/// point of the unit cube).
fn soup(v: &mut impl FnMut() -> Vec3, n: usize, size: f32) -> Vec<[Vec3; 3]> {
    (0..n)
        .map(|_| {
            let c = v() * size;
            [c, c + v() * 0.3, c + v() * 0.3]
        })
        .collect()
}

/// A tree refitted to moved triangles answers as a search of every moved triangle
/// does: every corner moved by up to a third of the soup's size, so boxes left where
/// the triangles were would miss.
#[test]
fn a_refitted_tree_finds_what_a_search_of_the_moved_triangles_finds() {
    use super::super::geometry::closest_on_triangle;
    let mut rnd = crate::test_rng::uniform(5);
    let mut v = || Vec3::new(rnd(), rnd(), rnd());
    let first = soup(&mut v, 400, 3.0);
    let moved: Vec<[Vec3; 3]> = (first.iter())
        .map(|t| t.map(|c| c + (v() - 0.5) * 2.0))
        .collect();
    let mut tree = TriangleTree::new(&first);
    tree.refit(|t| moved[t]);
    for _ in 0..300 {
        let p = v() * 4.0 - 0.5;
        let brute = (moved.iter())
            .map(|t| p.distance(closest_on_triangle(p, *t)))
            .filter(|d| *d <= 0.5)
            .fold(f32::INFINITY, f32::min);
        let found = tree.nearest(p, 0.5).map_or(f32::INFINITY, |n| n.distance);
        assert_eq!(found, brute, "{p}");
    }
}

/// Every query on a random soup of triangles agrees with testing every triangle.
#[test]
fn the_tree_finds_what_a_search_of_every_triangle_finds() {
    use super::super::geometry::{closest_on_triangle, segment_crosses};
    let mut rnd = crate::test_rng::uniform(4);
    let mut v = || Vec3::new(rnd(), rnd(), rnd());
    let corners = soup(&mut v, 500, 4.0);
    let tree = TriangleTree::new(&corners);
    for _ in 0..300 {
        let p = v() * 4.5 - 0.25;
        let reach = 0.4;
        let brute = (corners.iter().enumerate())
            .map(|(i, t)| (i, p.distance(closest_on_triangle(p, *t))))
            .filter(|(_, d)| *d <= reach)
            .min_by(|a, b| a.1.total_cmp(&b.1));
        let found = tree.nearest(p, reach);
        assert_eq!(found.map(|n| n.distance), brute.map(|b| b.1), "{p}");
        let q = v() * 4.5 - 0.25;
        let brute = (corners.iter().enumerate())
            .filter_map(|(i, t)| segment_crosses(p, q, *t).map(|t| (i as u32, t)))
            .min_by(|a, b| a.1.total_cmp(&b.1));
        assert_eq!(tree.first_crossing(p, q).map(|c| c.1), brute.map(|b| b.1));
    }
}
