//! The floor shadow: a shadow map of cloth and props seen from a light nearly overhead, and
//! the floor it falls on, filtered in `fs_floor` (`shaders/scene.wgsl`) with a penumbra
//! that widens with the distance between what casts the shadow and the floor.
//!
//! The filter is Fernando's percentage-closer soft shadows (*Percentage-Closer Soft
//! Shadows*, NVIDIA 2005): a search of the map round the floor point for what lies between
//! it and the light gives the blockers' mean depth; the penumbra's radius is that distance
//! times [`PENUMBRA_SLOPE`]; the light is the share of 32 bilinear depth comparisons over
//! a disc of that radius that pass, their pattern turned per pixel, so that the shadow
//! fades smoothly, with no steps, from its core to the bare background.
//!
//! ```text
//!        light (orthographic, along −SHADOW_FROM)
//!          ↓   ↓   ↓
//!         ▄▄▄▄▄▄▄▄▄      blocker, depth d_b
//!          ╱       ╲
//!   ──────░▓▓▓▓▓▓▓▓▓░──── floor, depth d_r: penumbra radius = slope · (d_r − d_b)
//! ```

use super::frame::Frame;
use super::vertex::{DEPTH_FORMAT, Vertex};
use glam::{Mat4, Vec2, Vec3};

/// The shadow map's side, texels. A garment's shadow on a floor spans about a metre and a
/// half: 0.7 mm a texel, finer than the narrowest penumbra.
pub const SIDE: u32 = 2048;

/// The penumbra's radius per metre between the shadow's caster and the floor, along the
/// light: the half-angle (about 6°) of a broad soft light, a window or a softbox.
pub const PENUMBRA_SLOPE: f32 = 0.1;

/// What one frame's shadow needs: the light's projection and the floor under the shadow.
pub struct Setup {
    /// World to the shadow map's clip space.
    pub light_view_proj: Mat4,
    /// The floor's rectangle under everything's shadow, two triangles.
    pub floor: [Vertex; 6],
    /// x: the map's side, m; y: its depth range, m; z: [`PENUMBRA_SLOPE`]; w: texels a side.
    pub params: [f32; 4],
}

/// The shadow's light and floor for `frame`, the light coming from `from` (z > 0); `None`
/// where there is no floor or nothing finite to cast a shadow.
pub fn setup(frame: &Frame, from: Vec3) -> Option<Setup> {
    let floor_z = frame.floor_z?;
    let d = -from.normalize();
    if d.z > -0.1 {
        return None;
    }
    let points: Vec<Vec3> = frame
        .cloth_positions
        .iter()
        .chain(frame.props.iter().flat_map(|p| p.positions.iter()))
        .map(|p| Vec3::from_array(*p))
        .filter(|p| p.is_finite())
        .collect();
    if points.is_empty() {
        return None;
    }
    // Where each point's shadow falls on the floor, and the widest penumbra.
    let (mut lo, mut hi, mut reach) = (Vec2::MAX, Vec2::MIN, 0.0f32);
    for p in &points {
        let along = (p.z - floor_z).max(0.0) / -d.z;
        let q = (*p + d * along).truncate();
        (lo, hi) = (lo.min(q), hi.max(q));
        reach = reach.max(PENUMBRA_SLOPE * along);
    }
    let margin = reach + 0.05 * (hi - lo).max_element() + 0.01;
    let (lo, hi) = (lo - Vec2::splat(margin), hi + Vec2::splat(margin));
    let corners = [Vec3::new(lo.x, lo.y, floor_z), Vec3::new(hi.x, lo.y, floor_z), Vec3::new(hi.x, hi.y, floor_z), Vec3::new(lo.x, hi.y, floor_z)];
    // The light's view, orthographic, square, from the nearest caster to the floor.
    let (box_lo, box_hi) = points.iter().chain(&corners).fold((Vec3::MAX, Vec3::MIN), |(a, b), p| (a.min(*p), b.max(*p)));
    let centre = 0.5 * (box_lo + box_hi);
    let up = if d.cross(Vec3::Y).length() > 0.1 { Vec3::Y } else { Vec3::X };
    let view = glam::camera::rh::view::look_at_mat4(centre - d, centre, up);
    let (v_lo, v_hi) = points.iter().chain(&corners).map(|p| view.transform_point3(*p)).fold((Vec3::MAX, Vec3::MIN), |(a, b), p| (a.min(p), b.max(p)));
    let side = 1.02 * (v_hi - v_lo).truncate().max_element().max(1e-3);
    let pad = 0.01 * side;
    let (near, far) = (-v_hi.z - pad, -v_lo.z + pad);
    let mid = 0.5 * (v_lo + v_hi);
    let projection = glam::camera::rh::proj::directx::orthographic(mid.x - 0.5 * side, mid.x + 0.5 * side, mid.y - 0.5 * side, mid.y + 0.5 * side, near, far);
    let vertex = |p: Vec3| Vertex { position: p.to_array(), normal: [0.0, 0.0, 1.0], uv: [0.0; 2], scale: -1.0 };
    let [a, b, c, e] = corners.map(vertex);
    Some(Setup { light_view_proj: projection * view, floor: [a, b, c, a, c, e], params: [side, far - near, PENUMBRA_SLOPE, SIDE as f32] })
}

