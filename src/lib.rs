//! Rosette: a woven-fabric simulator and virtual fabric laboratory.
//!
//! `sim` is the physics (no I/O); `scene` turns presets into runnable laboratory tests
//! with measurements; `render` draws snapshots with wgpu (window and headless); the
//! `rosette` binary drives scenes from the command line; `fabric` turns laboratory
//! measurement sheets (KES-F, FAST, cantilever) into fabrics and `lab` runs the standard
//! tests on them virtually; `physics` holds gravity and the bending-length relations, once;
//! `reference` holds the analytic
//! solutions (elastica, off-axis formulas) the tests and the chart compare against; `chart`
//! sweeps integrators, time steps and meshes for speed against accuracy; `bench` times
//! scenes; `io` reads the files a user names and writes every output whole, never over
//! an input; `appearance` is a fabric's look (colour, weave or print, sheen), which every
//! picture and the glTF export draw it with.
pub mod app;
pub mod appearance;
pub mod bench;
pub mod card;
pub mod chart;
pub mod export;
pub mod fabric;
pub mod garment;
pub mod io;
pub mod lab;
pub mod physics;
pub mod reference;
pub mod render;
pub mod scene;
pub mod settings;
pub mod sim;
