use super::walks::FacesAt;
use super::*;
use crate::sim::obstacle::Surface;
use crate::sim::obstacle::geometry::welded;

/// A grid cloth's span: its diagonals are its longest edges, and a right triangle's
/// circumradius is half its hypotenuse.
#[test]
fn a_grids_span_is_its_diagonal_and_half_of_it() {
    let rest = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 0.0, 1.0), Vec3::Z];
    let span = ClothSpan::of(&rest, &[[0, 1, 2], [0, 2, 3]], 2.0, 0.01);
    assert!((span.edge - 2.0 * 2f32.sqrt()).abs() < 1e-6, "{span:?}");
    assert!((span.lever - 2f32.sqrt()).abs() < 1e-6, "{span:?}");
}

/// What the bound's walks read of `surface`'s faces, its vertices welded as `same`.
fn read_of(surface: &Surface, same: &[u32]) -> FacesAt {
    FacesAt::of(surface.vertices(), surface.triangles(), same)
}

/// The edges and vertices of `surface` that a cloth of `span` reaches.
fn reached(surface: &Surface, span: &ClothSpan) -> (Vec<[u32; 2]>, Vec<u32>) {
    let (place, triangles) = ([surface.vertices()], surface.triangles());
    Dips::measure(place, triangles, welded(surface.vertices()), span)
        .reached(place, triangles, span)
}

/// A ball of 3 072 triangles, 20 cm in radius (a cube's faces cut into squares pushed
/// onto it).
fn ball() -> Surface {
    let soup = crate::bench_contact::cube_sphere(0.2, 3072);
    let triangles: Vec<[u32; 3]> = (soup.face_indices.chunks_exact(3))
        .map(|f| [f[0], f[1], f[2]])
        .collect();
    Surface::new(soup.positions, triangles)
}

/// A rail: [`prism`] as a surface.
fn rail(sides: u32, radius: f32) -> Surface {
    let (vertices, triangles) = prism(sides, radius);
    Surface::new(vertices, triangles)
}

/// A cloth span with its own lever, 1 cm thick.
fn span_with(edge: f32, lever: f32) -> ClothSpan {
    ClothSpan {
        edge,
        lever,
        thickness: 0.01,
    }
}

fn span(edge: f32, thickness: f32) -> ClothSpan {
    ClothSpan {
        edge,
        lever: 0.5 * edge,
        thickness,
    }
}

/// How many of the surface's edges a cloth of `span` is kept off.
fn kept_off(surface: &Surface, span: &ClothSpan) -> usize {
    surface
        .reaching(span)
        .map_or(surface.sharp_edges().len(), |s| s.sharp_edges().len())
}

/// How far a regular polygon of `sides` corners on a circle of `radius` falls below the
/// line through one corner square to its radius, at `d` along that line (the bisecting
/// plane of a rail's ridge, seen end on): where a cloth edge of length `2d` laid across
/// the ridge, its two particles alike, comes into the surface.
fn polygon_falls(sides: u32, radius: f32, d: f32) -> f32 {
    let step = std::f32::consts::TAU / sides as f32;
    let corner = |k: u32| {
        let a = step * k as f32;
        (radius * a.cos(), radius * a.sin())
    };
    for k in 0..sides / 4 {
        let ((x0, y0), (x1, y1)) = (corner(k), corner(k + 1));
        if (y0..=y1).contains(&d) {
            return radius - (x0 + (x1 - x0) * (d - y0) / (y1 - y0));
        }
    }
    panic!("{d} m is beyond a quarter of the rail");
}

