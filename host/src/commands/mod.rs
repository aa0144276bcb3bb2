//! One module per subcommand of `pada`.

pub mod capture;
pub mod claims;
pub mod claims_demand;
pub mod demo;
pub mod drive;
pub mod leo;
pub mod mtbf;
pub mod options;
pub mod paper;
pub mod paper_args;
pub mod paper_leo;
pub mod paper_wear;
pub mod paper_transfer;
pub mod plant_args;
pub mod policy_args;
pub mod new_robot;
pub mod render;
pub mod run;
pub mod servos;
pub mod sil;
pub mod stream_args;
pub mod trial;
pub mod watch;
