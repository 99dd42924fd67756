// The specular image light's rough levels on the GPU (core/render/src/prefilter_gpu/mod.rs): one
// level of the prefiltered environment, roughness² = `alpha`, convolved from the box-filtered
// halving of level 0 at `source_level` (twice the target's width) with the same 96 Hammersley GGX
// samples a texel and the same n·l weights as phantogram_assets::ibl::prefiltered_levels on the
// CPU, so both give the same levels (to f16 and summation order). The bilinear reads are made
// here in f32 as Environment::sample makes them, not by a sampler: GPUs' filtering units weight
// texels in a few bits (8 on NVIDIA), which around a bright sun moved the rough levels by 0.3 %
// on an H200 where lavapipe, filtering in f32, agreed to 0.19 %.

struct Params {
    alpha: f32,
    source_level: f32,
    width: u32,
    height: u32,
    // The source was divided by this power of two to fit f16 (a sun brighter than 65504);
    // multiplied back here, before the result is stored (and clamped as the CPU path's upload).
    scale: f32,
}

@group(0) @binding(0) var source: texture_2d<f32>;
@group(0) @binding(2) var level_out: texture_storage_2d<rgba16float, write>;
@group(0) @binding(3) var<uniform> params: Params;

const PI: f32 = 3.14159265358979;
// PREFILTER_SAMPLES in prefilter.rs.
const SAMPLES: u32 = 96u;

// Equirectangular coordinates of world direction d (ibl/mod.rs; scene.wgsl's equirect_uv).
fn equirect_uv(d: vec3<f32>) -> vec2<f32> {
    let u = fract(atan2(d.y, d.x) / (2.0 * PI) + 1.0);
    let v = acos(clamp(d.z, -1.0, 1.0)) / PI;
    return vec2<f32>(u, v);
}

// Bilinear read of the source's `level` at equirectangular (u, v), wrapping in azimuth and clamped
// at the poles (Environment::sample).
fn bilinear(uv: vec2<f32>, level: i32) -> vec3<f32> {
    let size = vec2<i32>(textureDimensions(source, level));
    let p = uv * vec2<f32>(size) - 0.5;
    let p0 = floor(p);
    let f = p - p0;
    let x0 = i32(p0.x);
    let y0 = i32(p0.y);
    let xa = ((x0 % size.x) + size.x) % size.x;
    let xb = (((x0 + 1) % size.x) + size.x) % size.x;
    let ya = clamp(y0, 0, size.y - 1);
    let yb = clamp(y0 + 1, 0, size.y - 1);
    let t00 = textureLoad(source, vec2<i32>(xa, ya), level).rgb;
    let t10 = textureLoad(source, vec2<i32>(xb, ya), level).rgb;
    let t01 = textureLoad(source, vec2<i32>(xa, yb), level).rgb;
    let t11 = textureLoad(source, vec2<i32>(xb, yb), level).rgb;
    return t00 * ((1.0 - f.x) * (1.0 - f.y)) + t10 * (f.x * (1.0 - f.y)) + t01 * ((1.0 - f.x) * f.y)
        + t11 * (f.x * f.y);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= params.width || id.y >= params.height) {
        return;
    }
    // The texel's centre direction (Environment::direction).
    let phi = 2.0 * PI * (f32(id.x) + 0.5) / f32(params.width);
    let theta = PI * (f32(id.y) + 0.5) / f32(params.height);
    let n = vec3<f32>(sin(theta) * cos(phi), sin(theta) * sin(phi), cos(theta));
    let up = select(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 0.0, 1.0), abs(n.z) < 0.999);
    let t = normalize(cross(up, n));
    let b = cross(n, t);
    let a2 = params.alpha * params.alpha;
    var acc = vec3<f32>(0.0);
    var weight = 0.0;
    for (var i = 0u; i < SAMPLES; i = i + 1u) {
        let u1 = f32(i) / f32(SAMPLES);
        let u2 = f32(reverseBits(i)) * 2.3283064365386963e-10;
        let azimuth = 2.0 * PI * u1;
        let cos_t = sqrt(max((1.0 - u2) / (1.0 + (a2 - 1.0) * u2), 0.0));
        let sin_t = sqrt(max(1.0 - cos_t * cos_t, 0.0));
        let h = normalize(t * (sin_t * cos(azimuth)) + b * (sin_t * sin(azimuth)) + n * cos_t);
        let l = normalize(h * (2.0 * dot(n, h)) - n);
        let n_dot_l = dot(n, l);
        if (n_dot_l > 0.0) {
            acc = acc + bilinear(equirect_uv(l), i32(params.source_level)) * n_dot_l;
            weight = weight + n_dot_l;
        }
    }
    let radiance = min(acc / max(weight, 1e-6) * params.scale, vec3<f32>(65000.0));
    textureStore(level_out, vec2<i32>(id.xy), vec4<f32>(radiance, 1.0));
}