/// A rail of 40 faces (each turning 9° from the next, under the creases' 10°) of 30 cm
/// radius: for cloth edges of 5, 12 and 24 cm laid across a ridge, the bound on how far
/// they come into it is at least how far they do (2.0, 6.8 and 26.0 mm) and at most
/// twice that (3.1, 11.4 and 48.2 mm). Counting the ridge alone (no slopes growing
/// farther out), it would be below how far the 12 and 24 cm edges come in.
#[test]
fn the_bound_on_a_rails_dip_holds_and_is_within_twice_it() {
    let (sides, radius) = (40, 0.3);
    let rail = rail(sides, radius);
    let same = welded(rail.vertices());
    let read = read_of(&rail, &same);
    let faces = read.faces(rail.triangles(), &same);
    // The ridge between facets 4 and 5: the edge from vertex 10 to 11, between the first
    // triangle of facet 4 and the second of facet 5.
    for length in [0.05, 0.12, 0.24] {
        let span = span(length, 0.01);
        let half = 0.5 * length;
        let walk = &mut Walk::over(&faces);
        let ridge = ([10, 11], [16, 21]);
        let vertices = rail.vertices();
        let bound = span.edge_dip((&faces, walk), vertices, ridge, [None; 2]);
        let dips = polygon_falls(sides, radius, half);
        assert!(
            dips <= bound && bound <= 2.0 * dips,
            "{length} m: dips {dips} m, bound {bound} m"
        );
    }
}

/// The same rail and a 1 cm thickness: a cloth edge of 12 cm laid across it comes in by
/// 6.8 mm, within three quarters of the thickness by the bound (what counts as reached);
/// so the 12 cm cloth is kept off the 40 ridges along the rail as well as its two rims'
/// 80 edges, the 5 cm one off the rims alone, and the 12 cm one off the rims alone with a
/// thickness of 2 cm.
#[test]
fn a_rails_ridges_are_within_a_coarse_cloths_reach_only() {
    let rail = rail(40, 0.3);
    assert_eq!(rail.sharp_edges().len(), 80, "the rims");
    assert_eq!(kept_off(&rail, &span(0.05, 0.01)), 80);
    assert_eq!(kept_off(&rail, &span(0.12, 0.01)), 120);
    assert_eq!(kept_off(&rail, &span(0.12, 0.02)), 80);
}

/// The faces of a box meet at creases or lie in one plane: nothing more is within any
/// cloth's reach (its faces' diagonals are flat), however long its edges, even at no
/// thickness, where any turn at all would be reached. (With faces in one plane not told
/// apart, the six diagonals are.)
#[test]
fn flat_faces_are_beyond_every_cloths_reach() {
    let (v, t, _) = crate::sim::obstacle::unit_cube();
    let cube = Surface::new(v, t);
    assert_eq!(cube.reaching(&span(10.0, 0.0)), None);
}

/// A roof of four faces rising 4.7° to an apex 1.6 m across (the faces turn 9.4° from
/// each other there, under the creases' 10°; it is not a tip). A cloth triangle of 18 cm
/// lever over the apex dips into it by about 15 mm (`λ·tan 4.7°`) against a 1 cm
/// thickness, one of 5 cm lever by about 4 mm: the coarse cloth is kept off the apex as
/// a tip, the fine one not. The vertex's own bound decides it: with the cloth's edges
/// held to 10 cm (too short to reach the ridges, 6.6 mm at most) and the lever at 18 cm,
/// the apex is still reached.
#[test]
fn a_low_apex_is_a_tip_to_a_coarse_cloth_only() {
    let rise = 0.8 * 4.7f32.to_radians().tan();
    let vertices = vec![
        Vec3::new(-0.8, 0.0, -0.8),
        Vec3::new(0.8, 0.0, -0.8),
        Vec3::new(0.8, 0.0, 0.8),
        Vec3::new(-0.8, 0.0, 0.8),
        Vec3::new(0.0, rise, 0.0),
    ];
    let triangles = vec![[0, 4, 1], [1, 4, 2], [2, 4, 3], [3, 4, 0]];
    let roof = Surface::new(vertices, triangles);
    let apex = |surface: &Surface| {
        let mut found = false;
        let at = Vec3::new(0.0, rise, 0.0);
        surface.tips().in_box(at, at, |_| found = true);
        found
    };
    assert!(!apex(&roof));
    assert!(
        roof.reaching(&span_with(0.1, 0.05))
            .is_none_or(|r| !apex(&r))
    );
    assert!(
        roof.reaching(&span_with(0.36, 0.18))
            .is_some_and(|r| apex(&r))
    );
    let (edges, vertices) = reached(&roof, &span_with(0.1, 0.18));
    assert!(edges.is_empty());
    assert!(vertices.contains(&4));
}

