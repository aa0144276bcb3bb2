//! `pada new-robot NAME`: a new robot's files, a `robot.toml` commented
//! field by field and a URDF of one arm on one servo, which run as they
//! are (pada_robot_file::template). Existing files are never overwritten.

use crate::console::outln;
use crate::error::{usage, CliError};
use clap::Args;
use pada_core::limits::MAX_ROBOT_NAME;
use std::path::PathBuf;

/// `pada new-robot`.
#[derive(Debug, Clone, Args)]
pub struct NewRobotArgs {
    /// The robot's name: 1 to 32 lowercase letters, digits or '-'. Its
    /// files go in a new directory of that name.
    pub name: String,
    /// Where to make that directory (default: the current directory).
    #[arg(long, value_name = "DIR", default_value = ".")]
    pub dir: PathBuf,
}

/// Runs `pada new-robot`.
pub fn run(args: NewRobotArgs) -> Result<(), CliError> {
    let name = args.name.as_str();
    if name.is_empty()
        || name.len() > MAX_ROBOT_NAME
        || !name.bytes().all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'-')
    {
        return Err(usage(format!(
            "robot name {name:?} is not valid: 1 to {MAX_ROBOT_NAME} lowercase letters, digits or '-'"
        )));
    }
    if pada_core::robot::registry::find(name).is_some() {
        return Err(usage(format!("{name:?} is one of pada's own robots: choose another name")));
    }
    let dir = args.dir.join(name);
    if dir.exists() {
        return Err(usage(format!("{} exists already: new-robot writes only into a new directory", dir.display())));
    }
    std::fs::create_dir_all(&dir).map_err(|e| usage(format!("cannot create {}: {e}", dir.display())))?;
    let toml = dir.join("robot.toml");
    let urdf = dir.join(format!("{name}.urdf"));
    crate::output::write_atomic(&toml, pada_robot_file::template::robot_toml(name).as_bytes())?;
    crate::output::write_atomic(&urdf, pada_robot_file::template::urdf(name).as_bytes())?;
    // What was written must load: the template is checked as a user's
    // file would be.
    pada_robot_file::load(&toml).map_err(|e| anyhow::anyhow!("the new robot's files do not load (a bug in pada): {e}"))?;
    outln!("wrote {} and {}", toml.display(), urdf.display())?;
    outln!("learn on it:   pada run --robot {} --algo pada", toml.display())?;
    outln!("see it move:   pada run --robot {} --algo pada --save-weights w.wts && pada render --robot {} --policy w.wts", toml.display(), toml.display())?;
    outln!("every field:   docs/your-robot.md")?;
    Ok(())
}
