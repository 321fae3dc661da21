//! Rosette: a woven-fabric simulator and virtual fabric laboratory.
//!
//! `sim` is the physics (no I/O); `scene` turns presets into runnable laboratory tests
//! with measurements; `render` draws snapshots with wgpu (window and headless); the
//! `rosette` binary drives scenes from the command line; `bench` times them.
pub mod app;
pub mod bench;
pub mod render;
pub mod scene;
pub mod sim;
