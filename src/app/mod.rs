//! The interactive viewer: a winit window with egui panels over the wgpu renderer, driving
//! a solver that runs on its own thread ([`worker`]).
pub mod camera;
pub mod files;
pub mod worker;
