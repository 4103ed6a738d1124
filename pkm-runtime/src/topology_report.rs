//! The topology report that `pkm::mechanism!` attaches to every generated
//! type: plain `'static` data, built at compile time.

use core::fmt;

/// One single open chain (SOC) of the ordered decomposition.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SocReport {
    /// The chain in the papers' notation, e.g. `P1⊥R11∥R12∥R13⊥P2`.
    pub notation: &'static str,
    /// Σf of its joints.
    pub dof: usize,
    /// Its actuated joints, I_j.
    pub actuators: usize,
    /// ξ_Lj, the independent displacement equations of the loop it closes.
    pub xi: usize,
    /// The constraint degree Δ_j = Σf − I_j − ξ_Lj.
    pub delta: i32,
}

/// One sub-kinematic chain (SKC).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SkcReport {
    /// The indices of its SOCs (0-based) in the ordered decomposition.
    pub socs: &'static [usize],
    /// Its coupling degree κ_k = ½ Σ|Δ_j|.
    pub kappa: usize,
}

/// The POC topology of a mechanism, as computed at compile time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TopologyReport {
    /// The mechanism's name in its description.
    pub name: &'static str,
    /// Its title, or an empty string.
    pub title: &'static str,
    /// Full-cycle DOF F = Σf − Σξ_Lj.
    pub dof: usize,
    /// Independent loops v = m − n + 1.
    pub loops: usize,
    /// The coupling degree κ = max κ_k.
    pub kappa: usize,
    /// ξ_Lj of each SOC in order.
    pub xi: &'static [usize],
    /// Δ_j of each SOC in order.
    pub delta: &'static [i32],
    /// The ordered SOCs.
    pub socs: &'static [SocReport],
    /// The SKCs.
    pub skcs: &'static [SkcReport],
    /// The actuated joints, in declaration order.
    pub actuators: &'static [&'static str],
    /// The platform's POC set, e.g. `[t²(∥◇xoz); r¹(∥R6)]`, if there is a platform.
    pub platform_poc: Option<&'static str>,
    /// Each branch's name and the POC set of its end.
    pub branch_poc: &'static [(&'static str, &'static str)],
    /// The topological expression.
    pub expression: &'static str,
    /// Motion decoupling: each platform output and the actuated joints it depends on.
    pub decoupling: &'static [(&'static str, &'static [&'static str])],
    /// The whole report as text.
    pub text: &'static str,
}

impl TopologyReport {
    /// The number of sub-kinematic chains.
    pub const fn skc_count(&self) -> usize {
        self.skcs.len()
    }
}

impl fmt::Display for TopologyReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.text)
    }
}
