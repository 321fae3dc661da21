//! Rosette: a woven-fabric simulator.
pub mod sim;
