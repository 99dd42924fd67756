// Composition pass: tone-maps each eye's linear HDR image (Khronos PBR Neutral, with exposure) and
// combines the two with the anaglyph matrices in linear light. On an sRGB target the hardware
// applies the sRGB transfer function on write; on another (a window whose surface offers no sRGB
// format, as an OpenGL ES surface without EGL_KHR_gl_colorspace) the shader does
// (`ENCODE_SRGB`, set by the pipeline).

override ENCODE_SRGB: bool = false;

struct Compose {
    // Rows of the left and right 3×3 matrices (xyz used).
    left: array<vec4<f32>, 3>,
    right: array<vec4<f32>, 3>,
    // x: exposure (linear multiplier).
    params: vec4<f32>,
};

@group(0) @binding(0) var left_image: texture_2d<f32>;
@group(0) @binding(1) var right_image: texture_2d<f32>;
@group(0) @binding(2) var<uniform> compose: Compose;

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    // One triangle covering the whole target.
    let x = f32((i << 1u) & 2u);
    let y = f32(i & 2u);
    return vec4<f32>(x * 2.0 - 1.0, 1.0 - y * 2.0, 0.0, 1.0);
}

// Khronos PBR Neutral tone mapping (https://github.com/KhronosGroup/ToneMapping).
fn pbr_neutral(color_in: vec3<f32>) -> vec3<f32> {
    let start_compression = 0.8 - 0.04;
    let desaturation = 0.15;
    let x = min(color_in.r, min(color_in.g, color_in.b));
    var offset = 0.04;
    if (x < 0.08) {
        offset = x - 6.25 * x * x;
    }
    var color = color_in - vec3<f32>(offset);
    let peak = max(color.r, max(color.g, color.b));
    if (peak < start_compression) {
        return color;
    }
    let d = 1.0 - start_compression;
    let new_peak = 1.0 - d * d / (peak + d - start_compression);
    color = color * (new_peak / peak);
    let g = 1.0 - 1.0 / (desaturation * (peak - new_peak) + 1.0);
    return mix(color, vec3<f32>(new_peak), g);
}

@fragment
fn fs_main(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(frag.xy);
    let exposure = compose.params.x;
    let l = pbr_neutral(max(textureLoad(left_image, p, 0).rgb * exposure, vec3<f32>(0.0)));
    let r = pbr_neutral(max(textureLoad(right_image, p, 0).rgb * exposure, vec3<f32>(0.0)));
    let out = vec3<f32>(
        dot(compose.left[0].xyz, l) + dot(compose.right[0].xyz, r),
        dot(compose.left[1].xyz, l) + dot(compose.right[1].xyz, r),
        dot(compose.left[2].xyz, l) + dot(compose.right[2].xyz, r),
    );
    let linear = clamp(out, vec3<f32>(0.0), vec3<f32>(1.0));
    if (ENCODE_SRGB) {
        return vec4<f32>(srgb_encode(linear), 1.0);
    }
    return vec4<f32>(linear, 1.0);
}

// The sRGB transfer function (IEC 61966-2-1), as an sRGB target applies it on write.
fn srgb_encode(c: vec3<f32>) -> vec3<f32> {
    let low = c * 12.92;
    let high = 1.055 * pow(c, vec3<f32>(1.0 / 2.4)) - vec3<f32>(0.055);
    return select(high, low, c <= vec3<f32>(0.0031308));
}