/// A ball of 3 072 triangles under cloths of 2, 5 and 12 cm edges (a 1 cm thickness): for
/// every edge between two faces whose ends' walks measured it (4 464 of 4 608 edges, and
/// 1 668 under the 12 cm cloth, which reaches most vertices from their nearest faces
/// alone), the bound taken from its ends' walks is never below the bound of a walk of its
/// own, and at most three times it (on average 1.41, 1.63 and 1.59 times).
#[test]
fn an_edges_bound_from_its_ends_walks_holds_its_own() {
    let ball = ball();
    let same = welded(ball.vertices());
    let read = read_of(&ball, &same);
    let (vertices, faces) = (ball.vertices(), read.faces(ball.triangles(), &same));
    let fans = faces.fans();
    for edge in [0.02, 0.05, 0.12] {
        let span = span(edge, 0.01);
        let mut walk = Walk::over(&faces);
        let mut around = vec![None; vertices.len()];
        for fan in fans.chunk_by(|a, b| a.0 == b.0) {
            if let Some((v, found)) = span.around(&faces, &mut walk, vertices, fan) {
                around[v as usize] = Some(found);
            }
        }
        let (mut derived, mut compared, mut ratios) = (0, 0, 0.0);
        for s in 0..faces.walked.len() {
            for (k, &t) in faces.walked[s].across.iter().enumerate() {
                if t == NONE || (t as usize) < s {
                    continue;
                }
                let tri = ball.triangles()[s];
                let ends = [tri[k], tri[(k + 1) % 3]].map(|i| faces.same[i as usize]);
                let sides = ([ends[0], ends[1]], [s as u32, t]);
                let walks = ends.map(|v| around[v as usize].as_ref());
                let mut dip = |walks| span.edge_dip((&faces, &mut walk), vertices, sides, walks);
                let own = dip([None; 2]);
                if walks.iter().all(Option::is_some) {
                    let from_ends = dip(walks);
                    assert!(
                        from_ends >= own,
                        "{edge} m, edge {ends:?}: {from_ends} < {own}"
                    );
                    assert!(
                        from_ends <= 3.0 * own + 1e-9,
                        "{edge} m, edge {ends:?}: {from_ends} against {own}"
                    );
                    derived += 1;
                    ratios += f64::from(from_ends / own.max(1e-12));
                }
                compared += 1;
            }
        }
        assert!(
            derived * 4 > compared,
            "{edge} m: {derived} of {compared} from their ends"
        );
        let mean = ratios / derived as f64;
        assert!(
            mean < 1.75,
            "{edge} m: on average {mean}× the own walk's bound"
        );
    }
}

/// A face collapsed to a point at the low roof's apex and another to a segment from it
/// change nothing a cloth reaches: they have no plane, so no neighbours, no slope and no
/// turn at the apex (which a long lever still reaches, and nothing else).
#[test]
fn degenerate_faces_change_nothing_a_cloth_reaches() {
    let rise = 0.8 * 4.7f32.to_radians().tan();
    let mut vertices: Vec<Vec3> = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]
        .map(|[x, z]| Vec3::new(0.8 * x, 0.0, 0.8 * z))
        .to_vec();
    vertices.push(Vec3::new(0.0, rise, 0.0));
    let triangles = vec![
        [0, 4, 1],
        [1, 4, 2],
        [2, 4, 3],
        [3, 4, 0],
        [4, 4, 4],
        [4, 0, 4],
    ];
    let roof = Surface::new(vertices, triangles);
    let (edges, vertices) = reached(&roof, &span_with(0.1, 0.18));
    assert!(edges.is_empty(), "{edges:?}");
    assert!(vertices.contains(&4), "{vertices:?}");
}

