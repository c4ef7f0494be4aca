// What every contact on the GPU shares (prepended to the step shaders with
// shaders/step_common.wgsl, and to shaders/obstacle.wgsl and shaders/self_contact.wgsl;
// src/gpu/kernel.rs): the velocity response of a particle that touches a surface (the
// CPU's `solid::touching`), and the sphere and plane colliders (the step resolves them at
// each substep's end; self-contact again where its pushes moved cloth into one).

// The velocity `v` of a particle touching a surface moving at `vs` (unit normal `n`),
// `part` of it (1: all) bearing on the contact: that part of its approach along `n` is
// removed, and its sliding slowed by Coulomb friction `mu` in proportion. Unchanged where
// it moves away.
fn touching(v: vec3<f32>, vs: vec3<f32>, n: vec3<f32>, mu: f32, part: f32) -> vec3<f32> {
    let rel = v - vs;
    let vn = dot(rel, n);
    if (vn >= 0.0) {
        return v;
    }
    let vt = rel - vn * n;
    let speed = length(vt);
    var keep = 0.0;
    if (speed > 0.0) {
        keep = max(1.0 - mu * part * (-vn) / speed, 0.0);
    }
    return vs + (1.0 - part) * vn * n + keep * vt;
}

struct Collider {
    // x: kind (0 none, 1 sphere, 2 plane); y: radius; z: friction.
    info: vec4<f32>,
    // Sphere: centre; plane: a point on it.
    a: vec4<f32>,
    // Sphere: angular velocity (rad/s); plane: unit normal.
    b: vec4<f32>,
}

// The first point where the segment a→b (relative to the centre) enters the sphere of
// radius r, if it starts outside and crosses in during the segment.
fn first_entry(a: vec3<f32>, b: vec3<f32>, r: f32) -> vec4<f32> {
    let d = b - a;
    let aa = dot(a, a);
    let dd = dot(d, d);
    if (aa < r * r || dd == 0.0) {
        return vec4<f32>(0.0);
    }
    let half_b = dot(a, d);
    let disc = half_b * half_b - dd * (aa - r * r);
    if (half_b >= 0.0 || disc < 0.0) {
        return vec4<f32>(0.0);
    }
    let t = (-half_b - sqrt(disc)) / dd;
    if (t < 0.0 || t > 1.0) {
        return vec4<f32>(0.0);
    }
    return vec4<f32>(a + t * d, 1.0);
}

fn unit_or_up(p: vec3<f32>) -> vec3<f32> {
    let len = length(p);
    if (len > 1e-9) {
        return p / len;
    }
    return vec3<f32>(0.0, 1.0, 0.0);
}

struct Motion {
    x: vec3<f32>,
    v: vec3<f32>,
}

// `m` kept `offset` above the plane `col`, where it is nearer: moved straight out, its
// approach taken out of its velocity and its sliding slowed by the plane's friction.
fn onto_plane(col: Collider, offset: f32, m: Motion) -> Motion {
    let normal = col.b.xyz;
    let depth = offset - dot(m.x - col.a.xyz, normal);
    if (depth <= 0.0) {
        return m;
    }
    return Motion(m.x + depth * normal, touching(m.v, vec3<f32>(0.0), normal, col.info.z, 1.0));
}

// `end` (position and velocity after a substep that started at `x`) with the first `count`
// of `colliders` (spheres and planes, the cloth kept `offset` off them) resolved against
// the substep's path, with friction.
fn collide_among(colliders: array<Collider, 4>, count: u32, offset: f32, x: vec3<f32>, end: Motion) -> Motion {
    var nx = end.x;
    var nv = end.v;
    for (var c = 0u; c < count; c = c + 1u) {
        let col = colliders[c];
        if (col.info.x == 1.0) {
            let centre = col.a.xyz;
            let radius = col.info.y;
            let reach = radius + offset;
            let entry = first_entry(x - centre, nx - centre, reach);
            let to = nx - centre;
            if (entry.w == 1.0 || dot(to, to) < reach * reach) {
                var moved = to;
                if (entry.w == 1.0) {
                    let hit = entry.xyz;
                    let hn = unit_or_up(hit);
                    let rest = to - hit;
                    moved = hit + rest - min(dot(rest, hn), 0.0) * hn;
                }
                let len = length(moved);
                let n = unit_or_up(moved);
                nx = centre + n * max(reach, len);
                nv = touching(nv, cross(col.b.xyz, n * radius), n, col.info.z, 1.0);
            }
        } else if (col.info.x == 2.0) {
            let m = onto_plane(col, offset, Motion(nx, nv));
            nx = m.x;
            nv = m.v;
        }
    }
    return settle_between(colliders, count, offset, Motion(nx, nv));
}

