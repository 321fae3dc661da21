//! The one reader of the files a user names: regular files only, each kind within its own
//! size, and every file read remembered for the output guard.
//!
//! The file's type is read from its metadata before it is opened, since opening a FIFO
//! blocks until a writer comes; the open itself is non-blocking and the opened file is
//! checked again (it may have been swapped in between), and the read stops one byte past
//! the limit whatever the metadata said (a file in /proc reports a size of 0).

use std::io::Read;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use thiserror::Error;

/// What a file is read as; each kind has its own size limit and name in messages.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileKind {
    /// A scene file (TOML).
    Scene,
    /// A fabric file or measurement sheet (TOML).
    Fabric,
    /// A prop's mesh (Wavefront OBJ).
    Obj,
    /// A CSV file Rosette wrote and reads back (the chart's drape reference).
    Csv,
    /// An ARCSim material (JSON).
    Arcsim,
    /// A sewing pattern in GarmentCode's specification format (JSON).
    Pattern,
    /// A scripted session for the viewer (TOML).
    Script,
    /// A fabric's texture: a PNG or JPEG image (`[appearance] texture`).
    Image,
    /// A sewing pattern from pattern CAD: DXF in the AAMA / ASTM D6673 convention, read as
    /// bytes (its text may be in a Windows code page, or the file binary DXF, refused).
    Dxf,
    /// The seams of a DXF pattern (TOML).
    Seams,
}

impl FileKind {
    /// The largest file of this kind that is read, bytes. A scene or a fabric is a few
    /// kilobytes (the longest bundled one, with its sheets and comments, under 6 kB); an OBJ
    /// of the largest prop contact resolves well (a million triangles) is about 60 MB.
    pub fn limit(self) -> u64 {
        match self {
            FileKind::Scene | FileKind::Fabric | FileKind::Script | FileKind::Seams => 1 << 20,
            FileKind::Obj => 128 << 20,
            FileKind::Csv => 16 << 20,
            // A material is under 2 kB; its comments may be long.
            FileKind::Arcsim => 1 << 20,
            // GarmentCode's largest bundled specification (a jumpsuit, 12 panels) is 48 kB.
            FileKind::Pattern => 16 << 20,
            // A 4096 × 4096 photograph of a print is a few MB as JPEG, up to about 50 MB as
            // a PNG of noise; past that it is not a texture (the decoded size has its own
            // bound, `appearance::texture::MAX_SIDE`).
            FileKind::Image => 64 << 20,
            // A pattern of two pieces exported by Valentina is 30 to 60 kB; a graded style of
            // thirty pieces in every size a few MB.
            FileKind::Dxf => 16 << 20,
        }
    }

    /// The kind's name in messages.
    pub fn noun(self) -> &'static str {
        match self {
            FileKind::Scene => "scene file",
            FileKind::Fabric => "fabric file",
            FileKind::Obj => "mesh file (OBJ)",
            FileKind::Csv => "CSV file",
            FileKind::Arcsim => "material file in ARCSim's JSON format",
            FileKind::Pattern => "pattern in GarmentCode's JSON format",
            FileKind::Script => "viewer script",
            FileKind::Image => "texture image (PNG or JPEG)",
            FileKind::Dxf => "pattern file (DXF)",
            FileKind::Seams => "seams file",
        }
    }

    /// The extension files of this kind carry. A file named otherwise is read, but its
    /// contents are not quoted in messages (see [`quotable`]).
    pub fn extension(self) -> &'static str {
        match self {
            FileKind::Scene | FileKind::Fabric | FileKind::Script | FileKind::Seams => "toml",
            FileKind::Dxf => "dxf",
            FileKind::Obj => "obj",
            FileKind::Csv => "csv",
            FileKind::Arcsim | FileKind::Pattern => "json",
            FileKind::Image => "png",
        }
    }
}

