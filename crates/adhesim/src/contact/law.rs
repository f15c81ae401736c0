//! The interface law of a contact pair (docs/model.md §5–§6): its Coulomb friction cone (μ,
//! and the material axes of an orthotropic interface) and the law of its bonds, a trait object
//! implementing [`Interface`] (RCC, `rcc.rs`), to which [`InterfaceLaw`]'s own [`Interface`]
//! implementation hands every call.
//!
//! # Conventions
//! - Local frame components are ordered (t1, t2, n).
//! - `r` is the force on the slave node [N]; `r_n > 0` is compression. `r = r̄ + r̃` (dry part plus
//!   adhesive part).
//! - `x = (x_t1, x_t2, x_n)` [m]: `x_n` is the gap at the end of the step (≥ 0 apart), `x_t` the
//!   slip increment over the step.
//! - Interface parameters are per unit area; nodal forces are traction × tributary area `A` [m²].
//!
//! The pieces a law is made of live apart: Coulomb's cone in `cone.rs`, what a bond law
//! provides in [`super::interface`], the point solver in [`super::point`], RCC's maths in
//! [`super::rcc`] and the registry of laws in [`super::registry`].

pub use super::anisotropic::Orthotropy;
use super::anisotropic::{scale, unscale};
use super::cone::{bipotential_trial, dry_projection};
use super::history::{HistoryField, PointHistory, SiteHistory};
use super::interface::{
    AdhEval, AdhesiveResponse, FrozenSprings, Interface, PairScales, PointSolution,
};
use super::rcc::RccParams;
use crate::Vec3;
use std::sync::Arc;

/// Interface law of a contact pair: its friction cone (μ, and the material axes of an
/// orthotropic interface) and the law of its bonds, which also keeps the history at each
/// slave node ([`Interface`]).
#[derive(Clone)]
pub struct InterfaceLaw {
    /// Coulomb friction coefficient μ ≥ 0 [-] (negative values are treated as 0); μ₁, along
    /// the first material axis, on an orthotropic interface.
    pub mu: f64,
    /// The bond law: RCC adhesion ([`super::rcc::Rcc`], without parameters for dry contact)
    /// or any other implementation of [`Interface`].
    pub bond: Arc<dyn Interface>,
    /// Material axes and μ₂ of an orthotropic interface (elliptic friction cone), or `None`
    /// for an isotropic one ([`super::anisotropic`]).
    pub anisotropy: Option<Orthotropy>,
}

/// The form the checkpoint fingerprint hashes: the bond law's under the name `adhesion`
/// (`None` or `Some(RccParams { .. })` for RCC), as when RCC was the only law, so that a
/// scenario's fingerprint does not change with this layout.
impl std::fmt::Debug for InterfaceLaw {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("InterfaceLaw")
            .field("mu", &self.mu)
            .field("adhesion", &self.bond)
            .field("anisotropy", &self.anisotropy)
            .finish()
    }
}

impl InterfaceLaw {
    /// Dry isotropic Coulomb friction with coefficient `mu` [-]: no adhesion, no anisotropy.
    pub fn coulomb(mu: f64) -> Self {
        Self::rcc(mu, None, None)
    }

    /// Coulomb friction `mu` [-] with RCC adhesion `adhesion` (None: dry) and the orthotropy
    /// `anisotropy` (None: isotropic).
    pub fn rcc(mu: f64, adhesion: Option<RccParams>, anisotropy: Option<Orthotropy>) -> Self {
        let bond: Arc<dyn Interface> = match adhesion {
            Some(_) => Arc::new(super::rcc::Rcc(adhesion)),
            None => super::rcc::Rcc::dry(),
        };
        InterfaceLaw {
            mu,
            bond,
            anisotropy,
        }
    }

    /// Whether the law has no friction (μ ≤ 0 along both axes).
    pub fn is_frictionless(&self) -> bool {
        self.mu <= 0.0 && self.anisotropy.as_ref().is_none_or(|o| o.mu2 <= 0.0)
    }

    /// The scale s = μ₂/μ₁ of the second tangential axis that maps the law's cone on the
    /// circular cone of μ₁ ([`super::anisotropic`]): 1 for an isotropic law (and for μ₁ = μ₂).
    pub fn tangent_scale(&self) -> f64 {
        match &self.anisotropy {
            Some(o) if o.mu2 != self.mu && self.mu > 0.0 && o.mu2 > 0.0 => o.mu2 / self.mu,
            _ => 1.0,
        }
    }
}

/// A contact pair's law is its bond law's, whatever that is.
impl Interface for InterfaceLaw {
    fn history_fields(&self) -> &'static [HistoryField] {
        self.bond.history_fields()
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self.bond.as_any()
    }

    fn bond_traction(&self) -> f64 {
        self.bond.bond_traction()
    }

    fn is_adhesive(&self) -> bool {
        self.bond.is_adhesive()
    }

    fn adhesion_at(&self, start: &PointHistory, dt: f64, area: f64, x: Vec3) -> AdhEval {
        self.bond.adhesion_at(start, dt, area, x)
    }

    fn frozen_springs(&self, start: &PointHistory, area: f64) -> Option<FrozenSprings> {
        self.bond.frozen_springs(start, area)
    }

    fn warnings(&self, pair: &PairScales, out: &mut Vec<String>) {
        self.bond.warnings(pair, out)
    }

    fn adhesive_response(
        &self,
        start: &PointHistory,
        dt: f64,
        area: f64,
        x: Vec3,
    ) -> Option<AdhesiveResponse> {
        self.bond.adhesive_response(start, dt, area, x)
    }

    fn point_history(&self, node: &SiteHistory, frame: &[[f64; 3]; 3]) -> PointHistory {
        self.bond.point_history(node, frame)
    }

    fn commit(
        &self,
        start: &PointHistory,
        sol: &PointSolution,
        frame: &[[f64; 3]; 3],
    ) -> SiteHistory {
        self.bond.commit(start, sol, frame)
    }

    fn release(&self, node: &SiteHistory) -> SiteHistory {
        self.bond.release(node)
    }
}

/// The defect r̄ − P_K(r̄ − ρ x̂) [N] of the law's bi-potential condition at a dry force `r_dry`
/// [N] and local relative displacement `x` [m], with `rho` [N/m]: zero exactly at a solution.
/// For an orthotropic law it is evaluated in the scaled variables and mapped back by T.
pub fn natural_map_defect(law: &InterfaceLaw, rho: f64, r_dry: Vec3, x: Vec3) -> Vec3 {
    let s = law.tangent_scale();
    let (r, y) = if s == 1.0 {
        (r_dry, x)
    } else {
        (unscale(r_dry, s), scale(x, s))
    };
    let p = dry_projection(bipotential_trial(r, y, law.mu, rho), law.mu).0;
    let d = r - p;
    if s == 1.0 {
        d
    } else {
        scale(d, s)
    }
}
