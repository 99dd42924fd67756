// Scene pass: one eye's view of the artifact, lit by the world-fixed directional light, written as
// linear HDR radiance. Metallic–roughness shading: Lambert diffuse + GGX / Smith / Schlick
// specular (the glTF BRDF), plus a small hemispherical ambient term.
//
// Coordinates: vertex positions and normals are in the device frame (metres); `eye.view_proj` is
// the core's off-axis projection (reverse-Z, wgpu clip space).

struct Eye {
    view_proj: mat4x4<f32>,
    // Eye position, device frame (w unused).
    eye_pos: vec4<f32>,
    // Unit vector towards the light, device frame (w unused).
    toward_light: vec4<f32>,
    // Light radiance (rgb, linear) and, in w, the ambient level.
    light: vec4<f32>,
    // "Up" in the device frame for the hemispherical ambient (w unused).
    up: vec4<f32>,
};

@group(0) @binding(0) var<uniform> eye: Eye;

struct VsIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) color: vec4<f32>,
    @location(3) material: vec2<f32>,
};

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) color: vec4<f32>,
    @location(3) material: vec2<f32>,
};

@vertex
fn vs_main(v: VsIn) -> VsOut {
    var out: VsOut;
    out.clip = eye.view_proj * vec4<f32>(v.position, 1.0);
    out.world = v.position;
    out.normal = v.normal;
    out.color = v.color;
    out.material = v.material;
    return out;
}

const PI: f32 = 3.14159265;

fn ggx(n_dot_h: f32, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let d = n_dot_h * n_dot_h * (a2 - 1.0) + 1.0;
    return a2 / (PI * d * d);
}

// Smith visibility (height-correlated, combined with the 1 / (4 n·l n·v) term).
fn smith_visibility(n_dot_l: f32, n_dot_v: f32, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let gv = n_dot_l * sqrt(n_dot_v * n_dot_v * (1.0 - a2) + a2);
    let gl = n_dot_v * sqrt(n_dot_l * n_dot_l * (1.0 - a2) + a2);
    return 0.5 / max(gv + gl, 1e-5);
}

@fragment
fn fs_main(in: VsOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    // Open surfaces (the amphora's mouth) are seen from inside too.
    var n = normalize(in.normal);
    if (!front) {
        n = -n;
    }
    let v = normalize(eye.eye_pos.xyz - in.world);
    let l = normalize(eye.toward_light.xyz);
    let h = normalize(l + v);
    let base = in.color.rgb;
    let metallic = clamp(in.material.x, 0.0, 1.0);
    let roughness = clamp(in.material.y, 0.045, 1.0);
    let alpha = roughness * roughness;

    let n_dot_l = max(dot(n, l), 0.0);
    let n_dot_v = max(dot(n, v), 1e-4);
    let n_dot_h = max(dot(n, h), 0.0);
    let v_dot_h = max(dot(v, h), 0.0);

    let f0 = mix(vec3<f32>(0.04), base, metallic);
    let fresnel = f0 + (vec3<f32>(1.0) - f0) * pow(1.0 - v_dot_h, 5.0);
    let specular = fresnel * ggx(n_dot_h, alpha) * smith_visibility(n_dot_l, n_dot_v, alpha);
    let diffuse = (vec3<f32>(1.0) - fresnel) * (1.0 - metallic) * base / PI;
    let direct = (diffuse + specular) * eye.light.rgb * n_dot_l;

    // Hemispherical ambient: brighter from above; metals reflect it tinted by their colour.
    let sky = 0.5 + 0.5 * dot(n, normalize(eye.up.xyz));
    let ambient_light = eye.light.w * mix(0.35, 1.0, sky);
    let ambient = ambient_light * mix(base * (1.0 - metallic), f0 * 0.8, metallic);

    return vec4<f32>(direct + ambient, 1.0);
}
