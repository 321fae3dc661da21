//! The wgpu renderer: pipelines, textures, and the per-frame upload of a [`Frame`].

use super::camera::Camera;
use super::frame::{Frame, PropMesh};
use super::shadow::{self, ShadowMap};
use super::vertex::{DEPTH_FORMAT, Vertex};
use crate::appearance::{Look, Pattern, shade::mean_linear};
use super::legend::{self, GRADIENT_ROWS, GRADIENT_TEXELS, OverlayVertex};
use super::{RenderOptions, font};
use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use wgpu::util::DeviceExt;


/// Where the key light comes from: high, and to the right of the default view, so folds
/// and buckles are modelled by light and shade.
const LIGHT_FROM: Vec3 = Vec3::new(0.75, 0.05, 0.7);

/// Where the light that casts the floor shadow comes from: nearly overhead, so the shadow
/// stays under what casts it.
const SHADOW_FROM: Vec3 = Vec3::new(0.2, -0.15, 1.0);

/// How much the core of the shadow darkens the background, 0..1.
const SHADOW_STRENGTH: f32 = 0.32;

/// How strongly a generated weave's light and shade show on the cloth, 0..1: a little over
/// half, so that the folds' light and shade read through the weave. A print is drawn at
/// full strength.
const WEAVE_STRENGTH: f32 = 0.55;

/// How far the back of the cloth is lightened towards white (sRGB), so that the two sides
/// read apart where a hem turns.
const BACK_LIGHTENING: f32 = 0.35;

/// Uniforms, laid out as `Globals` in the shaders.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
struct Globals {
    view_proj: [[f32; 4]; 4],
    eye: [f32; 4],
    light: [f32; 4],
    front: [f32; 4],
    back: [f32; 4],
    prop: [f32; 4],
    wire: [f32; 4],
    background: [f32; 4],
    shadow: [f32; 4],
    params: [f32; 4],
    light_view_proj: [[f32; 4]; 4],
    cloth: [f32; 4],
    sheen: [f32; 4],
    shadow_map: [f32; 4],
}


/// A vertex buffer that grows as needed and is rewritten each frame.
struct GrowingBuffer {
    label: &'static str,
    buffer: Option<wgpu::Buffer>,
    /// Vertices written by the last upload.
    count: u32,
}

impl GrowingBuffer {
    fn new(label: &'static str) -> Self {
        Self { label, buffer: None, count: 0 }
    }

    fn upload<T: Pod>(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, data: &[T]) {
        self.count = data.len() as u32;
        if data.is_empty() {
            return;
        }
        let bytes: &[u8] = bytemuck::cast_slice(data);
        let size = bytes.len() as u64;
        if self.buffer.as_ref().is_none_or(|b| b.size() < size) {
            self.buffer = Some(device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(self.label),
                size: size.next_power_of_two().max(256),
                usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }));
        }
        queue.write_buffer(self.buffer.as_ref().expect("just made"), 0, bytes);
    }

    /// The buffer when it holds vertices.
    fn filled(&self) -> Option<(&wgpu::Buffer, u32)> {
        self.buffer.as_ref().filter(|_| self.count > 0).map(|b| (b, self.count))
    }
}

/// Depth (and multisampled colour) targets for [`Renderer::render`].
struct Targets {
    size: [u32; 2],
    depth: wgpu::TextureView,
    multisampled: Option<wgpu::TextureView>,
}

/// Draws [`Frame`]s; see the module documentation for the calling sequence.
pub struct Renderer {
    color_format: wgpu::TextureFormat,
    sample_count: u32,
    cloth_pipeline: wgpu::RenderPipeline,
    prop_pipeline: wgpu::RenderPipeline,
    floor_pipeline: wgpu::RenderPipeline,
    overlay_pipeline: wgpu::RenderPipeline,
    globals: wgpu::Buffer,
    layout: wgpu::BindGroupLayout,
    fixed: FixedTextures,
    shadow_map: ShadowMap,
    bind_group: wgpu::BindGroup,
    /// The look's pattern now on the GPU, and the mean of its texels in linear light.
    pattern: (Pattern, f32),
    cloth: GrowingBuffer,
    props: GrowingBuffer,
    floor: GrowingBuffer,
    overlay: GrowingBuffer,
    targets: Option<Targets>,
    /// Of the last `prepare`.
    size: [u32; 2],
    background: [f32; 3],
    shadow: bool,
}

