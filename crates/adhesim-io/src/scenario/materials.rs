//! A body's `material`: the compressible (coupled) models, the nearly incompressible
//! (uncoupled) ones and their optional Prony series.

use super::{Ctx, FileMaterial, ScenarioError};
use adhesim::material::{self, Hyperelastic};
use std::sync::Arc;

/// The material of the table at `key` (`body[i].material`); moduli in Pa.
pub(super) fn build_material(
    m: &FileMaterial,
    key: &str,
    ctx: &Ctx,
) -> Result<Arc<dyn Hyperelastic>, ScenarioError> {
    if matches!(
        m.model.as_str(),
        "uncoupled-neo-hookean" | "mooney-rivlin" | "ogden"
    ) {
        let elastic = build_uncoupled_material(m, key, ctx)?;
        let Some(prony) = &m.prony else {
            return Ok(elastic);
        };
        let terms = prony_terms(prony, key, ctx)?;
        return Ok(Arc::new(material::Viscoelastic { elastic, terms }));
    }
    reject_uncoupled_keys(m, key, ctx)?;
    build_coupled_material(m, key, ctx)
}

/// The Prony series `prony = [[g1, tau1], ...]`: relative moduli g in (0, 1) adding up to
/// less than 1, relaxation times tau [s].
fn prony_terms(
    prony: &[[f64; 2]],
    key: &str,
    ctx: &Ctx,
) -> Result<Vec<material::PronyTerm>, ScenarioError> {
    if prony.is_empty() || prony.len() > 12 {
        return Err(ctx.err(format!(
            "`{key}.prony` needs 1 to 12 terms [[g1, tau1], ...], got {}",
            prony.len()
        )));
    }
    let mut terms = Vec::new();
    for (i, &[g, tau]) in prony.iter().enumerate() {
        if !(g > 0.0 && g < 1.0) {
            return Err(ctx.err(format!(
                "`{key}.prony[{i}]`: the relative modulus g must be in (0, 1), got {g}"
            )));
        }
        ctx.positive(&format!("{key}.prony[{i}] (relaxation time tau [s])"), tau)?;
        terms.push(material::PronyTerm { g, tau });
    }
    let total: f64 = terms.iter().map(|t| t.g).sum();
    if total >= 1.0 {
        return Err(ctx.err(format!(
            "`{key}.prony`: the relative moduli add up to {total}; their sum must stay below 1 (the long-term shear modulus is μ (1 − Σ g))"
        )));
    }
    Ok(terms)
}

/// Rejects the keys of the uncoupled models (and `prony`) on a coupled model.
fn reject_uncoupled_keys(m: &FileMaterial, key: &str, ctx: &Ctx) -> Result<(), ScenarioError> {
    let extra = [
        ("c10", m.c10.is_some()),
        ("c01", m.c01.is_some()),
        ("d1", m.d1.is_some()),
        ("kappa", m.kappa.is_some()),
        ("mu", m.mu.is_some()),
        ("alpha", m.alpha.is_some()),
        ("prony", m.prony.is_some()),
    ];
    if let Some((name, _)) = extra.iter().find(|(_, given)| *given) {
        return Err(ctx.err(format!(
            "`{key}.{name}` is not used by model {:?}; it belongs to \"uncoupled-neo-hookean\", \"mooney-rivlin\" or \"ogden\"",
            m.model
        )));
    }
    Ok(())
}

/// The compressible models: Blatz-Ko (shear modulus `g`), neo-Hookean, Saint Venant-Kirchhoff
/// and linear elastic (Young's modulus and Poisson's ratio).
fn build_coupled_material(
    m: &FileMaterial,
    key: &str,
    ctx: &Ctx,
) -> Result<Arc<dyn Hyperelastic>, ScenarioError> {
    Ok(match m.model.as_str() {
        "blatz-ko" => {
            if m.young.is_some() || m.poisson.is_some() {
                return Err(ctx.err(format!("`{key}`: the Blatz-Ko model takes only `g` (shear modulus [Pa]); its Poisson ratio is ¼")));
            }
            let g = m.g.ok_or_else(|| ctx.err(format!("`{key}` with model \"blatz-ko\" needs `g` (shear modulus [Pa])")))?;
            Arc::new(material::BlatzKo { g: ctx.positive(&format!("{key}.g"), g)? })
        }
        "neo-hookean" => {
            let (e, nu) = young_poisson(m, key, ctx)?;
            Arc::new(material::NeoHookean::from_young_poisson(e, nu))
        }
        "saint-venant-kirchhoff" => {
            let (e, nu) = young_poisson(m, key, ctx)?;
            Arc::new(material::SaintVenantKirchhoff::from_young_poisson(e, nu))
        }
        "linear-elastic" => {
            let (e, nu) = young_poisson(m, key, ctx)?;
            Arc::new(material::LinearElastic::from_young_poisson(e, nu))
        }
        other => {
            return Err(ctx.err(format!(
                "`{key}.model` = {other:?}; valid models are \"blatz-ko\", \"neo-hookean\", \"saint-venant-kirchhoff\", \"linear-elastic\", \"uncoupled-neo-hookean\", \"mooney-rivlin\", \"ogden\""
            )))
        }
    })
}

