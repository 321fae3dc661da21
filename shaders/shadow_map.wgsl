// The shadow map (src/render/shadow.rs): the depth of cloth and props seen from the light
// that casts the floor shadow, through an orthographic projection. No colour is written.

@group(0) @binding(0) var<uniform> light_view_proj: mat4x4<f32>;

@vertex
fn vs_depth(@location(0) position: vec3<f32>) -> @builtin(position) vec4<f32> {
    return light_view_proj * vec4<f32>(position, 1.0);
}
