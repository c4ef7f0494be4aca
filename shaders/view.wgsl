// The 3D view's finished image put into the window's egui pass: an opaque rectangle, one
// texel per pixel (the viewport is set to the image's size). No blending, no dithering: on a
// software adapter this is close to a memory copy, where egui's own image shader costs about
// as much as drawing the scene.

@group(0) @binding(0) var view_image: texture_2d<f32>;
@group(0) @binding(1) var view_sampler: sampler;

struct Corner {
    @builtin(position) position: vec4<f32>,
    @location(0) uv: vec2<f32>,
};

// A four-vertex triangle strip over the viewport: vertex i is the corner (i & 1, i >> 1),
// with v growing downwards as the image's rows do.
@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> Corner {
    let uv = vec2<f32>(f32(index & 1u), f32(index >> 1u));
    var out: Corner;
    out.position = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, 0.0, 1.0);
    out.uv = uv;
    return out;
}

// The image holds sRGB-encoded bytes in a plain unorm texture, as the window expects them.
@fragment
fn fs_main(in: Corner) -> @location(0) vec4<f32> {
    return textureSample(view_image, view_sampler, in.uv);
}

// For a window whose format encodes to sRGB itself: hand it linear values.
@fragment
fn fs_srgb_window(in: Corner) -> @location(0) vec4<f32> {
    let c = textureSample(view_image, view_sampler, in.uv);
    let low = c.rgb / 12.92;
    let high = pow((c.rgb + vec3<f32>(0.055)) / 1.055, vec3<f32>(2.4));
    return vec4<f32>(select(high, low, c.rgb <= vec3<f32>(0.04045)), c.a);
}
