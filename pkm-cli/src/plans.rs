//! A mechanism's solution plans, planar or spatial, as the command line and
//! the report run them through the plan interpreter. The one place pkm-cli
//! calls the planners: a change in how plans are obtained stays here.

use pkm_dsl::{Analysis, Diagnostics};
use pkm_runtime::model::Model;
use pkm_runtime::primitives::Sign;
use pkm_runtime::singular;
use pkm_runtime::spatial::Pose3;

/// A solution plan, planar or spatial.
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
            pkm_dsl::plan::forward_plan(a).map(AnyPlan::Planar)
        } else {
            pkm_dsl::plan3::forward_plan(a).map(AnyPlan::Spatial)
        }
    }

    /// The inverse plan (declared outputs to joints) of `a`, planar when its model is.
    pub fn inverse(a: &Analysis, planar: bool) -> Result<AnyPlan, Diagnostics> {
        if planar {
            pkm_dsl::plan::inverse_plan(a).map(AnyPlan::Planar)
        } else {
            pkm_dsl::plan3::inverse_plan(a).map(AnyPlan::Spatial)
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
