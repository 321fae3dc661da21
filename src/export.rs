//! The cloth out to other tools: glTF 2.0 binary (`.glb`), which Blender, three.js and web
//! viewers open (`rosette run --export`, the viewer's File menu).
//!
//! What the file holds: one mesh, the cloth, with positions, unit vertex normals (area
//! weighted over the triangles round each vertex) and texture coordinates in the warp/weft
//! frame (texture u along the warp, v along the weft, in metres of the cloth at rest, each
//! panel of a garment in its own grain), on a two-sided PBR material in the fabric's look
//! (`crate::appearance`): its colour as the base colour, its weave or print embedded as
//! the base colour texture, scaled by `KHR_texture_transform` to one repeat per
//! `Look::repeat_m`, so that the pattern follows each panel's grain as the renderer draws
//! it; and its sheen as `KHR_materials_sheen` (colour and roughness as the fabric file
//! gives them). Metres, and y up as glTF has it (the scenes' z up becomes y; the scenes' y
//! becomes −z).
//!
//! Several frames make an animation: the first frame is the mesh and every later frame a
//! morph target (its positions and normals less the first's), and one animation steps the
//! targets' weights through them at the frames' simulated times, linearly, so that frame k
//! has weight 1 on target k − 1 and 0 elsewhere. Blender imports the targets as shape keys
//! driven by an action, three.js as morph targets played by its AnimationMixer.

use crate::appearance::{Look, Pattern, linear_to_srgb};
use crate::render::Frame;
use crate::scene::Topology;
use std::sync::Arc;
use glam::DVec3;
use serde_json::{Value, json};
use std::path::Path;
use thiserror::Error;

/// How strongly a weave's light and shade are kept in the exported texture: as the
/// renderer draws it (`render::renderer::WEAVE_STRENGTH`).
const WEAVE_STRENGTH: f32 = 0.55;

/// glTF's component types and buffer targets (glTF 2.0 §5).
const FLOAT: u32 = 5126;
const UNSIGNED_INT: u32 = 5125;
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;

#[derive(Debug, Error)]
pub enum ExportError {
    #[error("nothing to export: {0}")]
    Empty(String),
    #[error("cannot write {path}: {message}")]
    Write { path: String, message: String },
}

/// One moment of the cloth: simulated time (s), the mesh then and its vertex positions
/// (m, z up), one per vertex of the mesh.
#[derive(Debug, Clone)]
pub struct ClothFrame {
    pub time: f64,
    pub topology: Arc<Topology>,
    pub positions: Vec<DVec3>,
}

/// A scene's position in glTF's frame: y up, right-handed.
fn to_gltf(p: DVec3) -> [f32; 3] {
    [p.x as f32, p.z as f32, -p.y as f32]
}

/// Unit vertex normals, in glTF's frame: each vertex the area-weighted sum of its
/// triangles' normals (a vertex with no area round it gets +y).
pub fn vertex_normals(x: &[DVec3], triangles: &[[u32; 3]]) -> Vec<[f32; 3]> {
    let mut sum = vec![DVec3::ZERO; x.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| x[i as usize]);
        // Twice the area times the unit normal.
        let n = (b - a).cross(c - a);
        for &i in t {
            sum[i as usize] += n;
        }
    }
    sum.into_iter().map(|n| to_gltf(n.try_normalize().unwrap_or(DVec3::Z))).map(|n| {
        // Renormalised in single precision, so that readers find them unit to f32's precision.
        let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        n.map(|c| c / l)
    })
    .collect()
}

