//! The interactive viewer: a winit window with egui panels over the wgpu renderer, driving
//! a solver that runs on its own thread ([`worker`]).
//!
//! - [`worker`]: the solver thread, its commands and snapshots (no GUI dependency).
//! - [`ui`]: the egui panels and the view's mouse and keys, turned into [`action`]s.
//! - [`camera`]: orbit camera and ray picking; [`colour`]: strain/bending colour maps;
//!   [`plots`]: live test plots and their references; [`files`]: TOML, OBJ, CSV;
//!   [`chart_view`]: the speed/accuracy charts of `rosette chart`; [`card_view`]: the
//!   fabric card of the fabric being edited; [`pin`]: a fabric's result kept beside the live
//!   one; [`pattern_view`]: a garment's grains and its flat pattern; [`swatch`]: the
//!   fabric's look beside its editor; [`job`]: a card or a sweep on a thread of its own,
//!   with the progress those windows show.
//! - [`script`]: scripted sessions read and checked; [`session`]: one played in the window
//!   through the panels' own code.
pub mod action;
pub mod camera;
pub mod card_view;
pub mod chart_view;
pub mod colour;
pub mod files;
pub mod job;
pub mod pattern_view;
pub mod pin;
pub mod plots;
pub mod script;
pub mod session;
pub mod swatch;
pub mod ui;
pub mod worker;
pub mod viewer;
