//! Benchmarks run by `swimlab bench ...`: work against precision, stability limits, and CPU against GPU. They use
//! the engine only and measure on the machine at hand; figures are reported, never asserted.

pub mod backends;
pub mod boundaries;
pub mod contacts;
pub mod ewald;
pub mod live_view;
pub mod pairs;
pub mod plots;
pub mod report;
pub mod scaling;
pub mod stability;
pub mod suspension;
pub mod table;
pub mod work_precision;
