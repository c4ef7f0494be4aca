// What every contact on the GPU shares (prepended to the step shaders with
// shaders/step_common.wgsl, and to shaders/obstacle.wgsl; src/gpu/kernel.rs): the velocity
// response of a particle that touches a surface (the CPU's `solid::touching`).

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