/// Young's modulus [Pa] and Poisson's ratio (in (−1, ½)) of a coupled model, which takes no
/// `g`.
fn young_poisson(m: &FileMaterial, key: &str, ctx: &Ctx) -> Result<(f64, f64), ScenarioError> {
    let e = m.young.ok_or_else(|| {
        ctx.err(format!(
            "`{key}` with model {:?} needs `young` [Pa] and `poisson`",
            m.model
        ))
    })?;
    let nu = m.poisson.ok_or_else(|| {
        ctx.err(format!(
            "`{key}` with model {:?} needs `young` [Pa] and `poisson`",
            m.model
        ))
    })?;
    ctx.positive(&format!("{key}.young"), e)?;
    if !(nu > -1.0 && nu < 0.5) {
        return Err(ctx.err(format!("`{key}.poisson` must be in (−1, 0.5), got {nu}")));
    }
    if m.g.is_some() {
        return Err(ctx.err(format!(
            "`{key}.g` is not used by model {:?}; give `young` and `poisson`",
            m.model
        )));
    }
    Ok((e, nu))
}

/// A material table of one of the uncoupled models, with the keys that model takes.
struct Uncoupled<'a> {
    m: &'a FileMaterial,
    model: &'a str,
    allowed: &'static [&'static str],
    key: &'a str,
    ctx: &'a Ctx<'a>,
}

/// The nearly incompressible (uncoupled) models: the isochoric parameters and a bulk modulus,
/// `kappa` [Pa] or the Abaqus `d1` [1/Pa] (κ = 2/D₁); the neo-Hookean one also accepts
/// `young` and `poisson` (ν < ½).
fn build_uncoupled_material(
    m: &FileMaterial,
    key: &str,
    ctx: &Ctx,
) -> Result<Arc<dyn Hyperelastic>, ScenarioError> {
    let model = m.model.as_str();
    let allowed: &[&str] = match model {
        "uncoupled-neo-hookean" => &["c10", "kappa", "d1", "young", "poisson"],
        "mooney-rivlin" => &["c10", "c01", "kappa", "d1"],
        _ => &["mu", "alpha", "kappa", "d1"],
    };
    let u = Uncoupled {
        m,
        model,
        allowed,
        key,
        ctx,
    };
    u.reject_other_keys()?;
    match model {
        "uncoupled-neo-hookean" => u.neo_hookean(),
        "mooney-rivlin" => u.mooney_rivlin(),
        _ => u.ogden(),
    }
}

