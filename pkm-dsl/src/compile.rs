//! The front door: [`compile`] runs the whole pipeline on a description,
//! the macro, the command line, the report and the tests alike:
//!
//! 1. parse (pest) → 2. model → 3. geometry → 4. topology
//!    ([`crate::analyze_source`], an [`Analysis`]) → 5. plans (the order in
//!    which a κ = 0 mechanism's joints are solved, [`Compiled::forward`],
//!    [`Compiled::inverse`], planned on first use) → 6. code
//!    ([`crate::expand`], from a [`Compiled`]).
//!
//! [`AnyPlan`] is a plan, planar or spatial, as the interpreter runs it.

use crate::{Analysis, Diagnostics};
use pkm_runtime::model::Model;
use pkm_runtime::primitives::Sign;
use pkm_runtime::singular;
use pkm_runtime::spatial::Pose3;
use std::cell::OnceCell;

/// A description compiled: its analysis, and its plans on first use.
#[derive(Debug)]
pub struct Compiled {
    /// Parse, model, geometry and topology.
    pub analysis: Analysis,
    forward: OnceCell<Result<AnyPlan, Diagnostics>>,
    inverse: OnceCell<Result<AnyPlan, Diagnostics>>,
}

/// Compiles a description: every error in it, or its analysis with the
/// plans to come.
///
/// ```
/// let c = pkm_dsl::compile("mechanism m { planar; base R1* ∥ R2 ∥ R3 ∥ R4 base; }").unwrap();
/// assert_eq!(c.analysis.topology.dof, 1);
/// // The forward plan: the crank given, the rest a dyad with its ± choice.
/// assert_eq!(c.forward().unwrap().choices(), 1);
/// ```
pub fn compile(source: &str) -> Result<Compiled, Diagnostics> {
    Ok(Compiled {
        analysis: crate::analyze_source(source)?,
        forward: OnceCell::new(),
        inverse: OnceCell::new(),
    })
}

impl Compiled {
    /// The forward plan (inputs to every joint), planned on first use.
    pub fn forward(&self) -> Result<&AnyPlan, Diagnostics> {
        let planar = self.analysis.mechanism.planar;
        self.forward
            .get_or_init(|| AnyPlan::forward(&self.analysis, planar))
            .as_ref()
            .map_err(Clone::clone)
    }

    /// The inverse plan (declared outputs to every joint), planned on first use.
    pub fn inverse(&self) -> Result<&AnyPlan, Diagnostics> {
        let planar = self.analysis.mechanism.planar;
        self.inverse
            .get_or_init(|| AnyPlan::inverse(&self.analysis, planar))
            .as_ref()
            .map_err(Clone::clone)
    }
}

/// A solution plan, planar or spatial.
#[derive(Debug, Clone, PartialEq)]
pub enum AnyPlan {
    /// A plan of a planar mechanism (every rotation about z).
    Planar(pkm_runtime::plan::Plan),
    /// A plan of a spatial mechanism.
    Spatial(pkm_runtime::spatial::Plan),
}

impl AnyPlan {
    /// The forward plan (inputs to joints) of `a`, planar when its model is.
    pub fn forward(a: &Analysis, planar: bool) -> Result<AnyPlan, Diagnostics> {
        if planar {
            crate::plan::forward_plan(a).map(AnyPlan::Planar)
        } else {
            crate::plan3::forward_plan(a).map(AnyPlan::Spatial)
        }
    }

    /// The inverse plan (declared outputs to joints) of `a`, planar when its model is.
    pub fn inverse(a: &Analysis, planar: bool) -> Result<AnyPlan, Diagnostics> {
        if planar {
            crate::plan::inverse_plan(a).map(AnyPlan::Planar)
        } else {
            crate::plan3::inverse_plan(a).map(AnyPlan::Spatial)
        }
    }

    /// How many ± choices the plan makes: it has 2^choices branches.
    pub fn choices(&self) -> usize {
        match self {
            AnyPlan::Planar(p) => p.branches,
            AnyPlan::Spatial(p) => p.branches,
        }
    }

    /// The joints a forward plan takes its given values for, in their order.
    pub fn inputs(&self, model: &Model) -> Vec<usize> {
        match self {
            AnyPlan::Planar(p) => p.inputs.clone(),
            AnyPlan::Spatial(p) if p.inputs.len() == p.n_inputs => p.inputs.clone(),
            AnyPlan::Spatial(_) => model.inputs(),
        }
    }

    /// The joint values of one branch, or why there is none.
    pub fn solve(&self, model: &Model, given: &[f64], signs: &[Sign]) -> Result<Vec<f64>, String> {
        match self {
            AnyPlan::Planar(p) => pkm_runtime::plan::run(model, p, given, signs).map(|s| s.values),
            AnyPlan::Spatial(p) => pkm_runtime::spatial::run(model, p, given, signs).map(|s| s.values),
        }
        .map_err(|e| e.to_string())
    }

    /// Its steps' determinant factors at the link poses `poses`.
    pub fn factors(&self, model: &Model, poses: &[Pose3]) -> Vec<singular::Factor> {
        match self {
            AnyPlan::Planar(p) => singular::planar_factors(model, p, poses),
            AnyPlan::Spatial(p) => singular::spatial_factors(model, p, poses),
        }
    }
}
