//! What a run writes besides the physics: frames, figures, maps, the names of reactions and
//! the tracked nodes of the history. The stepper never reads these; the run's observers do.

/// A node whose fields are written to the history at every step.
#[derive(Clone, Debug, PartialEq)]
pub struct Track {
    /// Column prefix in history.csv.
    pub name: String,
    /// Global node index.
    pub node: usize,
}

/// Output settings.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct OutputSettings {
    /// Write a VTU frame every this many seconds of simulated time (0 = every step).
    pub frame_interval: f64,
    /// Draw the history figures (PNG) when the run ends.
    pub figures: bool,
    /// Maps of contact fields over a pair's slave surface at given times.
    pub maps: Vec<MapRequest>,
    /// Name under which the reaction of each entry of [`adhesim::problem::Problem::dirichlet`] is written to
    /// the history (same order); an empty name, or an entry beyond the list, is not written.
    pub boundary_names: Vec<String>,
    /// Nodes whose fields are written to the history at every step.
    pub tracks: Vec<Track>,
}

/// Maps of contact fields over the slave surface of a contact pair, drawn at the first
/// committed step at or after each requested time.
#[derive(Clone, Debug, PartialEq)]
pub struct MapRequest {
    /// Index of the contact pair.
    pub pair: usize,
    /// Contact fields to map (`beta`, `rn`, `rn_adh`, `rt`, `rt_adh`, `gap`, `slip`, ...).
    pub fields: Vec<String>,
    /// Times [s], increasing.
    pub times: Vec<f64>,
}
