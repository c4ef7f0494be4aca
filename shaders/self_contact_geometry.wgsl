// The geometry of self-contact's pairs on the GPU (prepended to shaders/self_contact.wgsl,
// after shaders/segments.wgsl): the nearest point of a triangle to a point, as the CPU's
// `closest_weights` gives it, and a pair's distance, in f32.

// The point of triangle (a, b, c) nearest to p.
fn closest_on_triangle(p: vec3<f32>, a: vec3<f32>, b: vec3<f32>, c: vec3<f32>) -> vec3<f32> {
    let w = closest_weights(p, a, b, c);
    return a * w.x + b * w.y + c * w.z;
}

// The distance between segments p0–p1 and q0–q1.
fn segments_distance(p0: vec3<f32>, p1: vec3<f32>, q0: vec3<f32>, q1: vec3<f32>) -> f32 {
    let st = segments_closest(p0, p1, q0, q1);
    return length((p0 + st.x * (p1 - p0)) - (q0 + st.y * (q1 - q0)));
}

// The distance between the pair's sides with its particles at x (relative to one point).
fn pair_distance(edges: bool, x: array<vec3<f32>, 4>) -> f32 {
    if (edges) {
        return segments_distance(x[0], x[1], x[2], x[3]);
    }
    return length(x[0] - closest_on_triangle(x[0], x[1], x[2], x[3]));
}

// The weights of the point of triangle (a, b, c) nearest to p (the CPU's
// `closest_weights`).
fn closest_weights(p: vec3<f32>, a: vec3<f32>, b: vec3<f32>, c: vec3<f32>) -> vec3<f32> {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = dot(ab, ap);
    let d2 = dot(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0) {
        return vec3<f32>(1.0, 0.0, 0.0);
    }
    let bp = p - b;
    let d3 = dot(ab, bp);
    let d4 = dot(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) {
        return vec3<f32>(0.0, 1.0, 0.0);
    }
    let vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
        let v = d1 / (d1 - d3);
        return vec3<f32>(1.0 - v, v, 0.0);
    }
    let cp = p - c;
    let d5 = dot(ab, cp);
    let d6 = dot(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) {
        return vec3<f32>(0.0, 0.0, 1.0);
    }
    let vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
        let w = d2 / (d2 - d6);
        return vec3<f32>(1.0 - w, 0.0, w);
    }
    let va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return vec3<f32>(0.0, 1.0 - w, w);
    }
    let denom = 1.0 / (va + vb + vc);
    let v = vb * denom;
    let w = vc * denom;
    return vec3<f32>(1.0 - v - w, v, w);
}

