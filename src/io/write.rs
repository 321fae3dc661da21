//! Every output written whole or not at all: a file is written beside its final name and
//! renamed over it once complete, so that a full disk, a crash or a divergence never leaves
//! half a file, nor destroys the file that was there. Streams (a character device such as
//! /dev/null, a pipe) are written directly: they have no "whole".
//!
//! PNGs carry a `Software: rosette` text chunk, by which [`super::guard`] recognises
//! Rosette's own pictures as ones it may replace.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// The text chunk every PNG Rosette writes carries (keyword, then the text's start).
pub const PNG_MARK: &[u8] = b"tEXtSoftware\0rosette";

/// An output being written: a staged file renamed over its target by [`Output::finish`],
/// or a stream written as it goes.
pub enum Output {
    Staged(Staged),
    Stream(std::io::BufWriter<std::fs::File>),
}

/// A file written beside its target (`.NAME.rosette-PID-N.tmp` in the same folder, so the
/// rename stays on one file system) and renamed over it on [`Staged::commit`]; dropped
/// uncommitted, it is removed and the target is untouched.
pub struct Staged {
    temp: PathBuf,
    target: PathBuf,
    file: std::io::BufWriter<std::fs::File>,
    committed: bool,
}

static STAGED: AtomicU64 = AtomicU64::new(0);

impl Staged {
    /// Creates the staging file for `target`.
    pub fn create(target: &Path) -> std::io::Result<Staged> {
        let name = target.file_name().ok_or_else(|| std::io::Error::other("the path names no file"))?;
        let temp = target.with_file_name(format!(
            ".{}.rosette-{}-{}.tmp",
            name.to_string_lossy(),
            std::process::id(),
            STAGED.fetch_add(1, Ordering::Relaxed)
        ));
        let file = std::fs::OpenOptions::new().write(true).create_new(true).open(&temp)?;
        Ok(Staged { temp, target: target.to_path_buf(), file: std::io::BufWriter::new(file), committed: false })
    }

    /// Flushes the file to disk and renames it over the target (keeping the replaced
    /// file's permissions).
    pub fn commit(mut self) -> std::io::Result<()> {
        self.file.flush()?;
        self.file.get_ref().sync_all()?;
        if let Ok(existing) = std::fs::metadata(&self.target) {
            std::fs::set_permissions(&self.temp, existing.permissions())?;
        }
        std::fs::rename(&self.temp, &self.target)?;
        self.committed = true;
        Ok(())
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        if !self.committed {
            std::fs::remove_file(&self.temp).ok();
        }
    }
}

impl Write for Staged {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.file.write(buf)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.file.flush()
    }
}

/// Whether `file_type` is a stream written directly: a character device or a FIFO.
pub fn is_stream(file_type: &std::fs::FileType) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        file_type.is_char_device() || file_type.is_fifo()
    }
    #[cfg(not(unix))]
    {
        let _ = file_type;
        false
    }
}

/// Opens a stream for writing; a FIFO nobody reads is an error, not a wait for ever.
fn open_stream(path: &Path) -> std::io::Result<std::fs::File> {
    let mut options = std::fs::OpenOptions::new();
    options.write(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        use std::os::unix::io::AsRawFd;
        options.custom_flags(libc::O_NONBLOCK);
        let file = options.open(path).map_err(|e| {
            if e.raw_os_error() == Some(libc::ENXIO) { std::io::Error::other("a named pipe with no reader") } else { e }
        })?;
        // Blocking again for the writes: a full pipe waits for its reader.
        // SAFETY: fcntl on a descriptor this function owns, with flags read from it.
        unsafe {
            let fd = file.as_raw_fd();
            let flags = libc::fcntl(fd, libc::F_GETFL);
            if flags < 0 || libc::fcntl(fd, libc::F_SETFL, flags & !libc::O_NONBLOCK) < 0 {
                return Err(std::io::Error::last_os_error());
            }
        }
        Ok(file)
    }
    #[cfg(not(unix))]
    options.open(path)
}

impl Output {
    /// Starts writing `path`: a regular file (or a new one) is staged beside its target,
    /// the file a link points to (the link stays); a stream is opened; a folder or any
    /// other kind of file is an error.
    /// A file this process has read (any reader goes through [`super::read::read_text`],
    /// which keeps the list) is never written: the last guard of inputs, behind the
    /// command's check before the run.
    pub fn open(path: &Path) -> std::io::Result<Output> {
        if let Some(input) = super::read::files_read().into_iter().find(|input| input.same_file(path)) {
            return Err(std::io::Error::other(format!("it is the {} this command read; give the output another name", input.kind.noun())));
        }
        Self::open_chosen(path)
    }

    /// As [`Output::open`], for a file the user chose in a save dialog, which may be one
    /// the viewer read (saving the scene or fabric it opened).
    pub fn open_chosen(path: &Path) -> std::io::Result<Output> {
        match std::fs::metadata(path) {
            Ok(m) if m.is_file() => Ok(Output::Staged(Staged::create(&std::fs::canonicalize(path)?)?)),
            Ok(m) if is_stream(&m.file_type()) => Ok(Output::Stream(std::io::BufWriter::new(open_stream(path)?))),
            Ok(m) => Err(std::io::Error::other(format!("it is {}", super::read::what_it_is(&m.file_type()).unwrap_or("not a file")))),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(Output::Staged(Staged::create(path)?)),
            Err(e) => Err(e),
        }
    }

