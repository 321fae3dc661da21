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
    // The fabric's tints (front: the side the triangle normals point to), linear RGB.
    front: vec4<f32>,
    back: vec4<f32>,
    prop: vec4<f32>,
    // rgb: wireframe colour; a: its opacity, 0 when the wireframe is off.
    wire: vec4<f32>,
    // rgb: the background, linear; a: how much the shadow's core darkens it, 0..1.
    background: vec4<f32>,
    // xyz: unit direction light travels (z < 0); w: floor height, m.
    shadow: vec4<f32>,
    // y: 1 to encode sRGB in the shader; z: gradient texture row (v) of the colour map.
    params: vec4<f32>,
    // World to the shadow map's clip space (src/render/shadow.rs).
    light_view_proj: mat4x4<f32>,
    // The pattern: x, y: repeats per metre along the warp and the weft; z: what its texels
    // are multiplied by (1 / their mean, for a weave); w: its strength, 0..1.
    cloth: vec4<f32>,
    // rgb: the sheen's colour, linear; a: its roughness, negative for no sheen.
    sheen: vec4<f32>,
    // x: the shadow map's side, m; y: its depth range, m; z: penumbra radius per metre
    // between caster and floor; w: texels a side.
    shadow_map: vec4<f32>,
};

@group(0) @binding(0) var<uniform> g: Globals;
@group(0) @binding(1) var pattern_texture: texture_2d<f32>;
@group(0) @binding(2) var pattern_sampler: sampler;
@group(0) @binding(3) var gradient_texture: texture_2d<f32>;
@group(0) @binding(4) var gradient_sampler: sampler;
@group(0) @binding(6) var shadow_texture: texture_depth_2d;
@group(0) @binding(7) var shadow_sampler: sampler_comparison;

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

const PI: f32 = 3.14159265;

// Sky/ground ambient, linear RGB, for a surface of normal n.
fn ambient(n: vec3<f32>) -> vec3<f32> {
    return mix(vec3<f32>(0.10, 0.10, 0.10), vec3<f32>(0.30, 0.32, 0.35), 0.5 + 0.5 * n.z);
}

// The diffuse light: sky/ground ambient, a key light with a soft wrap (cloth scatters
// light round its edges) and a weak fill from the opposite side.
fn diffuse_light(n: vec3<f32>) -> vec3<f32> {
    let key = max((dot(n, g.light.xyz) + 0.1) / 1.1, 0.0);
    let fill = max(dot(n, normalize(vec3<f32>(-0.5, -0.7, 0.3))), 0.0);
    return ambient(n) + 0.95 * key + 0.22 * fill;
}

// A prop's light: diffuse and a faint highlight.
fn shade(base: vec3<f32>, n: vec3<f32>, world: vec3<f32>, highlight: f32) -> vec3<f32> {
    let v = normalize(g.eye.xyz - world);
    let h = normalize(g.light.xyz + v);
    return base * diffuse_light(n) + vec3<f32>(highlight * pow(max(dot(n, h), 0.0), 24.0));
}

// Charlie's sheen distribution (Estevez and Kulla 2017, as glTF's KHR_materials_sheen gives
// it) and Neubelt and Pettineo's visibility: src/appearance/shade.rs, which the swatch uses.
fn charlie(roughness: f32, n_dot_h: f32) -> f32 {
    let alpha = max(roughness * roughness, 0.007);
    let inverse = 1.0 / alpha;
    let sin2 = max(1.0 - n_dot_h * n_dot_h, 0.0);
    return (2.0 + inverse) * pow(sin2, 0.5 * inverse) / (2.0 * PI);
}

fn sheen_visibility(n_dot_l: f32, n_dot_v: f32) -> f32 {
    return 1.0 / max(4.0 * (n_dot_l + n_dot_v - n_dot_l * n_dot_v), 1e-4);
}

fn sheen_ambient(roughness: f32, n_dot_v: f32) -> f32 {
    let grazing = pow(1.0 - clamp(n_dot_v, 0.0, 1.0), 2.5);
    return (0.08 + 0.4 * grazing) * (0.7 + 0.3 * roughness);
}

// Cloth: the diffuse base, and over it the fabric's sheen where it has one (the base dimmed
// by the share of light the sheen takes, appearance::shade::SHEEN_ALBEDO); a faint
// highlight where it has none.
fn shade_cloth(base: vec3<f32>, n: vec3<f32>, world: vec3<f32>) -> vec3<f32> {
    if (g.sheen.a < 0.0) {
        return shade(base, n, world, 0.05);
    }
    let l = g.light.xyz;
    let v = normalize(g.eye.xyz - world);
    let n_dot_l = max(dot(n, l), 0.0);
    let n_dot_v = max(dot(n, v), 1e-3);
    let colour = g.sheen.rgb;
    let roughness = g.sheen.a;
    let scale = 1.0 - 0.25 * max(colour.r, max(colour.g, colour.b));
    let h = normalize(l + v);
    let lobe = charlie(roughness, clamp(dot(n, h), 0.0, 1.0)) * sheen_visibility(n_dot_l, n_dot_v);
    let sky = dot(ambient(n), vec3<f32>(1.0 / 3.0));
    let sheen = PI * 0.95 * n_dot_l * lobe + 2.0 * sky * sheen_ambient(roughness, n_dot_v);
    return base * diffuse_light(n) * scale + colour * sheen;
}

