//! A mechanism's analysis: its model, geometry and topology from one text
//! (`analyze_source`), and the topology report `pkm analyze` prints and the
//! generated type's `REPORT` holds.

use crate::semantics::mechanism::Mechanism;
use crate::topology::{delta_unicode, Topology};
use std::fmt::Write;

/// A mechanism together with its analysis.
#[derive(Debug, Clone)]
pub struct Analysis {
    /// The semantic model.
    pub mechanism: Mechanism,
    /// The topology.
    pub topology: Topology,
    /// Parameters and geometry.
    pub geometry: crate::semantics::geometry::Geometry,
    /// Units, mass properties, gravity and loads.
    pub mass_and_loads: crate::semantics::mass_and_loads::MassAndLoads,
    /// The declared limbs' properties for the stiffness model, checked, in
    /// branch order (only the branches given in `limbs { … }`).
    pub limbs: Vec<crate::semantics::limb_properties::Limb>,
}

impl Analysis {
    /// The joint names of a list of joint indices.
    pub fn names(&self, joints: &[usize]) -> Vec<String> {
        joints.iter().map(|&j| self.mechanism.joints[j].name.clone()).collect()
    }

    /// The link whose place is joint `joint`'s point: the slider's for a P
    /// joint (the link without the guide line), otherwise its first link.
    pub fn point_link(&self, joint: usize) -> usize {
        let links = self.mechanism.joints[joint].links;
        let guide_first = matches!(
            self.place(joint, links[0]),
            crate::semantics::geometry::JointPlace::Line(..)
        );
        links[usize::from(guide_first)]
    }

    /// Where joint `joint` sits on `link` (one of its two links), in a complete geometry.
    pub fn place(&self, joint: usize, link: usize) -> &crate::semantics::geometry::JointPlace {
        let side = self.mechanism.joints[joint]
            .links
            .iter()
            .position(|&l| l == link)
            .expect("the joint touches the link");
        self.geometry.places[joint][side]
            .as_ref()
            .expect("a complete geometry places every joint")
    }

    /// The platform's POC set in Unicode, or an empty string without a platform.
    pub fn platform_poc(&self) -> String {
        self.topology
            .platform_poc
            .as_ref()
            .map(|p| p.unicode())
            .unwrap_or_default()
    }

