//! What the reference kernel counts: [`Counts`], the fates, interactions and flux bins
//! of a traced batch, as `tests/bench_reference.rs` compares them with blutrace's.

/// What a traced batch of photons did: fates (each photon has exactly one), interactions
/// and the flux bins.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    /// Photons traced.
    pub photons: u64,
    /// Reached the target plane.
    pub detected: u64,
    /// Of those, the ones within 30 degrees of its normal (a coarse angular check).
    pub detected_near_normal: u64,
    /// Absorbed by the ink of the dots.
    pub absorbed_by_ink: u64,
    /// Absorbed by the sheet.
    pub absorbed_by_sheet: u64,
    /// Absorbed in the guide's bulk.
    pub absorbed_in_medium: u64,
    /// Absorbed by the strip's body.
    pub absorbed_by_source: u64,
    /// Left the scene.
    pub escaped: u64,
    /// Stopped by the bounce cap.
    pub killed: u64,
    /// Surface and body interactions.
    pub interactions: u64,
    /// Sum over photons of the square of their interaction counts (for errors).
    pub interactions_sq: u128,
    /// Detected photons per flux bin (row-major, x fastest, as blutrace's grid).
    pub flux: Vec<u64>,
}

impl Counts {
    pub(crate) fn new(bins: usize) -> Self {
        Self {
            flux: vec![0; bins],
            ..Default::default()
        }
    }

    pub(crate) fn merge(mut self, o: Counts) -> Counts {
        self.photons += o.photons;
        self.detected += o.detected;
        self.detected_near_normal += o.detected_near_normal;
        self.absorbed_by_ink += o.absorbed_by_ink;
        self.absorbed_by_sheet += o.absorbed_by_sheet;
        self.absorbed_in_medium += o.absorbed_in_medium;
        self.absorbed_by_source += o.absorbed_by_source;
        self.escaped += o.escaped;
        self.killed += o.killed;
        self.interactions += o.interactions;
        self.interactions_sq += o.interactions_sq;
        self.flux.iter_mut().zip(&o.flux).for_each(|(a, b)| *a += b);
        self
    }

    /// Photons with any fate: equals `photons` (the ledger closes).
    pub fn fates(&self) -> u64 {
        self.detected
            + self.absorbed_by_ink
            + self.absorbed_by_sheet
            + self.absorbed_in_medium
            + self.absorbed_by_source
            + self.escaped
            + self.killed
    }
}