/// The roof of `a_low_apex_is_a_tip_to_a_coarse_cloth_only` (four faces, 1.6 m across)
/// 5 m along x from the rail of [`prism`]`(40, 0.3)`, and 10 m along a cone of 40 faces
/// (80 cm in radius), the apex of each `rise` m up: one mesh.
fn rail_roof_and_cone(rise: f32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let (mut vertices, mut triangles) = prism(40, 0.3);
    let at = vertices.len() as u32;
    vertices.extend(
        [[-0.8, -0.8], [0.8, -0.8], [0.8, 0.8], [-0.8, 0.8]]
            .map(|[x, z]| Vec3::new(5.0 + x, 0.0, z)),
    );
    vertices.push(Vec3::new(5.0, rise, 0.0));
    triangles.extend([[0, 4, 1], [1, 4, 2], [2, 4, 3], [3, 4, 0]].map(|t| t.map(|v| at + v)));
    let apex = vertices.len() as u32;
    vertices.push(Vec3::new(10.0, rise, 0.0));
    for k in 0..40u32 {
        let a = std::f32::consts::TAU * k as f32 / 40.0;
        vertices.push(Vec3::new(10.0 + 0.8 * a.cos(), 0.0, 0.8 * a.sin()));
        triangles.push([apex, apex + 1 + (k + 1) % 40, apex + 1 + k]);
    }
    (vertices, triangles)
}

/// Whether `surface` keeps the cloth off the apex at `x` (the roof's or the cone's) as a
/// tip.
fn apex_is_a_tip(surface: &Surface, x: f32) -> bool {
    let mut found = false;
    let (lo, hi) = (Vec3::new(x - 0.1, -1.0, -0.1), Vec3::new(x + 0.1, 1.0, 0.1));
    surface.tips().in_box(lo, hi, |_| found = true);
    found
}

/// A sequence of the rail, the roof and the cone, the roof and the cone flat in frame 0
/// and risen 30 cm in frame 1: there the roof's faces turn 29° from each other across its
/// four ridges, which are creases, and the cone's neighbouring faces 3°, yet its opposite
/// ones 41°: both apexes are tips. The sequence's surface keeps the cloth off the ridges
/// and both apexes from frame 0 on (edges: the rail's rims 80, the roof's border 4 and
/// ridges 4, the cone's border 40). Fitted to a 12 cm cloth that reaches the rail's 40
/// ridges and the risen cone's 40 gentle spokes, it keeps those off too, and the roof's
/// ridges and both apexes still; fitted by frame 0 alone (where the cone is flat and
/// nothing of it is reached), the rail's ridges, and the ridges and apexes it kept off.
/// The roof and the cone risen 4.7° instead (no crease, no tip), the curvature of their
/// smooth parts is the risen ones' (0.15/m), not frame 0's (0.016/m, the rail's), and
/// stays so when fitted. Red with each part undone: the frames' creases not kept (124
/// edges), their tips (no tip at the cone's apex), the fit not keeping the surface's
/// edges (204) or tips (by frame 0 alone, none at the cone), frame 0's curvature kept, or
/// the fit's.
#[test]
fn a_sequence_keeps_off_what_creases_in_any_frame() {
    let (flat, triangles) = rail_roof_and_cone(0.0);
    let risen = rail_roof_and_cone(0.3).0;
    let frames = [flat.clone(), risen.clone()];
    let sequence = Surface::of_frames(flat.clone(), triangles.clone(), &frames);
    assert_eq!(sequence.sharp_edges().len(), 128);
    assert!(apex_is_a_tip(&sequence, 5.0) && apex_is_a_tip(&sequence, 10.0));
    let frames_reached = sequence.reached_over(
        &span(0.12, 0.01),
        frames.iter().map(Vec::as_slice),
        &mut None,
    );
    let fitted = (sequence.keeping_off(&frames_reached)).expect("the rail's ridges reached");
    assert_eq!(fitted.sharp_edges().len(), 208);
    assert!(apex_is_a_tip(&fitted, 5.0) && apex_is_a_tip(&fitted, 10.0));
    let by_frame_0 = sequence
        .reaching(&span(0.12, 0.01))
        .expect("the rail's ridges reached");
    assert_eq!(by_frame_0.sharp_edges().len(), 168);
    assert!(apex_is_a_tip(&by_frame_0, 5.0) && apex_is_a_tip(&by_frame_0, 10.0));
    let gentle = rail_roof_and_cone(0.8 * 4.7f32.to_radians().tan()).0;
    let curving = Surface::of_frames(flat.clone(), triangles.clone(), &[flat, gentle.clone()]);
    let expected = Surface::new(gentle, triangles).tips().curvature();
    assert!(expected > 0.1, "{expected}");
    assert_eq!(curving.tips().curvature(), expected);
    let fitted = curving
        .reaching(&span(0.05, 0.001))
        .expect("the rail's ridges reached");
    assert_eq!(fitted.tips().curvature(), expected);
    assert!(!apex_is_a_tip(&curving, 5.0) && !apex_is_a_tip(&curving, 10.0));
}

