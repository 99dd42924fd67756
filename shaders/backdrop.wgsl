// The backdrop of glass that blurs or bends the view through it (render crate, backdrop.rs): each
// level of an eye's copy of what it drew before its farthest such glass, drawn from the level
// above (level 0 from the eye's HDR target, the same size). One bilinear read at the centre of
// each target pixel: the mean of the 2 × 2 source texels under it for a halving (of the nearer
// ones where a size is odd), the texel itself for the copy.

@group(0) @binding(0) var source: texture_2d<f32>;
@group(0) @binding(1) var source_sampler: sampler;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
};

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> VsOut {
    // One triangle covering the whole target; uv 0–1 over it, v down.
    let x = f32((i << 1u) & 2u);
    let y = f32(i & 2u);
    var out: VsOut;
    out.clip = vec4<f32>(x * 2.0 - 1.0, 1.0 - y * 2.0, 0.0, 1.0);
    out.uv = vec2<f32>(x, y);
    return out;
}

@fragment
fn fs_main(in: VsOut) -> @location(0) vec4<f32> {
    return textureSampleLevel(source, source_sampler, in.uv, 0.0);
}
