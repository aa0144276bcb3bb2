//! `pada watch`: a live page in the browser for any telemetry stream — a
//! board's serial port, a recorded stream, or a live `pada run` / `pada
//! sil` over loopback TCP.
//!
//! ```text
//!  source ─ decoder thread ─ Recorder (pada capture's decoder, CSV, counts)
//!                         └─ WatchState (curve, fatigue, last episode, …) ─┐
//!  browser ─ GET / , /live (once a second), /api/state ─ HTTP workers ─────┘
//! ```
//!
//! - [`state`]: what the page shows, built frame by frame;
//! - [`series`]: the bounded history behind the fatigue plots;
//! - [`plots`]: the four plots, server-rendered SVG (plotters);
//! - [`page`]: the HTML, with a few lines of script for the live part;
//! - [`server`]: the HTTP server (tiny_http) and `/api/state`;
//! - [`source`]: the sources and the decoder thread.

pub mod page;
pub mod plots;
pub mod series;
pub mod server;
pub mod source;
pub mod state;