/// Why a file was not read. The message names the file and, where it is not a regular
/// file of a sensible size, what it is instead; the caller adds the key that named it.
#[derive(Debug, Error)]
pub enum ReadError {
    #[error("{path}: no such file")]
    Missing { path: String },
    #[error("{path} is {what}, not a {noun}; give the path of a {noun}")]
    NotAFile { path: String, what: &'static str, noun: &'static str },
    #[error("{path} is {size}, more than the {limit} a {noun} may be; is it the right file?")]
    TooLarge { path: String, size: String, limit: String, noun: &'static str },
    #[error("{path} is not a text file (it is not UTF-8), so it is not a {noun}")]
    NotText { path: String, noun: &'static str },
    #[error("cannot read {path}: {message}")]
    Io { path: String, message: String },
}

/// A file as the file system knows it: its device and inode (the same file under any
/// name, link or `..`), and its canonical path.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Identity {
    /// The path as the user gave it.
    pub path: PathBuf,
    pub canonical: PathBuf,
    /// (device, inode) on Unix; None elsewhere.
    pub id: Option<(u64, u64)>,
    /// What the file was read as.
    pub kind: FileKind,
}

impl Identity {
    /// Whether `other` is this file (same device and inode, or the same canonical path).
    ///
    /// An input removed since it was read is no longer anything: its inode may have gone to
    /// a new file.
    pub fn same_file(&self, other: &Path) -> bool {
        match (self.id, file_id(other)) {
            (Some(a), Some(b)) => a == b && file_id(&self.canonical) == Some(a),
            _ => std::fs::canonicalize(other).is_ok_and(|c| c == self.canonical),
        }
    }
}

/// Every file read so far by this process, for [`super::guard`].
static READ: Mutex<Vec<Identity>> = Mutex::new(Vec::new());

/// The files this process has read through [`read_text`], in order.
pub fn files_read() -> Vec<Identity> {
    READ.lock().unwrap_or_else(|p| p.into_inner()).clone()
}

/// The (device, inode) of the file at `path`, following links; None where it does not exist.
pub fn file_id(path: &Path) -> Option<(u64, u64)> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        std::fs::metadata(path).ok().map(|m| (m.dev(), m.ino()))
    }
    #[cfg(not(unix))]
    {
        let _ = path;
        None
    }
}

/// What a file that is not a regular file is, in words ("a folder", "a device").
pub fn what_it_is(file_type: &std::fs::FileType) -> Option<&'static str> {
    if file_type.is_file() {
        return None;
    }
    if file_type.is_dir() {
        return Some("a folder");
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if file_type.is_fifo() {
            return Some("a named pipe (FIFO)");
        }
        if file_type.is_char_device() {
            return Some("a character device");
        }
        if file_type.is_block_device() {
            return Some("a block device");
        }
        if file_type.is_socket() {
            return Some("a socket");
        }
    }
    Some("not a regular file")
}

/// Megabytes or kilobytes, for messages.
fn size_text(bytes: u64) -> String {
    if bytes >= 1 << 20 { format!("{:.1} MB", bytes as f64 / (1u64 << 20) as f64) } else { format!("{:.1} kB", bytes as f64 / 1024.0) }
}

/// Opens `path` for reading without blocking on a FIFO that appeared since its metadata
/// was read.
fn open_nonblocking(path: &Path) -> std::io::Result<std::fs::File> {
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    options.open(path)
}

/// Reads the regular file at `path` as text of `kind`: refused if it is not a regular file
/// (a folder, a device such as /dev/zero, a FIFO, a socket), larger than the kind's
/// limit, or not UTF-8. The file is remembered for the output guard.
pub fn read_text(path: &Path, kind: FileKind) -> Result<String, ReadError> {
    let bytes = read_bytes(path, kind)?;
    String::from_utf8(bytes).map_err(|_| ReadError::NotText { path: path.display().to_string(), noun: kind.noun() })
}

/// Reads the regular file at `path` as bytes of `kind`, with the checks of [`read_text`]
/// but its text's encoding; the file is remembered for the output guard.
pub fn read_bytes(path: &Path, kind: FileKind) -> Result<Vec<u8>, ReadError> {
    let shown = path.display().to_string();
    let io = |e: std::io::Error| ReadError::Io { path: shown.clone(), message: e.to_string() };
    let metadata = match std::fs::metadata(path) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Err(ReadError::Missing { path: shown }),
        Err(e) => return Err(io(e)),
    };
    let check = |m: &std::fs::Metadata| -> Result<(), ReadError> {
        if let Some(what) = what_it_is(&m.file_type()) {
            return Err(ReadError::NotAFile { path: shown.clone(), what, noun: kind.noun() });
        }
        if m.len() > kind.limit() {
            return Err(too_large(&shown, m.len(), kind));
        }
        Ok(())
    };
    check(&metadata)?;
    let file = open_nonblocking(path).map_err(io)?;
    check(&file.metadata().map_err(io)?)?;
    let mut bytes = Vec::new();
    file.take(kind.limit() + 1).read_to_end(&mut bytes).map_err(io)?;
    if bytes.len() as u64 > kind.limit() {
        return Err(too_large(&shown, bytes.len() as u64, kind));
    }
    let identity = Identity {
        path: path.to_path_buf(),
        canonical: std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf()),
        id: file_id(path),
        kind,
    };
    READ.lock().unwrap_or_else(|p| p.into_inner()).push(identity);
    Ok(bytes)
}

fn too_large(path: &str, bytes: u64, kind: FileKind) -> ReadError {
    let size = if bytes == kind.limit() + 1 { format!("over {}", size_text(kind.limit())) } else { size_text(bytes) };
    ReadError::TooLarge { path: path.to_string(), size, limit: size_text(kind.limit()), noun: kind.noun() }
}

