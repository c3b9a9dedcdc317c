//! Writing results to disk: generic, scene-agnostic writers.
//!
//! - [`atomic`]: [`atomic::OutputSet`] writes every output file of a run into a staging
//!   folder that replaces the output folder in one step once the whole set is written, so
//!   the folder always holds one complete set (the previous or the new one).
//! - [`exr`]: multi-channel OpenEXR images (32-bit float or unsigned integer channels,
//!   lossless ZIP compression) with text and number header attributes, plus a reader for
//!   the files it writes.
//! - [`png`]: false-colour previews (viridis colour map with a colour bar) for people.
//! - [`colormap`]: the viridis colour map; `font`: the 5×7 pixel font of previews and charts.
//! - [`plot`]: line charts (convergence, optimizer histories).
//!
//! Grid convention shared by [`exr`] and [`png`]: a `width × height` grid is a row-major
//! slice, `x` fastest, and grid row 0 is the `y = 0` row (the lowest `y`). Both writers put
//! grid row 0 at the *bottom* of the image, so that the picture looks like the plot of the
//! grid with `y` pointing up.

pub mod atomic;
pub mod colormap;
pub mod exr;
pub(crate) mod font;
pub mod plot;
pub mod png;
#[cfg(test)]
mod test_png;
