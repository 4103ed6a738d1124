//! The plan stage: the order in which a κ = 0 mechanism's joints are
//! solved, one closed-form step each (`planner`, planar and spatial alike),
//! and a κ = 1 mechanism's plan around one virtual variable
//! (`planner_numeric`). A plan is `pkm_runtime::plan::Plan`.

pub mod planner;
pub mod planner_numeric;

#[cfg(test)]
mod tests;
