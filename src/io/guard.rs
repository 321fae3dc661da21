//! The output guard: every file a command will write, checked together before any work.
//!
//! An output is refused (exit 2, naming its flag and file) when it
//! - is a file the command reads (the same file by device and inode, so also under another
//!   name, through a link or `..`), or another output of the same command;
//! - is a folder, a block device or a socket;
//! - already exists and is not Rosette's own output of the same kind (recognised by its
//!   first bytes: the metrics' first key, a CSV's header, the PNG's `Software: rosette`
//!   chunk, the glTF generator), unless the command has `--force`;
//! - cannot be created in its folder.
//!
//! Character devices (/dev/null) and pipes are streams: they are written directly.

use super::read::{Identity, file_id, what_it_is};
use super::write::{PNG_MARK, Staged, is_stream};
use std::io::Read;
use std::path::{Path, PathBuf};

/// How a kind of output is recognised among existing files.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Signature {
    /// The file starts with this text.
    Starts(&'static str),
    /// The file's second line starts with this text.
    SecondLine(&'static str),
    /// A PNG with Rosette's text chunk.
    Png,
    /// A glTF binary that names Rosette as its generator.
    Glb,
}

/// A kind of output: its name in messages and how an earlier one is recognised.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Kind {
    /// "a metrics file", "a step log".
    pub noun: &'static str,
    pub signature: Signature,
}

impl Kind {
    /// Whether `head`, the first bytes of an existing file, is this kind of Rosette output.
    pub fn recognises(&self, head: &[u8]) -> bool {
        match self.signature {
            Signature::Starts(text) => head.starts_with(text.as_bytes()),
            Signature::SecondLine(text) => {
                head.iter().position(|&b| b == b'\n').is_some_and(|i| head[i + 1..].starts_with(text.as_bytes()))
            }
            Signature::Png => head.starts_with(b"\x89PNG\r\n\x1a\n") && head.windows(PNG_MARK.len()).any(|w| w == PNG_MARK),
            Signature::Glb => head.starts_with(b"glTF") && head.windows(20).any(|w| w == b"\"generator\":\"rosette"),
        }
    }
}

/// One output of a command.
#[derive(Debug, Clone)]
pub struct Planned {
    /// The flag that names it, as the user wrote it (`--metrics`, `--out`).
    pub flag: String,
    pub path: PathBuf,
    pub kind: Kind,
}

/// The outputs of one command.
#[derive(Debug, Clone, Default)]
pub struct Plan {
    pub outputs: Vec<Planned>,
    /// `--force`: existing files that are not Rosette's own output are replaced too.
    pub force: bool,
}

/// How many bytes of an existing file are read to recognise it.
const HEAD: u64 = 4096;

fn head(path: &Path) -> Vec<u8> {
    let mut bytes = Vec::new();
    if let Ok(file) = std::fs::File::open(path) {
        file.take(HEAD).read_to_end(&mut bytes).ok();
    }
    bytes
}

/// Where a path's file is or would be: its canonical path, or its folder's canonical path
/// and its name when it does not exist yet.
pub fn place(path: &Path) -> PathBuf {
    if let Ok(canonical) = std::fs::canonicalize(path) {
        return canonical;
    }
    let parent = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    match (std::fs::canonicalize(parent), path.file_name()) {
        (Ok(dir), Some(name)) => dir.join(name),
        _ => path.to_path_buf(),
    }
}

impl Plan {
    pub fn new(force: bool) -> Plan {
        Plan { outputs: Vec::new(), force }
    }

    pub fn add(&mut self, flag: &str, path: &Path, kind: Kind) {
        self.outputs.push(Planned { flag: flag.to_string(), path: path.to_path_buf(), kind });
    }

