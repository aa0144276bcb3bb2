//! Reproducing the paper: its published numbers ([`numbers`]), the mean
//! learning curves over trials ([`curves`]), the
//! objective of Section VI ([`objective`]), the pendulum experiments of
//! Section VII ([`pendulum`]) and their report ([`report`]), and learning
//! on a wear budget ([`wear`], `pada paper wear`), and what pretraining in
//! simulation saves on a robot that is not its model ([`transfer`], `pada
//! paper transfer`).

pub mod csv_row;
pub mod curves;
pub mod figure_data;
pub mod leo;
pub mod numbers;
pub mod objective;
pub mod pendulum;
pub mod report;
pub mod transfer;
pub mod wear;
