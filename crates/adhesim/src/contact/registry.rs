//! The registry of interface laws: the history fields of every law the program knows, for
//! what is drawn from a history file alone (figure labels and map colour ranges). A new law
//! adds its history's fields here.

use super::history::{HistoryField, LawHistory};

/// The history fields of every registered interface law.
pub const REGISTERED_HISTORIES: &[&[HistoryField]] = &[super::rcc::RccHistory::FIELDS];

/// The history fields of every registered law (one list per law), for the labels of
/// figures drawn from a history file alone.
pub fn registered_fields() -> impl Iterator<Item = &'static HistoryField> {
    REGISTERED_HISTORIES.iter().flat_map(|f| f.iter())
}

/// Quantity and unit of the history field `name` of any registered law.
pub fn field_label(name: &str) -> Option<&'static str> {
    registered_fields()
        .find(|f| f.name == name)
        .map(|f| f.label)
}

/// Fixed colour range of the maps of the history field `name` of any registered law.
pub fn field_range(name: &str) -> Option<(f64, f64)> {
    registered_fields()
        .find(|f| f.name == name)
        .and_then(|f| f.range)
}