/// What every pipeline draws into: the shared layout, the colour format and the samples.
struct Target<'a> {
    layout: &'a wgpu::PipelineLayout,
    color_format: wgpu::TextureFormat,
    multisample: wgpu::MultisampleState,
}

/// The one bind group's layout: the globals (0), the cloth's pattern and its sampler (1, 2),
/// the colour scales and theirs (3, 4), the font atlas (5), and the shadow map with its
/// comparison sampler (6, 7).
fn bind_group_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let visibility = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT;
    let texture_entry = |binding| wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: true },
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    };
    let sampler_entry = |binding| wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
        count: None,
    };
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("rosette globals and textures"),
        entries: &[
            wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: wgpu::BufferSize::new(std::mem::size_of::<Globals>() as u64),
                },
                count: None,
            },
            texture_entry(1),
            sampler_entry(2),
            texture_entry(3),
            sampler_entry(4),
            texture_entry(5),
            wgpu::BindGroupLayoutEntry {
                binding: 6,
                visibility,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Depth,
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                count: None,
            },
            wgpu::BindGroupLayoutEntry { binding: 7, visibility, ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Comparison), count: None },
        ],
    })
}

fn depth_state(write: bool, compare: wgpu::CompareFunction) -> Option<wgpu::DepthStencilState> {
    Some(wgpu::DepthStencilState {
        format: DEPTH_FORMAT,
        depth_write_enabled: Some(write),
        depth_compare: Some(compare),
        stencil: wgpu::StencilState::default(),
        bias: wgpu::DepthBiasState::default(),
    })
}

/// The cloth, prop and floor pipelines of `shaders/scene.wgsl`.
fn scene_pipelines(device: &wgpu::Device, target: &Target) -> [wgpu::RenderPipeline; 3] {
    let scene_shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("rosette scene shader"),
        source: wgpu::ShaderSource::Wgsl(include_str!("../../shaders/scene.wgsl").into()),
    });
    let vertex_attributes = wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x2, 3 => Float32];
    let vertex_layout = wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<Vertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &vertex_attributes,
    };
    let scene_pipeline = |label: &str, vertex: &str, fragment: &str, blend: Option<wgpu::BlendState>, write_depth: bool| {
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(label),
            layout: Some(target.layout),
            vertex: wgpu::VertexState {
                module: &scene_shader,
                entry_point: Some(vertex),
                compilation_options: Default::default(),
                buffers: &[Some(vertex_layout.clone())],
            },
            // Cloth is two-sided; props are drawn from both sides too, so a mesh with
            // inconsistent winding still shows.
            primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
            depth_stencil: depth_state(write_depth, wgpu::CompareFunction::Less),
            multisample: target.multisample,
            fragment: Some(wgpu::FragmentState {
                module: &scene_shader,
                entry_point: Some(fragment),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState { format: target.color_format, blend, write_mask: wgpu::ColorWrites::ALL })],
            }),
            multiview_mask: None,
            cache: None,
        })
    };
    let cloth_pipeline = scene_pipeline("rosette cloth", "vs_main", "fs_cloth", None, true);
    let prop_pipeline = scene_pipeline("rosette props", "vs_main", "fs_prop", None, true);
    // The floor hides nothing: it shows only where nothing is in front of it.
    let floor_pipeline = scene_pipeline("rosette floor", "vs_main", "fs_floor", None, false);
    [cloth_pipeline, prop_pipeline, floor_pipeline]
}

