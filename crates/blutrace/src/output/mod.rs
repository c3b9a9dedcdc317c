//! Writing results to disk: generic, scene-agnostic writers.
//!
//! - [`atomic`]: [`atomic::OutputSet`] writes every output file of a run into a staging
//!   folder that replaces the output folder in one step once the whole set is written, so
//!   the folder always holds one complete set (the previous or the new one).
//! - [`exr`]: multi-channel OpenEXR images (32-bit float or unsigned integer channels,
//!   lossless ZIP compression) with text and number header attributes, plus a reader for
//!   the files it writes.
//! - [`map`]: false-colour maps (viridis, with a colour bar, title and mm axes) for people.
//! - [`polar`]: polar false-colour plots of (theta, phi) grids (the conoscope view).
//! - [`plot`]: line charts (convergence, optimizer histories).
//! - [`figure`]: what maps and charts share: the embedded font, the colour map, drawing
//!   with `plotters` into a buffer; `png`: encoding that buffer as a PNG file.
//!
//! Grid convention shared by [`exr`] and [`map`]: a `width × height` grid is a row-major
//! slice, `x` fastest, and grid row 0 is the `y = 0` row (the lowest `y`). Both writers put
//! grid row 0 at the *bottom* of the image, so that the picture looks like the plot of the
//! grid with `y` pointing up.

pub mod atomic;
pub mod exr;
pub mod figure;
pub mod map;
pub mod plot;
pub(crate) mod png;
pub mod polar;
#[cfg(test)]
mod test_png;
