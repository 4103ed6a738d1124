//! Generated spatial solvers: the plan's steps as constants, each executed
//! by the runtime's `spatial::execute` (the kernel the interpreter runs), on
//! joint geometry written out as expressions in the parameters.

use crate::analysis::Analysis;
use crate::geometry::{JointPlace, Vec3};
use crate::model::JointKind;
use pkm_runtime::plan::PointRef;
use pkm_runtime::spatial::{Anchor, Constraint, Direction, Hop, Plan, Step};
use proc_macro2::TokenStream;
use quote::{format_ident, quote};

pub(crate) fn xyz(v: &Vec3) -> TokenStream {
    let params = quote! { params };
    let (x, y, z) = (
        v[0].to_tokens(&params),
        v[1].to_tokens(&params),
        v[2].to_tokens(&params),
    );
    quote! { [#x, #y, #z] }
}

pub(crate) fn place(p: &JointPlace) -> TokenStream {
    let m = quote! { ::pkm::runtime::model::Place };
    match p {
        JointPlace::Point(at, Some(axis)) => {
            let (at, axis) = (xyz(at), xyz(axis));
            quote! { #m::Axis { at: #at, axis: #axis } }
        }
        JointPlace::Point(at, None) => {
            let at = xyz(at);
            quote! { #m::Point { at: #at } }
        }
        JointPlace::Line(at, along) => {
            let (at, along) = (xyz(at), xyz(along));
            quote! { #m::Line { through: #at, along: #along } }
        }
        JointPlace::Arm(at, axis, arm) => {
            let (at, axis, arm) = (xyz(at), xyz(axis), xyz(arm));
            quote! { #m::Arm { at: #at, axis: #axis, arm: #arm } }
        }
    }
}

fn point_ref(p: PointRef) -> TokenStream {
    match p {
        PointRef::Joint(j) => quote! { ::pkm::runtime::plan::PointRef::Joint(#j) },
        PointRef::Named(n) => quote! { ::pkm::runtime::plan::PointRef::Named(#n) },
    }
}

fn hops(h: &[Hop]) -> TokenStream {
    let items = h.iter().map(|Hop { joint, forward }| {
        quote! { ::pkm::runtime::spatial::Hop { joint: #joint, forward: #forward } }
    });
    quote! { ::std::borrow::Cow::Borrowed(&[#(#items),*]) }
}

fn anchor(a: &Anchor) -> TokenStream {
    let (link, h, p) = (a.link, hops(&a.hops), point_ref(a.point));
    quote! { ::pkm::runtime::spatial::Anchor { link: #link, hops: #h, point: #p } }
}

fn direction(d: &Direction) -> TokenStream {
    let (link, h, joint) = (d.link, hops(&d.hops), d.joint);
    quote! { ::pkm::runtime::spatial::Direction { link: #link, hops: #h, joint: #joint } }
}

fn option<T: quote::ToTokens>(o: Option<T>) -> TokenStream {
    match o {
        Some(v) => quote! { ::core::option::Option::Some(#v) },
        None => quote! { ::core::option::Option::None },
    }
}

/// A step as a constant expression.
fn step(s: &Step) -> TokenStream {
    let sp = quote! { ::pkm::runtime::spatial };
    match s {
        Step::Place {
            link,
            point,
            input,
            about,
        } => {
            let (p, about) = (
                point_ref(*point),
                option(about.map(|a| {
                    let [x, y, z] = a;
                    quote! { [#x, #y, #z] }
                })),
            );
            quote! { #sp::Step::Place { link: #link, point: #p, input: #input, about: #about } }
        }
        Step::Transfer { joint, from, to, input } => {
            quote! { #sp::Step::Transfer { joint: #joint, from: #from, to: #to, input: #input } }
        }
        Step::Aim {
            joint,
            from,
            to,
            point,
            target,
        } => {
            let (p, t) = (point_ref(*point), anchor(target));
            quote! { #sp::Step::Aim { joint: #joint, from: #from, to: #to, point: #p, target: #t } }
        }
        Step::Locus {
            joint,
            from,
            to,
            point,
            constraint,
            branch,
        } => {
            let p = point_ref(*point);
            let c = match constraint {
                Constraint::Sphere { centre, pa } => {
                    let c = anchor(centre);
                    quote! { #sp::Constraint::Sphere { centre: #c, pa: #pa } }
                }
                Constraint::Plane { normal, anchor: a } => {
                    let (n, a) = (direction(normal), anchor(a));
                    quote! { #sp::Constraint::Plane { normal: #n, anchor: #a } }
                }
                Constraint::Cylinder { hops: h, joint, link } => {
                    let h = hops(h);
                    quote! { #sp::Constraint::Cylinder { hops: #h, joint: #joint, link: #link } }
                }
                Constraint::Slider { hops: h, joint, link } => {
                    let h = hops(h);
                    quote! { #sp::Constraint::Slider { hops: #h, joint: #joint, link: #link } }
                }
            };
            let b = option(*branch);
            quote! { #sp::Step::Locus { joint: #joint, from: #from, to: #to, point: #p, constraint: #c, branch: #b } }
        }
        Step::Align {
            joint,
            from,
            to,
            group,
            target,
        } => {
            let (g, t) = (direction(group), direction(target));
            quote! { #sp::Step::Align { joint: #joint, from: #from, to: #to, group: #g, target: #t } }
        }
        Step::PaPlane {
            joint,
            from,
            to,
            pa,
            target,
        } => {
            let t = anchor(target);
            quote! { #sp::Step::PaPlane { joint: #joint, from: #from, to: #to, pa: #pa, target: #t } }
        }
    }
}

/// The runtime's joint type of a joint kind (every kind with a numeric
/// model: the planners refuse the others before code is generated).
pub(crate) fn joint_type(kind: JointKind) -> TokenStream {
    match kind {
        JointKind::P => quote! { ::pkm::runtime::model::JointType::P },
        JointKind::Pa => quote! { ::pkm::runtime::model::JointType::Pa },
        JointKind::S => quote! { ::pkm::runtime::model::JointType::S },
        _ => quote! { ::pkm::runtime::model::JointType::R },
    }
}

/// The joints and named points at the parameters, generated once for both
/// directions: `Name::joints(params)` and `Name::named_points(params)`.
pub fn shared_items(a: &Analysis, ident: &proc_macro2::Ident) -> TokenStream {
    let m = &a.mechanism;
    let sp = quote! { ::pkm::runtime::spatial };
    let params_ty = format_ident!("{}Params", ident);
    let joints = m.joints.iter().enumerate().map(|(j, joint)| {
        let kind = joint_type(joint.kind);
        let [u, v] = joint.links;
        let (p0, p1) = (place(a.place(j, u)), place(a.place(j, v)));
        quote! {
            #sp::Joint3::new(#kind, [#u, #v], [#p0, #p1])
        }
    });
    let named: Vec<TokenStream> = a.geometry.points.iter().map(|p| xyz(&p.at)).collect();
    let (n_joints, n_named) = (m.joints.len(), named.len());
    quote! {
        #[automatically_derived]
        impl #ident {
            /// Every joint's geometry at `params` (order `JOINTS`), for the
            /// `*_poses` solvers: computed once, they serve many calls.
            pub fn joints(params: &#params_ty) -> [#sp::Joint3; #n_joints] {
                let _ = params;
                [#(#joints),*]
            }

            /// Every named point in its link's frame at `params`.
            pub fn named_points(params: &#params_ty) -> [[f64; 3]; #n_named] {
                let _ = params;
                [#(#named),*]
            }
        }
    }
}

/// Which given values of a plan are angles (the runtime's rule, on the
/// nominal model's joints).
fn angular_inputs(a: &Analysis, plan: &Plan) -> Vec<bool> {
    match crate::plan::model(a, &Default::default()) {
        Ok(model) => {
            let joints: Vec<pkm_runtime::spatial::Joint3> =
                model.joints.iter().map(pkm_runtime::spatial::Joint3::of).collect();
            plan.angular_inputs(&joints)
        }
        Err(_) => vec![false; plan.n_inputs],
    }
}

/// A spatial solver: the body of its `*_branch` function, the expression of
/// its solution, its number of ± choices, its input joints, and the
/// `*_poses` function (the steps alone, on joints computed beforehand).
pub fn body(
    a: &Analysis,
    plan: &Plan,
    ident: &proc_macro2::Ident,
    poses_fn: &proc_macro2::Ident,
    what: &str,
) -> (TokenStream, TokenStream, usize, Vec<usize>, TokenStream) {
    let m = &a.mechanism;
    let sp = quote! { ::pkm::runtime::spatial };
    let sol_ty = format_ident!("{}Solution", ident);
    let (n_joints, n_named, n_links) = (m.joints.len(), a.geometry.points.len(), m.links.len());
    let n_values = plan.n_inputs;
    let n_branches = plan.branches;
    let mut steps = Vec::new();
    for (k, s) in plan.steps.iter().enumerate() {
        let c = format_ident!("STEP_{}", k);
        let s = step(s);
        steps.push(quote! {
            const #c: #sp::Step = #s;
            #sp::execute(#k, &#c, joints, named, &mut poses, q, &signs, |j| {
                ::std::borrow::Cow::Borrowed(Self::JOINTS[j])
            })?;
        });
    }
    let doc = format!(
        " {what} position for one branch, link poses only (order of the links), on joints and named points from `joints` and `named_points`: the fast path for sweeps."
    );
    let signature = quote! {
        (
            joints: &[#sp::Joint3; #n_joints],
            named: &[[f64; 3]; #n_named],
            q: &[f64; #n_values],
            signs: [::pkm::runtime::primitives::Sign; #n_branches],
        ) -> ::core::result::Result<[#sp::Pose3; #n_links], ::pkm::runtime::plan::SolveError>
    };
    let steps_body = quote! {
        let _ = (&signs, named);
        if !q.iter().all(|v| v.is_finite()) {
            return ::core::result::Result::Err(::pkm::runtime::plan::SolveError::BadInput {
                what: ::std::borrow::Cow::Borrowed("a given value is not finite"),
            });
        }
        let mut poses = [#sp::Pose3::identity(); #n_links];
        #(#steps)*
        ::core::result::Result::Ok(poses)
    };
    // Joints no step closes are verified after the last step; the steps
    // alone serve the projection that names a contradicted given value.
    let open = plan.open_joints(n_joints);
    let poses_item = if open.is_empty() {
        quote! {
            #[automatically_derived]
            impl #ident {
                #[doc = #doc]
                pub fn #poses_fn #signature {
                    #steps_body
                }
            }
        }
    } else {
        let unverified = format_ident!("{}_unverified", poses_fn);
        let angular = angular_inputs(a, plan);
        let n_open = open.len();
        let names = if what == "Forward" {
            quote! { &Self::INPUTS }
        } else {
            quote! { &Self::OUTPUTS }
        };
        quote! {
            #[automatically_derived]
            impl #ident {
                #[doc = #doc]
                /// Verified: the joints no step closes must close.
                pub fn #poses_fn #signature {
                    const OPEN: [usize; #n_open] = [#(#open),*];
                    const ANGULAR: [bool; #n_values] = [#(#angular),*];
                    let poses = Self::#unverified(joints, named, q, signs)?;
                    #sp::verify(
                        joints,
                        &poses,
                        &OPEN,
                        &|j| ::std::borrow::Cow::Borrowed(Self::JOINTS[j]),
                        q,
                        &ANGULAR,
                        #names,
                        |g| {
                            let g: &[f64; #n_values] = g.try_into().ok()?;
                            Self::#unverified(joints, named, g, signs).ok().map(|p| p.to_vec())
                        },
                    )?;
                    ::core::result::Result::Ok(poses)
                }

                /// The steps alone, unverified.
                fn #unverified #signature {
                    #steps_body
                }
            }
        }
    };
    let body = quote! {
        let joints = Self::joints(params);
        let named = Self::named_points(params);
        let poses = Self::#poses_fn(&joints, &named, q, signs)?;
    };
    let mut points = Vec::new();
    for j in 0..m.joints.len() {
        let l = a.point_link(j);
        let at = xyz(a.place(j, l).at());
        points.push(quote! { #sp::at(&poses[#l], #at) });
    }
    for (k, np) in a.geometry.points.iter().enumerate() {
        let l = np.link;
        points.push(quote! { #sp::at(&poses[#l], named[#k]) });
    }
    let (lets, outputs) = crate::codegen_fk::outputs(a, |link, at, about| {
        let local = match at {
            PointRef::Joint(j) => xyz(a.place(j, link).at()),
            PointRef::Named(n) => quote! { named[#n] },
        };
        let at = quote! { #sp::at(&poses[#link], #local) };
        match about {
            crate::codegen_fk::Angle::About(k) => {
                let k = xyz(k);
                quote! {{ let [x, y, z] = #at; [x, y, z, #sp::angle_about(&poses[#link], #k)] }}
            }
            _ => at,
        }
    });
    let result = quote! {{
        let values = #sp::values(&joints, &poses);
        #lets
        #sol_ty { q: values, points: [#(#points),*], outputs: [#(#outputs),*] }
    }};
    (body, result, plan.branches, plan.inputs.clone(), poses_item)
}