    /// Checks every output against `inputs` (the files the command read), the others and
    /// the file system; the first problem found, as a message for exit 2.
    pub fn check(&self, inputs: &[Identity]) -> Result<(), String> {
        for (i, out) in self.outputs.iter().enumerate() {
            let stream = self.check_one(out, inputs)?;
            if stream {
                continue;
            }
            let (here, id) = (place(&out.path), file_id(&out.path));
            if let Some(other) = self.outputs[..i].iter().find(|o| place(&o.path) == here || (id.is_some() && file_id(&o.path) == id)) {
                return Err(format!(
                    "{} {} and {} {} are the same file: one would overwrite the other; give each its own name",
                    other.flag,
                    other.path.display(),
                    out.flag,
                    out.path.display()
                ));
            }
        }
        Ok(())
    }

    /// One output on its own; true where it is a stream (written directly).
    fn check_one(&self, out: &Planned, inputs: &[Identity]) -> Result<bool, String> {
        let shown = format!("{} {}", out.flag, out.path.display());
        let text = out.path.as_os_str().to_string_lossy();
        if text.is_empty() || text.ends_with(std::path::MAIN_SEPARATOR) || out.path.file_name().is_none() || text.ends_with("/.") {
            return Err(format!("{shown}: names a folder, not a file; give the name of a file to write, in that folder or another"));
        }
        let metadata = match std::fs::metadata(&out.path) {
            Ok(m) => m,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                return writable_folder(&out.path).map(|()| false).map_err(|e| format!("{shown}: cannot write there: {e}"));
            }
            Err(e) => return Err(format!("{shown}: {e}")),
        };
        let file_type = metadata.file_type();
        if is_stream(&file_type) {
            return Ok(true);
        }
        if let Some(what) = what_it_is(&file_type) {
            let fix = if file_type.is_dir() { "give a file name" } else { "give the name of a file to write" };
            return Err(format!("{shown}: is {what}; {fix}"));
        }
        if let Some(input) = inputs.iter().find(|input| input.same_file(&out.path)) {
            let named = if input.path == out.path { String::new() } else { format!(" ({})", input.path.display()) };
            return Err(format!(
                "{shown} is the {} this command reads{named}: writing there would destroy it; give the output another name",
                input.kind.noun()
            ));
        }
        // An empty file holds nothing to lose (a name made ready with touch or mktemp).
        if !self.force && metadata.len() > 0 && !out.kind.recognises(&head(&out.path)) {
            return Err(format!(
                "{shown}: the file exists and is not {} Rosette wrote; give another name, or add --force to replace it",
                out.kind.noun
            ));
        }
        std::fs::OpenOptions::new().append(true).open(&out.path).map_err(|e| format!("{shown}: cannot write there: {e}"))?;
        writable_folder(&out.path).map_err(|e| format!("{shown}: cannot replace it in its folder: {e}"))?;
        Ok(false)
    }
}