/// The screen-space overlay's pipeline (`shaders/overlay.wgsl`): legends and labels,
/// alpha-blended over the scene.
fn overlay_pipeline(device: &wgpu::Device, target: &Target) -> wgpu::RenderPipeline {
    let overlay_shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("rosette overlay shader"),
        source: wgpu::ShaderSource::Wgsl(include_str!("../../shaders/overlay.wgsl").into()),
    });
    let overlay_attributes = wgpu::vertex_attr_array![0 => Float32x2, 1 => Float32x2, 2 => Float32x4, 3 => Float32];
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("rosette overlay"),
        layout: Some(target.layout),
        vertex: wgpu::VertexState {
            module: &overlay_shader,
            entry_point: Some("vs_overlay"),
            compilation_options: Default::default(),
            buffers: &[Some(wgpu::VertexBufferLayout {
                array_stride: std::mem::size_of::<OverlayVertex>() as u64,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &overlay_attributes,
            })],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: depth_state(false, wgpu::CompareFunction::Always),
        multisample: target.multisample,
        fragment: Some(wgpu::FragmentState {
            module: &overlay_shader,
            entry_point: Some("fs_overlay"),
            compilation_options: Default::default(),
            targets: &[Some(wgpu::ColorTargetState {
                format: target.color_format,
                blend: Some(wgpu::BlendState::ALPHA_BLENDING),
                write_mask: wgpu::ColorWrites::ALL,
            })],
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// The textures every frame uses whatever the look: the colour scales and the font atlas,
/// with the samplers of these and of the cloth's pattern.
struct FixedTextures {
    gradient: wgpu::TextureView,
    font: wgpu::TextureView,
    pattern_sampler: wgpu::Sampler,
    gradient_sampler: wgpu::Sampler,
}

impl FixedTextures {
    fn new(device: &wgpu::Device, queue: &wgpu::Queue) -> Self {
        let gradient = device.create_texture_with_data(
            queue,
            &texture_descriptor("rosette colour scales", [GRADIENT_TEXELS, GRADIENT_ROWS], 1, wgpu::TextureFormat::Rgba8UnormSrgb),
            wgpu::util::TextureDataOrder::LayerMajor,
            &legend::gradient_texels(),
        );
        let (font_w, font_h, font_texels) = font::atlas();
        let font = device.create_texture_with_data(
            queue,
            &texture_descriptor("rosette font", [font_w, font_h], 1, wgpu::TextureFormat::R8Unorm),
            wgpu::util::TextureDataOrder::LayerMajor,
            &font_texels,
        );
        // The pattern repeats both ways: it tiles the cloth.
        let pattern_sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("rosette pattern sampler"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::Repeat,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });
        let gradient_sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("rosette gradient sampler"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let view = |t: &wgpu::Texture| t.create_view(&wgpu::TextureViewDescriptor::default());
        Self { gradient: view(&gradient), font: view(&font), pattern_sampler, gradient_sampler }
    }
}

/// The bind group of [`bind_group_layout`]: `globals`, the cloth's `pattern`, the fixed
/// textures and the shadow map.
fn bind_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    globals: &wgpu::Buffer,
    fixed: &FixedTextures,
    shadow_map: &ShadowMap,
    pattern: &wgpu::TextureView,
) -> wgpu::BindGroup {
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("rosette bind group"),
        layout,
        entries: &[
            wgpu::BindGroupEntry { binding: 0, resource: globals.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(pattern) },
            wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::Sampler(&fixed.pattern_sampler) },
            wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::TextureView(&fixed.gradient) },
            wgpu::BindGroupEntry { binding: 4, resource: wgpu::BindingResource::Sampler(&fixed.gradient_sampler) },
            wgpu::BindGroupEntry { binding: 5, resource: wgpu::BindingResource::TextureView(&fixed.font) },
            wgpu::BindGroupEntry { binding: 6, resource: wgpu::BindingResource::TextureView(&shadow_map.view) },
            wgpu::BindGroupEntry { binding: 7, resource: wgpu::BindingResource::Sampler(&shadow_map.sampler) },
        ],
    })
}

/// Whether two patterns are the same texture: the same weave, or the same decoded image
/// (compared by address: the decoder keeps one per file).
fn same_pattern(a: &Pattern, b: &Pattern) -> bool {
    match (a, b) {
        (Pattern::Weave(a), Pattern::Weave(b)) => a == b,
        (Pattern::Image(a), Pattern::Image(b)) => std::sync::Arc::ptr_eq(a, b),
        _ => false,
    }
}

