//! Optical models: what happens to a photon where it meets a surface.
//!
//! One module per physical model: [`fresnel`] (dielectric interfaces), [`sampling`]
//! (direction sampling for diffuse and Phong lobes), [`dots`] (procedural ink-dot
//! patterns), [`grooves`] (procedural V-grooves and prism films, traced exactly in their
//! layer), [`diffuser`] (rough diffusing faces), [`gradation`] (values graded along a
//! guide) and [`surface`] (the per-tag model and its Russian roulette).

pub mod diffuser;
pub mod dots;
pub mod fresnel;
pub mod gradation;
pub mod grooves;
pub mod sampling;
pub mod surface;