/// Whether a file can be created beside `path` (where its staged copy will be written).
fn writable_folder(path: &Path) -> std::io::Result<()> {
    let target = place(path);
    let parent = target.parent().unwrap_or(Path::new("."));
    if !parent.is_dir() {
        return Err(std::io::Error::other(format!("no folder {}", parent.display())));
    }
    Staged::create(&target).map(drop)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::read::{FileKind, files_read, read_text};

    const METRICS: Kind = Kind { noun: "a metrics file", signature: Signature::Starts("{\n  \"preset\": ") };
    const LOG: Kind = Kind { noun: "a step log", signature: Signature::Starts("step,time_s") };

    fn temp(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("rosette-guard-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir.join(name)
    }

    fn plan(force: bool, outputs: &[(&str, &Path, Kind)]) -> Plan {
        let mut plan = Plan::new(force);
        for (flag, path, kind) in outputs {
            plan.add(flag, path, *kind);
        }
        plan
    }

    #[test]
    fn an_output_may_not_be_an_input_under_any_name() {
        let input = temp("scene.toml");
        std::fs::write(&input, "[scene]\n").unwrap();
        read_text(&input, FileKind::Scene).unwrap();
        let inputs = files_read();
        let dotted = input.parent().unwrap().join(".").join("scene.toml");
        for path in [input.clone(), dotted] {
            let err = plan(true, &[("--metrics", &path, METRICS)]).check(&inputs).unwrap_err();
            assert!(err.contains("--metrics") && err.contains("scene file this command reads"), "{err}");
        }
        #[cfg(unix)]
        {
            let link = temp("link.json");
            let _ = std::fs::remove_file(&link);
            std::os::unix::fs::symlink(&input, &link).unwrap();
            let err = plan(true, &[("--metrics", &link, METRICS)]).check(&inputs).unwrap_err();
            assert!(err.contains("scene file this command reads"), "{err}");
        }
    }

    /// A path that can only be a folder is refused before the run, not when it is written.
    #[test]
    fn an_output_named_as_a_folder_is_refused_before_any_work() {
        let dir = temp("folder-out");
        for shown in [format!("{}/", dir.display()), format!("{}/.", dir.display()), format!("{}/..", dir.display())] {
            let err = plan(false, &[("--metrics", Path::new(&shown), METRICS)]).check(&[]).unwrap_err();
            assert!(err.contains("names a folder") || err.contains("is a folder"), "{shown}: {err}");
        }
    }

    /// Whatever a command's check knew, a file it read is not replaced by its writes.
    #[test]
    fn a_file_that_was_read_is_never_written() {
        let input = temp("read-then-written.toml");
        std::fs::write(&input, "[scene]\n").unwrap();
        read_text(&input, FileKind::Scene).unwrap();
        let err = crate::io::write::whole(&input, b"{}").unwrap_err().to_string();
        assert!(err.contains("this command read"), "{err}");
        assert_eq!(std::fs::read_to_string(&input).unwrap(), "[scene]\n");
    }

    #[test]
    fn two_outputs_may_not_share_a_file() {
        let path = temp("twice.csv");
        let _ = std::fs::remove_file(&path);
        let err = plan(false, &[("--metrics", &path, METRICS), ("--step-log", &path, LOG)]).check(&[]).unwrap_err();
        assert!(err.contains("--metrics") && err.contains("--step-log") && err.contains("same file"), "{err}");
        let other = path.parent().unwrap().join("..").join(path.parent().unwrap().file_name().unwrap()).join("twice.csv");
        assert!(plan(false, &[("--metrics", &path, METRICS), ("--outline", &other, LOG)]).check(&[]).is_err());
    }

    #[test]
    fn an_existing_file_is_replaced_only_when_it_is_rosettes_own_or_forced() {
        let path = temp("notes.json");
        std::fs::write(&path, "my only notes").unwrap();
        let err = plan(false, &[("--metrics", &path, METRICS)]).check(&[]).unwrap_err();
        assert!(err.contains("not a metrics file Rosette wrote") && err.contains("--force"), "{err}");
        assert!(plan(true, &[("--metrics", &path, METRICS)]).check(&[]).is_ok());
        std::fs::write(&path, "{\n  \"preset\": \"cantilever\"\n}\n").unwrap();
        assert!(plan(false, &[("--metrics", &path, METRICS)]).check(&[]).is_ok());
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "{\n  \"preset\": \"cantilever\"\n}\n", "checking writes nothing");
    }

    #[test]
    fn folders_and_missing_folders_are_refused_and_streams_pass() {
        let err = plan(true, &[("--metrics", Path::new("/"), METRICS)]).check(&[]).unwrap_err();
        assert!(err.contains("folder"), "{err}");
        let err = plan(true, &[("--metrics", &temp("no-such-dir").join("m.json"), METRICS)]).check(&[]).unwrap_err();
        assert!(err.contains("no-such-dir"), "{err}");
        assert!(plan(false, &[("--metrics", Path::new("/dev/null"), METRICS), ("--step-log", Path::new("/dev/null"), LOG)]).check(&[]).is_ok());
    }
}
