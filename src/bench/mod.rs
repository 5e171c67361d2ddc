//! The benchmark's pure parts: its configuration, the records of every frame and run, the
//! statistics (median, p95, speed-ups) and the Markdown tables. The GPU run loop, the progress
//! bar and the plots are in the binary (`leapview bench`).

pub mod config;
pub mod record;
pub mod stats;
pub mod tables;
pub mod targets;

pub use config::{BenchConfig, ConfigError, Filters};
pub use record::{BenchResults, FrameRecord, RunKey, RunRecord};
pub use stats::{RunSummary, Table1Row, speed_up};
pub use tables::Summary;
