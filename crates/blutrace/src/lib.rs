//! blutrace: Monte Carlo photon tracing and optimization of LCD backlight units.
//!
//! One module per physical concept: [`scene`] (files and validation), [`geometry`],
//! [`accel`] (intersection backends), [`optics`] (surface models), [`color`] (CIE
//! colorimetry: tables, spectra, XYZ, u'v', CCT), [`sources`],
//! [`tracer`] (the photon loop), [`detector`] and [`tally`] (what is scored),
//! [`output`] (EXR, PNG, JSON), [`run`] (a whole traced job with its summary) and
//! [`optimize`] (the dot and layout searches). The command line is the `blutrace` binary's
//! own (the workspace's root package, `src/cli/`, over this library) and the benchmarks
//! are the `blutrace-bench` crate's (`crates/bench`); `examples/design_study.rs` uses the
//! library.

pub mod accel;
pub mod characterise;
pub mod color;
pub mod count;
pub mod detector;
pub mod estimator;
pub mod geometry;
pub mod input_file;
pub mod optics;
pub mod optimize;
pub mod output;
pub mod rng;
pub mod rounding;
pub mod run;
pub mod scene;
pub mod shard;
pub mod sources;
pub mod spec_check;
pub mod tally;
pub mod tracer;
pub mod transform;