    /// Completes the output: the staged file replaces its target; a stream is flushed.
    pub fn finish(self) -> std::io::Result<()> {
        match self {
            Output::Staged(staged) => staged.commit(),
            Output::Stream(mut stream) => stream.flush(),
        }
    }
}

impl Write for Output {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        match self {
            Output::Staged(s) => s.write(buf),
            Output::Stream(s) => s.write(buf),
        }
    }
    fn flush(&mut self) -> std::io::Result<()> {
        match self {
            Output::Staged(s) => s.flush(),
            Output::Stream(s) => s.flush(),
        }
    }
}

/// Writes `bytes` to `path` whole or not at all.
pub fn whole(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let mut out = Output::open(path)?;
    out.write_all(bytes)?;
    out.finish()
}

/// Writes `bytes` whole to a file the user chose in a save dialog ([`Output::open_chosen`]).
pub fn whole_chosen(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let mut out = Output::open_chosen(path)?;
    out.write_all(bytes)?;
    out.finish()
}

/// How hard the PNG encoder works: pictures committed to the repository (cards, charts)
/// are worth the slower, smaller encoding.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Effort {
    Balanced,
    Smallest,
}

/// Encodes 8-bit RGB (3 channels) or RGBA (4) pixels as a PNG marked as Rosette's
/// ([`PNG_MARK`]).
pub fn png(pixels: &[u8], size: (u32, u32), channels: u8, effort: Effort) -> Result<Vec<u8>, String> {
    let mut bytes = Vec::new();
    let mut encoder = png::Encoder::new(&mut bytes, size.0, size.1);
    encoder.set_color(if channels == 4 { png::ColorType::Rgba } else { png::ColorType::Rgb });
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_compression(if effort == Effort::Smallest { png::Compression::High } else { png::Compression::Balanced });
    encoder.set_filter(png::Filter::Adaptive);
    encoder.add_text_chunk("Software".into(), format!("rosette {}", env!("CARGO_PKG_VERSION"))).map_err(|e| e.to_string())?;
    let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
    writer.write_image_data(pixels).map_err(|e| e.to_string())?;
    writer.finish().map_err(|e| e.to_string())?;
    Ok(bytes)
}

/// Writes a PNG whole ([`png`], then [`whole`]); the error names the file.
pub fn png_file(path: &Path, pixels: &[u8], size: (u32, u32), channels: u8, effort: Effort) -> Result<(), String> {
    let bytes = png(pixels, size, channels, effort).map_err(|e| format!("cannot encode {}: {e}", path.display()))?;
    whole(path, &bytes).map_err(|e| format!("cannot write {}: {e}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp(name: &str) -> PathBuf {
        std::env::temp_dir().join(format!("rosette-write-{}-{name}", std::process::id()))
    }

    #[test]
    fn a_file_is_replaced_whole_and_an_abandoned_one_leaves_the_old_in_place() {
        let path = temp("whole.txt");
        std::fs::write(&path, "old").unwrap();
        let mut out = Output::open(&path).unwrap();
        out.write_all(b"half").unwrap();
        drop(out);
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "old", "an unfinished output leaves the file as it was");
        whole(&path, b"new").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "new");
        let dir = path.parent().unwrap();
        // This file's own staging files only: the other tests here stage theirs in the
        // same folder at the same time.
        let staging = format!(".{}.", path.file_name().unwrap().to_string_lossy());
        let stray = std::fs::read_dir(dir).unwrap().flatten().any(|e| e.file_name().to_string_lossy().starts_with(&staging) && e.file_name().to_string_lossy().ends_with(".tmp"));
        assert!(!stray, "no staging file is left behind");
        std::fs::remove_file(&path).ok();
    }

    #[cfg(unix)]
    #[test]
    fn a_link_keeps_pointing_at_the_file_it_names() {
        let (target, link) = (temp("target.txt"), temp("link.txt"));
        std::fs::write(&target, "old").unwrap();
        let _ = std::fs::remove_file(&link);
        std::os::unix::fs::symlink(&target, &link).unwrap();
        whole(&link, b"new").unwrap();
        assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "new");
        std::fs::remove_file(&link).ok();
        std::fs::remove_file(&target).ok();
    }

    #[test]
    fn streams_are_written_directly_and_a_full_device_says_so() {
        whole(Path::new("/dev/null"), b"discarded").unwrap();
        if Path::new("/dev/full").exists() {
            let err = whole(Path::new("/dev/full"), &[0u8; 70_000]).unwrap_err();
            assert_eq!(err.raw_os_error(), Some(28), "{err}");
        }
        assert!(Output::open(Path::new("/")).is_err(), "a folder is not an output");
    }

    #[test]
    fn pngs_carry_the_mark_and_decode() {
        let bytes = png(&[255, 0, 0, 0, 255, 0], (2, 1), 3, Effort::Balanced).unwrap();
        assert!(bytes.windows(PNG_MARK.len()).any(|w| w == PNG_MARK));
        let image = image::load_from_memory(&bytes).unwrap().to_rgb8();
        assert_eq!(image.get_pixel(1, 0).0, [0, 255, 0]);
    }
}