// The normal facing the viewer (cloth and props are drawn from both sides).
fn facing_normal(normal: vec3<f32>, front: bool) -> vec3<f32> {
    let n = normalize(normal);
    return select(-n, n, front);
}

@fragment
fn fs_cloth(in: VertexOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    // Sampled and differentiated before any branch (uniform control flow). The pattern is
    // laid along the warp (u) and the weft (v), one repeat per 1 / g.cloth.xy metres.
    let texel = textureSample(pattern_texture, pattern_sampler, in.uv * g.cloth.xy).rgb;
    let pattern = mix(vec3<f32>(1.0), texel * g.cloth.z, g.cloth.w);
    let mapped = textureSample(gradient_texture, gradient_sampler, vec2<f32>(clamp(in.scale, 0.0, 1.0), g.params.z)).rgb;
    let width = max(fwidth(in.barycentric), vec3<f32>(1e-6));
    let n = facing_normal(in.normal, front);
    var base = select(g.back.rgb, g.front.rgb, front) * pattern;
    var c = vec3<f32>(0.0);
    if (in.scale >= 0.0) {
        // The map's colour, with a trace of the pattern so the cloth still reads as cloth.
        let luma = dot(pattern, vec3<f32>(0.3, 0.55, 0.15));
        c = shade(mapped * mix(1.0, luma, 0.5), n, in.world, 0.05);
    } else {
        c = shade_cloth(base, n, in.world);
    }
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

// Interleaved gradient noise (Jimenez 2014): a per-pixel angle that turns the filter's
// pattern, so that its few samples leave fine grain instead of steps.
fn pixel_angle(pixel: vec2<f32>) -> f32 {
    return 2.0 * PI * fract(52.9829189 * fract(dot(pixel, vec2<f32>(0.06711056, 0.00583715))));
}

// The i-th of n points of a Vogel (golden-angle) disc of unit radius, turned by `angle`.
fn vogel(i: u32, n: u32, angle: f32) -> vec2<f32> {
    let r = sqrt((f32(i) + 0.5) / f32(n));
    let theta = f32(i) * 2.39996323 + angle;
    return r * vec2<f32>(cos(theta), sin(theta));
}

// The share of the shadow's light that reaches the floor point `world`, 0..1: percentage-
// closer soft shadows (src/render/shadow.rs).
fn floor_light(world: vec3<f32>, pixel: vec2<f32>) -> f32 {
    let clip = g.light_view_proj * vec4<f32>(world, 1.0);
    let uv = vec2<f32>(0.5 + 0.5 * clip.x, 0.5 - 0.5 * clip.y);
    let depth = clip.z;
    let side_m = g.shadow_map.x;
    let range_m = g.shadow_map.y;
    let slope = g.shadow_map.z;
    let texels = g.shadow_map.w;
    let angle = pixel_angle(pixel);
    // Blockers: searched over the widest penumbra a caster near the light would cast.
    let search = min(slope * depth * range_m / side_m, 0.25);
    var blockers = 0.0;
    var blocker_depth = 0.0;
    for (var i = 0u; i < 16u; i = i + 1u) {
        let p = uv + search * vogel(i, 16u, angle);
        let texel = vec2<i32>(clamp(p, vec2<f32>(0.0), vec2<f32>(1.0)) * (texels - 1.0));
        let d = textureLoad(shadow_texture, texel, 0);
        if (d < depth - 1e-4) {
            blockers = blockers + 1.0;
            blocker_depth = blocker_depth + d;
        }
    }
    if (blockers == 0.0) {
        return 1.0;
    }
    blocker_depth = blocker_depth / blockers;
    // The penumbra: its radius grows with the caster's distance from the floor.
    let radius = clamp(slope * (depth - blocker_depth) * range_m / side_m, 1.5 / texels, search);
    var lit = 0.0;
    for (var i = 0u; i < 32u; i = i + 1u) {
        let p = uv + radius * vogel(i, 32u, angle);
        lit = lit + textureSampleCompareLevel(shadow_texture, shadow_sampler, p, depth - 1e-4);
    }
    return lit / 32.0;
}

@fragment
fn fs_floor(in: VertexOut) -> @location(0) vec4<f32> {
    // The background, darkened where the shadow falls: no floor is drawn, the shadow falls
    // on the background.
    let darkening = g.background.a * (1.0 - floor_light(in.world, in.clip.xy));
    return output(g.background.rgb * (1.0 - darkening), 1.0);
}
