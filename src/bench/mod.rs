//! Benchmarks run by `swimlab bench ...`: work against precision, and stability limits. They use
//! the engine only and measure on the machine at hand; figures are reported, never asserted.

pub mod stability;
pub mod table;
pub mod work_precision;
