//! The analytic references live in the library (`rosette::reference`), where the chart
//! (`rosette chart`) uses them too; the tests import them from here.

pub use rosette::reference::*;