impl Uncoupled<'_> {
    /// Rejects a given key that the model does not take.
    fn reject_other_keys(&self) -> Result<(), ScenarioError> {
        let (m, key, model, allowed) = (self.m, self.key, self.model, self.allowed);
        let given = [
            ("g", m.g.is_some()),
            ("young", m.young.is_some()),
            ("poisson", m.poisson.is_some()),
            ("c10", m.c10.is_some()),
            ("c01", m.c01.is_some()),
            ("d1", m.d1.is_some()),
            ("kappa", m.kappa.is_some()),
            ("mu", m.mu.is_some()),
            ("alpha", m.alpha.is_some()),
        ];
        if let Some((name, _)) = given.iter().find(|(name, g)| *g && !allowed.contains(name)) {
            return Err(self.ctx.err(format!(
                "`{key}.{name}` is not used by model {model:?}; its keys are {}",
                allowed.join(", ")
            )));
        }
        Ok(())
    }

    /// The bulk modulus κ [Pa], given as `kappa` or as `d1` (κ = 2/D₁).
    fn bulk(&self) -> Result<f64, ScenarioError> {
        let (key, model, ctx) = (self.key, self.model, self.ctx);
        match (self.m.kappa, self.m.d1) {
            (Some(_), Some(_)) => Err(ctx.err(format!(
                "`{key}`: give the bulk modulus either as `kappa` [Pa] or as `d1` [1/Pa] (κ = 2/D1), not both"
            ))),
            (Some(k), None) => ctx.positive(&format!("{key}.kappa"), k),
            (None, Some(d1)) => Ok(material::bulk_from_d1(
                ctx.positive(&format!("{key}.d1"), d1)?,
            )),
            (None, None) => Err(ctx.err(format!(
                "`{key}` with model {model:?} needs a bulk modulus: `kappa` [Pa] or `d1` [1/Pa] (κ = 2/D1)"
            ))),
        }
    }

    /// The modulus `name` [Pa], which the model needs, as a finite number.
    fn need(&self, v: Option<f64>, name: &str) -> Result<f64, ScenarioError> {
        let (key, model, ctx) = (self.key, self.model, self.ctx);
        let v = v.ok_or_else(|| {
            ctx.err(format!(
                "`{key}` with model {model:?} needs `{name}` [Pa]; its keys are {}",
                self.allowed.join(", ")
            ))
        })?;
        ctx.finite(&format!("{key}.{name}"), v)
    }

    /// The uncoupled neo-Hookean model, from `c10` and κ or from `young` and `poisson`.
    fn neo_hookean(&self) -> Result<Arc<dyn Hyperelastic>, ScenarioError> {
        let (m, key, ctx) = (self.m, self.key, self.ctx);
        if m.young.is_none() && m.poisson.is_none() {
            let c10 = ctx.positive(&format!("{key}.c10"), self.need(m.c10, "c10")?)?;
            let kappa = self.bulk()?;
            return Ok(Arc::new(material::UncoupledNeoHookean { c10, kappa }));
        }
        if m.c10.is_some() || m.kappa.is_some() || m.d1.is_some() {
            return Err(ctx.err(format!(
                "`{key}`: give either `young` and `poisson`, or `c10` and `kappa` (or `d1`), not both"
            )));
        }
        let e = ctx.positive(&format!("{key}.young"), self.need(m.young, "young")?)?;
        let nu = m
            .poisson
            .ok_or_else(|| ctx.err(format!("`{key}` with `young` needs `poisson` too")))?;
        if !(nu > -1.0 && nu < 0.5) {
            return Err(ctx.err(format!(
                "`{key}.poisson` must be in (−1, 0.5), got {nu}; for incompressibility use e.g. 0.4999"
            )));
        }
        Ok(Arc::new(material::UncoupledNeoHookean::from_young_poisson(
            e, nu,
        )))
    }

    /// The Mooney-Rivlin model: `c10`, `c01` (default 0) with c10 + c01 > 0, and κ.
    fn mooney_rivlin(&self) -> Result<Arc<dyn Hyperelastic>, ScenarioError> {
        let (m, key, ctx) = (self.m, self.key, self.ctx);
        let c10 = self.need(m.c10, "c10")?;
        let c01 = m
            .c01
            .map_or(Ok(0.0), |v| ctx.finite(&format!("{key}.c01"), v))?;
        if c10 + c01 <= 0.0 {
            return Err(ctx.err(format!(
                "`{key}`: the shear modulus 2 (c10 + c01) must be positive, got c10 = {c10}, c01 = {c01}"
            )));
        }
        let kappa = self.bulk()?;
        Ok(Arc::new(material::MooneyRivlin { c10, c01, kappa }))
    }

    /// The Ogden model: the terms `mu` [Pa] and `alpha`, and κ.
    fn ogden(&self) -> Result<Arc<dyn Hyperelastic>, ScenarioError> {
        let (mu, alpha) = self.ogden_terms()?;
        let kappa = self.bulk()?;
        Ok(Arc::new(material::Ogden { mu, alpha, kappa }))
    }

    /// The Ogden terms μᵢ [Pa] and αᵢ: 1 to 6 of each, μᵢαᵢ > 0.
    fn ogden_terms(&self) -> Result<(Vec<f64>, Vec<f64>), ScenarioError> {
        let (key, ctx) = (self.key, self.ctx);
        let (mu, alpha) = match (&self.m.mu, &self.m.alpha) {
            (Some(mu), Some(alpha)) => (mu.clone(), alpha.clone()),
            _ => {
                return Err(ctx.err(format!(
                    "`{key}` with model \"ogden\" needs `mu = [μ1, ...]` [Pa] and `alpha = [α1, ...]` of the same length"
                )))
            }
        };
        if mu.is_empty() || mu.len() != alpha.len() || mu.len() > 6 {
            return Err(ctx.err(format!(
                "`{key}.mu` and `{key}.alpha` must have the same length, 1 to 6 terms; got {} and {}",
                mu.len(),
                alpha.len()
            )));
        }
        for (i, (&mi, &ai)) in mu.iter().zip(&alpha).enumerate() {
            ctx.finite(&format!("{key}.mu[{i}]"), mi)?;
            if !ai.is_finite() || ai == 0.0 {
                return Err(ctx.err(format!(
                    "`{key}.alpha[{i}]` must be a finite non-zero number, got {ai}"
                )));
            }
            if mi * ai <= 0.0 {
                return Err(ctx.err(format!(
                    "`{key}`: term {i} has μ·α = {} ≤ 0; each term needs μᵢαᵢ > 0 to be stable in the small-strain limit",
                    mi * ai
                )));
            }
        }
        Ok((mu, alpha))
    }
}