impl Renderer {
    /// Pipelines for a `color_format` target drawn at `sample_count` samples per pixel
    /// (1, or 4 where the adapter supports it for the format and [`DEPTH_FORMAT`]).
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, color_format: wgpu::TextureFormat, sample_count: u32) -> Self {
        let layout = bind_group_layout(device);
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("rosette pipeline layout"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let target = Target { layout: &pipeline_layout, color_format, multisample: wgpu::MultisampleState { count: sample_count, ..Default::default() } };
        let [cloth_pipeline, prop_pipeline, floor_pipeline] = scene_pipelines(device, &target);
        let overlay_pipeline = overlay_pipeline(device, &target);
        let globals = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("rosette globals"),
            size: std::mem::size_of::<Globals>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let fixed = FixedTextures::new(device, queue);
        let shadow_map = ShadowMap::new(device);
        let look = Look::default();
        let (pattern_view, mean) = pattern_texture(device, queue, &look);
        let bind_group = bind_group(device, &layout, &globals, &fixed, &shadow_map, &pattern_view);
        Self {
            color_format,
            sample_count,
            cloth_pipeline,
            prop_pipeline,
            floor_pipeline,
            overlay_pipeline,
            globals,
            layout,
            fixed,
            shadow_map,
            bind_group,
            pattern: (look.pattern, mean),
            cloth: GrowingBuffer::new("rosette cloth vertices"),
            props: GrowingBuffer::new("rosette prop vertices"),
            floor: GrowingBuffer::new("rosette floor vertices"),
            overlay: GrowingBuffer::new("rosette overlay vertices"),
            targets: None,
            size: [1, 1],
            background: RenderOptions::default().background,
            shadow: false,
        }
    }

    /// Puts `look`'s pattern on the GPU unless it is there already.
    fn use_look(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, look: &Look) {
        if same_pattern(&self.pattern.0, &look.pattern) {
            return;
        }
        let (view, mean) = pattern_texture(device, queue, look);
        self.bind_group = bind_group(device, &self.layout, &self.globals, &self.fixed, &self.shadow_map, &view);
        self.pattern = (look.pattern.clone(), mean);
    }

    /// The colour format and sample count given to [`Renderer::new`].
    pub fn target_format(&self) -> (wgpu::TextureFormat, u32) {
        (self.color_format, self.sample_count)
    }

    /// Uploads `frame` seen by `camera` in a view of `size` pixels (width, height).
    pub fn prepare(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        frame: &Frame,
        camera: &Camera,
        options: &RenderOptions,
        size: [u32; 2],
    ) {
        let size = [size[0].max(1), size[1].max(1)];
        self.size = size;
        self.background = options.background;
        self.use_look(device, queue, &frame.look);
        let shadow = if options.shadow { shadow::setup(frame, SHADOW_FROM) } else { None };
        self.shadow = shadow.is_some();
        let aspect = f64::from(size[0]) / f64::from(size[1]);
        let scalar = frame.cloth_scalar.as_ref();
        let globals = Globals {
            view_proj: camera.view_proj(aspect).to_cols_array_2d(),
            eye: camera.eye().as_vec3().extend(1.0).to_array(),
            light: LIGHT_FROM.normalize().extend(0.0).to_array(),
            prop: linear(options.prop_color, 1.0),
            wire: linear(options.wire_color, if options.wireframe { 0.7 } else { 0.0 }),
            background: linear(options.background, SHADOW_STRENGTH),
            shadow: (-SHADOW_FROM.normalize()).extend(frame.floor_z.unwrap_or(0.0)).to_array(),
            params: [
                0.0,
                if self.color_format.is_srgb() { 0.0 } else { 1.0 },
                scalar.map_or(0.5, |s| (s.map.row() as f32 + 0.5) / GRADIENT_ROWS as f32),
                0.0,
            ],
            light_view_proj: shadow.as_ref().map_or(glam::Mat4::IDENTITY, |s| s.light_view_proj).to_cols_array_2d(),
            shadow_map: shadow.as_ref().map_or([1.0; 4], |s| s.params),
            ..look_globals(&frame.look, self.pattern.1)
        };
        queue.write_buffer(&self.globals, 0, bytemuck::bytes_of(&globals));
        self.cloth.upload(device, queue, &cloth_vertices(frame));
        let props: Vec<Vertex> = frame.props.iter().flat_map(prop_vertices).collect();
        self.props.upload(device, queue, &props);
        self.floor.upload(device, queue, shadow.as_ref().map_or(&[][..], |s| &s.floor[..]));
        if let Some(s) = &shadow {
            let meshes: Vec<(&wgpu::Buffer, u32)> = [self.cloth.filled(), self.props.filled()].into_iter().flatten().collect();
            self.shadow_map.draw(device, queue, s.light_view_proj, &meshes);
        }
        let overlay = match scalar {
            Some(field) if options.legend => legend::legend(field, size[0], size[1]),
            _ => Vec::new(),
        };
        self.overlay.upload(device, queue, &overlay);
        if self.targets.as_ref().is_none_or(|t| t.size != size) {
            self.targets = Some(self.make_targets(device, size));
        }
    }

    fn make_targets(&self, device: &wgpu::Device, size: [u32; 2]) -> Targets {
        let make = |label, format| {
            let mut descriptor = texture_descriptor(label, size, 1, format);
            descriptor.sample_count = self.sample_count;
            descriptor.usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
            device.create_texture(&descriptor).create_view(&wgpu::TextureViewDescriptor::default())
        };
        Targets {
            size,
            depth: make("rosette depth", DEPTH_FORMAT),
            multisampled: (self.sample_count > 1).then(|| make("rosette multisampled colour", self.color_format)),
        }
    }

    /// Records a pass that clears `target` (of the prepared size and the renderer's colour
    /// format) to the background and draws the prepared frame.
    pub fn render(&self, encoder: &mut wgpu::CommandEncoder, target: &wgpu::TextureView) {
        let targets = self.targets.as_ref().expect("Renderer::prepare before Renderer::render");
        let [r, g, b] = if self.color_format.is_srgb() { self.background.map(srgb_to_linear) } else { self.background };
        let clear = wgpu::Color { r: f64::from(r), g: f64::from(g), b: f64::from(b), a: 1.0 };
        let (view, resolve_target) = match &targets.multisampled {
            Some(multisampled) => (multisampled, Some(target)),
            None => (target, None),
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("rosette scene"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(clear),
                    store: if resolve_target.is_some() { wgpu::StoreOp::Discard } else { wgpu::StoreOp::Store },
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &targets.depth,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Discard }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        self.paint(&mut pass);
    }

    /// Draws the prepared frame into a pass the caller began (see the module documentation
    /// for what the pass needs). Opaque geometry first, then the floor with its shadow
    /// (depth-tested against it, so it only shows on the background), then the legend.
    pub fn paint(&self, pass: &mut wgpu::RenderPass<'_>) {
        pass.set_bind_group(0, &self.bind_group, &[]);
        let meshes = [(&self.cloth_pipeline, self.cloth.filled()), (&self.prop_pipeline, self.props.filled())];
        for (pipeline, buffer) in meshes {
            if let Some((buffer, count)) = buffer {
                pass.set_pipeline(pipeline);
                pass.set_vertex_buffer(0, buffer.slice(..));
                pass.draw(0..count, 0..1);
            }
        }
        if self.shadow
            && let Some((buffer, count)) = self.floor.filled()
        {
            pass.set_pipeline(&self.floor_pipeline);
            pass.set_vertex_buffer(0, buffer.slice(..));
            pass.draw(0..count, 0..1);
        }
        if let Some((buffer, count)) = self.overlay.filled() {
            pass.set_pipeline(&self.overlay_pipeline);
            pass.set_vertex_buffer(0, buffer.slice(..));
            pass.draw(0..count, 0..1);
        }
    }
}

fn texture_descriptor(label: &'static str, [width, height]: [u32; 2], mips: u32, format: wgpu::TextureFormat) -> wgpu::TextureDescriptor<'static> {
    wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
        mip_level_count: mips,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    }
}

/// Linear RGBA of an sRGB colour, with alpha `a`.
fn linear(c: [f32; 3], a: f32) -> [f32; 4] {
    [srgb_to_linear(c[0]), srgb_to_linear(c[1]), srgb_to_linear(c[2]), a]
}

/// The globals that come from the fabric's look: the front and back tints, the pattern's
/// repeat and strength (`mean`: its texels' mean in linear light) and the sheen.
fn look_globals(look: &Look, mean: f32) -> Globals {
    let front = look.colour.srgb();
    let back = front.map(|c| c + BACK_LIGHTENING * (1.0 - c));
    // A weave is a multiplier about its mean, so the cloth keeps its colour on average;
    // a print is the cloth's colour as it is.
    let (normaliser, strength) = match look.pattern {
        Pattern::Weave(_) => (1.0 / mean.max(1e-3), WEAVE_STRENGTH),
        Pattern::Image(_) => (1.0, 1.0),
    };
    let [warp, weft] = look.repeat_m.map(|m| (1.0 / m.max(1e-6)) as f32);
    Globals {
        front: linear(front, 1.0),
        back: linear(back, 1.0),
        cloth: [warp, weft, normaliser, strength],
        // A negative roughness: no sheen.
        sheen: look.sheen.map_or([0.0, 0.0, 0.0, -1.0], |s| {
            let [r, g, b] = s.colour.linear();
            [r, g, b, s.roughness]
        }),
        ..Globals::zeroed()
    }
}

/// The look's pattern as a texture with its mipmap chain (box-filtered in linear light), so
/// that the weave or print fades to its mean colour instead of shimmering when the cloth is
/// far away; and the mean of its texels in linear light. An image larger than the device
/// takes is scaled down to fit.
fn pattern_texture(device: &wgpu::Device, queue: &wgpu::Queue, look: &Look) -> (wgpu::TextureView, f32) {
    let texels = look.texels();
    let limit = device.limits().max_texture_dimension_2d.max(1);
    let image = if texels.width() > limit || texels.height() > limit {
        let scale = f64::from(limit) / f64::from(texels.width().max(texels.height()));
        let (w, h) = ((f64::from(texels.width()) * scale) as u32, (f64::from(texels.height()) * scale) as u32);
        image::imageops::resize(&*texels, w.max(1), h.max(1), image::imageops::FilterType::Triangle)
    } else {
        (*texels).clone()
    };
    let mean = mean_linear(&image);
    let (width, height) = image.dimensions();
    let mut level: Vec<[f32; 4]> = image.pixels().map(|p| [0, 1, 2, 3].map(|c| if c < 3 { srgb_to_linear(f32::from(p[c]) / 255.0) } else { f32::from(p[c]) / 255.0 })).collect();
    let (mut w, mut h) = (width as usize, height as usize);
    let mut data = Vec::new();
    let mut mips = 0;
    loop {
        data.extend(level.iter().flat_map(|p| [0, 1, 2, 3].map(|c| {
            let v = if c < 3 { linear_to_srgb(p[c]) } else { p[c] };
            (v * 255.0).round() as u8
        })));
        mips += 1;
        if w == 1 && h == 1 {
            break;
        }
        let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
        let mut next = vec![[0.0f32; 4]; nw * nh];
        for y in 0..nh {
            for x in 0..nw {
                let mut sum = [0.0f32; 4];
                for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let p = level[(2 * y + dy).min(h - 1) * w + (2 * x + dx).min(w - 1)];
                    for c in 0..4 {
                        sum[c] += 0.25 * p[c];
                    }
                }
                next[y * nw + x] = sum;
            }
        }
        (level, w, h) = (next, nw, nh);
    }
    let texture = device.create_texture_with_data(
        queue,
        &texture_descriptor("rosette cloth pattern", [width, height], mips, wgpu::TextureFormat::Rgba8UnormSrgb),
        wgpu::util::TextureDataOrder::LayerMajor,
        &data,
    );
    (texture.create_view(&wgpu::TextureViewDescriptor::default()), mean)
}

