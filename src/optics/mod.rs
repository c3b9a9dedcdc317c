//! Optical models: what happens to a photon where it meets a surface.
//!
//! One module per physical model: [`fresnel`] (dielectric interfaces), [`sampling`]
//! (direction sampling for diffuse and Phong lobes), [`dots`] (procedural ink-dot
//! patterns) and [`surface`] (the per-tag model and its Russian roulette).

pub mod dots;
pub mod fresnel;
pub mod sampling;
pub mod surface;