/// How many edges `surface` (taking the places `frames` too) keeps a cloth of `span` off
/// by the walks kept in `measured`, and how many of them have walked on their own so far;
/// the surface kept off the same as by walks taken for `span` alone.
fn fit_kept(
    surface: &Surface,
    frames: &[Vec<Vec3>],
    span: &ClothSpan,
    measured: &mut Option<Dips>,
) -> (usize, usize) {
    let frames = || frames.iter().map(Vec::as_slice);
    let kept = surface.keeping_off(&surface.reached_over(span, frames(), measured));
    let fresh = surface.keeping_off(&surface.reached_over(span, frames(), &mut None));
    assert_eq!(kept, fresh, "{span:?}");
    let edges = kept.map_or(surface.sharp_edges().len(), |s| s.sharp_edges().len());
    (edges, measured.as_ref().map_or(0, Dips::own_walks))
}

/// The ball of `an_edges_bound_from_its_ends_walks_holds_its_own`, measured once for a
/// cloth of 5 cm edges, answers it at thicknesses from 2 cm down to 6 mm and back as a
/// measure of each thickness's own does: none of its 4 584 edges kept off at 2 and 1 cm,
/// 408 at 8 mm, 4 530 at 6 mm. The edges whose ends' walks leave them within reach take
/// walks of their own only as a thinner cloth asks for them (120 at 2 cm, 4 062 at 1 cm,
/// all from 8 mm), and once: thicknesses asked again walk no more. Red with the walks
/// measured anew at each thickness (back at 1 cm, 4 062 walked), with every edge's own
/// walk taken at once (4 584 at 2 cm), or with none taken (nothing kept off at 8 mm).
#[test]
fn one_measure_answers_every_thickness() {
    let surface = ball();
    let mut measured = None;
    let mut fit = |thickness| fit_kept(&surface, &[], &span(0.05, thickness), &mut measured);
    assert_eq!(fit(0.02), (0, 120));
    assert_eq!(fit(0.01), (0, 4062));
    assert_eq!(fit(0.008), (408, 4584));
    assert_eq!(fit(0.006), (4530, 4584));
    assert_eq!(fit(0.01), (0, 4584));
    assert_eq!(fit(0.008), (408, 4584));
}

/// The sequence of `a_sequence_keeps_off_what_creases_in_any_frame`, measured once over
/// both its frames for a cloth of 12 cm edges, answers it at each thickness as a measure
/// of that thickness's own does, what any frame reaches kept off in all: 3 cm thick, the
/// cone's 40 spokes besides its 128 creases and borders (reached in the frame where the
/// cone has risen alone), 1.5 cm and 5 mm the rail's 40 ridges too, and back at 3 cm the
/// spokes alone. Red with the frames after the first left out of the measure (128 at 3
/// cm) or with each edge's own walk taken in the first frame alone (the same).
#[test]
fn one_measure_of_a_sequence_answers_every_thickness() {
    let (flat, triangles) = rail_roof_and_cone(0.0);
    let risen = rail_roof_and_cone(0.3).0;
    let frames = [flat.clone(), risen];
    let sequence = Surface::of_frames(flat, triangles, &frames);
    let mut measured = None;
    let mut fit = |thickness| fit_kept(&sequence, &frames, &span(0.12, thickness), &mut measured);
    assert_eq!(fit(0.03), (168, 80));
    assert_eq!(fit(0.015), (208, 80));
    assert_eq!(fit(0.005), (208, 80));
    assert_eq!(fit(0.03), (168, 80));
}

