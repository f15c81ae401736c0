//! The history an interface law keeps at each contact site between steps, and what the rest of
//! the program knows about it: named fields (name, quantity and unit, kind, where they go in
//! the outputs) and their values. Outputs (history columns, VTK contact fields, maps,
//! figures) and checkpoints iterate over these fields; none of them names a law's field.
//!
//! A law's history is a typed value (e.g. [`super::rcc::RccHistory`]) that implements
//! [`LawHistory`]: it lists its [`HistoryField`]s once and encodes itself, in global axes, to
//! a law-agnostic [`SiteHistory`] (a short array of numbers in the order of its fields). The
//! stepper stores a [`SiteHistory`] per contact site; the law turns it back into its typed
//! history at the start of a step and writes the committed one at its end
//! ([`super::interface::Interface`]).
//!
//! Within a step a contact point carries its law's history frozen at the start of the step,
//! in the point's local frame, as a [`PointHistory`]: plain numbers again, which the law
//! writes ([`super::interface::Interface::point_history`]) and reads (its adhesive evaluation and
//! its commit) through its own typed view ([`LawPointHistory`], e.g. RCC's
//! [`super::rcc::BondState`]). The point solvers, the stepper and the fclib bridge only pass
//! it along; a point's solution carries the history the step leads to in the same form.

/// Largest number of values a site's history holds ([`SiteHistory`]): a scalar field takes
/// one, a vector field three.
pub const MAX_HISTORY_VALUES: usize = 8;

/// What a history field holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FieldKind {
    /// One number.
    Scalar,
    /// A vector in global axes (three numbers), e.g. a tangential stretch. Vector fields go to
    /// the VTK outputs only; the history and the maps carry scalars.
    Vector,
}

/// Where a history field goes among the contact fields that every law has (forces, gap,
/// slip, state, tractions), in the history columns, the maps and the VTK contact fields.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Slot {
    /// Before the forces: the first contact fields of a site.
    First,
    /// After the gap and slip, before the contact state: with the kinematics.
    Motion,
    /// After all the others.
    Last,
}

/// One named field of a law's history.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HistoryField {
    /// Name of the field in the outputs (history column suffix, map field, VTK array).
    pub name: &'static str,
    /// Quantity and unit, the axis or colour-bar label of its figures.
    pub label: &'static str,
    /// Scalar or vector.
    pub kind: FieldKind,
    /// Where it goes among the contact fields.
    pub slot: Slot,
    /// Fixed colour range of its maps, or None for the range of the values.
    pub range: Option<(f64, f64)>,
}

impl HistoryField {
    /// How many values the field takes in a [`SiteHistory`].
    pub const fn len(&self) -> usize {
        match self.kind {
            FieldKind::Scalar => 1,
            FieldKind::Vector => 3,
        }
    }

    /// Always false: a field has at least one value.
    pub const fn is_empty(&self) -> bool {
        false
    }
}

/// How many values the fields `fields` take in a [`SiteHistory`].
pub fn values_of(fields: &[HistoryField]) -> usize {
    fields.iter().map(HistoryField::len).sum()
}

/// The history of one contact site as plain numbers, in the order of its law's
/// [`HistoryField`]s (global axes for vectors), zero-padded to [`MAX_HISTORY_VALUES`].
///
/// By convention the first value is the law's bond intensity: a site counts as bonded (the
/// `bonded` column of a pair) when it is positive. A law without bonds keeps it 0.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SiteHistory(pub [f64; MAX_HISTORY_VALUES]);

impl SiteHistory {
    /// Whether the site is bonded (its first value is positive).
    pub fn bonded(&self) -> bool {
        self.0[0] > 0.0
    }

    /// Each field of `fields` with its values (one, or three for a vector).
    pub fn fields<'a>(
        &'a self,
        fields: &'a [HistoryField],
    ) -> impl Iterator<Item = (&'a HistoryField, &'a [f64])> + 'a {
        let mut at = 0;
        fields.iter().map(move |f| {
            let v = &self.0[at..at + f.len()];
            at += f.len();
            (f, v)
        })
    }

    /// The value of the scalar field `name` of `fields`, or None if there is none.
    pub fn scalar(&self, fields: &[HistoryField], name: &str) -> Option<f64> {
        self.fields(fields)
            .find(|(f, _)| f.name == name && f.kind == FieldKind::Scalar)
            .map(|(_, v)| v[0])
    }
}

/// The history of one contact point within a step as plain numbers, in the point's local
/// frame (t₁, t₂, n), in an order of its law's choosing, zero-padded to
/// [`MAX_HISTORY_VALUES`]: the frozen history at the start of the step, or the one the step
/// leads to (in a point's solution). Only the law reads its values
/// ([`LawPointHistory::decode`]).
///
/// The same convention as [`SiteHistory`]: the first value is the law's bond intensity, the
/// point is bonded when it is positive, and a law without bonds keeps it 0.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PointHistory(pub [f64; MAX_HISTORY_VALUES]);

impl PointHistory {
    /// Whether the point is bonded (its first value is positive).
    pub fn bonded(&self) -> bool {
        self.0[0] > 0.0
    }
}

/// A law's typed history at a contact point, in the point's local frame.
pub trait LawPointHistory: Copy + Default + PartialEq + std::fmt::Debug {
    /// Its values, the bond intensity first (or 0).
    fn encode(&self) -> PointHistory;

    /// The history whose [`LawPointHistory::encode`] is `h`.
    fn decode(h: &PointHistory) -> Self;
}

/// A law's typed history at a contact site.
pub trait LawHistory: Copy + Default + PartialEq + std::fmt::Debug {
    /// Its fields, in the order of [`LawHistory::encode`]; together they take at most
    /// [`MAX_HISTORY_VALUES`] values.
    const FIELDS: &'static [HistoryField];

    /// The values of its fields, in order.
    fn encode(&self) -> SiteHistory;

    /// The history whose [`LawHistory::encode`] is `h`.
    fn decode(h: &SiteHistory) -> Self;
}