/// The shadow map: its depth texture, the sampler that compares against it, and the
/// depth-only pipeline that draws it (`shaders/shadow_map.wgsl`).
pub struct ShadowMap {
    pub view: wgpu::TextureView,
    pub sampler: wgpu::Sampler,
    pipeline: wgpu::RenderPipeline,
    uniform: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
}

impl ShadowMap {
    pub fn new(device: &wgpu::Device) -> Self {
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("rosette shadow map"),
            size: wgpu::Extent3d { width: SIDE, height: SIDE, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("rosette shadow comparison"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            compare: Some(wgpu::CompareFunction::LessEqual),
            ..Default::default()
        });
        let uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("rosette shadow light"),
            size: 64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("rosette shadow light"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX,
                ty: wgpu::BindingType::Buffer { ty: wgpu::BufferBindingType::Uniform, has_dynamic_offset: false, min_binding_size: wgpu::BufferSize::new(64) },
                count: None,
            }],
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("rosette shadow light"),
            layout: &layout,
            entries: &[wgpu::BindGroupEntry { binding: 0, resource: uniform.as_entire_binding() }],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("rosette shadow map"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("rosette shadow map shader"),
            source: wgpu::ShaderSource::Wgsl(include_str!("../../shaders/shadow_map.wgsl").into()),
        });
        let attributes = wgpu::vertex_attr_array![0 => Float32x3];
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("rosette shadow map"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &shader,
                entry_point: Some("vs_depth"),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: std::mem::size_of::<Vertex>() as u64,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &attributes,
                })],
            },
            primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: wgpu::StencilState::default(),
                bias: wgpu::DepthBiasState::default(),
            }),
            multisample: wgpu::MultisampleState::default(),
            fragment: None,
            multiview_mask: None,
            cache: None,
        });
        Self { view: texture.create_view(&wgpu::TextureViewDescriptor::default()), sampler, pipeline, uniform, bind_group }
    }

    /// Draws `meshes` (vertex buffers of [`Vertex`], with their vertex counts) into the map
    /// as the light `light_view_proj` sees them, and submits the pass, ahead of the frame
    /// that reads the map.
    pub fn draw(&self, device: &wgpu::Device, queue: &wgpu::Queue, light_view_proj: Mat4, meshes: &[(&wgpu::Buffer, u32)]) {
        queue.write_buffer(&self.uniform, 0, bytemuck::cast_slice(&light_view_proj.to_cols_array()));
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("rosette shadow map") });
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("rosette shadow map"),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &self.view,
                    depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Store }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.bind_group, &[]);
            for (buffer, count) in meshes {
                pass.set_vertex_buffer(0, buffer.slice(..));
                pass.draw(0..*count, 0..1);
            }
        }
        queue.submit([encoder.finish()]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_floor_lies_under_the_shadow_and_the_light_sees_it_all() {
        let frame = Frame {
            cloth_positions: vec![[0.0, 0.0, 1.0], [0.2, 0.0, 1.0], [0.0, 0.2, 1.0]],
            cloth_triangles: vec![[0, 1, 2]],
            cloth_uv: vec![[0.0; 2]; 3],
            floor_z: Some(0.0),
            ..Frame::default()
        };
        let s = setup(&frame, Vec3::new(0.2, -0.15, 1.0)).unwrap();
        // Every point and floor corner is inside the map and its depth range.
        for p in frame.cloth_positions.iter().chain(s.floor.iter().map(|v| &v.position)) {
            let c = s.light_view_proj.project_point3(Vec3::from_array(*p));
            assert!(c.x.abs() < 1.0 && c.y.abs() < 1.0 && (0.0..1.0).contains(&c.z), "{p:?} → {c}");
        }
        // The cloth is nearer the light than the floor under it.
        let cloth = s.light_view_proj.project_point3(Vec3::new(0.05, 0.05, 1.0)).z;
        let under = s.light_view_proj.project_point3(Vec3::new(0.05 - 0.2, 0.05 + 0.15, 0.0)).z;
        assert!(cloth < under, "{cloth} {under}");
        // The floor reaches past the shadow by its penumbra, 0.1 m for a 1 m height.
        let xs: Vec<f32> = s.floor.iter().map(|v| v.position[0]).collect();
        assert!(xs.iter().cloned().fold(f32::MAX, f32::min) < -0.2 - 0.1 && xs.iter().cloned().fold(f32::MIN, f32::max) > 0.0 + 0.1, "{xs:?}");
        assert!(setup(&Frame { floor_z: None, ..frame }, Vec3::Z).is_none());
    }
}
