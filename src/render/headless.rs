//! Rendering with no window: a device without a surface (on a machine without a GPU, Mesa's
//! lavapipe), an offscreen target read back into an RGBA image.

use super::camera::Camera;
use super::colormap::ColorMap;
use super::frame::Frame;
use super::renderer::Renderer;
use super::{RenderError, RenderOptions};
use crate::scene::Scene;
use std::path::PathBuf;
use std::sync::mpsc::channel;

/// The offscreen target's format: non-sRGB, as the viewer's window surface, so the shaders
/// take the same path in both.
const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// A GPU device with no window and a [`Renderer`] on it.
pub struct Headless {
    device: wgpu::Device,
    queue: wgpu::Queue,
    renderer: Renderer,
    adapter: wgpu::AdapterInfo,
}

impl Headless {
    /// Opens the first adapter wgpu offers (`WGPU_BACKEND=vulkan|gl` picks a backend), with
    /// the same limits the viewer asks for; 4× multisampling where the adapter has it.
    pub fn new() -> Result<Self, RenderError> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions::default()))
            .map_err(|e| RenderError::NoAdapter(e.to_string()))?;
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("rosette headless"),
            required_limits: wgpu::Limits::downlevel_webgl2_defaults().using_resolution(adapter.limits()),
            ..Default::default()
        }))
        .map_err(|e| RenderError::Device(e.to_string()))?;
        let supports = |format| adapter.get_texture_format_features(format).flags.sample_count_supported(4);
        let sample_count = if supports(FORMAT) && supports(super::DEPTH_FORMAT) { 4 } else { 1 };
        let renderer = Renderer::new(&device, &queue, FORMAT, sample_count);
        Ok(Self { device, queue, renderer, adapter: adapter.get_info() })
    }

    /// The adapter in use (name, backend, device type).
    pub fn adapter_info(&self) -> &wgpu::AdapterInfo {
        &self.adapter
    }

    /// Renders `frame` into a `size` = [width, height] pixel image.
    pub fn render(&mut self, frame: &Frame, camera: &Camera, options: &RenderOptions, size: [u32; 2]) -> Result<image::RgbaImage, RenderError> {
        let [width, height] = size;
        let limit = self.device.limits().max_texture_dimension_2d;
        if width == 0 || height == 0 || width > limit || height > limit {
            return Err(RenderError::BadOption(format!("image size {width}x{height} is outside 1..={limit} pixels each way")));
        }
        let extent = wgpu::Extent3d { width, height, depth_or_array_layers: 1 };
        let texture = self.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("rosette headless target"),
            size: extent,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
        self.renderer.prepare(&self.device, &self.queue, frame, camera, options, size);
        let mut encoder = self.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("rosette headless frame") });
        self.renderer.render(&mut encoder, &view);
        self.queue.submit([encoder.finish()]);
        read_back(&self.device, &self.queue, &texture)
    }
}

/// Copies a rendered texture back from the GPU as an opaque RGBA image: the headless
/// screenshots and the viewer's Screenshot button both read their frames this way. The
/// texture needs `COPY_SRC` usage and an 8-bit RGBA or BGRA format (sRGB or not: the
/// bytes are taken as they are stored); BGRA pixels are reordered to RGBA.
pub fn read_back(device: &wgpu::Device, queue: &wgpu::Queue, texture: &wgpu::Texture) -> Result<image::RgbaImage, RenderError> {
    let (width, height) = (texture.width(), texture.height());
    let bgra = match texture.format() {
        wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb => true,
        wgpu::TextureFormat::Rgba8Unorm | wgpu::TextureFormat::Rgba8UnormSrgb => false,
        other => return Err(RenderError::Readback(format!("cannot read back a {other:?} texture as RGBA"))),
    };
    // Rows of a texture-to-buffer copy are padded to 256 bytes.
    let row = (width * 4).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("rosette readback"),
        size: u64::from(row) * u64::from(height),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("rosette readback copy") });
    encoder.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(row), rows_per_image: Some(height) },
        },
        texture.size(),
    );
    queue.submit([encoder.finish()]);
    let slice = buffer.slice(..);
    let (tx, rx) = channel();
    slice.map_async(wgpu::MapMode::Read, move |result| drop(tx.send(result)));
    device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| RenderError::Readback(e.to_string()))?;
    rx.recv().map_err(|e| RenderError::Readback(e.to_string()))?.map_err(|e| RenderError::Readback(e.to_string()))?;
    let data = slice.get_mapped_range().map_err(|e| RenderError::Readback(e.to_string()))?;
    let mut pixels = Vec::with_capacity((width * height * 4) as usize);
    for y in 0..height as usize {
        pixels.extend_from_slice(&data[y * row as usize..][..width as usize * 4]);
    }
    drop(data);
    buffer.unmap();
    for pixel in pixels.chunks_exact_mut(4) {
        if bgra {
            pixel.swap(0, 2);
        }
        // The picture is opaque whatever the blending left in alpha.
        pixel[3] = 255;
    }
    Ok(image::RgbaImage::from_raw(width, height, pixels).expect("width × height × 4 bytes"))
}

