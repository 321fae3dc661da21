//! Rendering: one wgpu renderer for the viewer's window and for headless screenshots, so a
//! screenshot shows exactly what the viewer shows.
//!
//! The renderer sees only a [`Frame`], a plain snapshot of what to draw (cloth positions,
//! topology, texture coordinates in the warp/weft frame, an optional colour-mapped field,
//! prop meshes and the floor height), and a [`Camera`]. It knows nothing of the solver.
//! [`Frame::from_scene`] builds one from a [`Scene`](crate::scene::Scene);
//! [`Frame::from_cloth`] from bare arrays (the viewer's snapshots).
//!
//! # API (kept stable for the viewer)
//!
//! ```text
//! Renderer::new(device: &wgpu::Device, queue: &wgpu::Queue,
//!               color_format: wgpu::TextureFormat, sample_count: u32) -> Renderer
//! renderer.prepare(&mut self, device: &wgpu::Device, queue: &wgpu::Queue,
//!                  frame: &Frame, camera: &Camera, options: &RenderOptions, size: [u32; 2])
//! renderer.render(&mut self, device: &wgpu::Device, encoder: &mut wgpu::CommandEncoder,
//!                 target: &wgpu::TextureView)          // clears, owns depth and MSAA targets
//! renderer.paint(&self, pass: &mut wgpu::RenderPass<'_>)  // into the caller's pass
//! Headless::new() -> Result<Headless, RenderError>
//! read_back(device: &wgpu::Device, queue: &wgpu::Queue, texture: &wgpu::Texture)
//!     -> Result<image::RgbaImage, RenderError>                 // the viewer's screenshots too
//! headless.render(&mut self, frame: &Frame, camera: &Camera, options: &RenderOptions,
//!                 size: [u32; 2]) -> Result<image::RgbaImage, RenderError>
//! save_screenshot(scene: &Scene, options: &Screenshot) -> Result<(), RenderError>
//! ```
//!
//! Each frame: `prepare` uploads the frame's geometry and the camera (it may be skipped when
//! nothing changed), then either `render` records a pass that clears `target` to
//! `options.background` and draws everything, or `paint` draws into a pass the caller began.
//! `target` must be `size` pixels and of the `color_format` given to `new`. For `paint` the
//! caller's pass needs a depth attachment of [`DEPTH_FORMAT`], cleared to 1.0, and the
//! `sample_count` given to `new`; the legend is laid out for a viewport of `size` pixels
//! (call `pass.set_viewport` to place it in part of the window).
//!
//! Colour: every colour in this module is sRGB (the values a colour picker shows). On a
//! non-sRGB target (`Bgra8Unorm`, `Rgba8Unorm`, as egui prefers) the shaders encode
//! lighting to sRGB themselves; on an `*Srgb` target the hardware does it. Either way the
//! pixels come out the same.
//!
//! What is drawn: the cloth in its fabric's look ([`Frame::look`], `crate::appearance`):
//! its colour, its weave or printed image repeated along the warp (texture u) and the weft
//! (v) at the look's repeat, so that the pattern turns with each panel's grain, lit from a
//! key light, a fill and a sky/ground ambient, with the look's sheen (the Charlie sheen of
//! glTF's `KHR_materials_sheen`, as `appearance::shade` computes it for the swatch);
//! two-sided, the back a lighter tint of the front. Or the cloth coloured by a strain or
//! curvature field on a [`ColorMap`] scale, with a legend bar at the right edge. Props in
//! a neutral grey. A soft shadow of cloth and props on the floor plane: a shadow map seen
//! from a light nearly overhead, filtered with a penumbra that widens with the height of
//! what casts it (percentage-closer soft shadows, `shadow.rs`), falling on the background
//! (no floor is drawn, like a photographer's shadow catcher). Optionally the mesh edges
//! over the cloth (the paper's Fig. 6a).
//!
//! Shaders are `shaders/scene.wgsl` (cloth, props, the floor's shadow),
//! `shaders/shadow_map.wgsl` (the depth seen from the shadow's light) and
//! `shaders/overlay.wgsl` (legend), bundled with `include_str!`. Nothing here needs more than WebGL2-level limits.

mod camera;
mod colormap;
mod font;
mod frame;
mod headless;
mod legend;
mod renderer;
mod shadow;
mod vertex;

pub use camera::Camera;
pub use colormap::{ColorMap, ScalarField};
pub use frame::{Frame, PropMesh};
pub use headless::{Headless, Screenshot, read_back, save_screenshot};
pub use legend::bar_rect as legend_bar_rect;
pub use renderer::Renderer;
pub use vertex::DEPTH_FORMAT;

use thiserror::Error;

/// How to draw a frame; everything but the geometry and the camera.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderOptions {
    /// Draw the mesh edges over the cloth (the paper's Fig. 6a).
    pub wireframe: bool,
    /// Draw the colour legend when the frame carries a scalar field.
    pub legend: bool,
    /// Draw the soft floor shadow.
    pub shadow: bool,
    /// Background, sRGB 0..1.
    pub background: [f32; 3],
    /// Props, sRGB 0..1.
    pub prop_color: [f32; 3],
    /// Wireframe lines, sRGB 0..1.
    pub wire_color: [f32; 3],
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            wireframe: false,
            legend: true,
            shadow: true,
            background: BACKGROUND,
            prop_color: [0.62, 0.63, 0.65],
            wire_color: [0.08, 0.08, 0.10],
        }
    }
}

/// The default background, sRGB.
pub const BACKGROUND: [f32; 3] = [0.80, 0.82, 0.85];

/// Why nothing could be rendered.
#[derive(Debug, Error)]
pub enum RenderError {
    #[error(
        "no graphics adapter found ({0}). On a machine without a GPU install Mesa's software \
         Vulkan driver (Debian/Ubuntu: `apt-get install mesa-vulkan-drivers`), or set \
         WGPU_BACKEND=gl with Mesa's EGL (libegl1 libegl-mesa0 libgl1-mesa-dri)"
    )]
    NoAdapter(String),
    #[error("cannot open the graphics device: {0}")]
    Device(String),
    #[error("cannot read the image back from the GPU: {0}")]
    Readback(String),
    #[error("cannot write {path}: {message}")]
    Write { path: String, message: String },
    #[error("{0}")]
    BadOption(String),
}