/// Two gently curved slopes of a roof meeting at a sharp ridge along z (90° between them),
/// each `n` × `n` quads, 0.5 m a side: vertices on both sides of the ridge lie a quad
/// apart.
fn ridge(n: u32) -> Surface {
    let step = 0.5 / n as f32;
    let height = |x: f32| 0.5 - x.abs() + 0.8 * x * x;
    let mut vertices = Vec::new();
    for k in 0..=n {
        for i in 0..=2 * n {
            let x = i as f32 * step - 0.5;
            // The ridge off the cells' bounds.
            vertices.push(Vec3::new(x + 0.0173, height(x), k as f32 * step));
        }
    }
    let row = 2 * n + 1;
    let mut triangles = Vec::new();
    for k in 0..n {
        for i in 0..2 * n {
            let [a, b] = [k * row + i, k * row + i + 1];
            let [c, d] = [a + row, b + row];
            triangles.extend([[a, c, b], [b, c, d]]);
        }
    }
    Surface::new(vertices, triangles)
}

/// Vertices' walks taken in groups gather what each one's own walk does: over a ball of
/// 49 152 triangles under cloths of 2 and 5 cm edges, and a ridge of 5 mm quads whose two
/// slopes meet at a crease (a walk never crosses it, so the vertices beside it on either
/// side, though in one cell, walk apart) under cloths of 2, 5 and 12 cm, every vertex's
/// walk as [`Faces::vertex_walks`] takes it is the one [`ClothSpan::around`] takes on its
/// own, to the bit; and most vertices walk with others. (Where a face at the edge of a
/// vertex's reach is met by its own walk only by way of faces beyond that reach, the group's
/// walk makes that ring steeper, never less steep: under a 12 cm cloth, whose walks reach
/// 13 cm, 266 of the ball's 25 350 walks.)
#[test]
fn walks_taken_together_gather_what_each_ones_own_does() {
    let soup = crate::bench_contact::cube_sphere(0.2, 49_152);
    let fine = (soup.face_indices.chunks_exact(3)).map(|f| [f[0], f[1], f[2]]);
    let ball = Surface::new(soup.positions, fine.collect());
    // What share of the walks (%) may differ from their own.
    let cases = [
        ("ball", ball, &[0.02, 0.05][..]),
        ("ridge", ridge(100), &[0.02, 0.05, 0.12][..]),
    ];
    for (name, surface, edges) in cases {
        let same = welded(surface.vertices());
        let read = read_of(&surface, &same);
        let (vertices, faces) = (surface.vertices(), read.faces(surface.triangles(), &same));
        let fans = faces.fans();
        for &edge in edges {
            let span = span(edge, 0.01);
            let together = faces.vertex_walks(vertices, &span);
            let mut walk = Walk::over(&faces);
            let mut alone = vec![None; vertices.len()];
            for fan in fans.chunk_by(|a, b| a.0 == b.0) {
                if let Some((v, found)) = span.around(&faces, &mut walk, vertices, fan) {
                    alone[v as usize] = Some(found);
                }
            }
            let mut differ = 0;
            for (together, alone) in together.iter().zip(&alone) {
                let (Some(t), Some(a)) = (together, alone) else {
                    assert_eq!(together, alone, "{name}, {edge} m");
                    continue;
                };
                let steeper = (t.steepest.iter().zip(&a.steepest)).all(|(t, a)| t >= a);
                assert!(
                    steeper && (t.rings, t.reference) == (a.rings, a.reference),
                    "{name}, {edge} m: {t:?} against {a:?}"
                );
                differ += usize::from(t != a);
            }
            assert!(
                differ == 0,
                "{name}, {edge} m: {differ} of {} differ",
                alone.len()
            );
            let walkers = (fans.chunk_by(|a, b| a.0 == b.0))
                .filter_map(|fan| span.walker(&faces, vertices, fan));
            let (walkers, groups) = faces.groups(walkers.collect(), CELL * span.width());
            let with_others = (groups.iter().filter(|g| g.len() > 1)).map(|g| g.len());
            assert!(
                2 * with_others.sum::<usize>() > walkers.len(),
                "{name}, {edge} m: {} walkers in {} groups",
                walkers.len(),
                groups.len()
            );
        }
    }
}
