//! Optical models: what happens to a photon where it meets a surface.
//!
//! One module per surface model, each with its scene-file entry, its checks and its
//! physics: [`dielectric`] (smooth interfaces), [`dots`] (procedural ink-dot patterns,
//! placed as [`dot_placement`] says),
//! [`grooves`] (procedural V-grooves and prism films, traced exactly in their layer),
//! [`diffuser`] (rough diffusing faces), [`phong`], [`lambert`], [`mirror`] and
//! [`absorber`]; [`surface`] joins them into the per-tag model and its Russian roulette.
//! Shared by several: [`medium`] (media and interfaces; volume scattering with
//! [`phase`], [`mie`] and [`particles`]), [`fresnel`] (Fresnel equations
//! and roulette), [`sampling`] (direction sampling) [`density`] (values graded along
//! a guide) and [`spectrum`] (the light a photon carries and the quantities read at it).

pub mod absorber;
pub mod bsdf_table;
pub mod density;
pub mod dielectric;
pub mod diffuser;
pub mod dot_placement;
pub mod dots;
pub mod fresnel;
pub mod grooves;
pub mod lambert;
pub mod medium;
pub mod mie;
pub mod mirror;
pub mod model;
pub mod opaque;
pub mod particles;
pub mod phase;
pub mod phong;
pub mod placement;
pub mod polarization;
pub mod polarizer;
pub mod sampling;
pub mod spectrum;
pub mod surface;
pub mod two_sided;
