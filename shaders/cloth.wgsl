// The cloth: two-sided Blinn-Phong, optional checker from the UVs.

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
};

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
};

@vertex
fn vs_main(in: VertexIn) -> VertexOut {
    var out: VertexOut;
    out.clip = globals.view_proj * vec4<f32>(in.position, 1.0);
    out.world = in.position;
    out.normal = in.normal;
    out.uv = in.uv;
    return out;
}

@fragment
fn fs_main(in: VertexOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    // Back faces show the other side of the cloth: flip the normal, use the back colour.
    let n = normalize(in.normal) * select(-1.0, 1.0, front);
    var base = select(globals.back_color.rgb, globals.front_color.rgb, front);
    if (globals.options.x > 0.5) {
        let cell = floor(in.uv * globals.options.y);
        let odd = (i32(cell.x) + i32(cell.y)) & 1;
        base = base * select(1.0, 0.6, odd == 1);
    }
    return vec4<f32>(to_srgb(blinn_phong(base, n, in.world, 24.0, 0.12)), 1.0);
}
