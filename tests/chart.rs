
/// The command line: an output directory that cannot be made is bad input (exit code 2),
/// reported before any run starts.
#[test]
fn chart_command_reports_an_unwritable_output_directory() {
    let blocker = std::env::temp_dir().join(format!("rosette-chart-blocker-{}", std::process::id()));
    std::fs::write(&blocker, "a file, not a directory").unwrap();
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_rosette"))
        .args(["chart", "--quick", "--out"])
        .arg(blocker.join("out"))
        .output()
        .unwrap();
    std::fs::remove_file(&blocker).ok();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("cannot write") && stderr.contains("--out"), "{stderr}");
}
