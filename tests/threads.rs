//! A run is the same cloth on one thread and on two. Meshes of a few thousand triangles
//! split their passes between the calling thread and a second one kept spinning between
//! them (`sim::team`); larger ones go to rayon's pool. Either way every sum is added in an
//! order fixed by the mesh alone, so the threads may change the time, never the result.

use std::path::PathBuf;
use std::process::Command;

fn temp(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("threads-{}-{name}", std::process::id()))
}

/// Runs `args` on `threads` threads, exporting the final cloth; returns its glTF bytes and
/// the metrics' iteration counts.
fn run_on(threads: usize, tag: &str, args: &[&str]) -> (Vec<u8>, [u64; 2]) {
    let (glb, metrics) = (temp(&format!("{tag}-{threads}.glb")), temp(&format!("{tag}-{threads}.json")));
    let out = Command::new(env!("CARGO_BIN_EXE_rosette"))
        .args(args)
        .args(["--export", glb.to_str().unwrap(), "--metrics", metrics.to_str().unwrap(), "--force"])
        .env("RAYON_NUM_THREADS", threads.to_string())
        .output()
        .expect("the rosette binary runs");
    assert!(out.status.success(), "{args:?} on {threads} threads: {}", String::from_utf8_lossy(&out.stderr));
    let m: serde_json::Value = serde_json::from_slice(&std::fs::read(&metrics).unwrap()).unwrap();
    let count = |key: &str| m[key].as_u64().unwrap_or_else(|| panic!("{key} in {m}"));
    let cloth = std::fs::read(&glb).unwrap();
    for f in [glb, metrics] {
        let _ = std::fs::remove_file(f);
    }
    (cloth, [count("newton_iterations"), count("cg_iterations")])
}

/// The tablecloth (3 200 triangles) through its landing on the table, and a gored skirt
/// (2 956 triangles) sewn (its seams close by 1 s): contact with a prop, cloth–cloth pairs, sewing,
/// forces, Newton's matrix and its solves all on the split passes.
#[test]
fn a_landing_and_a_sewing_are_the_same_cloth_on_one_thread_and_two() {
    for (tag, args) in [
        ("tablecloth", &["run", "tablecloth", "--fast", "--duration", "0.3"][..]),
        ("skirt", &["run", "skirt-gored-bias", "--fast", "--duration", "1.1"][..]),
    ] {
        let (one, counts_one) = run_on(1, tag, args);
        let (two, counts_two) = run_on(2, tag, args);
        assert_eq!(counts_one, counts_two, "{tag}: Newton and CG iterations on one thread and two");
        assert!(one == two, "{tag}: the final cloth differs between one thread and two");
    }
}
