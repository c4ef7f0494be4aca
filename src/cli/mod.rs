//! The headless command line: one file per subcommand. `anyhow` is used here and in
//! `main.rs` only.

mod accuracy;
mod args;
mod bench;
mod command;
mod grid;
mod info;
mod paths;
mod render;
mod scenes;
mod simulate;

pub use args::Cli;
pub use command::run;
