//! Props from scene files: `[[props]]` tables turned into the simulator's parry3d props,
//! with OBJ meshes read from the bundled assets or from disk.

use crate::settings::{ASSETS, PropConfig, PropKind};
use crate::sim::contact::{MAX_REACH, Prop, PropShape};
use glam::{DQuat, DVec3, EulerRot};
use crate::io::number::short;
use crate::io::read::{FileKind, quotable, read_text};
use std::path::{Path, PathBuf};

/// Builds every prop of a scene; errors name the prop and the key to fix.
pub fn build_props(configs: &[PropConfig], base_dir: Option<&Path>) -> Result<Vec<Prop>, String> {
    configs.iter().enumerate().map(|(i, c)| build_prop(i, c, base_dir)).collect()
}

fn build_prop(index: usize, c: &PropConfig, base_dir: Option<&Path>) -> Result<Prop, String> {
    let name = c.name.clone().unwrap_or_else(|| format!("props[{index}] ({:?})", c.shape).to_lowercase());
    let need = |key: &str, v: Option<f64>| v.ok_or_else(|| format!("prop '{name}': a {:?} needs `{key}`", c.shape).to_lowercase());
    let shape = match c.shape {
        PropKind::Ground => PropShape::Ground,
        PropKind::Box => {
            let size = c.size.ok_or_else(|| format!("prop '{name}': a box needs `size = [x, y, z]` in metres"))?;
            PropShape::Box { half_extents: 0.5 * DVec3::from_array(size) }
        }
        PropKind::Cylinder => PropShape::Cylinder { radius: need("radius", c.radius)?, height: need("height", c.height)? },
        PropKind::Sphere => PropShape::Sphere { radius: need("radius", c.radius)? },
        PropKind::Mesh => {
            let file = c.file.as_deref().ok_or_else(|| format!("prop '{name}': a mesh needs `file`, an OBJ path"))?;
            let scale = c.scale.unwrap_or(1.0);
            if !(scale.is_finite() && scale > 0.0 && scale <= MAX_REACH) {
                return Err(format!("prop '{name}': scale must be a positive number up to {MAX_REACH}, got {}", short(scale)));
            }
            let (vertices, triangles) = load_obj(file, base_dir, scale).map_err(|e| format!("prop '{name}': {e}"))?;
            PropShape::Mesh { vertices: vertices.into_iter().map(|v| v * scale).collect(), triangles }
        }
    };
    let [rx, ry, rz] = c.rotation_deg.map(f64::to_radians);
    let rotation = DQuat::from_euler(EulerRot::ZYX, rz, ry, rx);
    Prop::new(&name, shape, DVec3::from_array(c.position), rotation).map_err(|e| e.to_string())
}

/// Reads an OBJ (all its objects, triangulated) from a bundled asset or a file whose
/// coordinates will be multiplied by `scale`.
pub fn load_obj(file: &str, base_dir: Option<&Path>, scale: f64) -> Result<(Vec<DVec3>, Vec<[u32; 3]>), String> {
    let (text, quotable) = match ASSETS.iter().find(|a| a.name == file) {
        Some(asset) => (asset.text.to_string(), true),
        None => {
            let path = obj_path(file, base_dir);
            let text = read_text(&path, FileKind::Obj).map_err(|e| {
                let bundled: Vec<_> = ASSETS.iter().map(|a| a.name).collect();
                format!("{e} (bundled meshes: {})", bundled.join(", "))
            })?;
            (text, quotable(&path, FileKind::Obj))
        }
    };
    check_vertices(file, &text, scale, quotable)?;
    let options = tobj::LoadOptions { triangulate: true, single_index: true, ..Default::default() };
    let (models, _) = tobj::load_obj_buf(&mut text.as_bytes(), &options, |_| Ok(Default::default()))
        .map_err(|e| format!("{file} is not a readable OBJ: {e}"))?;
    let (mut vertices, mut triangles) = (Vec::new(), Vec::new());
    for m in models {
        let offset = vertices.len() as u32;
        vertices.extend(m.mesh.positions.chunks_exact(3).map(|p| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64)));
        triangles.extend(m.mesh.indices.chunks_exact(3).map(|t| [t[0] + offset, t[1] + offset, t[2] + offset]));
    }
    if triangles.is_empty() {
        return Err(format!("{file} has no faces"));
    }
    Ok((vertices, triangles))
}

/// The file a mesh prop's `file` names on disk: relative to the scene's folder where the
/// scene is a file.
pub fn obj_path(file: &str, base_dir: Option<&Path>) -> PathBuf {
    let path = Path::new(file);
    match base_dir {
        Some(base) if path.is_relative() => base.join(path),
        _ => path.to_path_buf(),
    }
}

/// Every file a scene names that is read only when the scene is built (the props' meshes,
/// the garment form's body), on disk, for the output guard to know before the run: the
/// one list of a scene's later inputs. Bundled assets are not files.
pub fn files_named(config: &crate::settings::SceneConfig) -> Vec<(PathBuf, FileKind)> {
    let base = config.base_dir.as_deref();
    let props = config.props.iter().filter_map(|p| p.file.as_deref());
    let form = config.garment.as_ref().and_then(|g| g.form.obj.as_deref());
    props
        .chain(form)
        .filter(|file| !ASSETS.iter().any(|a| a.name == *file))
        .map(|file| (obj_path(file, base), FileKind::Obj))
        .collect()
}

/// Checks every vertex line (`v x y z`) before the OBJ reader sees it, so that a bad
/// coordinate is named by its line: the reader takes `nan`, `inf` and numbers past f32's
/// range (1e39) without complaint, and such a prop would silently drop out of contact.
/// The word is quoted only from a file named FILE.obj (`quotable`).
fn check_vertices(file: &str, text: &str, scale: f64, quotable: bool) -> Result<(), String> {
    for (number, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        if words.next() != Some("v") {
            continue;
        }
        for word in words.take(3) {
            let value: f64 = word.parse().map_err(|_| {
                if quotable { format!("{file}:{}: '{word}' is not a number", number + 1) } else { format!("{file}:{}: not an OBJ mesh (a vertex line without numbers); name the mesh FILE.obj", number + 1) }
            })?;
            if !(value * scale).is_finite() || (value * scale).abs() > MAX_REACH {
                return Err(format!(
                    "{file}:{}: coordinate {} (× scale {}) must be finite and within {MAX_REACH} m of the origin; fix the vertex or the prop's scale",
                    number + 1,
                    if word.len() <= 12 { word.to_string() } else { short(value) },
                    short(scale)
                ));
            }
        }
    }
    Ok(())
}
