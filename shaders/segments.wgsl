// The nearest points of two segments (prepended to shaders/obstacle.wgsl and
// shaders/self_contact_geometry.wgsl), shared by the obstacles' edge pass and
// self-contact's edge–edge pairs.

// The nearest points of segments a–b and p–q: x where along a–b, y along p–q (the CPU's
// `segments_closest`, which runs in f64).
fn segments_closest(p0: vec3<f32>, p1: vec3<f32>, q0: vec3<f32>, q1: vec3<f32>) -> vec2<f32> {
    let d1 = p1 - p0;
    let d2 = q1 - q0;
    let r = p0 - q0;
    let a = dot(d1, d1);
    let e = dot(d2, d2);
    let f = dot(d2, r);
    let tiny = 1e-20;
    if (a <= tiny && e <= tiny) {
        return vec2<f32>(0.0);
    }
    if (a <= tiny) {
        return vec2<f32>(0.0, clamp(f / e, 0.0, 1.0));
    }
    let c = dot(d1, r);
    if (e <= tiny) {
        return vec2<f32>(clamp(-c / a, 0.0, 1.0), 0.0);
    }
    let b = dot(d1, d2);
    let denom = a * e - b * b;
    var s = 0.0;
    if (denom > 0.0) {
        s = clamp((b * f - c * e) / denom, 0.0, 1.0);
    }
    var t = (b * s + f) / e;
    if (t < 0.0) {
        t = 0.0;
        s = clamp(-c / a, 0.0, 1.0);
    } else if (t > 1.0) {
        t = 1.0;
        s = clamp((b - c) / a, 0.0, 1.0);
    }
    return vec2<f32>(s, t);
}
