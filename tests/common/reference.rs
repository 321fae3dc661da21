//! The analytic references live in the library (`rosette::reference`), where the chart
//! (`rosette chart`) uses them too; the tests import them from here.

// Not every test binary that includes `common` uses them.
#[allow(unused_imports)]
pub use rosette::reference::*;
