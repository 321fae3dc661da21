// The 2D overlay: the colour legend's panel, bar and labels (src/render/legend.rs).
// Positions are already in clip space. Colours are sRGB with straight alpha.

struct Globals {
    view_proj: mat4x4<f32>,
    eye: vec4<f32>,
    light: vec4<f32>,
    front: vec4<f32>,
    back: vec4<f32>,
    prop: vec4<f32>,
    wire: vec4<f32>,
    background: vec4<f32>,
    shadow: vec4<f32>,
    // y: 1 to encode sRGB in the shader (non-sRGB target).
    params: vec4<f32>,
};

@group(0) @binding(0) var<uniform> g: Globals;
@group(0) @binding(3) var gradient_texture: texture_2d<f32>;
@group(0) @binding(4) var gradient_sampler: sampler;
@group(0) @binding(5) var font_texture: texture_2d<f32>;

struct VertexIn {
    @location(0) position: vec2<f32>,
    @location(1) uv: vec2<f32>,
    @location(2) color: vec4<f32>,
    // 0: solid colour; 1: the gradient texture at uv; 2: the font atlas texel at uv (texels).
    @location(3) mode: f32,
};

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
    @location(1) color: vec4<f32>,
    @location(2) mode: f32,
};

@vertex
fn vs_overlay(in: VertexIn) -> VertexOut {
    var out: VertexOut;
    out.clip = vec4<f32>(in.position, 0.0, 1.0);
    out.uv = in.uv;
    out.color = in.color;
    out.mode = in.mode;
    return out;
}

fn srgb_to_linear(c: vec3<f32>) -> vec3<f32> {
    return select(pow((c + 0.055) / 1.055, vec3<f32>(2.4)), c / 12.92, c <= vec3<f32>(0.04045));
}

fn linear_to_srgb(c: vec3<f32>) -> vec3<f32> {
    let x = clamp(c, vec3<f32>(0.0), vec3<f32>(1.0));
    return select(1.055 * pow(x, vec3<f32>(1.0 / 2.4)) - 0.055, 12.92 * x, x <= vec3<f32>(0.0031308));
}

@fragment
fn fs_overlay(in: VertexOut) -> @location(0) vec4<f32> {
    let gradient = textureSampleLevel(gradient_texture, gradient_sampler, in.uv, 0.0).rgb;
    let size = vec2<i32>(textureDimensions(font_texture));
    let texel = clamp(vec2<i32>(floor(in.uv)), vec2<i32>(0), size - vec2<i32>(1));
    let ink = textureLoad(font_texture, texel, 0).r;
    var c = srgb_to_linear(in.color.rgb);
    var alpha = in.color.a;
    if (in.mode > 1.5) {
        alpha = alpha * ink;
    } else if (in.mode > 0.5) {
        c = gradient;
    }
    if (g.params.y > 0.5) {
        c = linear_to_srgb(c);
    }
    return vec4<f32>(c, alpha);
}
