//! The root package's integration tests in one binary, in cargo's own
//! `tests/testsuite/main.rs` pattern: one module per subject, linked once
//! (`cargo test --test testsuite MODULE::` runs one of them). The helpers
//! in `tests/common/` are shared with pkm-cli's tests and the benches,
//! which include them by `#[path]` as well.

#[path = "../common/mod.rs"]
mod common;
mod mechanisms;
#[path = "../common/work_precision.rs"]
mod work_precision;

mod allocations;
mod ball_legs;
mod batch;
mod consistency;
mod contract;
mod docs;
mod dynamics_agreement;
mod dynamics_generated;
mod fk_agreement;
mod fk_follow;
mod fk_generated;
mod fk_numeric;
mod fk_planar;
mod fuzz;
mod ik_agreement;
mod ik_planar;
mod limits;
mod near_coincident;
mod newton_euler;
mod paper_topology;
mod planar_univariate;
mod pose_parts;
mod rates;
mod reference;
mod round_trip_conditioning;
mod round_trips;
mod seed000_dynamics;
mod seed000_kinematics;
mod seed003_dynamics;
mod seed004;
mod singularities;
mod snapshots;
mod spatial_generated;
mod sphere_centres;
mod stiffness_generated;
mod trajectory;
mod upx_legs;
mod velocity;
mod virtual_work;
mod wrenches;
