#![doc = include_str!("../README.md")]

pub mod advection;
#[cfg(feature = "cases")]
pub mod cases;
pub mod error;
pub mod kind;
pub mod mac;
pub mod memory;
pub mod pressure;
pub mod scenes;
pub mod smoke;
pub mod stam;

pub use error::FluidError;
pub use kind::KIND;