pub(crate) fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

pub(crate) fn linear_to_srgb(c: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    if c <= 0.0031308 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 }
}

/// The cloth de-indexed, with smooth (area-weighted) vertex normals and the colour-scale
/// position of each vertex.
fn cloth_vertices(frame: &Frame) -> Vec<Vertex> {
    if !frame.cloth_is_whole() {
        // Positions and triangles of two different meshes: drawing them would index past
        // the positions or draw a torn cloth, so the cloth is left out of this frame.
        return Vec::new();
    }
    let positions: Vec<Vec3> = frame.cloth_positions.iter().map(|p| Vec3::from_array(*p)).collect();
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for tri in &frame.cloth_triangles {
        let [a, b, c] = tri.map(|v| positions[v as usize]);
        let n = (b - a).cross(c - a);
        for &v in tri {
            normals[v as usize] += n;
        }
    }
    let scalar = frame.cloth_scalar.as_ref().filter(|s| s.values.len() == positions.len());
    let mut vertices = Vec::with_capacity(3 * frame.cloth_triangles.len());
    for tri in &frame.cloth_triangles {
        for &v in tri {
            let v = v as usize;
            vertices.push(Vertex {
                position: positions[v].to_array(),
                normal: normals[v].try_normalize().unwrap_or(Vec3::Z).to_array(),
                uv: frame.cloth_uv.get(v).copied().unwrap_or_default(),
                scale: scalar.map_or(-1.0, |s| s.normalised(s.values[v])),
            });
        }
    }
    vertices
}

