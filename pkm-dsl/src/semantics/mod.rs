//! The semantic stage: from the syntax tree to the mechanism it describes,
//! checked. The model (`mechanism`: links, joints, relations; U joints as
//! two revolutes and a cross), its geometry at the parameters'
//! expressions (`geometry`), units, masses, gravity and loads
//! (`mass_and_loads`), the limbs' stiffness properties (`limb_properties`)
//! and the study a report samples (`study`). It imports only `syntax`.

pub mod geometry;
pub mod limb_properties;
pub mod mass_and_loads;
pub mod mechanism;
pub mod study;
