#![doc = include_str!("../README.md")]

mod output;
pub mod run;
pub mod scene;
pub mod tolerance;
pub mod view;
