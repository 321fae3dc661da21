//! Window smoke test: the viewer opens under a virtual X display (Xvfb), draws frames with
//! the real GPU path (Mesa's software drivers on a machine without a GPU) and exits 0 when
//! told to; without any display it says how to render headless instead.
//!
//! Needs `xvfb-run` (Debian: xvfb, xauth) and Mesa; `.ci/run` installs them. Where
//! `xvfb-run` is missing the window test is skipped with a notice, except in CI (`CI` set),
//! where it fails.

use std::fs::File;
use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// A command with a private 0700 runtime directory (silences Mesa's warning about a
/// missing one).
fn command(program: &str) -> Command {
    let runtime = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("xdg-runtime");
    std::fs::create_dir_all(&runtime).unwrap();
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&runtime, std::fs::Permissions::from_mode(0o700)).unwrap();
    }
    let mut command = Command::new(program);
    command.env("XDG_RUNTIME_DIR", runtime);
    command
}

fn xvfb_available() -> bool {
    Command::new("sh").args(["-c", "command -v xvfb-run"]).stdout(Stdio::null()).status().is_ok_and(|s| s.success())
}

#[test]
fn viewer_draws_frames_under_xvfb_and_exits_zero() {
    if !xvfb_available() {
        assert!(std::env::var_os("CI").is_none(), "CI must install xvfb and xauth (see .ci/run)");
        eprintln!("skipped: xvfb-run is not installed (apt-get install xvfb xauth mesa-vulkan-drivers)");
        return;
    }
    let log = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("window-{}.log", std::process::id()));
    let mut child = command("xvfb-run")
        .args(["-a", "-s", "-screen 0 1280x800x24", env!("CARGO_BIN_EXE_rosette"), "view", "euler-buckling"])
        .args(["--quit-after-frames", "30"])
        .env_remove("WAYLAND_DISPLAY")
        .stdout(File::create(&log).unwrap())
        .stderr(File::create(log.with_extension("err")).unwrap())
        .spawn()
        .expect("xvfb-run starts");
    // Generous: a debug build on a software rasteriser with 2 cores.
    let deadline = Instant::now() + Duration::from_secs(300);
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            panic!("the viewer did not exit after 30 frames within 300 s");
        }
        std::thread::sleep(Duration::from_millis(100));
    };
    let stderr = std::fs::read_to_string(log.with_extension("err")).unwrap_or_default();
    assert!(status.success(), "viewer exited with {status}: {stderr}");
}

#[test]
fn without_a_display_the_viewer_points_to_headless_rendering() {
    let output = command(env!("CARGO_BIN_EXE_rosette"))
        .args(["view", "--quit-after-frames", "1"])
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("no display") && stderr.contains("--screenshot"), "{stderr}");
}