/// The binary chunk under construction and the JSON's views and accessors into it.
#[derive(Default)]
struct Builder {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Builder {
    /// Appends `bytes` as a buffer view (4-byte aligned) and returns its index.
    fn view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let mut view = json!({ "buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len() });
        if let Some(t) = target {
            view["target"] = json!(t);
        }
        self.bin.extend_from_slice(bytes);
        self.views.push(view);
        self.views.len() - 1
    }

    /// A float accessor of `kind` (`VEC3`, `VEC2`, `SCALAR`) over `values`, with its bounds
    /// (glTF requires them for positions and animation inputs; they are written for all).
    fn floats<const N: usize>(&mut self, values: &[[f32; N]], kind: &str, target: Option<u32>) -> usize {
        let bytes: Vec<u8> = values.iter().flatten().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes, target);
        let mut lo = [f32::INFINITY; N];
        let mut hi = [f32::NEG_INFINITY; N];
        for v in values {
            for k in 0..N {
                lo[k] = lo[k].min(v[k]);
                hi[k] = hi[k].max(v[k]);
            }
        }
        self.accessors.push(json!({
            "bufferView": view, "componentType": FLOAT, "count": values.len(), "type": kind,
            "min": lo.to_vec(), "max": hi.to_vec(),
        }));
        self.accessors.len() - 1
    }
}

/// The file's bytes: `frames` of the cloth named `name` (one frame: a still; more: an
/// animation). Frames on one mesh share one glTF mesh whose later frames are morph
/// targets; where the mesh changes during the run (a garment's weld, a finer level of the
/// fast path) each mesh is a node of its own, shown by its scale (1, or 0 to hide it) from
/// its first frame until the next mesh's, with a step interpolation.
pub fn glb(name: &str, frames: &[ClothFrame], look: &Look) -> Result<Vec<u8>, ExportError> {
    if frames.is_empty() {
        return Err(ExportError::Empty("no frame".into()));
    }
    for f in frames {
        if f.topology.triangles.is_empty() || f.positions.is_empty() {
            return Err(ExportError::Empty("the cloth has no triangles".into()));
        }
        if !f.topology.fits(&f.positions) || f.positions.iter().any(|p| !p.is_finite()) {
            return Err(ExportError::Empty(format!(
                "the frame at t = {} s has {} positions for a mesh of {} vertices, or a position that is not finite",
                f.time,
                f.positions.len(),
                f.topology.vertex_count
            )));
        }
    }
    if frames.windows(2).any(|w| w[1].time.partial_cmp(&w[0].time) != Some(std::cmp::Ordering::Greater)) {
        return Err(ExportError::Empty("the frames' times do not increase".into()));
    }
    // Runs of frames on one mesh.
    let mut segments: Vec<&[ClothFrame]> = Vec::new();
    let mut first = 0;
    for k in 1..=frames.len() {
        if k == frames.len() || frames[k].topology.version != frames[first].topology.version {
            segments.push(&frames[first..k]);
            first = k;
        }
    }
    let start = frames[0].time;
    let mut b = Builder::default();
    let (mut meshes, mut nodes, mut samplers, mut channels) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for (i, segment) in segments.iter().enumerate() {
        let label = if segments.len() == 1 {
            name.to_string()
        } else {
            format!("{name}, from t = {:.3} s ({} vertices)", segment[0].time, segment[0].topology.vertex_count)
        };
        let (mesh, weights) = segment_mesh(&mut b, segment, &label, start);
        meshes.push(mesh);
        let mut node = json!({ "mesh": i, "name": label });
        if let Some((input, output)) = weights {
            samplers.push(json!({ "input": input, "output": output, "interpolation": "LINEAR" }));
            channels.push(json!({ "sampler": samplers.len() - 1, "target": { "node": i, "path": "weights" } }));
        }
        if segments.len() > 1 {
            // Shown from its first frame until the next mesh's first frame.
            let from = (segment[0].time - start) as f32;
            let until = segments.get(i + 1).map(|next| (next[0].time - start) as f32);
            let mut keys: Vec<([f32; 1], [f32; 3])> = Vec::new();
            if i > 0 {
                keys.push(([0.0], [0.0; 3]));
            }
            keys.push(([from], [1.0; 3]));
            if let Some(until) = until {
                keys.push(([until], [0.0; 3]));
            }
            let times: Vec<[f32; 1]> = keys.iter().map(|k| k.0).collect();
            let scales: Vec<[f32; 3]> = keys.iter().map(|k| k.1).collect();
            let input = b.floats(&times, "SCALAR", None);
            let output = b.floats(&scales, "VEC3", None);
            samplers.push(json!({ "input": input, "output": output, "interpolation": "STEP" }));
            channels.push(json!({ "sampler": samplers.len() - 1, "target": { "node": i, "path": "scale" } }));
            // As the animation's first moment shows it, for readers that do not play it.
            node["scale"] = json!(if i == 0 { [1.0; 3] } else { [0.0; 3] });
        }
        nodes.push(node);
    }
    let (material, image) = material(&mut b, look);
    let mut document = json!({
        "asset": { "version": "2.0", "generator": format!("rosette {}", env!("CARGO_PKG_VERSION")) },
        "extensionsUsed": ["KHR_materials_sheen", "KHR_texture_transform"],
        "scene": 0,
        "scenes": [{ "nodes": (0..nodes.len()).collect::<Vec<_>>() }],
        "nodes": nodes,
        "meshes": meshes,
        "materials": [material],
        // Linear filtering with mipmaps, repeating both ways: the pattern tiles the cloth.
        "samplers": [{ "magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 10497 }],
        "images": [image],
        "textures": [{ "sampler": 0, "source": 0 }],
        "accessors": b.accessors,
        "bufferViews": b.views,
        "buffers": [{ "byteLength": 0 }],
    });
    if !channels.is_empty() {
        document["animations"] = json!([{ "name": "drape", "samplers": samplers, "channels": channels }]);
    }
    while !b.bin.len().is_multiple_of(4) {
        b.bin.push(0);
    }
    document["buffers"][0]["byteLength"] = json!(b.bin.len());
    let mut text = serde_json::to_vec(&document).expect("JSON values serialise");
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    // GLB: a 12-byte header, then the JSON chunk and the binary chunk (glTF 2.0 §4.4).
    let total = 12 + 8 + text.len() + 8 + b.bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(text.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&text);
    out.extend_from_slice(&(b.bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&b.bin);
    Ok(out)
}

/// One mesh's glTF mesh: the first of `frames` as its vertices, every later one a morph
/// target (positions and normals less the first's). Returns the mesh and, with more than
/// one frame, the accessors of its weights' animation: times (s from `start`) and weights,
/// frame k showing target k − 1 alone.
fn segment_mesh(b: &mut Builder, frames: &[ClothFrame], label: &str, start: f64) -> (Value, Option<(usize, usize)>) {
    let topology = &frames[0].topology;
    let first = &frames[0].positions;
    let indices: Vec<u8> = topology.triangles.iter().flatten().flat_map(|i| i.to_le_bytes()).collect();
    let index_view = b.view(&indices, Some(ELEMENT_ARRAY_BUFFER));
    b.accessors.push(json!({ "bufferView": index_view, "componentType": UNSIGNED_INT, "count": 3 * topology.triangles.len(), "type": "SCALAR" }));
    let index_accessor = b.accessors.len() - 1;
    let positions: Vec<[f32; 3]> = first.iter().map(|&p| to_gltf(p)).collect();
    let normals = vertex_normals(first, &topology.triangles);
    // Metres along the warp and the weft; the material's texture transform scales them.
    let uv: Vec<[f32; 2]> = Frame::from_cloth(first, &topology.triangles, &topology.texture, topology.warp_angle).cloth_uv;
    let position = b.floats(&positions, "VEC3", Some(ARRAY_BUFFER));
    let normal = b.floats(&normals, "VEC3", Some(ARRAY_BUFFER));
    let texcoord = b.floats(&uv, "VEC2", Some(ARRAY_BUFFER));
    let mut primitive = json!({
        "attributes": { "POSITION": position, "NORMAL": normal, "TEXCOORD_0": texcoord },
        "indices": index_accessor, "material": 0, "mode": 4,
    });
    let mut mesh = json!({ "name": label, "primitives": [] });
    let mut weights_animation = None;
    if frames.len() > 1 {
        let mut targets = Vec::new();
        let mut names = Vec::new();
        for frame in &frames[1..] {
            let delta: Vec<[f32; 3]> = frame
                .positions
                .iter()
                .zip(&positions)
                .map(|(&p, q)| {
                    let p = to_gltf(p);
                    [p[0] - q[0], p[1] - q[1], p[2] - q[2]]
                })
                .collect();
            let n = vertex_normals(&frame.positions, &topology.triangles);
            let n_delta: Vec<[f32; 3]> = n.iter().zip(&normals).map(|(a, b)| [a[0] - b[0], a[1] - b[1], a[2] - b[2]]).collect();
            targets.push(json!({ "POSITION": b.floats(&delta, "VEC3", Some(ARRAY_BUFFER)), "NORMAL": b.floats(&n_delta, "VEC3", Some(ARRAY_BUFFER)) }));
            names.push(format!("t = {:.3} s", frame.time));
        }
        let count = targets.len();
        primitive["targets"] = json!(targets);
        mesh["weights"] = json!(vec![0.0; count]);
        // Blender names the shape keys from here.
        mesh["extras"] = json!({ "targetNames": names });
        let times: Vec<[f32; 1]> = frames.iter().map(|f| [(f.time - start) as f32]).collect();
        let weights: Vec<[f32; 1]> = (0..frames.len()).flat_map(|k| (0..count).map(move |j| [if k == j + 1 { 1.0 } else { 0.0 }])).collect();
        weights_animation = Some((b.floats(&times, "SCALAR", None), b.floats(&weights, "SCALAR", None)));
    }
    mesh["primitives"] = json!([primitive]);
    (mesh, weights_animation)
}

/// Writes [`glb`] to `path`.
pub fn write_glb(path: &Path, name: &str, frames: &[ClothFrame], look: &Look) -> Result<(), ExportError> {
    let bytes = glb(name, frames, look)?;
    crate::io::write::whole(path, &bytes).map_err(|e| ExportError::Write { path: path.display().to_string(), message: e.to_string() })
}

/// The cloth's material in `look` and its image (embedded in `b`): a two-sided PBR
/// material, not metallic and rough, the look's colour times its pattern, the pattern
/// repeated along the warp and the weft (`KHR_texture_transform`), and the look's sheen
/// (`KHR_materials_sheen`; none when the look has no sheen).
fn material(b: &mut Builder, look: &Look) -> (Value, Value) {
    let (bytes, mime_type, name) = match &look.pattern {
        Pattern::Weave(w) => (weave_png(look), "image/png", format!("{} weave, {} yarns each way", w.name(), w.yarns())),
        Pattern::Image(t) => (t.encoded.to_vec(), t.mime_type, t.name.clone()),
    };
    let image_view = b.view(&bytes, None);
    let [r, g, bl] = look.colour.linear();
    let [warp, weft] = look.repeat_m.map(|m| (1.0 / m) as f32);
    let mut material = json!({
        "name": "woven cloth",
        "doubleSided": true,
        "pbrMetallicRoughness": {
            "baseColorFactor": [r, g, bl, 1.0],
            "baseColorTexture": { "index": 0, "extensions": { "KHR_texture_transform": { "scale": [warp, weft] } } },
            "metallicFactor": 0.0,
            "roughnessFactor": 0.9,
        },
    });
    let [sr, sg, sb] = look.sheen.map_or([0.0; 3], |s| s.colour.linear());
    let roughness = look.sheen.map_or(0.0, |s| s.roughness);
    material["extensions"] = json!({ "KHR_materials_sheen": { "sheenColorFactor": [sr, sg, sb], "sheenRoughnessFactor": roughness } });
    (material, json!({ "bufferView": image_view, "mimeType": mime_type, "name": name }))
}

/// A weave's texture as the renderer draws it: its light and shade about its mean, at the
/// renderer's strength, so that the material's base colour is the cloth's colour on average.
fn weave_png(look: &Look) -> Vec<u8> {
    let texels = look.texels();
    let mean = crate::appearance::shade::mean_linear(&texels);
    let mut image = (*texels).clone();
    for p in image.pixels_mut() {
        for k in 0..3 {
            let t = crate::appearance::srgb_to_linear(f32::from(p[k]) / 255.0);
            let v = 1.0 + WEAVE_STRENGTH * (t / mean - 1.0);
            p[k] = (255.0 * linear_to_srgb(v)).round() as u8;
        }
    }
    let mut bytes = Vec::new();
    // Encoding an image in memory cannot fail; an empty image would leave the texture out.
    let _ = image::DynamicImage::ImageRgba8(image).write_to(&mut std::io::Cursor::new(&mut bytes), image::ImageFormat::Png);
    bytes
}

/// Keeps the cloth's positions through a run for an animation of `frames` frames spread
/// evenly over however long the run turns out (a drape may settle early): it samples eight
/// times as often as the frames need and picks the frames from the samples at the end.
#[derive(Debug, Clone)]
pub struct Recorder {
    frames: usize,
    spacing: f64,
    next: f64,
    samples: Vec<ClothFrame>,
}

impl Recorder {
    /// For a run from `start` lasting at most `duration` seconds.
    pub fn new(frames: usize, start: f64, duration: f64) -> Self {
        let frames = frames.max(2);
        Self { frames, spacing: duration / (8 * (frames - 1)) as f64, next: start, samples: Vec::new() }
    }

    /// Takes the cloth at `time` (its mesh and positions) if a sample is due.
    pub fn observe(&mut self, time: f64, topology: &Arc<Topology>, x: &[DVec3]) {
        if time + 1e-9 >= self.next {
            self.samples.push(ClothFrame { time, topology: Arc::clone(topology), positions: x.to_vec() });
            while self.next <= time + 1e-9 {
                self.next += self.spacing.max(f64::MIN_POSITIVE);
            }
        }
    }

    /// The frames: the cloth at `time` last, and those samples nearest in time to evenly
    /// spaced moments before it, each at most once (fewer frames than asked for only when
    /// the run was shorter than its sampling).
    pub fn finish(mut self, time: f64, topology: &Arc<Topology>, x: &[DVec3]) -> Vec<ClothFrame> {
        if self.samples.last().is_none_or(|f| f.time < time) {
            self.samples.push(ClothFrame { time, topology: Arc::clone(topology), positions: x.to_vec() });
        }
        let start = self.samples[0].time;
        let mut picked: Vec<usize> = (0..self.frames)
            .map(|k| {
                let target = start + (time - start) * k as f64 / (self.frames - 1) as f64;
                let i = self.samples.partition_point(|f| f.time < target);
                // The nearer of the samples either side.
                match (i.checked_sub(1), self.samples.get(i)) {
                    (Some(j), Some(f)) if target - self.samples[j].time < f.time - target => j,
                    (_, Some(_)) => i,
                    (Some(j), None) => j,
                    (None, None) => 0,
                }
            })
            .collect();
        picked.dedup();
        let mut samples: Vec<Option<ClothFrame>> = self.samples.into_iter().map(Some).collect();
        picked.into_iter().filter_map(|i| samples[i].take()).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec2;

    #[test]
    fn normals_of_a_flat_sheet_point_up_in_gltf() {
        let x = [DVec3::ZERO, DVec3::X, DVec3::Y];
        // Counter-clockwise seen from +z: the normal is +z, which glTF calls +y.
        assert_eq!(vertex_normals(&x, &[[0, 1, 2]]), vec![[0.0, 1.0, 0.0]; 3]);
    }

    /// A mesh of one triangle.
    fn triangle() -> Arc<Topology> {
        let texture = vec![DVec2::ZERO, DVec2::X, DVec2::Y];
        Arc::new(Topology { version: 1, vertex_count: 3, triangles: vec![[0, 1, 2]], texture, warp_angle: 0.0, merged_from: None })
    }

    #[test]
    fn the_recorder_spreads_its_frames_over_the_run_it_saw() {
        let mut r = Recorder::new(5, 0.0, 1.0);
        let topology = triangle();
        let x = vec![DVec3::ZERO; topology.vertex_count];
        // A run that stops at 0.5 s of its 1 s, in 0.01 s steps.
        for k in 1..=50 {
            r.observe(k as f64 * 0.01, &topology, &x);
        }
        let frames = r.finish(0.5, &topology, &x);
        let times: Vec<f64> = frames.iter().map(|f| f.time).collect();
        assert_eq!(times.len(), 5);
        for (t, want) in times.iter().zip([0.01, 0.13, 0.26, 0.38, 0.5]) {
            assert!((t - want).abs() <= 0.0126, "{times:?}");
        }
    }
}
