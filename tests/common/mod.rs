//! Helpers shared by the integration tests.

// Each test binary compiles this module on its own and uses only part of it, so unused
// items are expected rather than a sign of dead code.
#![allow(dead_code)]

pub mod reference;