/// What `rosette run --screenshot` draws and where it writes it.
#[derive(Debug, Clone, PartialEq)]
pub struct Screenshot {
    /// PNG file to write.
    pub path: PathBuf,
    /// Width and height, pixels.
    pub size: [u32; 2],
    /// Yaw and pitch, degrees, and optionally the eye's distance from the centre of the
    /// scene, m; the default view, framing the scene, when `None`.
    pub view: Option<(f64, f64, Option<f64>)>,
    pub color_map: Option<ColorMap>,
    pub wireframe: bool,
}

impl Screenshot {
    /// Default image size, pixels.
    pub const DEFAULT_SIZE: [u32; 2] = [1280, 800];

    /// `WxH`, e.g. `1280x800`.
    pub fn parse_size(text: &str) -> Result<[u32; 2], String> {
        let bad = || format!("--size {text}: expected WIDTHxHEIGHT in pixels, e.g. 1280x800");
        let (w, h) = text.split_once(['x', 'X']).ok_or_else(bad)?;
        let w: u32 = w.trim().parse().map_err(|_| bad())?;
        let h: u32 = h.trim().parse().map_err(|_| bad())?;
        if !(1..=8192).contains(&w) || !(1..=8192).contains(&h) {
            return Err(format!("--size {text}: each side must be 1 to 8192 pixels"));
        }
        Ok([w, h])
    }

    /// `yaw,pitch[,distance]`: degrees, degrees, metres.
    pub fn parse_view(text: &str) -> Result<(f64, f64, Option<f64>), String> {
        let bad = || format!("--camera {text}: expected YAW,PITCH[,DISTANCE] (degrees, degrees, metres), e.g. -60,30 or -60,30,0.25");
        let numbers: Vec<f64> = text.split(',').map(|s| s.trim().parse::<f64>()).collect::<Result<_, _>>().map_err(|_| bad())?;
        match numbers[..] {
            [yaw, pitch] if yaw.is_finite() && pitch.abs() < 90.0 => Ok((yaw, pitch, None)),
            [yaw, pitch, distance] if yaw.is_finite() && pitch.abs() < 90.0 && distance > 0.0 && distance.is_finite() => {
                Ok((yaw, pitch, Some(distance)))
            }
            _ => Err(bad()),
        }
    }

    /// The camera for `frame`: the chosen (or default) direction, aimed at the centre of
    /// the scene, at the chosen distance or else just far enough to frame it.
    pub fn camera(&self, frame: &Frame) -> Camera {
        let mut camera = Camera::default();
        if let Some((yaw, pitch, _)) = self.view {
            camera.yaw = yaw.to_radians();
            camera.pitch = pitch.to_radians();
        }
        let [width, height] = self.size.map(f64::from);
        // With a legend, the scene is framed in the part of the image left of it.
        let legend = if frame.cloth_scalar.is_some() { f64::from(super::legend::reserved_width(self.size[1])) } else { 0.0 };
        let legend = legend.min(0.4 * width);
        if let Some((lo, hi)) = frame.view_bounds() {
            camera.frame_bounds(lo, hi, (width - legend) / height);
        }
        if let Some((_, _, Some(distance))) = self.view {
            camera.distance = distance;
        }
        // Moving the target right by half the legend's width moves the scene left by as much.
        let metres_per_pixel = 2.0 * camera.distance * (0.5 * camera.fov_y).tan() / height;
        camera.target += camera.basis().1 * (0.5 * legend * metres_per_pixel);
        camera
    }
}

/// Renders the scene's current state headless and writes the PNG.
pub fn save_screenshot(scene: &Scene, shot: &Screenshot) -> Result<(), RenderError> {
    let frame = Frame::from_scene(scene, shot.color_map);
    let camera = shot.camera(&frame);
    let options = RenderOptions { wireframe: shot.wireframe, ..RenderOptions::default() };
    let image = Headless::new()?.render(&frame, &camera, &options, shot.size)?;
    // Written whole, with the mark by which a later run may replace it (src/io/write.rs).
    crate::io::write::png_file(&shot.path, image.as_raw(), image.dimensions(), 4, crate::io::write::Effort::Balanced)
        .map_err(|message| RenderError::Write { path: shot.path.display().to_string(), message })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_and_views_parse_or_say_what_is_expected() {
        assert_eq!(Screenshot::parse_size("320x240"), Ok([320, 240]));
        assert!(Screenshot::parse_size("320").unwrap_err().contains("WIDTHxHEIGHT"));
        assert!(Screenshot::parse_size("0x240").is_err());
        assert_eq!(Screenshot::parse_view("-60,30"), Ok((-60.0, 30.0, None)));
        assert_eq!(Screenshot::parse_view("10, 45, 0.3"), Ok((10.0, 45.0, Some(0.3))));
        assert!(Screenshot::parse_view("10,95").is_err());
        assert!(Screenshot::parse_view("10,45,-1").unwrap_err().contains("YAW,PITCH"));
    }
}
