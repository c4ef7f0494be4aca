// The forces that act on a triangle or a hinge rather than between two particles, one
// invocation per element, written to a slot of their own: the substep then sums the slots
// each particle is in (no atomics, the same sum in the same order every run).
// - Wind (src/sim/effects/wind.rs): each triangle's drag and lift from its velocity
//   relative to the gusting air; a third goes to each corner, so the triangle has one slot.
// - Dihedral bending (src/sim/forces/dihedral.rs): each hinge's force on its four points,
//   four slots.
// The arithmetic is the CPU's in its order, in f32. Prepended with shaders/cloth_layout.wgsl.

struct Params {
    // x: the submission's start time (s); y: substep length h (s); z: dihedral stiffness
    // (N·m).
    clock: vec4<f32>,
    // xyz: steady wind velocity (m/s); w: gust strength.
    wind: vec4<f32>,
    // x: gust period (s); y: drag coefficient; z: lift coefficient; w: air density (kg/m³).
    air: vec4<f32>,
    // x: triangles (0 without wind); y: hinges (0 without dihedral bending).
    counts: vec4<u32>,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> particles: array<Particle>;
// Triangles (xyz: corners), then per hinge two rows: [x0, x1, a, b] and the bits of
// [rest angle, weight, 0, 0].
@group(0) @binding(2) var<storage, read> elements: array<vec4<u32>>;
// [0].x: substeps the frame has taken (the substep counts them); then the slots.
@group(0) @binding(3) var<storage, read_write> forces: array<vec4<f32>>;

const TAU: f32 = 6.2831855;
const PI: f32 = 3.1415927;
// Wings lower than this fraction of their hinge get a limited force (the CPU's MIN_WING).
const MIN_WING: f32 = 0.02;

// The air's velocity at `x` at time `t` (Wind::air_velocity).
fn air_velocity(x: vec3<f32>, t: f32) -> vec3<f32> {
    let velocity = params.wind.xyz;
    let gust = params.wind.w;
    let speed = length(velocity);
    if (speed == 0.0 || gust == 0.0) {
        return velocity;
    }
    let along = velocity / speed;
    let s = t - dot(x, along) / speed;
    let p = max(params.air.x, 1e-3);
    let strength = sin(TAU * s / p) * 0.5
        + sin(TAU * s / (0.61 * p) + 1.3) * 0.3
        + sin(TAU * s / (0.37 * p) + 2.1) * 0.2;
    let veer = sin(TAU * s / (0.83 * p) + 0.7) * 0.25 * gust;
    let sn = sin(veer);
    let cs = cos(veer);
    let turned = vec3<f32>(cs * along.x + sn * along.z, along.y, -sn * along.x + cs * along.z);
    return turned * speed * (1.0 + gust * strength);
}

fn wind_share(tri: vec4<u32>, t: f32) -> vec3<f32> {
    let a = particles[tri.x];
    let b = particles[tri.y];
    let c = particles[tri.z];
    let normal = cross(b.x.xyz - a.x.xyz, c.x.xyz - a.x.xyz);
    let twice_area = length(normal);
    if (twice_area <= 1e-12) {
        return vec3<f32>(0.0);
    }
    let n = normal / twice_area;
    let centre = (a.x.xyz + b.x.xyz + c.x.xyz) / 3.0;
    let air = air_velocity(centre, t);
    let relative = (a.v.xyz + b.v.xyz + c.v.xyz) / 3.0 - air;
    let speed = length(relative);
    if (speed <= 1e-6) {
        return vec3<f32>(0.0);
    }
    let flow = relative / speed;
    let facing = dot(flow, n);
    let area = 0.5 * twice_area;
    let half_rho = 0.5 * params.air.w;
    let drag = n * (-half_rho * params.air.y * area * speed * speed * facing);
    let across = n - flow * facing;
    let lift = across * (-half_rho * params.air.z * area * speed * speed * facing);
    return (drag + lift) / 3.0;
}

// Writes hinge `h`'s forces on its four points to slots `first`…`first + 3`.
fn hinge_forces(h: u32, row: u32, first: u32) {
    let ids = elements[row];
    let extra = bitcast<vec4<f32>>(elements[row + 1u]);
    let x0 = particles[ids.x].x.xyz;
    let x1 = particles[ids.y].x.xyz;
    let a = particles[ids.z].x.xyz;
    let b = particles[ids.w].x.xyz;
    let e = x1 - x0;
    let len2 = dot(e, e);
    let na = cross(e, a - x0);
    let nb = cross(x0 - x1, b - x1);
    let na2 = dot(na, na);
    let nb2 = dot(nb, nb);
    var g = array<vec3<f32>, 4>(vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0));
    var scale = 0.0;
    let tiny = 1e-24;
    if (len2 > tiny && na2 > tiny && nb2 > tiny) {
        let len = sqrt(len2);
        let axis = e / len;
        let theta = atan2(dot(cross(na, nb), axis), dot(na, nb));
        let ga = -na * (len / na2);
        let gb = -nb * (len / nb2);
        let alpha_a = dot(a - x0, e) / len2;
        let alpha_b = dot(b - x0, e) / len2;
        g[0] = ga * (alpha_a - 1.0) + gb * (alpha_b - 1.0);
        g[1] = ga * (-alpha_a) - gb * alpha_b;
        g[2] = ga;
        g[3] = gb;
        let largest = max(length(ga), length(gb));
        let cap = 1.0 / (MIN_WING * length(e));
        var limit = 1.0;
        if (largest > cap) {
            limit = cap / largest;
        }
        var d = theta - extra.x;
        if (d > PI) {
            d = d - TAU;
        } else if (d < -PI) {
            d = d + TAU;
        }
        scale = (-2.0 * params.clock.z * extra.y) * d * limit;
    }
    for (var k = 0u; k < 4u; k = k + 1u) {
        forces[first + k] = vec4<f32>(g[k] * scale, 0.0);
    }
}

@compute @workgroup_size(64)
fn elements_forces(@builtin(global_invocation_id) id: vec3<u32>) {
    let e = id.x;
    let triangles = params.counts.x;
    let hinges = params.counts.y;
    if (e < triangles) {
        let t = params.clock.x + forces[0].x * params.clock.y;
        forces[1u + e] = vec4<f32>(wind_share(elements[e], t), 0.0);
    } else if (e < triangles + hinges) {
        let h = e - triangles;
        hinge_forces(h, triangles + 2u * h, 1u + triangles + 4u * h);
    }
}
