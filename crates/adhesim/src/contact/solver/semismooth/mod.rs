//! The semismooth Newton contact solve (docs/contact-solver.md): [`mixed`] solves the contact
//! problem of a Newton iteration on the mixed (displacement, force) system without W;
//! `coupling` takes its directions from the step's factorisation and GMRES; [`reduced`] is
//! the same method on the reduced problem x = q + W r with W given.

pub(crate) mod coupling;
pub mod mixed;
pub mod reduced;