/// A prop de-indexed, each corner's normal averaged over the faces round its vertex that
/// meet its own face at less than 40°: smooth spheres and cylinder sides, sharp box edges.
fn prop_vertices(mesh: &PropMesh) -> Vec<Vertex> {
    let positions: Vec<Vec3> = mesh.positions.iter().map(|p| Vec3::from_array(*p)).collect();
    let face_normals: Vec<Vec3> = mesh
        .triangles
        .iter()
        .map(|tri| {
            let [a, b, c] = tri.map(|v| positions[v as usize]);
            (b - a).cross(c - a)
        })
        .collect();
    let mut faces_of: Vec<Vec<usize>> = vec![Vec::new(); positions.len()];
    for (f, tri) in mesh.triangles.iter().enumerate() {
        for &v in tri {
            faces_of[v as usize].push(f);
        }
    }
    let crease = 40f32.to_radians().cos();
    let mut vertices = Vec::with_capacity(3 * mesh.triangles.len());
    for (f, tri) in mesh.triangles.iter().enumerate() {
        let own = face_normals[f].normalize_or_zero();
        for &v in tri {
            let n: Vec3 = faces_of[v as usize]
                .iter()
                .map(|&g| face_normals[g])
                .filter(|n| n.normalize_or_zero().dot(own) >= crease)
                .sum();
            vertices.push(Vertex {
                position: positions[v as usize].to_array(),
                normal: n.try_normalize().unwrap_or(own).to_array(),
                uv: [0.0; 2],
                scale: -1.0,
            });
        }
    }
    vertices
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_round_trips() {
        for c in [0.0, 0.002, 0.04, 0.5, 1.0] {
            assert!((linear_to_srgb(srgb_to_linear(c)) - c).abs() < 1e-5, "{c}");
        }
    }

    #[test]
    fn box_corners_keep_their_face_normals() {
        // Two faces of a cube meeting at 90° along the edge 0–1.
        let mesh = PropMesh {
            positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]],
            triangles: vec![[0, 1, 2], [1, 0, 3]],
        };
        let vertices = prop_vertices(&mesh);
        assert_eq!(vertices.len(), 6);
        assert!(vertices[..3].iter().all(|v| v.normal == [0.0, 0.0, 1.0]), "{vertices:?}");
        assert!(vertices[3..].iter().all(|v| v.normal == [0.0, -1.0, 0.0]), "{vertices:?}");
    }
}
