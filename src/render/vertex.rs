//! What the scene's passes share: the vertex every cloth and prop triangle is drawn with,
//! and the depth format (the main pass's and the shadow map's).

use bytemuck::{Pod, Zeroable};

/// Depth buffer format the renderer draws with (the caller's, for `Renderer::paint`).
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// A vertex of the cloth or a prop (buffers are de-indexed: three per triangle).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub(super) struct Vertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
    /// Rest position along warp and weft, m.
    pub uv: [f32; 2],
    /// Position on the colour scale 0..1, or −1 for the fabric look.
    pub scale: f32,
}