    /// The human-readable report.
    pub fn report(&self) -> String {
        let m = &self.mechanism;
        let t = &self.topology;
        let mut s = String::new();
        let _ = writeln!(s, "mechanism {}", m.name);
        if let Some(title) = &m.title {
            let _ = writeln!(s, "  {title}");
        }
        // Local (idle) DOF are not counted in Σf (an S–S link's spin about
        // its S–S line): say how many were left out, where any were.
        let joints_f: usize = m.joints.iter().map(|j| j.kind.dof()).sum();
        let idle = match joints_f.saturating_sub(t.total_f) {
            0 => String::new(),
            1 => format!(" ({joints_f} less 1 local idle DOF)"),
            i => format!(" ({joints_f} less {i} local idle DOF)"),
        };
        // A U joint is one joint of f = 2 here; the model holds it as two
        // revolutes and a cross link, which adds one link and one joint each.
        let u = m.universals.len();
        let held = if u > 0 {
            format!(
                " (U joints counted once; as two revolutes and a cross each: n = {}, m = {})",
                m.links.len(),
                m.joints.len()
            )
        } else {
            String::new()
        };
        let _ = writeln!(
            s,
            "\nlinks n = {}, joints m = {}, loops v = m − n + 1 = {}, Σf = {}{idle}{held}",
            m.links.len() - u,
            m.joints.len() - u,
            t.loops,
            t.total_f
        );
        let _ = writeln!(s, "\nPOC sets");
        for (j, joint) in m.joints.iter().enumerate() {
            if let Some(u) = m.universals.iter().find(|u| u.halves.contains(&j)) {
                // R∧R: two rotations about the U's centre, no translation of it.
                if u.halves[0] == j {
                    let [a, b] = u.halves.map(|h| m.joints[h].name.as_str());
                    let poc = crate::topology::PocSet {
                        t: 0,
                        t_dir: None,
                        r: 2,
                        r_dir: Some(format!("∥◇({a},{b})")),
                        dim: 2,
                    };
                    let _ = writeln!(s, "  {:<8} {:<3} {poc}", u.name, "U");
                }
                continue;
            }
            let mark = if joint.actuated { "*" } else { "" };
            let _ = writeln!(
                s,
                "  {:<8} {:<3} {}",
                format!("{}{mark}", joint.name),
                joint.kind.symbol(),
                t.joint_poc[j]
            );
        }
        for (b, br) in m.branches.iter().enumerate() {
            if let Some(p) = t.branch_poc.get(b) {
                let own = match t.branch_own_poc.get(b) {
                    Some(Some((j, own))) => format!(
                        "; {own} at its own {}, the rest derived at o by its rotations",
                        m.joints[*j].name
                    ),
                    _ => String::new(),
                };
                let _ = writeln!(s, "  branch {:<5} M_b = {p}  (dim {}{own})", br.name, p.dim);
            }
        }
        if let Some(p) = &t.platform_poc {
            let o = t
                .base_point
                .map(|j| format!(", o on {}", m.joints[j].name))
                .unwrap_or_default();
            match (m.platform, m.output_link) {
                (None, Some((l, _))) => {
                    let _ = writeln!(s, "  output link {}  M = {p}  (dim {}{o})", m.links[l].name, p.dim);
                }
                _ => {
                    let _ = writeln!(s, "  platform     M_Pa = {p}  (dim {}{o})", p.dim);
                }
            }
        }
        let _ = writeln!(s, "\nordered single open chains");
        for (j, soc) in t.socs.iter().enumerate() {
            let _ = writeln!(
                s,
                "  SOC{} {{{}}}  {} → {}:  Σf = {}, I = {}, ξ_L{} = {}, Δ{} = {}",
                j + 1,
                soc.notation,
                m.links[soc.ends[0]].name,
                m.links[soc.ends[1]].name,
                soc.dof,
                soc.actuators,
                j + 1,
                soc.xi,
                j + 1,
                delta_unicode(soc.delta)
            );
        }
        if let Some(generic) = t.generic_dof {
            let _ = writeln!(
                s,
                "\nmobility by geometry: counted at configurations of the declared dimensions\n  \
                 (generic instances of the declared relations give F = {generic})"
            );
        }
        let _ = writeln!(
            s,
            "\nF = Σf − Σξ_L = {} − {} = {}",
            t.total_f,
            t.xi().iter().map(|x| x.to_string()).collect::<Vec<_>>().join(" − "),
            t.dof
        );
        for (k, skc) in t.skcs.iter().enumerate() {
            let socs: Vec<String> = skc.socs.clone().map(|j| format!("SOC{}", j + 1)).collect();
            let _ = writeln!(s, "SKC{}: {}, κ{} = {}", k + 1, socs.join(" + "), k + 1, skc.kappa);
        }
        let _ = writeln!(s, "κ = {}", t.kappa);
        let _ = writeln!(s, "\n{}", t.expression);
        if !t.decoupling.is_empty() {
            let _ = writeln!(
                s,
                "\nmotion decoupling (outputs of the base point o and the platform's rotation)"
            );
            for d in t.decoupling.iter().filter(|d| !d.parasitic) {
                let _ = writeln!(s, "  {:<3} ← {}", d.output, self.names(&d.inputs).join(", "));
            }
            let parasitic: Vec<&crate::topology::Dependence> = t.decoupling.iter().filter(|d| d.parasitic).collect();
            if !parasitic.is_empty() {
                let independent: Vec<&str> = t
                    .decoupling
                    .iter()
                    .filter(|d| !d.parasitic)
                    .map(|d| d.output.as_str())
                    .collect();
                let _ = writeln!(
                    s,
                    "  parasitic motions (the POC set has dim {}: they follow {}, the outputs declared)",
                    independent.len(),
                    independent.join(", ")
                );
                for d in parasitic {
                    let _ = writeln!(s, "  {:<3} ← {}", d.output, self.names(&d.inputs).join(", "));
                }
            } else if let Some(p) = t.platform_poc.as_ref().filter(|p| t.decoupling.len() > p.dim) {
                let name = |l: usize| m.links[l].name.as_str();
                let hint = match m.platform {
                    Some(l) if !m.planar => format!(
                        "; declare its independent outputs as `pose (…) of {}` to name them",
                        name(l)
                    ),
                    _ => String::new(),
                };
                let _ = writeln!(
                    s,
                    "  (the POC set has dim {}: only {} of these {} are independent, the others follow them{hint})",
                    p.dim,
                    p.dim,
                    t.decoupling.len(),
                );
            }
        }
        let _ = writeln!(
            s,
            "\ncross-check: ξ_L by the POC formula ({}) = ξ_L by the loop-closure rank ({})",
            t.xi_by_poc_formula
                .iter()
                .map(|x| x.to_string())
                .collect::<Vec<_>>()
                .join(", "),
            t.xi().iter().map(|x| x.to_string()).collect::<Vec<_>>().join(", ")
        );
        s
    }
}

/// Parses, builds and analyses a mechanism text.
///
/// ```
/// let a = pkm_dsl::analyze_source("mechanism five_bar { planar; base R1* ∥ R2 ∥ R3 ∥ R4 ∥ R5* base; }").unwrap();
/// assert_eq!(a.topology.dof, 2);
/// ```
pub fn analyze_source(source: &str) -> Result<Analysis, crate::Diagnostics> {
    analyze_ast(&crate::syntax::parser::parse(source)?)
}

/// [`analyze_source`] from the parsed text.
pub fn analyze_ast(ast: &crate::syntax::ast::MechanismAst) -> Result<Analysis, crate::Diagnostics> {
    let ast = ast.clone();
    let mechanism = crate::semantics::mechanism::build(&ast)?;
    let geometry = crate::semantics::geometry::build(&ast, &mechanism);
    let topology = crate::topology::analyze(&mechanism);
    // Mass properties, loads and limb properties read the geometry's
    // parameters and points; their errors are reported together.
    let geometry = geometry.and_then(|g| {
        let declared = crate::semantics::mass_and_loads::Declared {
            units: &ast.units,
            masses: &ast.masses,
            gravity: &ast.gravity,
            loads: &ast.loads,
        };
        let masses = crate::semantics::mass_and_loads::resolve(declared, &mechanism, &g);
        let limbs = crate::semantics::limb_properties::check(&ast.limbs, !ast.units.is_empty(), &mechanism, &g);
        match (masses, limbs) {
            (Ok(d), Ok(l)) => Ok((g, d, l)),
            (Err(mut e), Err(f)) => {
                e.0.extend(f.0);
                Err(e)
            }
            (Err(e), _) | (_, Err(e)) => Err(e),
        }
    });
    // Report geometry and topology errors together.
    match (geometry, topology) {
        (Ok((geometry, mass_and_loads, limbs)), Ok(topology)) => Ok(Analysis {
            mechanism,
            topology,
            geometry,
            mass_and_loads,
            limbs,
        }),
        (Err(mut g), Err(t)) => {
            g.0.extend(t.0);
            Err(g)
        }
        (Err(e), _) | (_, Err(e)) => Err(e),
    }
}
