//! Generated static stiffness (capability `stiffness`): the inverse
//! solution run on symbols gives every limb joint's unit twist, the limbs'
//! centres, the platform's reference point and the limbs' declared
//! properties, written out as straight-line Rust; the runtime's wrench
//! analysis ([`pkm_runtime::wrench::analyse_twists`]) turns them into the
//! actuation and constraint wrenches and `J`, and
//! [`pkm_runtime::stiffness::PlatformStiffness`] into `K = Jᵀ K_p J`, the
//! deflections and the directional stiffnesses.
//!
//! The limbs and their joints come from the model's structure
//! ([`pkm_runtime::wrench::limbs`]) at compile time; what depends on the
//! configuration (the twists and points) is traced, so the generated code
//! does not interpret the plan.

use super::{sym, Branch, Direction};
use crate::analysis::Analysis;
use crate::emit::Emit;
use crate::limb_properties::{LegStiffness, Limb};
use crate::trace::Sym;
use pkm_runtime::solution::PointRef;
use pkm_runtime::steps::Geometry;
use pkm_runtime::velocity::unit_twists;
use proc_macro2::TokenStream;
use quote::{format_ident, quote};

/// One limb joint variable in the trace.
struct Variable {
    joint: usize,
    variable: usize,
    actuated: bool,
    /// ω then v (6 symbols).
    twist: Vec<Sym>,
}

/// One limb in the trace.
struct TracedLimb {
    joints: Vec<usize>,
    variables: Vec<Variable>,
    distal: [Sym; 3],
    centres: Vec<[Sym; 3]>,
}

/// A limb's declared properties as symbols of the parameters.
struct Properties {
    leg: LegStiffness<Sym>,
    actuator: Option<Sym>,
}

/// The stiffness of one mechanism in terms of the inverse solution.
pub(super) struct Traced {
    limbs: Vec<TracedLimb>,
    properties: Vec<Properties>,
    size: Sym,
    point: [Sym; 3],
}

/// Traces what `stiffness` computes from the solved branch `b`.
pub(super) fn trace(a: &Analysis, g: &Geometry<Sym>, b: &Branch) -> Result<Traced, String> {
    let m = &a.mechanism;
    // `check_capabilities` has refused a file without one.
    let (platform, point) = a
        .geometry
        .first_point_output()
        .ok_or("no output places a platform point")?;
    let model = crate::numeric::model(a, &Default::default()).map_err(|d| d.to_string())?;
    let paths = pkm_runtime::wrench::limbs(&model, platform).map_err(|e| e.to_string())?;
    if paths.len() > pkm_runtime::wrench::MAX_LIMBS {
        return Err(format!(
            "{} limbs: the stiffness takes at most {}",
            paths.len(),
            pkm_runtime::wrench::MAX_LIMBS
        ));
    }
    let world = |j: usize| {
        let l = a.point_link(j);
        b.poses[l].apply(g.local(PointRef::Joint(j), l))
    };
    let mut limbs = Vec::with_capacity(paths.len());
    let mut properties = Vec::with_capacity(paths.len());
    for path in paths {
        let Some(limb) = crate::limb_properties::with_joints(&a.limbs, |l: &Limb| &l.joints, &path) else {
            let names: Vec<&str> = path.iter().map(|&j| m.joints[j].name.as_str()).collect();
            return Err(format!(
                "the limb {} has no entry in the `limbs` block",
                names.join("–")
            ));
        };
        let to_sym = |v: &crate::limb_properties::LimbValue| sym(&v.expr);
        properties.push(Properties {
            leg: match &limb.leg {
                LegStiffness::Section { e, a, i } => LegStiffness::Section {
                    e: to_sym(e),
                    a: to_sym(a),
                    i: to_sym(i),
                },
                LegStiffness::Direct { axial, bending } => LegStiffness::Direct {
                    axial: to_sym(axial),
                    bending: to_sym(bending),
                },
            },
            actuator: limb.actuator.as_ref().map(to_sym),
        });
        let mut variables = Vec::new();
        for &j in &path {
            let jg = &g.joints[j];
            for (k, xi) in unit_twists(jg, b.states[j], &b.poses[jg.links[0]])
                .into_iter()
                .enumerate()
            {
                variables.push(Variable {
                    joint: j,
                    variable: k,
                    actuated: m.joints[j].actuated,
                    twist: xi.w.iter().chain(&xi.v).copied().collect(),
                });
            }
        }
        let names = || {
            path.iter()
                .map(|&j| m.joints[j].name.as_str())
                .collect::<Vec<_>>()
                .join("–")
        };
        if path.len() > pkm_runtime::wrench::MAX_LIMB_JOINTS
            || variables.len() > pkm_runtime::wrench::MAX_LIMB_VARIABLES
        {
            return Err(format!(
                "the limb {} has {} joints and {} joint variables: the stiffness takes at most {} and {}",
                names(),
                path.len(),
                variables.len(),
                pkm_runtime::wrench::MAX_LIMB_JOINTS,
                pkm_runtime::wrench::MAX_LIMB_VARIABLES
            ));
        }
        let last = *path.last().expect("a limb has a joint");
        let centres = pkm_runtime::wrench::centre_joints(&model, &path).map(world).collect();
        limbs.push(TracedLimb {
            distal: world(last),
            joints: path,
            variables,
            centres,
        });
    }
    Ok(Traced {
        limbs,
        properties,
        size: g.scale(),
        point: b.poses[platform].apply(g.local(point, platform)),
    })
}

