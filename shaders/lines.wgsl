// Coloured line segments: springs, wireframe.

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) color: vec4<f32>,
};

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) color: vec4<f32>,
};

@vertex
fn vs_main(in: VertexIn) -> VertexOut {
    var out: VertexOut;
    var clip = globals.view_proj * vec4<f32>(in.position, 1.0);
    // Pull lines slightly towards the camera so they win against the surface they lie on.
    clip.z = clip.z - 2.0e-4 * clip.w;
    out.clip = clip;
    out.color = in.color;
    return out;
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    return vec4<f32>(to_srgb(in.color.rgb), in.color.a);
}
