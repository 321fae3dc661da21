//! Helpers shared by the integration tests.

// Each test binary compiles this module on its own and uses only part of it, so unused
// items are expected rather than a sign of dead code.
#![allow(dead_code)]

pub mod reference;

use rosette::scene::{Metrics, RunOptions, Scene, SceneConfig, load_scene, run_scene};

/// Runs `preset` with `--set` style `overrides` to the end of its scene, which must not
/// diverge.
pub fn run(preset: &str, overrides: &[String]) -> (SceneConfig, Metrics) {
    let (config, _) = load_scene(preset, overrides).unwrap_or_else(|e| panic!("{e}"));
    let mut scene = Scene::build(config.clone()).unwrap_or_else(|e| panic!("{e}"));
    let (metrics, error) = run_scene(&mut scene, preset, RunOptions::default());
    assert!(error.is_none(), "{preset} {overrides:?}: {error:?}");
    (config.into_config(), metrics)
}

/// The drape coefficient of a drape scene's run.
pub fn drape_coefficient(m: &Metrics) -> f64 {
    m.measures.drape().expect("drape measures").drape_coefficient
}

/// Runs `preset` for several override sets, one thread each (both cores).
pub fn run_all(preset: &str, sets: Vec<Vec<String>>) -> Vec<(SceneConfig, Metrics)> {
    std::thread::scope(|s| {
        let handles: Vec<_> = sets.iter().map(|o| s.spawn(move || run(preset, o))).collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    })
}

/// A private 0700 runtime directory for Mesa (else it warns on every device).
pub fn runtime_dir() -> std::path::PathBuf {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("xdg-runtime");
    std::fs::create_dir_all(&dir).unwrap();
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o700)).unwrap();
    }
    dir
}
