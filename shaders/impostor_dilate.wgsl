// Relief-texture impostors, second bake pass (render crate, impostor.rs): one face's depth map
// made conservative. The bake samples each texel's first surface at the texel's centre; a ray
// through another point of that texel may meet the surface nearer (a slope seen at a grazing
// angle, or the surface's edge covering part of the texel only). The ray's inside test reads,
// in green, the nearest depth of the texel and its eight neighbours — never behind the surface
// anywhere in the texel — and the material's lookups read the centre's, in red. Each value is
// the bits of an f32 in a u32 (impostor.rs says why).

@group(0) @binding(0) var raw_depth: texture_2d<u32>;

@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    // One triangle over the whole target.
    let uv = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    return vec4<f32>(uv * 2.0 - vec2<f32>(1.0), 0.0, 1.0);
}

@fragment
fn fs_main(@builtin(position) position: vec4<f32>) -> @location(0) vec4<u32> {
    let size = vec2<i32>(textureDimensions(raw_depth));
    let at = vec2<i32>(position.xy);
    let centre = bitcast<f32>(textureLoad(raw_depth, at, 0).r);
    var nearest = centre;
    for (var dy = -1; dy <= 1; dy = dy + 1) {
        for (var dx = -1; dx <= 1; dx = dx + 1) {
            let p = clamp(at + vec2<i32>(dx, dy), vec2<i32>(0), size - vec2<i32>(1));
            nearest = min(nearest, bitcast<f32>(textureLoad(raw_depth, p, 0).r));
        }
    }
    return vec4<u32>(bitcast<u32>(centre), bitcast<u32>(nearest), 0u, 0u);
}
