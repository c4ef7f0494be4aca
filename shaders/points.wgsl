// Particles as round screen-space dots: one instanced quad per particle.

struct InstanceIn {
    @location(0) position: vec3<f32>,
    @location(1) color: vec4<f32>,
};

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) color: vec4<f32>,
    @location(1) local: vec2<f32>,
};

@vertex
fn vs_main(@builtin(vertex_index) vi: u32, in: InstanceIn) -> VertexOut {
    var corners = array<vec2<f32>, 6>(
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, -1.0), vec2<f32>(1.0, 1.0),
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, 1.0), vec2<f32>(-1.0, 1.0),
    );
    let corner = corners[vi];
    var clip = globals.view_proj * vec4<f32>(in.position, 1.0);
    // Half the dot diameter, converted from pixels to clip units (scaled by w to undo the
    // perspective divide).
    let half_px = 0.5 * globals.viewport.z;
    clip = vec4<f32>(clip.xy + corner * half_px * 2.0 / globals.viewport.xy * clip.w, clip.z - 4.0e-4 * clip.w, clip.w);
    var out: VertexOut;
    out.clip = clip;
    out.color = in.color;
    out.local = corner;
    return out;
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    if (dot(in.local, in.local) > 1.0) {
        discard;
    }
    return vec4<f32>(to_srgb(in.color.rgb), 1.0);
}
