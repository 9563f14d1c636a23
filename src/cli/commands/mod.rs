//! One module per subcommand, as cargo's `src/bin/cargo/commands/`: each
//! has its flags (a clap `Args` struct) and a `run` that prints its output
//! or returns a [`super::CliError`].

pub mod annual;
pub mod export_radiance;
pub mod info;
pub mod render;
pub mod sensors;
pub mod sun;
pub mod sweep;
pub mod view;