impl Traced {
    /// Every symbol the generated function reads.
    fn roots(&self) -> Vec<Sym> {
        let mut out = Vec::new();
        for l in &self.limbs {
            out.extend(l.variables.iter().flat_map(|v| v.twist.iter().copied()));
            out.extend(l.distal);
            out.extend(l.centres.iter().flatten());
        }
        for p in &self.properties {
            match p.leg {
                LegStiffness::Section { e, a, i } => out.extend([e, a, i]),
                LegStiffness::Direct { axial, bending } => out.extend([axial, bending]),
            }
            out.extend(p.actuator);
        }
        out.push(self.size);
        out.extend(self.point);
        out
    }
}

/// The generated functions on the prepared solver: `stiffness_limbs`
/// (straight-line, verified like the inverse solution) and `stiffness`.
pub(super) fn functions(
    emit: &Emit,
    d: &Direction,
    t: &Traced,
    given_sig: &TokenStream,
    finite: &TokenStream,
    check_of: &dyn Fn(&[TokenStream]) -> TokenStream,
) -> TokenStream {
    let rt = quote! { ::pkm::runtime::__private };
    let roots = t.roots();
    let n_roots = roots.len();
    let mut all = roots.clone();
    all.extend(&d.given.residual);
    all.push(d.given.extent);
    let (lets, exprs) = emit.straight(&all, &emit.needed_guards(&all, &d.given.guards, &d.given.waivable));
    let (values, rest) = exprs.split_at(n_roots);
    let check = check_of(rest);
    // Each symbol's expression, by the symbol.
    let by_sym: std::collections::HashMap<Sym, TokenStream> = roots.into_iter().zip(values.iter().cloned()).collect();
    let e = |x: &Sym| by_sym[x].clone();
    let v3 = |p: &[Sym]| {
        let (x, y, z) = (e(&p[0]), e(&p[1]), e(&p[2]));
        quote! { #rt::nalgebra::Vector3::new(#x, #y, #z) }
    };
    let limbs: Vec<TokenStream> = t
        .limbs
        .iter()
        .map(|l| {
            let variables = l.variables.iter().map(|v| {
                let (w, vel) = (v3(&v.twist[..3]), v3(&v.twist[3..]));
                let (joint, variable, actuated) = (v.joint, v.variable, v.actuated);
                quote! {
                    #rt::wrench::LimbVariable {
                        joint: #joint,
                        variable: #variable,
                        actuated: #actuated,
                        twist: #rt::velocity::Twist { w: #w, v: #vel },
                    }
                }
            });
            let distal = v3(&l.distal);
            let centres = l.centres.iter().map(|c| v3(c));
            let joints = &l.joints;
            // Inline lists (`From` an array: its size checked when compiled).
            quote! {
                #rt::wrench::LimbTwists {
                    joints: ::core::convert::From::from([#(#joints),*]),
                    variables: ::core::convert::From::from([#(#variables),*]),
                    distal: #distal,
                    centres: ::core::convert::From::from([#(#centres),*]),
                }
            }
        })
        .collect();
    let properties: Vec<TokenStream> = t
        .properties
        .iter()
        .map(|p| {
            let section = match p.leg {
                LegStiffness::Section { e: young, a, i } => {
                    let (young, area, inertia) = (e(&young), e(&a), e(&i));
                    quote! { #rt::stiffness::Section::Beam { e: #young, area: #area, inertia: #inertia } }
                }
                LegStiffness::Direct { axial, bending } => {
                    let (axial, bending) = (e(&axial), e(&bending));
                    quote! {
                        #rt::stiffness::Section::Springs {
                            axial: #axial,
                            bending: #bending,
                            couple: ::core::option::Option::None,
                        }
                    }
                }
            };
            let actuator = match &p.actuator {
                Some(k) => {
                    let k = e(k);
                    quote! { ::core::option::Option::Some(#k) }
                }
                None => quote! { ::core::option::Option::None },
            };
            quote! { #rt::stiffness::LimbProperties { section: #section, actuator: #actuator } }
        })
        .collect();
    let size = e(&t.size);
    let [px, py, pz] = t.point.map(|x| e(&x));
    let n_limbs = t.limbs.len();
    let (n_given, n_choices) = (d.plan.n_inputs, d.plan.branches);
    quote! {
        /// What the static stiffness of one branch reads, written out: each
        /// limb's joint twists and centres, the limbs' properties, the
        /// model's size and the reference point; verified like the inverse
        /// solution.
        #[allow(clippy::type_complexity)]
        fn stiffness_limbs(
            &self,
            #given_sig,
        ) -> ::core::result::Result<
            (
                [#rt::wrench::LimbTwists; #n_limbs],
                [#rt::stiffness::LimbProperties; #n_limbs],
                f64,
                [f64; 3],
            ),
            #rt::solution::SolveError,
        > {
            let _ = &signs;
            #finite
            #lets
            #check
            ::core::result::Result::Ok((
                [#(#limbs),*],
                [#(#properties),*],
                #size,
                [#px, #py, #pz],
            ))
        }

        /// The platform's static stiffness for one branch at the pose
        /// `given`: each limb's actuation and constraint wrenches, their
        /// stack `J`, the springs `K_p` from the declared limbs and `K =
        /// Jᵀ K_p J`, referred to the platform point the outputs place
        /// (forces in N, lengths in the file's unit). A singular
        /// configuration is a typed error naming its kind.
        pub fn stiffness(
            &self,
            given: &[f64; #n_given],
            signs: [#rt::primitives::Sign; #n_choices],
        ) -> ::core::result::Result<#rt::stiffness::PlatformStiffness, #rt::stiffness::StiffnessError> {
            let (limbs, properties, scale, point) = self
                .stiffness_limbs(given, signs)
                .map_err(#rt::stiffness::StiffnessError::Position)?;
            #rt::stiffness::PlatformStiffness::from_twists(&limbs, scale, &properties, point)
        }
    }
}

/// `Name::stiffness`, which prepares and calls the prepared solver's.
pub(super) fn items(ident: &proc_macro2::Ident, d: &Direction) -> TokenStream {
    let rt = quote! { ::pkm::runtime::__private };
    let params_ty = format_ident!("{}Params", ident);
    let (n_given, n_choices) = (d.plan.n_inputs, d.plan.branches);
    let doc = format!(" The platform's static stiffness for one branch ([`{ident}Prepared::stiffness`]).");
    quote! {
        #[automatically_derived]
        impl #ident {
            #[doc = #doc]
            /// Prepares the solver and solves: to solve often at the same
            /// parameters, prepare once (`prepare`) and call its `stiffness`.
            pub fn stiffness(
                params: &#params_ty,
                q: &[f64; #n_given],
                signs: [#rt::primitives::Sign; #n_choices],
            ) -> ::core::result::Result<#rt::stiffness::PlatformStiffness, #rt::stiffness::StiffnessError> {
                Self::prepare(params).stiffness(q, signs)
            }
        }
    }
}
