//! A fabric's own texture: a PNG or JPEG image, bundled (`assets/prints/…`) or a file read
//! through the bounded reader (`io::read`, so that the output guard knows it as an input),
//! checked and decoded once.
//!
//! A decoded image is kept for the rest of the process, keyed by its file's path, size and
//! modification time: the viewer asks for its fabric's look every frame, and a changed
//! file is read again.

use crate::io::read::{FileKind, read_bytes};
use crate::settings::registry::IMAGES;
use image::RgbaImage;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// The largest side a texture may have, pixels: every GPU Rosette runs on samples 4096
/// (WebGL2 guarantees 2048, and the renderer asks the adapter's own limit), and a 4096²
/// image is 64 MB decoded.
pub const MAX_SIDE: u32 = 4096;

/// A decoded texture and the file it came from.
#[derive(Debug, PartialEq)]
pub struct TextureImage {
    /// The file as the fabric names it.
    pub name: String,
    /// Its pixels, sRGB RGBA.
    pub image: Arc<RgbaImage>,
    /// The file's bytes as they are, for glTF to embed.
    pub encoded: Arc<[u8]>,
    /// `image/png` or `image/jpeg`.
    pub mime_type: &'static str,
}

/// Whether `file` names a bundled texture.
pub fn is_bundled(file: &str) -> bool {
    IMAGES.iter().any(|i| i.name == file)
}

/// The image `file` names: a bundled texture, or a file (relative to `base_dir` where given),
/// read, checked and decoded. The error names the file and says what is wrong with it.
pub fn load(file: &str, base_dir: Option<&Path>) -> Result<Arc<TextureImage>, String> {
    if let Some(bundled) = IMAGES.iter().find(|i| i.name == file) {
        let key = Key { path: PathBuf::from(file), len: bundled.bytes.len() as u64, modified: None };
        return cached(key, || decode(file, bundled.bytes.to_vec()));
    }
    let path = match base_dir {
        Some(base) if Path::new(file).is_relative() => base.join(file),
        _ => PathBuf::from(file),
    };
    let bundled = || IMAGES.iter().map(|i| i.name).collect::<Vec<_>>().join(", ");
    let metadata = std::fs::metadata(&path).map_err(|_| format!("{}: no such file (bundled textures: {})", path.display(), bundled()))?;
    let key = Key { path: path.clone(), len: metadata.len(), modified: metadata.modified().ok() };
    cached(key, || {
        let bytes = read_bytes(&path, FileKind::Image).map_err(|e| e.to_string())?;
        decode(&path.display().to_string(), bytes)
    })
}

/// What a decoded image is kept under.
#[derive(Debug, Clone, PartialEq)]
struct Key {
    path: PathBuf,
    len: u64,
    modified: Option<std::time::SystemTime>,
}

/// The images decoded so far. A handful at most: one per fabric looked at.
static DECODED: Mutex<Vec<(Key, Arc<TextureImage>)>> = Mutex::new(Vec::new());

fn cached(key: Key, decode: impl FnOnce() -> Result<TextureImage, String>) -> Result<Arc<TextureImage>, String> {
    if let Some((_, image)) = DECODED.lock().unwrap_or_else(|p| p.into_inner()).iter().find(|(k, _)| *k == key) {
        return Ok(Arc::clone(image));
    }
    let image = Arc::new(decode()?);
    let mut decoded = DECODED.lock().unwrap_or_else(|p| p.into_inner());
    decoded.retain(|(k, _)| k.path != key.path);
    decoded.push((key, Arc::clone(&image)));
    Ok(image)
}

