//! `--interop` at the front door: the scene executor decides the route of
//! the edges frame's buffers to GL (see [`crate::scene::exec::interop`]);
//! [`interop_offer`] says what the device, a GL context and Vulkan offer.

pub use crate::scene::exec::interop::interop_offer;
