//! The subcommands of `penumbra`, one module each; `args` is the grammar they share.

pub(crate) mod args;
pub(crate) mod bench;
pub(crate) mod cache;
pub(crate) mod choice;
pub(crate) mod edit;
pub(crate) mod env_options;
pub(crate) mod figure;
#[cfg(feature = "gui")]
pub(crate) mod gui;
pub(crate) mod ltc;
pub(crate) mod probe;
pub(crate) mod process_env;
pub(crate) mod progress;
pub(crate) mod render;
pub(crate) mod stress;

pub(crate) use args::*;