/// Decodes `bytes` (of the file `name`) as PNG or JPEG, by their signature, within
/// [`MAX_SIDE`].
fn decode(name: &str, bytes: Vec<u8>) -> Result<TextureImage, String> {
    let (format, mime_type) = if bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
        (image::ImageFormat::Png, "image/png")
    } else if bytes.starts_with(&[0xFF, 0xD8, 0xFF]) {
        (image::ImageFormat::Jpeg, "image/jpeg")
    } else {
        return Err(format!("{name} is not a PNG or JPEG image (its first bytes are neither's signature); save the texture as PNG or JPEG"));
    };
    let reader = image::ImageReader::with_format(std::io::Cursor::new(&bytes), format);
    let (width, height) = reader.into_dimensions().map_err(|e| format!("{name} cannot be read as {mime_type}: {e}"))?;
    if width == 0 || height == 0 || width > MAX_SIDE || height > MAX_SIDE {
        return Err(format!("{name} is {width}×{height} pixels; a texture may be 1 to {MAX_SIDE} pixels each way: scale it down"));
    }
    let image = image::load_from_memory_with_format(&bytes, format).map_err(|e| format!("{name} cannot be decoded as {mime_type}: {e}"))?.to_rgba8();
    Ok(TextureImage { name: name.to_string(), image: Arc::new(image), encoded: bytes.into(), mime_type })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp(name: &str) -> PathBuf {
        std::env::temp_dir().join(format!("rosette-texture-{}-{name}", std::process::id()))
    }

    #[test]
    fn files_that_are_not_small_png_or_jpeg_images_are_refused_by_name() {
        let text = temp("not-an-image.png");
        std::fs::write(&text, "name = \"a fabric\"\n").unwrap();
        let e = load(text.to_str().unwrap(), None).unwrap_err();
        assert!(e.contains("not a PNG or JPEG") && e.contains("not-an-image.png"), "{e}");
        let huge = temp("huge.png");
        let mut bytes = Vec::new();
        let wide = RgbaImage::new(MAX_SIDE + 1, 1);
        image::DynamicImage::ImageRgba8(wide).write_to(&mut std::io::Cursor::new(&mut bytes), image::ImageFormat::Png).unwrap();
        std::fs::write(&huge, &bytes).unwrap();
        let e = load(huge.to_str().unwrap(), None).unwrap_err();
        assert!(e.contains("4097×1") && e.contains("scale it down"), "{e}");
        let e = load("/", None).unwrap_err();
        assert!(e.contains("folder"), "{e}");
        std::fs::remove_file(&text).ok();
        std::fs::remove_file(&huge).ok();
    }

    #[test]
    fn a_jpeg_reads_and_a_changed_file_is_read_again() {
        let path = temp("swatch.jpg");
        let mut bytes = Vec::new();
        image::DynamicImage::ImageRgb8(image::RgbImage::from_pixel(8, 4, image::Rgb([200, 30, 30])))
            .write_to(&mut std::io::Cursor::new(&mut bytes), image::ImageFormat::Jpeg)
            .unwrap();
        std::fs::write(&path, &bytes).unwrap();
        let first = load(path.file_name().unwrap().to_str().unwrap(), path.parent()).unwrap();
        assert_eq!((first.image.dimensions(), first.mime_type), ((8, 4), "image/jpeg"));
        assert!(crate::io::read::files_read().iter().any(|f| f.same_file(&path)), "read through io::read");
        assert!(Arc::ptr_eq(&first, &load(path.to_str().unwrap(), None).unwrap()), "kept once decoded");
        let mut wider = Vec::new();
        image::DynamicImage::ImageRgb8(image::RgbImage::from_pixel(16, 4, image::Rgb([200, 30, 30])))
            .write_to(&mut std::io::Cursor::new(&mut wider), image::ImageFormat::Jpeg)
            .unwrap();
        std::fs::write(&path, &wider).unwrap();
        assert_eq!(load(path.to_str().unwrap(), None).unwrap().image.dimensions(), (16, 4));
        std::fs::remove_file(&path).ok();
    }

    #[test]
    fn every_bundled_texture_decodes() {
        for i in IMAGES {
            let t = load(i.name, None).unwrap_or_else(|e| panic!("{}: {e}", i.name));
            assert!(t.image.width() >= 16 && t.mime_type == "image/png", "{}", i.name);
        }
    }
}
