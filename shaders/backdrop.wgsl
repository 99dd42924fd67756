// The backdrop of glass that blurs or bends the view through it (render crate, backdrop.rs): each
// level of an eye's copy of what it drew before its farthest such glass, drawn from the level
// above (level 0 from the eye's HDR target, the same size). The copy reads the texel itself. A
// halving weighs the 4 × 4 source texels around each target texel by the separable kernel
// [1 3 3 1] / 8 (four bilinear reads 0.75 texel off its centre, each the mean of a 2 × 2 block
// weighted 1 : 3): a 2 × 2 box's chain aliases what repeats near its texel size into a pattern
// of crosses and squares through frosted glass, this one's (a quadratic B-spline's) barely does.

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
fn fs_copy(in: VsOut) -> @location(0) vec4<f32> {
    return textureSampleLevel(source, source_sampler, in.uv, 0.0);
}

@fragment
fn fs_halve(in: VsOut) -> @location(0) vec4<f32> {
    let off = 0.75 / vec2<f32>(textureDimensions(source, 0));
    return 0.25 * (textureSampleLevel(source, source_sampler, in.uv + vec2<f32>(-off.x, -off.y), 0.0)
        + textureSampleLevel(source, source_sampler, in.uv + vec2<f32>(off.x, -off.y), 0.0)
        + textureSampleLevel(source, source_sampler, in.uv + vec2<f32>(-off.x, off.y), 0.0)
        + textureSampleLevel(source, source_sampler, in.uv + vec2<f32>(off.x, off.y), 0.0));
}
