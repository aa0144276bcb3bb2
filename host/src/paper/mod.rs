//! Reproducing the paper: its published numbers ([`numbers`]), the
//! objective of Section VI ([`objective`]), the pendulum experiments of
//! Section VII ([`pendulum`]) and their report ([`report`]).

pub mod figure_data;
pub mod leo;
pub mod numbers;
pub mod objective;
pub mod pendulum;
pub mod report;