// A collider's surface near `p`: its outward normal (xyz) and signed distance (w, m).
fn collider_surface(col: Collider, p: vec3<f32>) -> vec4<f32> {
    if (col.info.x == 1.0) {
        let r = p - col.a.xyz;
        return vec4<f32>(unit_or_up(r), length(r) - col.info.y);
    }
    return vec4<f32>(col.b.xyz, dot(p - col.a.xyz, col.b.xyz));
}

// Two surfaces near a particle, the deeper first: each a normal (xyz) and how deep (w; a
// depth inside the offset, or an approach speed; -1e30: none).
struct Deepest {
    a: vec4<f32>,
    b: vec4<f32>,
}

const NONE: vec4<f32> = vec4<f32>(0.0, 0.0, 0.0, -1e30);

const TOUCHING: f32 = 1e-3;

// `two` with `near` taken in where it is deeper than either.
fn deeper(two: Deepest, near: vec4<f32>) -> Deepest {
    if (near.w > two.a.w) {
        return Deepest(near, two.a);
    }
    if (near.w > two.b.w) {
        return Deepest(two.a, near);
    }
    return two;
}

// The two colliders a particle at `p` is deepest within `offset` of (at least
// -TOUCHING·offset deep; else none).
fn deepest_two(colliders: array<Collider, 4>, count: u32, offset: f32, p: vec3<f32>) -> Deepest {
    var two = Deepest(NONE, NONE);
    for (var c = 0u; c < count; c = c + 1u) {
        let s = collider_surface(colliders[c], p);
        if (offset - s.w >= -TOUCHING * offset) {
            two = deeper(two, vec4<f32>(s.xyz, offset - s.w));
        }
    }
    return two;
}

// The least move that takes a point `a.w` along unit normal `a.xyz` and `b.w` along
// `b.xyz` (at least; negative depths count as none), or, facing each other, halfway (the
// CPU's `between::least_move`).
fn least_move(a: vec4<f32>, b: vec4<f32>) -> vec3<f32> {
    let da = max(a.w, 0.0);
    let db = max(b.w, 0.0);
    let along_a = da * a.xyz;
    if (dot(along_a, b.xyz) >= db) {
        return along_a;
    }
    let along_b = db * b.xyz;
    if (dot(along_b, a.xyz) >= da) {
        return along_b;
    }
    let c = dot(a.xyz, b.xyz);
    let det = 1.0 - c * c;
    if (det < 1e-6) {
        return 0.5 * (da - db) * a.xyz;
    }
    return ((da - c * db) / det) * a.xyz + ((db - c * da) / det) * b.xyz;
}

// A particle left inside one collider's offset while touching another's (a sphere resting
// on the ground, near where it touches: each acting in turn leaves it where the last put
// it) is moved by the least that keeps both, a few short rounds over, and its approach to
// both taken out of its velocity (the CPU's `effects/between.rs`).
fn settle_between(colliders: array<Collider, 4>, count: u32, offset: f32, m: Motion) -> Motion {
    var two = deepest_two(colliders, count, offset, m.x);
    if (two.b.w < -TOUCHING * offset || two.a.w <= TOUCHING * offset) {
        return m;
    }
    var x = m.x;
    for (var k = 0u; k < 6u; k = k + 1u) {
        let step = least_move(two.a, two.b);
        let most = 3.0 * two.a.w;
        let len = length(step);
        x = x + select(step, step * (most / len), len > most);
        two = deepest_two(colliders, count, offset, x);
        if (two.b.w < -TOUCHING * offset || two.a.w <= TOUCHING * offset) {
            break;
        }
    }
    // The approach to the two it touches (or nearly) the fastest, the least change that
    // leaves it moving towards neither.
    var fast = Deepest(NONE, NONE);
    for (var c = 0u; c < count; c = c + 1u) {
        let col = colliders[c];
        let s = collider_surface(col, x);
        if (s.w > offset * 1.1) {
            continue;
        }
        var vs = vec3<f32>(0.0);
        if (col.info.x == 1.0) {
            vs = cross(col.b.xyz, s.xyz * col.info.y);
        }
        fast = deeper(fast, vec4<f32>(s.xyz, dot(vs - m.v, s.xyz)));
    }
    var v = m.v;
    if (fast.a.w > 0.0) {
        if (fast.b.w > -1e29) {
            v = v + least_move(fast.a, fast.b);
        } else {
            v = v + fast.a.w * fast.a.xyz;
        }
    }
    return Motion(x, v);
}
