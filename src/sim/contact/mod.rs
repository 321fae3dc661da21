//! Contact: cloth against rigid props and cloth against itself.
pub mod props;

pub use props::{Prop, PropError, PropShape, SurfacePoint};
