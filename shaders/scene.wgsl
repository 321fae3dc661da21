// Cloth, props and the floor shadow (src/render/renderer.rs).
//
// Vertex buffers are de-indexed (three vertices per triangle), so vertex_index % 3 is the
// corner of the triangle: the barycentric coordinates the wireframe is drawn from.
// Colours in `Globals` are linear; `params.y` says whether to encode sRGB here (non-sRGB
// target) or leave it to the hardware (sRGB target).

struct Globals {
    view_proj: mat4x4<f32>,
    // xyz: eye position, m.
    eye: vec4<f32>,
    // xyz: unit vector towards the key light.
    light: vec4<f32>,
    // Fabric tints (front: the side the triangle normals point to), linear RGB.
    front: vec4<f32>,
    back: vec4<f32>,
    prop: vec4<f32>,
    // rgb: wireframe colour; a: its opacity, 0 when the wireframe is off.
    wire: vec4<f32>,
    // rgb: the background, linear; a: how much the shadow's core darkens it, 0..1.
    background: vec4<f32>,
    // xyz: unit direction light travels (z < 0); w: floor height, m.
    shadow: vec4<f32>,
    // x: weave repeats per metre; y: 1 to encode sRGB in the shader; z: gradient texture row
    // (v) of the colour map; w: penumbra spread per metre of height above the floor.
    params: vec4<f32>,
};

@group(0) @binding(0) var<uniform> g: Globals;
@group(0) @binding(1) var weave_texture: texture_2d<f32>;
@group(0) @binding(2) var weave_sampler: sampler;
@group(0) @binding(3) var gradient_texture: texture_2d<f32>;
@group(0) @binding(4) var gradient_sampler: sampler;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    // Rest position along warp and weft, m.
    @location(2) uv: vec2<f32>,
    // Position on the colour scale 0..1, or negative for the fabric's own look.
    @location(3) scale: f32,
};

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) scale: f32,
    @location(4) barycentric: vec3<f32>,
};

@vertex
fn vs_main(in: VertexIn, @builtin(vertex_index) index: u32) -> VertexOut {
    var out: VertexOut;
    out.clip = g.view_proj * vec4<f32>(in.position, 1.0);
    out.world = in.position;
    out.normal = in.normal;
    out.uv = in.uv;
    out.scale = in.scale;
    let corner = index % 3u;
    out.barycentric = vec3<f32>(f32(corner == 0u), f32(corner == 1u), f32(corner == 2u));
    return out;
}

fn linear_to_srgb(c: vec3<f32>) -> vec3<f32> {
    let x = clamp(c, vec3<f32>(0.0), vec3<f32>(1.0));
    return select(1.055 * pow(x, vec3<f32>(1.0 / 2.4)) - 0.055, 12.92 * x, x <= vec3<f32>(0.0031308));
}

fn output(c: vec3<f32>, alpha: f32) -> vec4<f32> {
    if (g.params.y > 0.5) {
        return vec4<f32>(linear_to_srgb(c), alpha);
    }
    return vec4<f32>(c, alpha);
}

// Sky/ground ambient, a key light with a soft wrap (cloth scatters light round its edges),
// a weak fill from the opposite side and a faint sheen.
fn shade(base: vec3<f32>, n: vec3<f32>, world: vec3<f32>, sheen: f32) -> vec3<f32> {
    let l = g.light.xyz;
    let v = normalize(g.eye.xyz - world);
    let key = max((dot(n, l) + 0.1) / 1.1, 0.0);
    let fill = max(dot(n, normalize(vec3<f32>(-0.5, -0.7, 0.3))), 0.0);
    let ambient = mix(vec3<f32>(0.10, 0.10, 0.10), vec3<f32>(0.30, 0.32, 0.35), 0.5 + 0.5 * n.z);
    let h = normalize(l + v);
    let specular = sheen * pow(max(dot(n, h), 0.0), 24.0);
    return base * (ambient + 0.95 * key + 0.22 * fill) + vec3<f32>(specular);
}

// The normal facing the viewer (cloth and props are drawn from both sides).
fn facing_normal(normal: vec3<f32>, front: bool) -> vec3<f32> {
    let n = normalize(normal);
    return select(-n, n, front);
}

@fragment
fn fs_cloth(in: VertexOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    // Sampled and differentiated before any branch (uniform control flow).
    // The texture's yarn shading at a little over half strength (its mean is about 0.75),
    // so light and shade on folds read through the weave.
    let weave = mix(vec3<f32>(1.0), textureSample(weave_texture, weave_sampler, in.uv * g.params.x).rgb / 0.75, 0.55);
    let mapped = textureSample(gradient_texture, gradient_sampler, vec2<f32>(clamp(in.scale, 0.0, 1.0), g.params.z)).rgb;
    let width = max(fwidth(in.barycentric), vec3<f32>(1e-6));
    let n = facing_normal(in.normal, front);
    var base = select(g.back.rgb, g.front.rgb, front) * weave;
    if (in.scale >= 0.0) {
        // The map's colour, with a trace of the weave so the cloth still reads as cloth.
        let luma = dot(weave, vec3<f32>(0.3, 0.55, 0.15));
        base = mapped * mix(1.0, luma, 0.5);
    }
    var c = shade(base, n, in.world, 0.05);
    // Edges: within about a pixel of a triangle side.
    let d = in.barycentric / width;
    let edge = 1.0 - smoothstep(0.4, 1.4, min(d.x, min(d.y, d.z)));
    c = mix(c, g.wire.rgb, edge * g.wire.a);
    return output(c, 1.0);
}

@fragment
fn fs_prop(in: VertexOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    let n = facing_normal(in.normal, front);
    return output(shade(g.prop.rgb, n, in.world, 0.12), 1.0);
}

struct ShadowOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) darkness: f32,
};

// The shadow: each vertex projected along the light onto the floor. Instance 0 is the core;
// instances 1–8, 9–16 and 17–24 are copies pushed out in eight directions by one, two and
// three steps of the penumbra spread, which grows with height above the floor, each ring
// lighter than the last. Drawn with a min blend, so overlapping copies never darken twice:
// the darkest copy over a pixel wins, and the edge fades in steps.
@vertex
fn vs_shadow(in: VertexIn, @builtin(instance_index) instance: u32) -> ShadowOut {
    let d = g.shadow.xyz;
    let floor_z = g.shadow.w;
    let height = max(in.position.z - floor_z, 0.0);
    var p = in.position + d * (height / max(-d.z, 1e-3));
    let ring = select(0u, (instance - 1u) / 8u + 1u, instance > 0u);
    let angle = f32((instance + 7u) % 8u) * 0.7853982 + f32(ring) * 0.3926991;
    p = vec3<f32>(p.xy + vec2<f32>(cos(angle), sin(angle)) * (f32(ring) * g.params.w * height), floor_z);
    var out: ShadowOut;
    out.clip = g.view_proj * vec4<f32>(p, 1.0);
    out.darkness = 1.0 - f32(ring) / 4.0;
    return out;
}

@fragment
fn fs_shadow(in: ShadowOut) -> @location(0) vec4<f32> {
    // The background, darkened: no floor is drawn, the shadow falls on the background.
    return output(g.background.rgb * (1.0 - g.background.a * in.darkness), 1.0);
}