/// Whether a message may quote the contents of `path` read as `kind`: only where the file
/// is named as that kind is (`.toml` for a scene or fabric, `.obj` for a mesh). A scene
/// naming `/etc/shadow` as its fabric gets "not a fabric file", never the file's first
/// line.
pub fn quotable(path: &Path, kind: FileKind) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case(kind.extension()))
}

/// Parses TOML text read from `path` as `kind`. A syntax error quotes the offending line
/// only where the file is named as its kind ([`quotable`]); otherwise it gives the line and
/// column alone and says the file is not of the kind.
pub fn parse_toml(text: &str, path: Option<&Path>, kind: FileKind) -> Result<toml::Table, String> {
    text.parse::<toml::Table>().map_err(|e| {
        if path.is_none_or(|p| quotable(p, kind)) {
            return format!("not valid TOML: {e}");
        }
        let start = e.span().map_or(0, |s| s.start).min(text.len());
        let before = &text[..text.floor_char_boundary(start)];
        let line = before.matches('\n').count() + 1;
        let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        format!(
            "not a {noun}: its text is not TOML (line {line}, column {column}); a {noun} is a TOML file, named NAME.{ext}",
            noun = kind.noun(),
            ext = kind.extension()
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp(name: &str) -> PathBuf {
        std::env::temp_dir().join(format!("rosette-read-{}-{name}", std::process::id()))
    }

    #[test]
    fn special_files_are_refused_by_their_type_before_any_read() {
        for (path, what) in [("/dev/zero", "device"), ("/dev/urandom", "device"), ("/", "folder")] {
            if !Path::new(path).exists() {
                continue;
            }
            let err = read_text(Path::new(path), FileKind::Fabric).unwrap_err().to_string();
            assert!(err.contains(what) && err.contains("fabric file") && err.contains(path), "{err}");
        }
        let missing = read_text(Path::new("/no/such/file.toml"), FileKind::Scene).unwrap_err().to_string();
        assert!(missing.contains("/no/such/file.toml") && missing.contains("no such file"), "{missing}");
    }

    #[cfg(unix)]
    #[test]
    fn a_fifo_is_refused_without_blocking() {
        let path = temp("fifo");
        let _ = std::fs::remove_file(&path);
        let c = std::ffi::CString::new(path.to_str().unwrap()).unwrap();
        // SAFETY: mkfifo reads a valid NUL-terminated path and touches nothing else.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        let err = read_text(&path, FileKind::Obj).unwrap_err().to_string();
        std::fs::remove_file(&path).ok();
        assert!(err.contains("FIFO") && err.contains("mesh file (OBJ)"), "{err}");
    }

    #[test]
    fn files_past_their_kind_limit_or_not_text_are_refused_and_good_ones_remembered() {
        let big = temp("big.toml");
        std::fs::write(&big, vec![b'#'; (FileKind::Scene.limit() + 10) as usize]).unwrap();
        let err = read_text(&big, FileKind::Scene).unwrap_err().to_string();
        assert!(err.contains("more than the 1.0 MB"), "{err}");
        std::fs::write(&big, [0xff, 0xfe, 0x00]).unwrap();
        let err = read_text(&big, FileKind::Scene).unwrap_err().to_string();
        assert!(err.contains("not a text file") && !err.contains('\u{fffd}'), "{err}");
        std::fs::write(&big, "a = 1\n").unwrap();
        assert_eq!(read_text(&big, FileKind::Fabric).unwrap(), "a = 1\n");
        assert!(files_read().iter().any(|f| f.same_file(&big)));
        std::fs::remove_file(&big).ok();
    }

    #[test]
    fn a_syntax_error_quotes_the_line_only_from_a_file_named_as_its_kind() {
        let secret = "root:$6$secret:19000:0:99999:7:::\n";
        let err = parse_toml(secret, Some(Path::new("/etc/shadow")), FileKind::Fabric).unwrap_err();
        assert!(!err.contains("secret") && err.contains("not a fabric file") && err.contains("line 1"), "{err}");
        let err = parse_toml("a = 1\nb = [\n", Some(Path::new("mine.toml")), FileKind::Scene).unwrap_err();
        assert!(err.contains("not valid TOML") && err.contains("b = ["), "{err}");
    }

    #[test]
    fn contents_are_quotable_only_from_a_file_named_as_its_kind() {
        assert!(quotable(Path::new("my.TOML"), FileKind::Fabric));
        assert!(!quotable(Path::new("/etc/shadow"), FileKind::Fabric));
        assert!(!quotable(Path::new("/proc/self/environ"), FileKind::Scene));
        assert!(quotable(Path::new("bowl.obj"), FileKind::Obj));
    }
}
