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

// `end` (position and velocity after a substep that started at `x`) with the first `count`
// of `colliders` (spheres and planes, the cloth kept `offset` off them) resolved against
// the substep's path, with friction.
fn collide_among(colliders: array<Collider, 4>, count: u32, offset: f32, x: vec3<f32>, end: Motion) -> Motion {
    var nx = end.x;
    var nv = end.v;
    for (var c = 0u; c < count; c = c + 1u) {
        let col = colliders[c];
        let mu = col.info.z;
        var caught = false;
        var n = vec3<f32>(0.0, 1.0, 0.0);
        var v_surface = vec3<f32>(0.0);
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
                n = unit_or_up(moved);
                nx = centre + n * max(reach, len);
                v_surface = cross(col.b.xyz, n * radius);
                caught = true;
            }
        } else if (col.info.x == 2.0) {
            let normal = col.b.xyz;
            let depth = offset - dot(nx - col.a.xyz, normal);
            if (depth > 0.0) {
                nx = nx + depth * normal;
                n = normal;
                caught = true;
            }
        }
        if (caught) {
            nv = touching(nv, v_surface, n, mu, 1.0);
        }
    }
    return Motion(nx, nv);
}
